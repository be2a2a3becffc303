"""SymPy view of a sheet: the typed tree printed as a SymPy expression.

The converter walks the engine's typed tree (:mod:`workbook.language.typecheck`), so the
unit logic is already resolved: every magnitude is in the unit the typed node
carries and every conversion is an explicit factor (``TScale``). Calls of the
sheet's own functions are inlined; inputs become exact rational numbers (their
decimal value) unless a symbol is asked for; the built-in ``pi`` is SymPy's
exact ``pi``.

API (kept small on purpose; other scenes use it)::

    from workbook.numerics import symbolic
    expr = symbolic.to_sympy(sheet, "h1")                 # in the symbol phi
    d1 = symbolic.derivative(sheet, "h1", "phi", 1)       # d h1 / d phi (phi in its binding unit)
    f = symbolic.lambdify(sheet, d1, "phi")               # numpy function of phi

A function argument is a magnitude in its binding unit: for ``plain = true``
arguments (Mathcad's ``phi*deg``) that is the plain number of degrees, so the
derivative is per degree; multiply by ``per_radian(sheet, "phi")`` for the
derivative per radian.

``sympy`` is imported lazily (inside functions) so that loading the engine
does not pay for it.
"""

from __future__ import annotations

import math
from fractions import Fraction

from ..errors import NotSymbolic, WorkbookError
from ..functions.constants import CONSTANTS

# the registry's dict (workbook.numerics.registry.REGISTRY), read from its home: the registry
# imports the entry of diff, which imports this module; every entry is registered by the time
# a tree is converted
from ..functions.entry import ENTRIES
from ..language import typed as ty
from ..language import units as un
from ..language.visitor import Visitor


def _sympy():
    import sympy

    return sympy


def exact_number(value: float):
    """A float as an exact SymPy number: a short fraction (times pi), else its decimal."""
    sp = _sympy()
    if isinstance(value, complex):  # a + b*I
        return exact_number(value.real) + sp.I * exact_number(value.imag)
    v = float(value)
    if not math.isfinite(v):
        raise NotSymbolic(f"{v} is not a finite number")
    if v == 0.0:
        return sp.Integer(0)
    if v.is_integer() and abs(v) < 2**53:
        return sp.Integer(int(v))
    for base, sym in ((1.0, sp.Integer(1)), (math.pi, sp.pi), (1 / math.pi, 1 / sp.pi)):
        q = v / base
        frac = Fraction(q).limit_denominator(10**6)
        if frac.denominator < 10**6 and abs(float(frac) - q) <= 4e-16 * abs(q):
            return sp.Rational(frac.numerator, frac.denominator) * sym
    return sp.Rational(repr(v))


class _Refusal(Visitor):
    """Why a typed node itself has no symbolic form (a message), or None. Reads no SymPy, so
    that ``diff()`` refuses such an EXPR when the sheet is loaded (:func:`refusal`) with the
    message the converter gives when it meets the node."""

    def _none(self, t, symbols, values) -> None:
        return None

    visit_TConst = visit_TText = visit_TParam = visit_TScale = visit_TUnary = _none
    visit_TCompare = visit_TLogic = visit_TCall = visit_TPiecewise = _none

    def visit_TRef(self, t, symbols, values):
        if t.kind == "choice" and t.name not in symbols and t.name not in values:
            # A choice is a word, not a number: with no value to compare (a derivative found
            # once for every value of the input) a condition on it has no symbolic form, and
            # comparing a symbol with the word would silently pick the last piece.
            return (
                f"a condition on the choice '{t.name}' has no symbolic form; "
                "write one function per option and choose between their results"
            )
        return None

    def visit_TBinary(self, t, symbols, values):
        if t.shape is not None or t.left.shape is not None or t.right.shape is not None:
            return self.visit_TMatrix(t, symbols, values)
        return None

    def visit_TFunc(self, t, symbols, values):
        return getattr(ENTRIES[t.func].sympy, "refusal", None)

    def visit_TBlock(self, t, symbols, values):
        return f"{t.name}() is a solver block ({t.ref}): it has no formula to differentiate"

    def visit_TMatrix(self, t, symbols, values):
        return "vectors and matrices are not differentiated symbolically"

    visit_TIndex = visit_TMatrix

    def visit_TProgram(self, t, symbols, values):
        return f"the program of {t.name} is statements, not one formula"

    def visit_TOde(self, t, symbols, values):
        return f"{t.name}() is the solution of ode '{t.ode}', a numerical result"

    def visit_TAggregate(self, t, symbols, values):
        return f"{t.func}_over({t.table}, {t.column}) is a value of a table, not a formula"


