"""``diff(EXPR, X, N)``: the derivative as a typed tree, found by SymPy from EXPR's own tree.

At load the typer gives ``diff`` its unit (EXPR's over X's to the N) and keeps a
:class:`Pending` record of the call; nothing is differentiated yet, and SymPy is not imported.
The first back end that needs the derivative (a value, a formula, a check) calls
:func:`formula`: EXPR's typed tree is printed as SymPy
(:class:`workbook.numerics.symbolic.SympyConverter`, inputs and definitions kept as symbols),
differentiated, and read back into a typed tree whose leaves are EXPR's own parameters and
references; it is kept for every later use. Every back end then treats the derivative as any
other formula: numpy evaluates it, Excel gets it as a live formula.
"""

from __future__ import annotations

import functools
import math
import types
import weakref
from dataclasses import dataclass, field

from ..errors import LimitError, NotSymbolic, TemplateError, WorkbookError
from ..language import typed as ty
from ..language import units as un
from ..language.visitor import Visitor
from ..limits_time import within_seconds


def sympy_functions() -> dict[str, str]:
    """SymPy's function -> the built-in written so (``log`` -> ``ln``, ``ceiling`` -> ``ceil``),
    read from the registry: an entry whose SymPy form, given symbols, is one SymPy function of
    exactly those symbols (``Abs(x)``, ``atan2(y, x)``). Plain built-ins come before those of
    vectors (``abs`` before ``mag``, whose SymPy form is ``Abs`` too)."""
    # workbook.numerics.registry.REGISTRY is this dict; it imports this module's entry, so the dict
    # is read from its home. By the time a derivative is read back every entry is registered.
    from ..functions.entry import ENTRIES

    table = _sympy_functions(tuple(ENTRIES.values()))  # read again when an entry is added
    return {name: entry for name, (entry, _) in table.items()}


def _sympy_function(name: str) -> tuple[str, tuple[int, ...]] | None:
    """The built-in written as SymPy's function ``name`` and, for each of its arguments, the
    position of that argument in SymPy's (``atan2(x, y)`` is SymPy's ``atan2(y, x)``)."""
    from ..functions.entry import ENTRIES

    return _sympy_functions(tuple(ENTRIES.values())).get(name)


@functools.lru_cache(maxsize=4)
def _sympy_functions(entries: tuple) -> dict[str, tuple[str, tuple[int, ...]]]:
    import sympy as sp

    out: dict[str, tuple[str, tuple[int, ...]]] = {}
    for entry in sorted(entries, key=lambda b: b.arrays):  # a stable sort
        if entry.binds or entry.data_args:
            continue
        for n in _argument_counts(entry.arity):
            symbols = sp.symbols(f"a0:{n}", real=True)
            try:
                e = entry.sympy(sp, *symbols)
            except Exception:  # noqa: BLE001 - a hook that refuses symbols names no function
                continue
            simple = isinstance(e, sp.Basic) and not isinstance(e, (sp.Add, sp.Mul, sp.Pow))
            if simple and not e.is_Atom and sorted(e.args, key=str) == list(symbols):
                order = tuple(e.args.index(s) for s in symbols)
                out.setdefault(type(e).__name__, (entry.name, order))
    return out


def _argument_counts(arity) -> range:
    if arity is None:
        return range(1, 3)
    if isinstance(arity, int):
        return range(arity, arity + 1)
    lo, hi = arity
    return range(lo, min(hi if hi is not None else lo + 1, lo + 2) + 1)


_REL = {"<": "<", "<=": "<=", ">": ">", ">=": ">=", "==": "==", "!=": "!="}


@dataclass(eq=False)
class Pending:
    """One diff() call: EXPR, the variable, the order, its unit and where it is written."""

    body: ty.T
    var: ty.TParam
    order: int
    unit: object
    where: dict = field(default_factory=dict)  # file, line, definition
    tree: ty.T | None = None
    error: WorkbookError | None = None  # SymPy's failure, remembered: it is not tried again
    compiled: weakref.WeakKeyDictionary = field(default_factory=weakref.WeakKeyDictionary)

    def __getstate__(self) -> dict:  # a Sheet pickles: the compiled closures are left out
        return {**self.__dict__, "compiled": None}

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state, compiled=weakref.WeakKeyDictionary())


