"""Translating a Mathcad worksheet (regions in reading order) into the worksheet language.

Mathcad's math trees become the language's expression trees (:mod:`workbook.language.expr`), names
go through :mod:`.names`, units through :mod:`.units`, built-in functions through
:mod:`.functions`. Every result Mathcad stored becomes a printed value. What the language
cannot express is kept as a list of untranslated regions (id, what, why); a definition
that uses an untranslated one is untranslated too.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from ..language import expr as ex
from . import inference
from . import names as nm
from . import trees as tt
from .expressions import ExprTranslator
from .reader import MNode, Region, Worksheet
from .results import ResultsMixin
from .solving import SolveMixin
from .symbols import Sym, Unknown, Untranslatable, matrix_size
from .symbols import key as _key
from .symbols import what as _what
from .translation import Item, Skipped, Translation, uses
from .units import FORMULA_UNITS


class Translator(ResultsMixin, SolveMixin):
    """Regions in order -> a :class:`Translation`. ``at_import(translator)`` makes what gives
    the unit and value of an expression of the translation so far (the engine's
    :class:`workbook.mathcad.engine.AtImport`; passed in, as the engine builds on this module)."""

    def __init__(self, at_import: Callable[[Translator], Any]):
        self._make_at_import = at_import
        self.scope: dict[tuple[str, str], Sym] = {}
        self.units: dict[str, Sym] = {}
        self.out = Translation()
        self.note: list[str] = []
        self.calls: dict[Sym, list[tuple[ex.Node, ...]]] = {}  # call sites of each function
        # names whose values Mathcad stored as complex numbers somewhere (f of f(x) =), and
        # whether the region being translated defines one (its square roots are complex)
        self.complex_shown: set[tuple[str, str]] = set()
        self.complex_roots = False
        self.parts_own = False  # the last [a; b] := value gave each name its own definition
        self.prime = False  # the worksheet is Mathcad Prime's
        self._index: Sym | None = None
        self.region = ""  # the region being translated
        self.given: list[str] | None = None  # regions of the open solve block
        self.constraints: list[MNode] = []
        self.guesses: list[MNode] = []  # the open solve block's guess values (Prime's)
        self.origin = 0  # Mathcad's ORIGIN where the translation is
        self.sheet_origin = 0  # the worksheet's [sheet] origin
        self.writes = 0  # values written to a file (WRITEPRN and friends) so far
        self.shown: dict[str, tuple[str, list]] = {}  # a name -> (unit, values Mathcad stored)
        # local functions of programs, written out at each call: token -> (parameters, body)
        self.inline: dict[str, tuple[list[str], ex.Node]] = {}
        self._at_import = None

    def at_import(self):
        """The engine's unit and value of an expression of the translation so far."""
        if self._at_import is None:
            self._at_import = self._make_at_import(self)
        return self._at_import

    def quantity(self, node: MNode, why: str = "a value that is not known at import"):
        """The value (a pint quantity) of a Mathcad expression of numbers, units, inputs and
        definitions, as the engine computes it."""
        try:
            return self.at_import().quantity(ExprTranslator(self).visit(node))
        except Unknown:
            raise Untranslatable(why) from None

    # -- symbols --------------------------------------------------------------
    def new_sym(self, kind: str, base: str, mathcad: str, region: str = "", **kw) -> Sym:
        sym = Sym(kind, base, mathcad, region=region, **kw)
        self.out.syms.append(sym)
        return sym

    def sym_of(self, name: ex.Name) -> Sym:
        return next(s for s in self.out.syms if s.token() == name.id)

    def mathcad_name(self, name: str) -> str:
        """The name as Mathcad shows it, for a message (a symbol's token is an object id)."""
        sym = next((s for s in self.out.syms if s.token() == name), None)
        return name if sym is None else sym.mathcad

    def unit_sym(self, name: str) -> Sym:
        if name not in self.units:
            self.units[name] = self.new_sym("unit", nm.identifier(name), name)
            self.units[name].unit = FORMULA_UNITS[name]
        return self.units[name]

    def local_call(self, sym: Sym, args: tuple[ex.Node, ...]) -> ex.Node:
        """A call of a program's local function: its body with the arguments in place of
        its parameters."""
        params, body = self.inline[sym.token()]
        if len(params) != len(args):
            raise Untranslatable(f"{sym.mathcad}() called with {len(args)} arguments")
        return tt.substitute(body, dict(zip(params, args)))

    def ignores_arguments(self, sym: Sym) -> bool:
        """Is the function ``sym`` one whose value does not depend on its arguments (a
        single expression without its parameters)?"""
        if sym.token() in self.inline:
            params, body = self.inline[sym.token()]
            return not ex.names(body) & set(params)
        item = next((i for i in self.out.items if i.sym is sym and i.kind == "function"), None)
        if item is None or item.body is None or item.pieces or item.program:
            return False
        return not ex.names(item.body) & {p.token() for p in item.params}

    def define(self, key: tuple[str, str], kind: str, region: str) -> Sym:
        sym = self.new_sym(kind, nm.identifier(*key), nm.mathcad_text(*key), region)
        self.scope[key] = sym
        return sym

    # -- regions --------------------------------------------------------------
    def run(self, ws: Worksheet, regions: list[Region]) -> Translation:
        self.origin = ws.origin
        self.sheet_origin = self.out.origin = tt.first_index_origin(ws.origin, regions)
        self.out.generator = ws.generator
        self.prime = ws.generator == "Mathcad Prime"
        # Mathcad evaluates global definitions (≡) first, top to bottom, then the others
        first = [r for r in regions if r.math is not None and r.math.tag == "globalDefine"]
        regions = first + [r for r in regions if r not in first]
        self.complex_shown = inference.shown_complex(regions)
        for region in regions:
            if region.kind == "text":
                if region.text:
                    if not self.out.title:
                        self.out.title = region.text.splitlines()[0][:120]
                    self.out.items.append(Item("note", region.id, value=region.text))
                continue
            if region.kind == "plot":
                try:
                    self.plot(region)
                except Untranslatable as why:
                    self.skip(region.id, "a plot", str(why))
                continue
            if region.kind == "component":
                self.component(region)
                continue
            if region.kind == "listed":  # a region its reader cannot give: what, and why
                self.skip(region.id, region.text, region.href)
                continue
            if region.kind != "math":
                what = {"plot": "a plot", "picture": "a picture"}.get(region.kind, "a component")
                if region.kind in ("reference", "area"):
                    continue  # followed by the caller; an area holds regions read on their own
                self.skip(region.id, what, "not translated: the language has no such region")
                continue
            if region.math is None:
                continue
            if region.disabled:
                self.skip(region.id, self.describe(region.math), "disabled in Mathcad")
                continue
            self.complex_roots = inference.defined_key(region.math) in self.complex_shown
            try:
                self.math(region)
            except Untranslatable as why:
                self.skip(region.id, self.describe(region.math), str(why))
            finally:
                self.complex_roots = False
        self.close_given("a solve block without Find")
        self.argument_units()
        return self.out

    def component(self, region: Region) -> None:
        """A data table of numbers: a matrix definition of its name. Any other component (a
        spreadsheet, ...): not translated; the names it defines are untranslated names
        (never a unit of the same name, as S for siemens)."""
        names = ", ".join(nm.mathcad_text(*_key(n)) for n in region.outputs)
        try:
            self.data_table(region)
            return
        except Untranslatable as error:
            why = str(error)
        self.skip(region.id, "a component" + (f" defining {names}" if names else ""), why)
        for node in region.outputs:
            sym = self.define(_key(node), "var", region.id)
            sym.broken = f"defined by a component (region {region.id}), {why}"

    def data_table(self, region: Region) -> None:
        """A data table (Insert > Data > Table) whose cells are numbers: ``S := [[...]]``
        by rows, or a column vector ``[a, b, ...]`` for a single column."""
        from .table import TABLE_CLSID, grid

        if region.component.get("clsid-buddy", "").upper() != TABLE_CLSID:
            raise Untranslatable("not translated: the language has no such region")
        if len(region.outputs) != 1 or region.outputs[0].tag != "id":
            raise Untranslatable("a data table that defines more than one name")
        if not region.binary:
            raise Untranslatable("a data table without its binary item (its cells)")
        if region.component.get("disable-calc") == "true":
            raise Untranslatable("disabled in Mathcad")
        cells = grid(region.binary)
        if not all(math.isfinite(v) for row in cells for v in row):
            raise Untranslatable("a data table with an empty cell or a value that is not a number")

        def number(v: float) -> ex.Node:
            return ex.Unary("-", ex.Number(-v)) if v < 0 else ex.Number(v)

        body = ex.Matrix(tuple(tuple(number(v) for v in row) for row in cells))
        sym = self.define(_key(region.outputs[0]), "var", region.id)
        rows, cols = len(cells), len(cells[0])
        self.out.items.append(
            Item("note", region.id, value=f"a data table of Mathcad ({rows} x {cols})")
        )
        self.out.items.append(Item("definition", region.id, sym=sym, body=body))

    def plot(self, region: Region) -> None:
        """An X-Y plot: a chart whose series are its traces, each over the range variable its
        expressions use (Mathcad plots a trace at every value of it)."""
        from .plot import payload, traces, x_limits

        if not region.binary:
            raise Untranslatable("a plot without its binary item (its definition)")
        series, why = [], []
        data = payload(region.binary)
        pairs, polar = traces(data)
        limits = None if polar else x_limits(data)
        for n, (x, y) in enumerate(pairs, 1):
            try:
                series.append((*self.trace(x, y, limits), n))
            except Untranslatable as err:
                why.append(f"trace {n}: {err}")
        if not series:
            raise Untranslatable("; ".join(why))
        if why:
            self.skip(region.id, "a plot (traces left out)", "; ".join(why))
        self.out.items.append(Item("chart", region.id, chart=series, value="polar" * polar))

    def trace(self, x: MNode, y: MNode, limits=None) -> tuple:
        free = self._free_names(x)
        if len(free) == 1:
            return self.quick_plot(free[0], x, y, limits if x.tag == "id" else None)
        et = ExprTranslator(self)
        xt, yt = et.visit(x), et.visit(y)
        ranges = list(dict.fromkeys(et.ranges))
        if not ranges:
            return self.points(xt, yt)
        if len(ranges) > 1:
            names = ", ".join(r.mathcad for r in ranges)
            raise Untranslatable(f"over two range variables at once ({names})")
        item = next(
            (i for i in reversed(self.out.items) if i.kind == "range" and i.sym is ranges[0]),
            None,
        )
        if item is None or ranges[0].broken:
            raise Untranslatable(f"the range variable {ranges[0].mathcad} is not translated")
        return xt, yt, item, False

    def _free_names(self, node: MNode) -> list[tuple[str, str]]:
        """Names in ``node`` that the worksheet has not defined (not units, not pi)."""
        out: list[tuple[str, str]] = []

        def walk(n: MNode, head: bool = False) -> None:
            if n.tag == "id":
                key = _key(n)
                if not head and self.scope.get(key) is None and key[0] not in tt.KNOWN:
                    out.append(key)
                return
            for i, c in enumerate(n.children):
                walk(c, head=n.tag == "apply" and i == 0)

        walk(node)
        return list(dict.fromkeys(out))

    def quick_plot(self, key, x: MNode, y: MNode, limits) -> tuple:
        """Mathcad's quick plot: a name the x expression uses that the worksheet has not
        defined is a variable from -10 to 10 (over the x axis's limits where the user set
        them and x is that name), drawn at tt.QUICK_PLOT_STEPS steps."""
        lo, hi = limits or (-10.0, 10.0)
        sym = self.new_sym("var", nm.identifier(*key), nm.mathcad_text(*key), unit="")
        sym.is_range = True
        step = (hi - lo) / tt.QUICK_PLOT_STEPS
        rng = Item(
            "range",
            "",
            sym=sym,
            range=(ex.Number(lo), ex.Number(lo + step), ex.Number(hi)),
        )
        et = ExprTranslator(self, {key: sym})
        return et.visit(x), et.visit(y), rng, False

    def points(self, xt: ex.Node, yt: ex.Node) -> tuple:
        """A trace without a range variable: a vector against a vector (Mathcad draws a point
        for each element: a series over their index) or a single point (a marker)."""
        lengths = [self.vector_length_of(t) for t in (xt, yt)]
        o = self.sheet_origin
        index = self.index_sym()
        if lengths == [None, None]:  # numbers: one point (the engine refuses a vector here)
            n, xt_, yt_ = 1, xt, yt
        elif None in lengths or lengths[0] != lengths[1]:
            raise Untranslatable(
                "a vector against a vector whose lengths are not both known at import"
                if None in lengths
                else f"a vector of {lengths[1]} against a vector of {lengths[0]}"
            )
        else:
            n = lengths[0]
            at = (ex.Name(index.token()),)
            xt_, yt_ = ex.Index(xt, at), ex.Index(yt, at)
        rng = Item("range", "", sym=index, range=(ex.Number(o), None, ex.Number(o + n - 1)))
        return xt_, yt_, rng, True

    def is_array(self, token: str) -> bool:
        """Does the definition ``token`` (a name of the worksheet) hold a vector or matrix
        as far as the import sees (a matrix written in it, or a name that does)?"""
        memo = self.__dict__.setdefault("_arrays", {})
        if token not in memo:
            memo[token] = False  # a cycle is not an array
            item = next(
                (i for i in self.out.items if i.sym is not None and i.sym.token() == token), None
            )
            if item is not None and item.kind == "definition" and item.body is not None:
                body = item.body
                memo[token] = tt.has_matrix(body) or any(self.is_array(n) for n in ex.names(body))
        return memo[token]

    def written_out(self, tree: ex.Node) -> ex.Node | None:
        """The expression a name stands for, following definitions of one name by another
        (None: a name not defined before, or defined by a region the translation left out)."""
        seen: set[str] = set()
        while isinstance(tree, ex.Name) and tree.id not in seen:
            seen.add(tree.id)
            item = next(
                (i for i in self.out.items if i.sym is not None and i.sym.token() == tree.id),
                None,
            )
            if item is None or item.kind != "definition" or item.body is None:
                return None
            tree = item.body
        return tree

    def vector_length_of(self, tree: ex.Node) -> int | None:
        """The length of a vector the worksheet defines by name (None: not a known vector)."""
        written = self.written_out(tree)
        if isinstance(written, ex.Matrix) and all(len(r) == 1 for r in written.rows):
            return len(written.rows)
        if written is None or not isinstance(tree, ex.Name):
            return None
        shape = self.at_import().shape(tree)  # a vector computed from vectors (v * mm)
        return shape[0] if shape is not None and shape[1] == 1 else None

    def argument_units(self) -> None:
        """Mathcad's functions are untyped: an argument takes the unit of the values the
        worksheet calls the function with (:func:`inference.argument_units`)."""
        inference.argument_units(self)

    def skip(self, region: str, what: str, why: str) -> None:
        self.out.skipped.append(Skipped(region, what, why))

    def describe(self, node: MNode) -> str:
        if node.tag == "define":
            lhs = node.children[0]
            if lhs.tag == "id":
                return f"{nm.mathcad_text(*_key(lhs))} := ..."
            if lhs.tag == "function":
                return f"{nm.mathcad_text(*_key(lhs.children[0]))}(...) := ..."
            if tt.is_indexer(lhs) and lhs.children[1].tag == "id":
                return f"{nm.mathcad_text(*_key(lhs.children[1]))}[...] := ..."
            return f"{_what(lhs.tag)} := ..."
        if node.tag == "eval":
            return "an evaluation ( = )"
        if node.tag == "id":
            return f"the name {nm.mathcad_text(*_key(node))} alone"
        return _what(node.tag)

    def math(self, region: Region) -> None:
        node = region.math
        self.region = region.id
        if node.tag in ("define", "globalDefine"):
            self.definition(region, node)
        elif node.tag == "eval":
            self.evaluation(region, node, None)
        elif node.tag == "symEval" and tt.symbolic_numbers(node) is not None:
            # expr → a number Mathcad found: compared as a stored result of expr
            found = MNode("result", {}, "", [tt.symbolic_numbers(node)], node.line)
            self.evaluation(region, MNode("eval", {}, "", [node.children[0], found]), None)
        elif node.tag == "id" and node.text.strip() == "Given":
            self.close_given("a solve block without Find")
            self.given = [region.id]
            self.constraints = []
            self.guesses = region.guesses
        elif node.tag == "apply" and node.children and node.children[0].tag in tt.COMPARE:
            if self.given is None:  # a comparison shown outside a solve block: nothing
                self.out.ignored.append(region.id)
                return
            self.given.append(region.id)
            self.constraints.append(node)
        else:  # a name or an expression alone: Mathcad shows nothing, defines nothing
            self.out.ignored.append(region.id)

    def definition(self, region: Region, node: MNode) -> None:
        lhs, rhs = node.children[0], node.children[1]
        evaluation = rhs if rhs.tag == "eval" else None
        if evaluation is not None:
            rhs = evaluation.children[0]
        writer = tt.writer(lhs, 1)  # WRITEPRN("file") := M
        if writer is not None:
            self.written(region, *writer[:2], rhs, evaluation)
            return
        if lhs.tag == "function":
            fname, bound = lhs.children[0], lhs.children[1]
            self.function(region, fname, [c for c in bound.children if c.tag == "id"], rhs)
            return
        if tt.is_indexer(lhs):  # v[i] := f(i), shown (= the whole vector) or not
            target = lhs.children[1] if len(lhs.children) > 1 else None
            try:
                self.elements(region, lhs, rhs, tt.shown_rows(evaluation))
            except Untranslatable:
                if evaluation is not None:
                    sym = self.scope.get(_key(target)) if target is not None else None
                    if sym is not None and sym.region == region.id:
                        self.evaluation(region, evaluation, sym)
                    else:
                        self.stored_but_broken(region, evaluation, "an element assignment")
                raise
            if evaluation is not None:
                key = _key(target)
                if self._shown_over_range(region, lhs, evaluation):
                    return
                # v[k] := expr = shows the element (one number): the value of expr
                element = not tt.shows_array(evaluation) and not tt.mentions(rhs, key)
                self.evaluation(region, evaluation, None if element else self.scope[key])
            return
        if lhs.tag == "matrix":
            try:
                whole = self.destructure(region, lhs, rhs)
            except Untranslatable:
                if evaluation is not None:
                    self.stored_but_broken(region, evaluation, "[...] := ...")
                raise
            if evaluation is not None:  # [a; b] := value = the value Mathcad shows
                if not self._shown_parts(region, lhs, evaluation):
                    self.evaluation(region, evaluation, whole)
            return
        if lhs.tag != "id":
            if evaluation is not None:
                self.stored_but_broken(region, evaluation, f"{_what(lhs.tag)} := ...")
            what = "an element assignment" if tt.is_indexer(lhs) else _what(lhs.tag)
            raise Untranslatable(f"a definition of {what} is not in the language yet")
        key = _key(lhs)
        if rhs.tag == "id" and self.range_of(rhs) is not None:  # j := i, a range again
            self.range_alias(region, key, self.range_of(rhs))
            return
        if key == ("TOL", "") and tt.quantity_text(rhs) is not None:
            try:
                tol = float(self.quantity(rhs).magnitude)
                self.out.solve_tolerance = max(self.out.solve_tolerance, tol)
            except Exception:  # noqa: BLE001 - a TOL that is not a number: the default
                pass
        if key == ("ORIGIN", "") and rhs.tag == "real":
            self.origin = int(float(rhs.text))
            self.out.items.append(
                Item("note", region.id, value=f"ORIGIN := {self.origin} (the first index)")
            )
            return
        if rhs.tag == "range":
            self.range_variable(region, key, rhs)
            return
        rhs = tt.symbolic_result(rhs)
        display = tt.override_unit(evaluation) if evaluation is not None else ""
        try:
            item = self.value_item(region, rhs, display)
        except Untranslatable as why:
            sym = self.define(key, "var", region.id)
            sym.broken = str(why)
            if evaluation is not None:
                self.evaluation(region, evaluation, sym)
            raise
        sym = self.define(key, "var", region.id)
        item.sym = sym
        self.out.items.append(item)
        if evaluation is not None:
            self.evaluation(region, evaluation, sym)

    def written(self, region: Region, func: str, file: str, value: MNode, evaluation):
        """The value Mathcad's WRITEPRN (and friends) wrote to a file: a definition of its
        own (``written_1``, ...) with a note naming the file, so that its stored result is
        compared; the worksheet writes no file."""
        self.writes += 1
        sym = self.new_sym("var", f"written_{self.writes}", f'{func}("{file}")', region.id)
        self.out.items.append(
            Item(
                "note",
                region.id,
                value=f'Mathcad\'s {func} wrote this value to the file "{file}" (the '
                "worksheet writes no files)",
            )
        )
        try:
            item = self.value_item(region, value, "")
        except Untranslatable as why:
            sym.broken = sym.broken or str(why)
            if evaluation is not None:
                self.evaluation(region, evaluation, sym)
            raise
        item.sym = sym
        self.out.items.append(item)
        if evaluation is not None:
            self.evaluation(region, evaluation, sym)

    def stored_but_broken(self, region: Region, evaluation: MNode, what: str) -> None:
        sym = self.new_sym("helper", f"result_{region.id}", what, region.id)
        sym.broken = "not translated"
        self.evaluation(region, evaluation, sym)

    def value_item(self, region: Region, rhs: MNode, display: str) -> Item:
        """The item a scalar definition becomes: an input for a number (with units), a
        piecewise definition for a program of ifs, or a definition."""
        literal = tt.quantity_text(rhs)
        if literal is not None:
            return Item("input", region.id, value=literal, unit=display)
        if rhs.tag == "program":
            return Item("definition", region.id, unit=display, **self.program(rhs, {}))
        if tt.is_if(rhs):
            return Item("definition", region.id, pieces=self.if_pieces(rhs, {}), unit=display)
        et = ExprTranslator(self)
        body = et.value(rhs)
        if et.ranges:
            raise Untranslatable(
                f"uses the range variable {et.ranges[0].mathcad} outside a function "
                "(a vector of values: arrays are not in the language yet)"
            )
        return Item("definition", region.id, body=body, unit=display)

    def program(self, program: MNode, local) -> dict:
        """A program made of `value if condition` lines and `otherwise` as a piecewise
        definition; any other as a program of the language."""
        try:
            return {"pieces": self.pieces(program, local)}
        except Untranslatable as why:
            from .program import ProgramTranslator

            try:
                return {"program": ProgramTranslator(self, local, ExprTranslator).lines(program)}
            except Untranslatable as why2:
                raise why2 from why

    def pieces(self, program: MNode, local) -> list[tuple[ex.Node, ex.Node | None]]:
        """A Mathcad program made only of `value if condition` lines and `otherwise`."""
        out = []
        for line in program.children:
            et = ExprTranslator(self, local)
            if line.tag == "ifThen" and len(line.children) == 2:
                cond, value = line.children
                if value.tag in ("program", "localDefine"):
                    raise Untranslatable("a program with local definitions or blocks")
                out.append((et.value(value), et.condition(cond)))
            elif line.tag == "otherwise" and len(line.children) == 1:
                out.append((et.value(line.children[0]), None))
            else:
                raise Untranslatable(
                    f"a program with {_what(line.tag)} lines (only 'if' and 'otherwise' "
                    "lines translate: as a piecewise definition)"
                )
            if et.ranges:
                raise Untranslatable("a program over a range variable")
        if not out:
            raise Untranslatable("an empty program")
        # Mathcad runs every line and the program's value is the last one it ran: where
        # conditions overlap, the last true `if` wins; pieces take the first true one
        ifs = [p for p in out if p[1] is not None][::-1]
        return ifs + [p for p in out if p[1] is None]

    def if_pieces(self, node: MNode, local) -> list[tuple[ex.Node, ex.Node | None]]:
        """Mathcad's if(cond, a, b), with further ifs in b, as pieces."""
        out = []
        while tt.is_if(node):
            cond, a, b = tt.if_args(node)
            et = ExprTranslator(self, local)
            out.append((et.value(a), et.condition(cond)))
            if et.ranges:
                raise Untranslatable("an if() over a range variable")
            node = b
        et = ExprTranslator(self, local)
        out.append((et.value(node), None))
        if et.ranges:
            raise Untranslatable("an if() over a range variable")
        return out

    def range_of(self, node: MNode) -> Item | None:
        sym = self.scope.get(_key(node))
        if sym is None or not sym.is_range or sym.broken:
            return None
        return next((i for i in self.out.items if i.sym is sym), None)

    def range_alias(self, region: Region, key, item: Item) -> None:
        sym = self.define(key, "var", region.id)
        sym.is_range, sym.unit = True, item.sym.unit
        self.out.items.append(
            Item(
                "range",
                region.id,
                sym=sym,
                range=item.range,
                range_values=item.range_values,
            )
        )

    def elements(self, region: Region, lhs: MNode, rhs: MNode, shown: int | None = None) -> None:
        """v[i] := f(i) over range variables with whole values (Mathcad builds the vector
        element by element): the vector [v_of(0), v_of(1), ...] of a function v_of, 0 where
        the range does not reach. ``shown``: the rows of the vector Mathcad showed after it
        (where it shows no more rows than the range reaches, nothing of v before is kept)."""
        target, index = lhs.children[1], lhs.children[2]
        if target.tag != "id":
            raise Untranslatable("an element assignment to something that is not a name")
        key = _key(target)
        nodes = index.children if index.tag == "sequence" else [index]
        shift = 0  # v[i + N] := f(i): the element at i + N, N a whole number known at import
        if len(nodes) == 1 and (shifted := self._shifted_index(nodes[0])) is not None:
            nodes, shift = [shifted[0]], shifted[1]
        ranges = [self.range_of(n) if n.tag == "id" else None for n in nodes]
        if all(r is None for r in ranges):
            self.element(region, key, lhs, rhs)
            return
        before = self.scope.get(key)
        sym = self.define(key, "var", region.id)
        try:
            if any(r is None for r in ranges) or len(ranges) > 2:
                raise Untranslatable(
                    "an element assignment v[k] := ... at a single index (the language "
                    "defines whole vectors)"
                )
            unique: list[Item] = []  # M[i, i] := ...: one range at two indices (a diagonal)
            for r in ranges:
                if all(r is not u for u in unique):
                    unique.append(r)
            place = [next(k for k, u in enumerate(unique) if u is r) for r in ranges]
            values = [[int(v) for v in u.range_values] for u in unique]
            if any(v != u.range_values for v, u in zip(values, unique)):
                raise Untranslatable("an element assignment over a range of fractional values")
            if any(min(v) + shift < self.origin for v in values):
                raise Untranslatable("an element assignment below ORIGIN")
            old = None
            reach = max(values[place[0]]) + shift - self.origin + 1
            if shown is not None and len(ranges) == 1 and shown == reach:
                before = None  # Mathcad showed the range's elements only: none kept
            if before is not None:  # Mathcad keeps the elements the range does not reach
                old = self._shape_of(before)
                if old is None or (len(ranges) == 1 and old[1] != 1):
                    raise Untranslatable(
                        "an element assignment over a range to a name defined before whose "
                        "size is not known at import"
                    )
            size = [max(values[place[k]]) + shift - self.origin + 1 for k in range(len(ranges))]
            if old is not None:
                size = [max(n, old[k]) for k, n in enumerate(size)]
            if math.prod(size) > 10_000:
                raise Untranslatable("an element assignment of more than 10,000 elements")
            local, params = {}, []
            for u in unique:
                n = nodes[ranges.index(u)]
                p = self.new_sym("param", u.sym.base, u.sym.mathcad, unit="")
                local[_key(n)] = p
                params.append(p)
            if rhs.tag == "program":  # K[i] := a program of i: a function of i
                parts = self.program(rhs, local)
            else:
                et = ExprTranslator(self, local)
                parts = {"body": et.value(rhs)}
                if et.ranges:
                    raise Untranslatable("an element assignment over another range variable")
        except Untranslatable as why:
            sym.broken = str(why)
            raise
        of = self.new_sym("func", sym.base + "_of", nm.mathcad_text(*key) + "[...]", region.id)
        self.out.items.append(Item("function", region.id, sym=of, params=params, **parts))
        o = self.origin

        def cell(*at: int) -> ex.Node:
            chosen: dict[int, int] = {}
            reached = True
            for k, a in enumerate(at):
                u, a = place[k], a - shift
                if a not in values[u] or chosen.setdefault(u, a) != a:
                    reached = False
            if reached:
                return ex.Call(
                    of.token(), tuple(ex.Number(float(chosen[u])) for u in range(len(unique)))
                )
            if old is not None and all(a - o < old[k] for k, a in enumerate(at)):
                return ex.Index(ex.Name(before.token()), tuple(ex.Number(float(a)) for a in at))
            return ex.Number(0.0)

        if len(size) == 1:
            rows = tuple((cell(o + r),) for r in range(size[0]))
        else:
            rows = tuple(tuple(cell(o + r, o + c) for c in range(size[1])) for r in range(size[0]))
        self.out.items.append(Item("definition", region.id, sym=sym, body=ex.Matrix(rows)))

    def _shown_over_range(self, region: Region, lhs: MNode, evaluation: MNode) -> bool:
        """v[i] := f(i) = over a range i that starts above ORIGIN, shown as one row per value
        of i (Prime shows the elements the range gives, ``s[i] := ... =`` with i := 1 .. 1 a
        matrix of one row, where v has the rows 0 and 1): each stored row compared with v at
        that value of i. False: the stored rows are not one per value of the range."""
        index = lhs.children[2]
        if index.tag != "id" or self.range_of(index) is None:
            return False
        values = self.range_of(index).range_values or []
        result = evaluation.find("result")
        shown = result.children[0] if result is not None and result.children else None
        if shown is None or shown.tag != "matrix" or matrix_size(shown) != (len(values), 1):
            return False
        reach = max(values) - self.origin + 1
        if len(values) == reach or len(shown.children) != len(values):
            return False  # the whole vector (Mathcad 15's display)
        target = lhs.children[1]
        for value, element in zip(values, shown.children, strict=True):
            at = MNode("real", {}, repr(float(value)), [])
            indexed = MNode("apply", {}, "", [MNode("indexer", {}, "", []), target, at])
            one = MNode("eval", {}, "", [indexed, MNode("result", {}, "", [element])])
            self.evaluation(region, one, None)
        return True

    def _shifted_index(self, node: MNode) -> tuple[MNode, int] | None:
        """``i + N``, ``N + i`` or ``i - N`` (i a range variable, N a name or number that is
        not one, a whole number known at import): (i, N or -N); else None."""
        if node.tag != "apply" or len(node.children) != 3:
            return None
        op, a, b = node.children
        if op.tag not in ("plus", "minus"):
            return None
        if op.tag == "plus" and self._is_range(b) and not self._is_range(a):
            a, b = b, a
        if not self._is_range(a) or b.tag not in ("id", "real") or self._is_range(b):
            return None
        try:
            value = float(self.quantity(b).to("").magnitude)
        except Exception:  # noqa: BLE001 - not a plain number known at import
            return None
        if not (math.isfinite(value) and value == int(value)):
            return None
        return a, int(value) if op.tag == "plus" else -int(value)

    def _is_range(self, node: MNode) -> bool:
        return node.tag == "id" and self.range_of(node) is not None

    def _shape_of(self, before: Sym) -> tuple[int, int] | None:
        """(rows, columns) of a vector or matrix the worksheet wrote out before (None: not
        known at import)."""
        if before.broken:
            return None
        tree = self.written_out(ex.Name(before.token()))
        if isinstance(tree, ex.Matrix) and not any(
            isinstance(e, ex.Matrix) for row in tree.rows for e in row
        ):
            return len(tree.rows), len(tree.rows[0])
        return None

    def destructure(self, region: Region, lhs: MNode, rhs: MNode) -> Sym:
        """[a; b] := value: the value a definition of its own (``parts``, returned), then
        each name its element at ORIGIN."""
        rows, cols = matrix_size(lhs)
        names = lhs.children
        if rows * cols != len(names) or not names or any(n.tag != "id" for n in names):
            raise Untranslatable("a definition of a matrix of something that is not names")
        whole = self.new_sym("var", "parts", f"[...] := (region {region.id})", region.id)
        whole.generated = True
        try:
            if rhs.tag == "program":  # [a; b] := a program giving them
                parts = self.program(rhs, {})
            else:
                et = ExprTranslator(self)
                parts = {"body": et.value(rhs)}
                if et.ranges:
                    raise Untranslatable(
                        f"uses the range variable {et.ranges[0].mathcad} outside a function"
                    )
        except Untranslatable as why:
            for n in names:
                self.define(_key(n), "var", region.id).broken = str(why)
            raise
        own = self._own_parts(rhs, parts, rows, cols)
        self.parts_own = own is not None
        # where each name has its own definition, the whole value (compared where Mathcad
        # shows it) is a part of the region of its own: the engine may refuse a matrix of
        # elements of different units without refusing the names
        at_region = region.id if own is None else f"{region.id}.value"
        self.out.items.append(Item("definition", at_region, sym=whole, **parts))
        o = self.sheet_origin
        # every element's definition is translated before any name is given (a program
        # may read a name of the worksheet that the matrix of names gives anew)
        owned: dict[tuple[int, int], dict | Untranslatable] = {}
        for c in range(cols if own is not None else 0):
            for r in range(rows):
                try:
                    owned[r, c] = own(r, c)
                except Untranslatable as why:
                    owned[r, c] = why
        for c in range(cols):
            for r in range(rows):
                at = (r,) if cols == 1 else (r, c)
                index = tuple(ex.Number(float(o + a)) for a in at)
                key = _key(names[c * rows + r])
                if own is not None:  # the name is its element's own expression or program
                    part = owned[r, c]
                    if isinstance(part, Untranslatable):
                        self.define(key, "var", region.id).broken = str(part)
                        continue
                    sym = self.define(key, "var", region.id)
                    self.out.items.append(Item("definition", region.id, sym=sym, **part))
                    continue
                sym = self.define(key, "var", region.id)
                item = ex.Index(ex.Name(whole.token()), index)
                self.out.items.append(Item("definition", region.id, sym=sym, body=item))
        return whole

    def _shown_parts(self, region: Region, lhs: MNode, evaluation: MNode) -> bool:
        """[a; b] := value = [x; y] where each name has its own definition and the stored
        matrix has an element per name: each element compared as that name's shown value
        (so that a matrix of different units, [0.002; 0.4/m], is compared too). False: the
        names share the whole value (compared as one matrix)."""
        result = evaluation.find("result")
        shown = result.children[0] if result is not None and result.children else None
        names = lhs.children
        syms = [self.scope.get(_key(n)) for n in names]
        if shown is None or shown.tag != "matrix" or matrix_size(shown) != matrix_size(lhs):
            return False
        if len(shown.children) != len(names) or any(s is None for s in syms):
            return False
        if not self.parts_own:
            return False
        for name, sym, element in zip(names, syms, shown.children, strict=True):
            one = MNode("eval", {}, "", [name, MNode("result", {}, "", [element])])
            self.evaluation(region, one, sym)
        return True

    def _own_parts(self, rhs: MNode, parts: dict, rows: int, cols: int):
        """[a; b] := value where the value is a matrix written out (``[x; y]``, Find's
        unknowns) or a program whose one value is such a matrix (its last line, no other
        ``return``): a function of (row, column) giving each name its element's own
        definition, so that the names need not share one unit (``[X; Y; j]``, lengths and a
        count, is three definitions, not one matrix). None: the value is not of that form."""
        body = parts.get("body")
        if isinstance(body, ex.Matrix):
            if len(body.rows) == rows and all(len(row) == cols for row in body.rows):
                return lambda r, c: {"body": body.rows[r][c]}
            return None
        if rhs.tag != "program" or not rhs.children:
            return None
        last = rhs.children[-1]
        value = last.children[0] if last.tag == "return" and len(last.children) == 1 else last
        if value.tag != "matrix" or matrix_size(value) != (rows, cols):
            return None
        if any(n.tag == "return" for c in rhs.children[:-1] for n in tt.walk(c)):
            return None  # a value returned before the end
        if len(value.children) != rows * cols:
            return None

        def own(r: int, c: int) -> dict:
            element = value.children[c * rows + r]
            program = MNode(rhs.tag, rhs.attrs, rhs.text, [*rhs.children[:-1], element], rhs.line)
            return self.program(program, {})

        return own

    def element(self, region: Region, key, lhs: MNode, rhs: MNode) -> None:
        """v[k] := value at an index that is not a range variable (Mathcad sets one element
        of v, making or growing it): a new definition of v, a program that copies the
        previous definition of v (if there is one), sets the element and gives it."""
        previous = self.scope.get(key)
        sym = self.define(key, "var", region.id)
        try:
            if previous is not None and previous.broken:
                raise Untranslatable(uses(previous))
            if previous is not None and (previous.kind == "func" or previous.is_range):
                raise Untranslatable(
                    f"an element of {previous.mathcad}, which is a "
                    + ("function" if previous.kind == "func" else "range variable")
                )
            et = ExprTranslator(self)
            self.scope.pop(key)  # the right side sees the previous definition (if any)
            if previous is not None:
                self.scope[key] = previous
            try:
                value = et.value(rhs)
            finally:
                self.scope[key] = sym
            local = self.new_sym("local", sym.base, sym.mathcad)
            lines = []
            if previous is not None:
                lines.append((0, [ex.Name(local.token()), " := ", ex.Name(previous.token())]))
            inner = ExprTranslator(self, {key: local})
            index = inner.value(lhs)  # v[k], its index shifted by ORIGIN
            if et.ranges or inner.ranges:
                raise Untranslatable(
                    "an element assignment whose index or value uses a range variable (other "
                    "than as the index itself)"
                )
            lines += [(0, [index, " := ", value]), (0, [ex.Name(local.token())])]
        except Untranslatable as why:
            sym.broken = str(why)
            raise
        self.out.items.append(Item("definition", region.id, sym=sym, program=lines))

    def range_variable(self, region: Region, key, rng: MNode) -> None:
        sym = self.define(key, "var", region.id)
        sym.is_range = True
        try:
            first_node = rng.children[0]
            et = ExprTranslator(self)
            if first_node.tag == "sequence":
                first, second = (et.visit(c) for c in first_node.children[:2])
                second_src = first_node.children[1]
                first_src = first_node.children[0]
            else:
                first, second, first_src, second_src = et.visit(first_node), None, first_node, None
            last = et.visit(rng.children[1])
            values = tt.range_values(self, first_src, second_src, rng.children[1])
        except Untranslatable as why:
            sym.broken = str(why)
            raise
        sym.unit = values[1]
        self.out.items.append(
            Item("range", region.id, sym=sym, range=(first, second, last), range_values=values[0])
        )

    def function(self, region: Region, fname: MNode, params: list[MNode], body: MNode) -> None:
        key = _key(fname)
        body = tt.symbolic_result(body)
        local: dict[tuple[str, str], Sym] = {}
        psyms = []
        for p in params:
            pkey = _key(p)
            outer = self.scope.get(pkey)
            unit = outer.unit if outer is not None and outer.is_range else ""
            ps = self.new_sym("param", nm.identifier(*pkey), nm.mathcad_text(*pkey), unit=unit)
            local[pkey] = ps
            psyms.append(ps)
        # a call of f inside f is Mathcad's recursion, unless f was a function before: then
        # it is that function (B(x) := stack(B(x), M) redefines B from the previous B)
        previous = self.scope.get(key)
        if previous is not None and previous.kind == "func":
            sym = self.new_sym("func", nm.identifier(*key), nm.mathcad_text(*key), region.id)
        else:
            sym = self.define(key, "func", region.id)
        try:
            if body.tag == "program":
                item = Item("function", region.id, params=psyms, **self.program(body, local))
            elif tt.is_if(body):
                item = Item("function", region.id, params=psyms, pieces=self.if_pieces(body, local))
            else:
                et = ExprTranslator(self, local)
                item = Item("function", region.id, params=psyms, body=et.value(body))
                if et.ranges:
                    raise Untranslatable(
                        f"uses the range variable {et.ranges[0].mathcad} inside a function"
                    )
        except Untranslatable as why:
            sym.broken = str(why)
            self.scope[key] = sym
            raise
        self.scope[key] = sym
        item.sym = sym
        self.out.items.append(item)

    # -- results --------------------------------------------------------------