_REFUSAL = _Refusal()


def refusal(typer, t: ty.T) -> str | None:
    """Why ``t`` (with the sheet functions it calls) has no symbolic form, or None; inputs and
    definitions it refers to count as symbols. No SymPy is imported."""
    for n in ty.with_calls(typer, t):  # a call's body is read after the call is checked
        why = _REFUSAL.visit(n, {}, {})
        if why:
            return why
        if isinstance(n, ty.TCall) and n.name in typer.recursive:
            return f"{n.name.split('@')[0]}() calls itself"
    return None


class SympyConverter(Visitor):
    """Converts typed nodes of one sheet to SymPy; one ``visit_<Node>`` method per node kind."""

    def __init__(self, sheet, symbols: dict | None = None, *, keep=(), true_pi: bool = False):
        self.sheet = sheet
        self.symbols = dict(symbols or {})
        self.keep = set(keep)
        self.true_pi = true_pi
        self._scalars: dict[str, object] = {}
        self._bodies: dict[str, tuple] = {}

    # -- entry points -------------------------------------------------------------------
    def visit(self, node, *args):
        why = _REFUSAL.visit(node, self.symbols, self.sheet.values)
        if why:
            raise NotSymbolic(why)
        return super().visit(node, *args)

    def convert(self, t: ty.T, env: dict | None = None):
        """SymPy expression of ``t``; ``env`` maps parameters to SymPy expressions."""
        return self.visit(t, env or {})

    def function(self, name: str):
        """(parameter symbols, body expression) of a sheet function."""
        if name not in self._bodies:
            if name in self.sheet.typer.recursive:
                raise NotSymbolic(f"{name.split('@')[0]}() calls itself")
            sp = _sympy()
            f = self.sheet.typer.function(name)
            syms = tuple(self.symbols.get(p, sp.Symbol(p, real=True)) for p in f.params)
            body = self.convert(f.body, dict(zip(f.params, syms)))
            self._bodies[name] = (syms, body)
        return self._bodies[name]

    # -- nodes --------------------------------------------------------------------------
    def visit_TConst(self, t, env):
        return exact_number(t.value)

    def visit_TText(self, t, env):
        return t.value

    def visit_TParam(self, t, env):
        if t.name in env:
            return env[t.name]
        if t.name in self.symbols:
            return self.symbols[t.name]
        return _sympy().Symbol(t.name, real=True)

    def visit_TRef(self, t, env):
        sp = _sympy()
        name, kind = t.name, t.kind
        if name in self.symbols:
            return self.symbols[name]
        if kind == "choice":  # its word (a choice without a value is refused: _Refusal)
            return self.sheet.values[name]
        if name in self.keep:
            return sp.Symbol(name, real=True)
        if kind == "builtin":  # a constant: pi, e, g
            return CONSTANTS[name].sympy()
        if kind == "input":
            if self.true_pi and name == "pi":
                return sp.pi
            return exact_number(self.sheet.values[name].magnitude)
        if name not in self._scalars:
            self._scalars[name] = self.convert(self.sheet.typer.scalar(name), {})
        return self._scalars[name]

    def visit_TScale(self, t, env):
        child = self.convert(t.child, env)
        return child if t.factor == 1.0 else exact_number(t.factor) * child

    def visit_TUnary(self, t, env):
        sp = _sympy()
        child = self.convert(t.child, env)
        return sp.Not(child) if t.op == "not" else -child

    def visit_TBinary(self, t, env):
        sp = _sympy()
        a, b = self.convert(t.left, env), self.convert(t.right, env)
        if t.op == "+":
            return a + b
        if t.op == "-":
            return a - b
        if t.op == "*":
            return a * b
        if t.op == "/":
            return a / b
        return sp.Pow(a, b)

    def visit_TCompare(self, t, env):
        sp = _sympy()
        vals = [self.convert(o, env) for o in t.operands]
        if any(isinstance(v, str) for v in vals):
            a, b = vals
            same = a == b
            return sp.true if (same if t.ops[0] == "==" else not same) else sp.false
        rel = {"<": sp.Lt, "<=": sp.Le, ">": sp.Gt, ">=": sp.Ge, "==": sp.Eq, "!=": sp.Ne}
        parts = [rel[op](x, y) for op, x, y in zip(t.ops, vals, vals[1:])]
        return parts[0] if len(parts) == 1 else sp.And(*parts)

    def visit_TLogic(self, t, env):
        sp = _sympy()
        vals = [self.convert(v, env) for v in t.values]
        return sp.And(*vals) if t.op == "and" else sp.Or(*vals)

    def visit_TFunc(self, t, env):
        sp = _sympy()
        entry = ENTRIES[t.func]
        if not entry.binds:
            return entry.sympy(sp, *[self.convert(a, env) for a in t.args])
        expr_at, var_at = entry.binds
        var = sp.Symbol(t.args[var_at].name, real=True)
        body = self.convert(t.args[expr_at], {**env, t.args[var_at].name: var})
        rest = [self.convert(a, env) for i, a in enumerate(t.args) if i not in (expr_at, var_at)]
        out = entry.sympy(sp, body, var, *rest)
        # the variable left free in the result (diff's) is the one of the enclosing scope
        name = t.args[var_at].name
        outer = env.get(name, self.symbols.get(name))
        if outer is not None and var in getattr(out, "free_symbols", ()):
            out = out.xreplace({var: outer})
        return out

    def visit_TCall(self, t, env):
        syms, body = self.function(t.name)
        args = [self.convert(a, env) for a in t.args]
        return body.xreplace(dict(zip(syms, args)))

    def visit_TPiecewise(self, t, env):
        sp = _sympy()
        pieces = []
        for cond, val in zip(t.conditions, t.values):
            c = sp.true if cond is None else self.convert(cond, env)
            pieces.append((self.convert(val, env), c))
        if pieces[-1][1] is not sp.true:
            pieces.append((sp.nan, True))
        return sp.Piecewise(*pieces)