def pending(typer, body: ty.T, var: ty.TParam, order: int, unit) -> Pending:
    """Record a diff() call being typed (no SymPy): its derivative is found at first use."""
    rec = Pending(body, var, order, unit, typer.where())
    typer.derivatives[id(body)] = rec
    return rec


def formula(defs, body: ty.T, var: ty.TParam, order: int) -> ty.T:
    """The typed tree of ``diff(body, var, order)`` (found once; later calls reuse it).

    An error of SymPy's derivative (a function with no formula in the worksheet language)
    names the file, line and definition of the diff() call."""
    rec = defs.derivatives.get(id(body))
    if rec is None or rec.body is not body or rec.order != order:
        # a call not met at load (a tree rebuilt by an analysis): no location known
        rec = Pending(body, var, order, body.unit / un.difference_unit(var.unit) ** order)
    if rec.error is not None:
        raise rec.error
    if rec.tree is None:
        try:
            rec.tree = derivative(defs, body, var, order, rec.unit)
        except WorkbookError as err:
            rec.error = err.located(**rec.where)
            raise rec.error from None
    return rec.tree


def compiled(evaluator, body: ty.T, var: ty.TParam, order: int):
    """The derivative compiled by ``evaluator`` (a numpy closure of an environment)."""
    tree = formula(evaluator.defs, body, var, order)
    rec = evaluator.defs.derivatives.get(id(body))
    if rec is None or rec.tree is not tree:
        return evaluator.compile(tree)
    fn = rec.compiled.get(evaluator)
    if fn is None:
        fn = rec.compiled[evaluator] = evaluator.compile(tree)
    return fn


def derivative(defs, body: ty.T, var: ty.TParam, order: int, unit) -> ty.T:
    """The ``order``-th derivative of ``body`` with respect to ``var``, in ``unit``."""
    import sympy as sp

    size = inlined_size(defs, body)
    if size > MAX_DIFF_NODES:  # SymPy's derivative grows with it (a product rule per node)
        raise LimitError(
            f"diff(): the expression is {size:,} nodes with the functions it calls written out "
            f"(limit {MAX_DIFF_NODES:,}); SymPy would take minutes. Differentiate a simpler "
            "function, or give the derivative as a formula"
        )
    leaves = _leaves(defs, body)
    refs = {n: t for n, t in leaves.items() if isinstance(t, ty.TRef)}
    from .symbolic import SympyConverter

    # no values: inputs and the definitions it refers to stay symbols
    conv = SympyConverter(types.SimpleNamespace(typer=defs, values={}), keep=set(refs))
    what = "diff(): SymPy's derivative (a function nested in itself grows it exponentially)"
    with within_seconds(MAX_DIFF_SECONDS, what):
        try:
            expr = conv.convert(body)
        except NotSymbolic as err:
            raise TemplateError(f"diff(): {err.message}") from None
        symbol = sp.Symbol(var.name, real=True)
        d = sp.diff(expr, symbol, order)
        nodes = {sp.Symbol(n, real=True): t for n, t in leaves.items()}
        nodes[symbol] = var
        out = _Back(nodes, defs.dimensionless).visit(d)
    return ty.TScale(unit, child=out, factor=1.0)


#: Nodes of an expression given to SymPy's diff, the sheet functions it calls written out
#: (a call inside a call repeats the inner body; the largest in the templates is 144).
MAX_DIFF_NODES = 1_000
#: Wall-clock seconds of SymPy's work for one diff() (a 125-node nest took 3.6 s, 377 nodes
#: more than 40 s).
MAX_DIFF_SECONDS = 10.0


def inlined_size(defs, body: ty.T) -> int:
    """Nodes of ``body`` with every sheet function it calls written out at each call (what
    SymPy receives); each function's size is counted once, so this is cheap however large."""
    sizes: dict[str, int] = {}

    def size(node: ty.T) -> int:
        total, stack = 0, [node]
        while stack:
            n = stack.pop()
            total += 1
            if isinstance(n, ty.TCall):
                if n.name not in sizes:
                    sizes[n.name] = 0  # a function calling itself: not written out
                    sizes[n.name] = size(defs.function(n.name).body)
                total += sizes[n.name]
            stack.extend(ty.children(n))
        return total

    return size(body)


def _leaves(defs, body: ty.T) -> dict[str, ty.T]:
    """Parameters and references of ``body``, also inside the sheet functions it calls."""
    out: dict[str, ty.T] = {}
    for n in ty.with_calls(defs, body):
        if isinstance(n, (ty.TParam, ty.TRef)):
            out.setdefault(n.name, n)
    return out


