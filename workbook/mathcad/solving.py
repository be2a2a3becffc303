"""Mathcad's solve blocks: Given, its equations and inequalities, Find, Maximize and Minimize,
as ``[[solve]]`` blocks of the language."""

from __future__ import annotations

from ..language import expr as ex
from . import names as nm
from . import trees as tt
from .expressions import ExprTranslator
from .reader import MNode
from .symbols import Sym, Unknown, Untranslatable
from .symbols import key as _key
from .translation import Item


class SolveMixin:
    """The :class:`~workbook.mathcad.translate.Translator`'s solve blocks."""

    def close_given(self, why: str | None) -> None:
        """End the open solve block: its regions are listed if it was not translated."""
        if self.given is not None and why is not None:
            for rid in self.given:
                self.skip(rid, "a region of a solve block (Given ... Find)", why)
        self.given = None
        self.constraints = []
        self.guesses = []

    def find(self, et: ExprTranslator, args: list[MNode], method: str = "") -> ex.Node:
        """Find(x, ...) of a solve block: a [[solve]] block of the language (its unknowns are
        names of their own, the guesses the values the variables had before the block, as in
        Mathcad's)."""
        if self.given is None:
            raise Untranslatable("Find without Given")
        try:
            tree = self.solve_block(et, args, method)
        except Untranslatable as why:
            self.close_given(str(why))
            raise
        self.close_given(None)
        return tree

    def solve_block(self, et: ExprTranslator, args: list[MNode], method: str = "") -> ex.Node:
        if not args or any(a.tag != "id" for a in args):
            raise Untranslatable("Find of something that is not a list of names")
        self.guesses_of_parameters(et)
        # Mathcad's chain a = b = c (a comparison whose left side is one, without brackets)
        # is two equations, a = b and b = c
        eqs = [
            pair
            for c in self.constraints
            if c.children[0].tag == "equal"
            for pair in tt.equal_chain(c)
        ]
        ineqs = [c for c in self.constraints if c.children[0].tag != "equal"]
        if any(c.children[0].tag not in tt.INEQUALITY for c in ineqs):
            raise Untranslatable("a solve block with a condition that is not < <= > >=")
        method = tt.METHODS.get(method, "")
        if len(eqs) != len(args) and not (0 < len(eqs) < len(args) and method):
            raise Untranslatable(f"a solve block of {len(eqs)} equations in {len(args)} unknowns")
        local, unknowns = {}, []
        for a in args:
            key = _key(a)
            q = self.guess(et, a)  # the value before the block
            sym = self.new_sym("var", nm.identifier(*key), nm.mathcad_text(*key), self.given[0])
            local[key] = sym
            magnitude = float(q.magnitude)
            unit = "" if q.dimensionless else f" {q.units:~}"
            unknowns.append((sym, f"{magnitude!r}{unit}"))
        inner = ExprTranslator(self, {**et.local, **local})
        equations = []
        for lhs, rhs in eqs:
            left, right = inner.value(lhs), inner.value(rhs)
            equations.append(ex.Compare(("==",), (left, right)))
        conditions = [inner.visit(c) for c in ineqs]  # checked at the root found
        if inner.ranges:
            raise Untranslatable("a solve block over a range variable")
        self.out.items.append(
            Item(
                "solve",
                self.given[0],
                solve=(unknowns, equations, list(self.given), conditions),
                value=method,
            )
        )
        names = [ex.Name(sym.token()) for sym, _ in unknowns]
        if len(names) == 1:
            return names[0]
        return ex.Matrix(tuple((n,) for n in names))

    def guesses_of_parameters(self, et: ExprTranslator) -> None:
        """A Prime solve block that is a function's body (``f(N, M) := Find(e, k)``) whose guess
        values read the function's parameters (``k := M/(E*I)``): Prime computes them from each
        call's arguments, and a [[solve]] block's guesses are constants, the same at every call
        (from another guess the solver may reach another root): refused, with the guess named."""
        params = {k: s for k, s in et.local.items() if s.kind == "param"}
        for node in self.guesses:
            if node.tag not in ("define", "globalDefine") or len(node.children) != 2:
                continue
            lhs, rhs = node.children
            read = [_key(n) for n in tt.walk(rhs) if n.tag == "id" and _key(n) in params]
            if read:
                what = nm.mathcad_text(*_key(lhs)) if lhs.tag == "id" else "an unknown"
                raise Untranslatable(
                    f"a solve block that is a function's body whose guess of {what} reads the "
                    f"function's parameter {nm.mathcad_text(*read[0])} (Prime computes it from "
                    "each call's arguments; a [[solve]] block's guesses are constants)"
                )

    def guess(self, et: ExprTranslator, name: MNode):
        """The value of the name ``name`` before a solve block (its guess), as the engine
        computes it."""
        try:
            return self.at_import().quantity(et.visit(name))
        except Unknown:
            what = nm.mathcad_text(*_key(name))
            raise Untranslatable(f"the guess of {what} is not known") from None

    def extremum(self, et: ExprTranslator, args: list[MNode], largest: bool) -> ex.Node:
        """Maximize(f, x) / Minimize(f, x) from the guess x (and the inequalities of an open
        Given block): the stationary point of f nearest the guess where f curves down (up),
        a [[solve]] block of f's slope (a helper function of the derivative) == 0 by the
        `nearest` method, with the curvature's sign a condition."""
        what = "Maximize" if largest else "Minimize"
        given, constraints = self.given, self.constraints
        try:
            if len(args) != 2 or any(a.tag != "id" for a in args):
                raise Untranslatable(f"{what} of a function of {len(args) - 1} unknowns")
            if any(c.children[0].tag not in tt.INEQUALITY for c in constraints):
                raise Untranslatable(f"{what} with an equation in its Given block")
            fsym = et.local.get(_key(args[0])) or self.scope.get(_key(args[0]))
            if fsym is None or fsym.kind != "func" or fsym.broken:
                raise Untranslatable(f"{what} of something that is not a function of the sheet")
            key = _key(args[1])
            q = self.guess(et, args[1])  # the value before
            guess = et.visit(args[1])
            region = given[0] if given else self.region
            slope = self._derivative(fsym, fsym, "slope", region, guess)
            curve = self._derivative(slope, fsym, "curvature", region, guess)
            sym = self.new_sym("var", nm.identifier(*key), nm.mathcad_text(*key), region)
            inner = ExprTranslator(self, {**et.local, key: sym})
            conditions = [inner.visit(c) for c in constraints]
            u = ex.Name(sym.token())
            conditions.append(
                ex.Compare(
                    ("<" if largest else ">",), (ex.Call(curve.token(), (u,)), ex.Number(0.0))
                )
            )
            equation = ex.Compare(("==",), (ex.Call(slope.token(), (u,)), ex.Number(0.0)))
            unit = "" if q.dimensionless else f" {q.units:~}"
        except Untranslatable as why:
            if given is not None:
                self.close_given(str(why))
            raise
        if given is not None:
            self.close_given(None)
        self.out.items.append(
            Item(
                "solve",
                region,
                solve=([(sym, f"{float(q.magnitude)!r}{unit}")], [equation], [region], conditions),
                value="nearest",
            )
        )
        return u

    def _derivative(self, fsym: Sym, of: Sym, word: str, region: str, guess: ex.Node) -> Sym:
        """A helper function: the derivative of the function ``fsym`` of one argument (the
        ``word`` of the function ``of``)."""
        param = self.new_sym("param", "x", "x")
        body = ex.Call(
            "diff", (ex.Call(fsym.token(), (ex.Name(param.token()),)), ex.Name(param.token()))
        )
        out = self.new_sym("func", f"{of.base}_{word}", f"the {word} of {of.mathcad}", region)
        self.out.items.append(Item("function", region, sym=out, params=[param], body=body))
        self.calls.setdefault(out, []).append((guess,))
        self.calls.setdefault(fsym, []).append((guess,))
        return out