def to_sympy(sheet, name_or_typed, symbols: dict | None = None, *, keep=(), true_pi=False):
    """SymPy expression of a definition (by name) or of a typed node.

    ``symbols`` maps parameter, input or definition names to SymPy symbols or expressions
    (parameters default to real symbols named like the parameter); names in ``keep`` stay
    symbols (for printing); ``true_pi=True`` replaces a sheet input named ``pi`` (such as
    the concave-cam sheet's 3.142) by the exact pi.
    """
    conv = SympyConverter(sheet, symbols, keep=keep, true_pi=true_pi)
    try:
        if isinstance(name_or_typed, str):
            d = sheet.spec.definitions.get(name_or_typed)
            if d is None:
                if name_or_typed in sheet.spec.inputs:
                    return conv.convert(
                        ty.TRef(sheet.typer.unit_of(name_or_typed), name=name_or_typed), {}
                    )
                raise NotSymbolic(f"'{name_or_typed}' is not defined in {sheet.name}")
            if d.is_function:
                return conv.function(name_or_typed)[1]
            return conv.convert(sheet.typer.scalar(name_or_typed), {})
        return conv.convert(name_or_typed, {})
    except WorkbookError as err:
        raise err.located(file=sheet.file) from None


def symbol(name: str, real: bool = True):
    """The SymPy symbol the converter uses for a parameter (real by default).

    Pass ``symbols={name: sympy.Symbol(name)}`` (no assumptions) where speed matters:
    differentiating with assumption-free symbols is several times faster.
    """
    return _sympy().Symbol(name, real=real)


def derivative(sheet, name: str, var: str | None = None, order: int = 1, **options):
    """d^order(name)/d(var)^order, with var in its binding unit (degrees for plain deg)."""
    sp = _sympy()
    d = sheet.spec.definitions.get(name)
    if d is None or not d.is_function:
        raise NotSymbolic(f"'{name}' is not a function of the sheet")
    var = var or d.params[0]
    if var not in d.params:
        raise NotSymbolic(f"{name}() has no argument '{var}' (arguments: {', '.join(d.params)})")
    expr = to_sympy(sheet, name, **options)
    sym = (options.get("symbols") or {}).get(var, symbol(var))
    return sp.diff(expr, sym, order)


def per_radian(sheet, var: str, unit: str = "rad") -> float:
    """Binding-unit magnitudes of ``var`` per one ``unit`` (57.29... for a degree argument)."""
    arg = sheet.spec.arguments[var]
    return un.factor(un.unit(unit), arg.unit)


def lambdify(sheet, expr, *params: str, modules="numpy"):
    """A fast function of the given parameters (names of symbols in ``expr``)."""
    sp = _sympy()
    return sp.lambdify([symbol(p) for p in params], expr, modules=modules)


def text(sheet, t: ty.T, keep=None) -> str:
    """Readable text of a typed sub-expression (inputs and scalar definitions kept as names)."""
    sp = _sympy()
    if keep is None:
        keep = set(sheet.spec.inputs) | {
            n for n, d in sheet.spec.definitions.items() if not d.is_function
        }
    expr = SympyConverter(sheet, keep=keep).convert(t, {})
    return sp.sstr(expr).replace("**", "^")