class _Back(Visitor):
    """A SymPy expression read back as a typed tree (inner nodes are plain numbers)."""

    def __init__(self, nodes: dict, dimensionless):
        self.nodes = nodes
        self.dl = dimensionless

    def visit(self, e, *args):
        if not e.free_symbols and not getattr(e, "is_Relational", False) and e.is_number:
            v = complex(e.evalf(30))
            if v.imag or not math.isfinite(v.real):
                raise TemplateError(f"diff(): the derivative holds {e}, not a finite number")
            return ty.TConst(self.dl, value=v.real)
        method = getattr(self, "visit_" + type(e).__name__, None)
        if method is None:
            method = self._function
        return method(e)

    def _function(self, e):
        found = _sympy_function(type(e).__name__)
        if found is None:
            raise TemplateError(
                f"diff(): the derivative contains {type(e).__name__} ({e}), which has no "
                "formula in the worksheet language"
            )
        name, order = found
        ordered = e.args if order == tuple(range(len(order))) else [e.args[i] for i in order]
        args = tuple(self.visit(a) for a in ordered)  # Max(a, b, c): every argument
        if name in ("min", "max") and len(args) > 2:
            out = args[0]
            for a in args[1:]:
                out = ty.TFunc(self.dl, func=name, args=(out, a))
            return out
        return ty.TFunc(self.dl, func=name, args=args)

    def visit_Symbol(self, e):
        if e not in self.nodes:  # pragma: no cover - every symbol came from the tree
            raise TemplateError(f"diff(): unknown symbol {e}")
        return self.nodes[e]

    def visit_Add(self, e):
        terms = [self.visit(a) for a in e.as_ordered_terms()]
        out = terms[0]
        for t in terms[1:]:
            out = ty.TBinary(self.dl, op="+", left=out, right=t)
        return out

    def visit_Mul(self, e):
        import sympy as sp

        num, den = sp.fraction(e)
        if den != 1:
            return ty.TBinary(self.dl, op="/", left=self.visit(num), right=self.visit(den))
        factors = [self.visit(a) for a in e.as_ordered_factors()]
        out = factors[0]
        for f in factors[1:]:
            out = ty.TBinary(self.dl, op="*", left=out, right=f)
        return out

    def visit_Pow(self, e):
        import sympy as sp

        base, exp = e.args
        if exp == sp.Rational(1, 2):
            return ty.TFunc(self.dl, func="sqrt", args=(self.visit(base),))
        if exp.is_number and exp < 0:
            one = ty.TConst(self.dl, value=1.0)
            return ty.TBinary(self.dl, op="/", left=one, right=self.visit(base ** (-exp)))
        if base == sp.E:
            return ty.TFunc(self.dl, func="exp", args=(self.visit(exp),))
        return ty.TBinary(self.dl, op="^", left=self.visit(base), right=self.visit(exp))

    def visit_exp(self, e):
        return ty.TFunc(self.dl, func="exp", args=(self.visit(e.args[0]),))

    def visit_Piecewise(self, e):
        import sympy as sp

        conds, values = [], []
        for value, cond in e.args:
            values.append(self.visit(value))
            conds.append(None if cond == sp.true else self._condition(cond))
        texts = tuple(str(v) for v, _ in e.args)
        return ty.TPiecewise(self.dl, conditions=tuple(conds), values=tuple(values), texts=texts)

    def visit_Heaviside(self, e):
        import sympy as sp

        u = e.args[0]
        return self.visit(sp.Piecewise((1, u > 0), (sp.Rational(1, 2), sp.Eq(u, 0)), (0, True)))

    def _condition(self, c):
        import sympy as sp

        if isinstance(c, (sp.And, sp.Or)):
            op = "and" if isinstance(c, sp.And) else "or"
            vals = tuple(self._condition(a) for a in c.args)
            return ty.TLogic(self.dl, op=op, values=vals, boolean=True)
        if isinstance(c, sp.Not):
            return ty.TUnary(self.dl, op="not", child=self._condition(c.args[0]), boolean=True)
        if getattr(c, "is_Relational", False) and c.rel_op in _REL:
            operands = (self.visit(c.lhs), self.visit(c.rhs))
            return ty.TCompare(self.dl, ops=(_REL[c.rel_op],), operands=operands, boolean=True)
        raise TemplateError(f"diff(): cannot write the condition {c} in the worksheet language")
