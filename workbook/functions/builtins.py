"""The built-in functions: one :class:`Builtin` entry per function, read by every back end.

An entry says everything the engine needs to know about one function:

* ``arity``: exact number of arguments, ``(min, max)`` (``max`` None: no limit), or None
  for one or more;
* ``unit_rule(ctx, name, args) -> T``: the typed node (:mod:`workbook.language.typed`) of a call
whose
  arguments are already typed; ``ctx`` is the typer (:class:`UnitContext`), which offers
  ``convert(t, unit, where)``, ``plain(t, where)``, ``meeting(values)`` (bare numbers next
  to an angle in degrees take its unit) and ``dimensionless``;
* ``numpy(*values)``: the function on numpy arrays (magnitudes in the units the rule chose);
* ``excel(args) -> (text, level)``: the Excel formula from the printed arguments, with the
  precedence level of the result (:data:`workbook.language.expr.PREC`); it raises
  :class:`workbook.errors.NotLive` when there is no live formula.
  A newer Excel function is printed with its stored prefix (``_xlfn.NORM.DIST``:
  :func:`workbook.functions.excel_functions.stored`); nothing else lists the functions a formula
  calls;
* ``sympy(sp, *exprs)``: the SymPy expression (``sp`` is the sympy module, imported lazily);
* ``domain``: the arguments' restricted domains (:class:`Domain`), explained by
  :mod:`workbook.engine.analysis` when a value is not finite;
* ``doc``: one line for the documentation;
* ``mpmath``: a function of one argument, the name of its mpmath function of the same meaning
  (the reference evaluator, :mod:`workbook.numerics.mpform`); "" when it has none there;
* ``singular``, ``jumps``, ``kinks``: where the value is singular, jumps or has a kink, as
  typed trees that are 0 there (``sqrt``: its argument; ``floor(u)``: ``sin(pi u)``; ``abs``:
  its argument), read when an integrand is split (:mod:`workbook.numerics.singular`,
  :mod:`workbook.numerics.switches`); ``angle``: the argument is an angle (the angle warnings);
* ``estimate``: how the value's error is estimated (``"iterative"`` for root, integral...,
  ``"condition"`` for lsolve, inverse...: :mod:`workbook.numerics.bench`); ``live_note``: how
  an approximate live Excel form computes, said beside its cell;
* ``mathml``: how a report writes a call (:mod:`workbook.outputs.report.mathml`): MathML in which
  ``{0}``, ``{1}``... are the arguments, ``{0:group}`` the argument bracketed unless it is a
  product or tighter, ``{args}`` all of them with commas; a call whose arguments the template
  does not all show (diff with N), or an empty template: the name and the arguments in
  brackets, ``sin(x)``. ``mathml_powered``: a power of a call is written on the name, as
  ``sin²(x)``.

Built-ins that bind a variable (``sum(EXPR, I, A, B)``, later ``root``, ``integral``...) set
``binds=(expr_index, var_index)``. The typer then types the argument at ``expr_index`` in the
scope extended with the variable named at ``var_index`` (its unit is the declared unit of that
name in ``[arguments]``; dimensionless if it is not declared), and the typed node keeps the
source order of the arguments (the variable as a ``TParam``). The hooks then receive:

* ``numpy(fn, *values)``: ``fn(v)`` evaluates EXPR with the variable set to ``v`` (the rest of
  the environment as in the call); ``values`` are the other arguments, evaluated;
* ``excel(body, args, consts) -> (text, level)``: ``body(text)`` prints EXPR with the variable
  replaced by the formula ``text``; ``args`` are the other arguments printed and ``consts``
  their values when they are constants (else None);
* ``sympy(sp, body, var, *exprs)``: ``body`` in the symbol ``var``.

Built-ins that read measured data (``linterp(X, Y, x)``) set ``data_args``: the arguments
at those positions must be names of ``[data]`` columns, typed as references of kind
``data`` (the column's values, in its declared unit); such names are refused elsewhere.

To add a built-in, write its rule and hooks and call :func:`register` at import of the module
that defines it (a module imported by :mod:`workbook.numerics.registry`, the complete registry),
e.g.::

    register(Builtin("cbrt", 1, unit_rule=root_unit(3), numpy=np.cbrt,
                     excel=excel_call("POWER", "{}, 1/3"), sympy=lambda sp, x: sp.cbrt(x),
                     doc="cube root"))

and document it in docs/language.md. Nothing else in the engine lists built-ins.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ..errors import InputError, LimitError, NotLive, TemplateError, UnitError
from ..language import typed as ty
from ..language.expr import PREC
from ..language.unitrules import sum_kind
from ..language.units import pretty, registry
from . import interval_arith as ia
from .complexes import classic, im_call, im_cosh, im_sinh, im_tan, im_tanh
from .entry import Builtin, Domain, UnitContext, register


# -- unit rules ------------------------------------------------------------------------------
def plain_in(ctx: UnitContext, name: str, args: tuple) -> ty.T:
    """A plain number in and out (angles in radians): sin, exp, asin..."""
    return ty.TFunc(ctx.dimensionless, func=name, args=(ctx.plain(args[0], f"{name}()"),))


def same_unit(ctx: UnitContext, name: str, args: tuple) -> ty.T:
    """The result in the unit of the first argument; the others converted to it (a bare
    number next to an angle in degrees is in degrees: max(theta, 45))."""
    args = tuple(ctx.meeting(args))
    first = args[0]
    rest = tuple(ctx.convert(a, first.unit, f"{name}() arguments") for a in args[1:])
    return ty.TFunc(first.unit, func=name, args=(first, *rest))


def _sqrt_unit(ctx: UnitContext, name: str, args: tuple) -> ty.T:
    return ty.TFunc(args[0].unit ** 0.5, func=name, args=(args[0],))


def _sign_unit(ctx: UnitContext, name: str, args: tuple) -> ty.T:
    return ty.TFunc(ctx.dimensionless, func=name, args=(args[0],))


def _atan2_unit(ctx: UnitContext, name: str, args: tuple) -> ty.T:
    x, y = args
    y = ctx.convert(y, x.unit, "atan2(x, y): x and y")
    return ty.TFunc(ctx.dimensionless, func=name, args=(x, y))


# -- Excel -------------------------------------------------------------------------------------
def excel_call(function: str) -> Callable[[list[str]], tuple[str, int]]:
    """The Excel function ``function`` called with the arguments in order."""

    def printed(args: list[str]) -> tuple[str, int]:
        return f"{function}({', '.join(args)})", PREC["atom"]

    return printed


def _excel_ceil(args: list[str]) -> tuple[str, int]:
    return f"-INT(-({args[0]}))", PREC["+"]


# -- the classic built-ins -----------------------------------------------------------------------
_SQRT = Domain("sqrt of a negative number", lambda v: v < 0, "sqrt({})")


def _inverse_domain(name: str) -> tuple[Domain, ...]:
    return (Domain(f"{name} of a value beyond 1", lambda v: np.abs(v) > 1, name + "({})"),)


def _log_domain(name: str) -> tuple[Domain, ...]:
    return (Domain(f"{name} of a value that is not positive", lambda v: v <= 0, name + "({})"),)


def _simple(name, numpy, excel, sympy, doc, rule=plain_in, domain=(), arity=1, **display):
    xl = excel if callable(excel) else excel_call(excel)
    register(Builtin(name, arity, rule, numpy, xl, sympy, domain, doc, **display))


def mathml_call(label: str) -> str:
    """MathML of a call written with another name: ``arcsin(x)`` for asin."""
    return f"<mi>{label}</mi><mo>\u2061</mo><mrow><mo>(</mo>{{args}}<mo>)</mo></mrow>"


def mathml_fence(left: str, right: str) -> str:
    """MathML of a one-argument call written between fences: ``|x|``."""
    return f"<mrow><mo>{left}</mo>{{0}}<mo>{right}</mo></mrow>"


_TRIG = {"mathml_powered": True}


# -- where a value is singular, jumps or has a kink (read by workbook.numerics) ----------------
def _argument(t: ty.TFunc) -> tuple[ty.T, ...]:
    """sqrt, ln, log10: singular where the argument is 0."""
    return (t.args[0],) if len(t.args) == 1 else ()


def _cosine(t: ty.TFunc) -> tuple[ty.T, ...]:
    """tan: its poles are the zeros of the cosine of its argument."""
    return (ty.TFunc(t.unit, func="cos", args=t.args),) if len(t.args) == 1 else ()


def _wave(wave: str, u: ty.T) -> ty.TFunc:
    """``wave(pi u)``, a smooth tree zero where a step function of u jumps."""
    one = registry().dimensionless
    return ty.TFunc(one, func=wave, args=(ty.TScale(one, child=u, factor=math.pi),))


def _integer_jumps(t: ty.TFunc) -> ty.T | None:
    """floor, ceil, trunc jump at every integer: the zeros of sin(pi u)."""
    return _wave("sin", t.args[0]) if len(t.args) == 1 else None


def _half_jumps(t: ty.TFunc) -> ty.T | None:
    """round jumps at every half-integer: the zeros of cos(pi u)."""
    return _wave("cos", t.args[0]) if len(t.args) == 1 else None


def _mod_jumps(t: ty.TFunc) -> ty.T | None:
    """mod(a, m) jumps where a/m is an integer: the zeros of sin(pi a/m)."""
    if len(t.args) != 2 or t.args[1].shape is not None:
        return None
    one = registry().dimensionless
    return _wave("sin", ty.TBinary(one, op="/", left=t.args[0], right=t.args[1]))


def _argument_kink(t: ty.TFunc) -> tuple:
    """abs, sign: a kink (or a jump) where the argument is 0."""
    return ((t.args[0], None),) if len(t.args) == 1 else ()


def _complex(function: str) -> dict:
    """The fields of a built-in over the complex plane, Excel's ``function`` its live form."""
    return {"complex": "complex", "complex_excel": im_call(function)}


def _classic(form) -> dict:
    """The same, the live form made of the classic IM* functions (tan, sinh, cosh)."""
    return {"complex": "complex", "complex_excel": classic(form)}


_simple(
    "sin",
    np.sin,
    "SIN",
    lambda sp, x: sp.sin(x),
    "sine (argument in radians)",
    mpmath="sin",
    interval=(ia.sin, ia.cos),
    angle=True,
    **_TRIG,
    **_complex("IMSIN"),
    mathcad=("sin",),
    excel_import=("SIN",),
    vba=("sin",),
)
_simple(
    "cos", np.cos, "COS", lambda sp, x: sp.cos(x), "cosine", mpmath="cos", angle=True,
    interval=(ia.cos, ia.minus_sin), **_TRIG, **_complex("IMCOS"),
    mathcad=("cos",),
    excel_import=("COS",), vba=("cos",),
)  # fmt: skip
_simple(
    "tan", np.tan, "TAN", lambda sp, x: sp.tan(x), "tangent", mpmath="tan", angle=True,
    singular=_cosine, interval=(ia.tan, ia.tan_slope), **_TRIG, **_classic(im_tan),
    mathcad=("tan",),
    excel_import=("TAN",), vba=("tan",),
)  # fmt: skip


def _reciprocal(excel: str) -> Callable[[list[str]], tuple[str, int]]:
    """1/COS(x): Excel's SEC, CSC and COT are 2013 functions that older readers lack."""
    return lambda args: (f"1/{excel}({args[0]})", PREC["/"])


def _reciprocals(table, **display) -> None:
    """sec = 1/cos and the others of ``table``: (name, numpy function, Excel's, what it is)."""
    for name, of, excel, what in table:
        _simple(
            name,
            lambda x, of=of: 1 / of(x),
            _reciprocal(excel),
            lambda sp, x, name=name: getattr(sp, name)(x),
            f"{what}, 1/{excel.lower()}(x)",
            mpmath=name,
            mathcad=(name,),
            **display,
        )


_reciprocals(
    (
        ("sec", np.cos, "COS", "secant"),
        ("csc", np.sin, "SIN", "cosecant"),
        ("cot", np.tan, "TAN", "cotangent"),
    ),
    **_TRIG,
)
_simple(
    "asin",
    np.arcsin,
    "ASIN",
    lambda sp, x: sp.asin(x),
    "arc sine",
    domain=_inverse_domain("asin"),
    mpmath="asin",
    mathml=mathml_call("arcsin"),
    mathcad=("asin",),
    excel_import=("ASIN",),
)
_simple(
    "acos",
    np.arccos,
    "ACOS",
    lambda sp, x: sp.acos(x),
    "arc cosine",
    domain=_inverse_domain("acos"),
    mpmath="acos",
    mathml=mathml_call("arccos"),
    mathcad=("acos",),
    excel_import=("ACOS",),
)
_simple(
    "atan",
    np.arctan,
    "ATAN",
    lambda sp, x: sp.atan(x),
    "arc tangent",
    mathml=mathml_call("arctan"),
    mpmath="atan",
    interval=(ia.atan, ia.atan_slope),
    mathcad=("atan",),
    excel_import=("ATAN",),
    vba=("atn",),
)
_simple(
    "atan2",
    lambda x, y: np.arctan2(y, x),
    "ATAN2",  # x first, as Mathcad's atan2 and Excel's ATAN2
    lambda sp, x, y: sp.atan2(y, x),
    "angle of the point (x, y), x first: atan2(x, y)",
    rule=_atan2_unit,
    arity=2,
    mathcad=("atan2", "angle"),
    excel_import=("ATAN2",),
)
_simple(
    "sinh",
    np.sinh,
    "SINH",
    lambda sp, x: sp.sinh(x),
    "hyperbolic sine",
    mpmath="sinh",
    interval=(ia.sinh, ia.cosh),
    **_TRIG,
    **_classic(im_sinh),
    mathcad=("sinh",),
    excel_import=("SINH",),
)
_simple(
    "cosh",
    np.cosh,
    "COSH",
    lambda sp, x: sp.cosh(x),
    "hyperbolic cosine",
    mpmath="cosh",
    interval=(ia.cosh, ia.sinh),
    **_TRIG,
    **_classic(im_cosh),
    mathcad=("cosh",),
    excel_import=("COSH",),
)
_simple(
    "tanh",
    np.tanh,
    "TANH",
    lambda sp, x: sp.tanh(x),
    "hyperbolic tangent",
    mpmath="tanh",
    interval=(ia.tanh, ia.tanh_slope),
    **_TRIG,
    complex="complex",
    complex_excel=classic(im_tanh),
    mathcad=("tanh",),
    excel_import=("TANH",),
)
_reciprocals(
    (
        ("coth", np.tanh, "TANH", "hyperbolic cotangent"),
        ("sech", np.cosh, "COSH", "hyperbolic secant"),
        ("csch", np.sinh, "SINH", "hyperbolic cosecant"),
    )
)
_simple(
    "asinh",
    np.arcsinh,
    "ASINH",
    lambda sp, x: sp.asinh(x),
    "inverse hyperbolic sine",
    mpmath="asinh",
    mathcad=("asinh",),
    excel_import=("ASINH",),
)
_simple(
    "acosh",
    np.arccosh,
    "ACOSH",
    lambda sp, x: sp.acosh(x),
    "inverse hyperbolic cosine (of x >= 1)",
    domain=(Domain("acosh of a value below 1", lambda v: v < 1, "acosh({})"),),
    mpmath="acosh",
    mathcad=("acosh",),
    excel_import=("ACOSH",),
)
_simple(
    "atanh",
    np.arctanh,
    "ATANH",
    lambda sp, x: sp.atanh(x),
    "inverse hyperbolic tangent (of -1 < x < 1)",
    domain=(
        Domain("atanh of a value not between -1 and 1", lambda v: np.abs(v) >= 1, "atanh({})"),
    ),
    mpmath="atanh",
    mathcad=("atanh",),
    excel_import=("ATANH",),
)


def _asech(x):
    """ln((1 + sqrt(1 - x^2))/x): acosh(1/x) loses digits near 1 (the rounding of 1/x)."""
    x = np.asarray(x, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.log1p(np.sqrt((1 - x) * (1 + x))) - np.log(x)


def _of_reciprocal(inverse: str, excel: str) -> Callable[[list[str]], tuple[str, int]]:
    """ACOS(1/x): Excel has no ASEC, ACSC, ACOTH (2013), ASECH or ACSCH."""
    return lambda args: (f"{excel}(1/({args[0]}))", PREC["atom"])


for _name, _of, _excel, _what, _bad, _outside in (
    ("asec", np.arccos, "ACOS", "arc secant", lambda v: np.abs(v) < 1, "between -1 and 1"),
    ("acsc", np.arcsin, "ASIN", "arc cosecant", lambda v: np.abs(v) < 1, "between -1 and 1"),
    ("acoth", np.arctanh, "ATANH", "inverse hyperbolic cotangent", lambda v: np.abs(v) <= 1,
     "from -1 to 1"),
    ("asech", np.arccosh, "ACOSH", "inverse hyperbolic secant", lambda v: (v <= 0) | (v > 1),
     "not in (0, 1]"),
    ("acsch", np.arcsinh, "ASINH", "inverse hyperbolic cosecant", lambda v: v == 0, "0"),
):  # fmt: skip
    _simple(
        _name,
        _asech if _name == "asech" else (lambda x, of=_of: of(1 / x)),
        _of_reciprocal(_name, _excel),
        lambda sp, x, name=_name: getattr(sp, name)(x),
        f"{_what}, {_excel.lower()}(1/x)",
        domain=(Domain(f"{_name} of a value {_outside}", _bad, _name + "({})"),),
        mpmath=_name,
        mathcad=(_name,),
    )
_simple(
    "sqrt",
    np.sqrt,
    "SQRT",
    lambda sp, x: sp.sqrt(x),
    "square root",
    _sqrt_unit,
    (_SQRT,),
    mathml="<msqrt>{0}</msqrt>",
    mpmath="sqrt",
    singular=_argument,
    interval=(ia.sqrt, ia.sqrt_slope),
    **_complex("IMSQRT"),
    mathcad=("sqrt",),
    mathcad_operator="sqrt",
    excel_import=("SQRT",),
    vba=("sqr",),
)
_simple(
    "exp", np.exp, "EXP", lambda sp, x: sp.exp(x), "exponential", mpmath="exp",
    interval=(ia.exp, ia.exp), **_complex("IMEXP"),
    mathcad=("exp",),
    excel_import=("EXP",), vba=("exp",),
)  # fmt: skip
_simple(
    "ln",
    np.log,
    "LN",
    lambda sp, x: sp.log(x),
    "natural logarithm",
    domain=_log_domain("ln"),
    mpmath="ln",
    singular=_argument,
    interval=(ia.ln, ia.reciprocal),
    **_complex("IMLN"),
    mathcad=("ln",),
    excel_import=("LN",),
    vba=("log",),
)
_simple(
    "log10",
    np.log10,
    "LOG10",
    lambda sp, x: sp.log(x, 10),
    "logarithm base 10",
    domain=_log_domain("log10"),
    mpmath="log10",
    singular=_argument,
    interval=(ia.log10, ia.log10_slope),
    **_complex("IMLOG10"),
    mathml="<msub><mi>log</mi><mn>10</mn></msub><mo>\u2061</mo><mrow><mo>(</mo>{0}<mo>)</mo></mrow>",
    mathcad=("log",),
    excel_import=("LOG10", "LOG"),
)
_simple(
    "abs",
    np.abs,
    "ABS",
    lambda sp, x: sp.Abs(x),
    "absolute value (of a complex number: its modulus)",
    same_unit,
    mathml=mathml_fence("|", "|"),
    interval=(ia.absolute, ia.sign),
    mpmath="fabs",
    complex="real",
    complex_excel=im_call("IMABS"),
    kinks=_argument_kink,
    mathcad=("abs",),
    mathcad_operator="absval",
    excel_import=("ABS",),
    vba=("abs",),
)
_simple(
    "sign", np.sign, "SIGN", lambda sp, x: sp.sign(x), "-1, 0 or 1", _sign_unit, mpmath="sign",
    kinks=_argument_kink,
    mathcad=("sign",),
    excel_import=("SIGN",), vba=("sgn",),
)  # fmt: skip


# -- floor, ceil, round and trunc: of plain numbers only ----------------------------------------
def _ratio_of_one_kind(unit) -> bool:
    """A dimensionless unit none of whose factors is dimensionless itself (m/mm, not deg/s*s)."""
    ureg = registry()
    return all(ureg.Unit(name).dimensionality for name, _ in (1 * unit).unit_items())


def _integer_unit(ctx: UnitContext, name: str, args: tuple) -> ty.T:
    """floor, ceil, round and trunc take a plain number: rounding 1.5 m gives 2 m in metres
    but 1.5 m in millimetres (Mathcad rounds the value in SI units), so a value with a unit is
    refused, and so is one in a named dimensionless unit (deg, %), whose plain number is not
    the one written. A ratio of units of one kind (b/mm with b in m) is its plain number, as
    in Mathcad: round(b/mm) counts millimetres."""
    x = args[0]
    factor = None if x.unit.dimensionality else (1 * x.unit).to(ctx.dimensionless).magnitude
    if factor != 1 and not (factor is not None and _ratio_of_one_kind(x.unit)):
        raise UnitError(
            f"{name}() needs a plain number, got a value in {pretty(x.unit)}: the result would "
            f"depend on the unit it is rounded in; round a ratio, {name}(x/step)*step"
        )
    rest = tuple(ctx.plain(a, f"{name}(): the number of decimals") for a in args[1:])
    return ty.TFunc(ctx.dimensionless, func=name, args=(ctx.plain(x, f"{name}()"), *rest))


register(
    Builtin(
        "floor",
        1,
        _integer_unit,
        np.floor,
        lambda args: (f"INT({args[0]})", PREC["atom"]),
        lambda sp, x: sp.floor(x),
        doc="largest integer not above",
        mathml=mathml_fence("\u230a", "\u230b"),
        mpmath="floor",
        jumps=_integer_jumps,
        mathcad=("floor",),
        excel_import=("INT",),
        vba=("int",),
    )
)
register(
    Builtin(
        "ceil",
        1,
        _integer_unit,
        np.ceil,
        _excel_ceil,
        lambda sp, x: sp.ceiling(x),
        doc="smallest integer not below",
        mathml=mathml_fence("\u2308", "\u2309"),
        mpmath="ceil",
        jumps=_integer_jumps,
        mathcad=("ceil",),
    )
)


def _mod_unit(ctx: UnitContext, name: str, args: tuple) -> ty.T:
    x, y = args
    y = ctx.convert(y, x.unit, "mod(x, y): x and y")
    return ty.TFunc(x.unit, func=name, args=(x, y))


def _excel_mod(args: list[str]) -> tuple[str, int]:
    x, y = args  # Excel's MOD takes the sign of y; Mathcad's mod that of x
    return f"({x})-({y})*TRUNC(({x})/({y}))", PREC["+"]


_simple(
    "mod",
    np.fmod,
    _excel_mod,
    lambda sp, x, y: x - y * sp.sign(x / y) * sp.floor(sp.Abs(x / y)),
    "remainder of x / y, with the sign of x (Mathcad's mod)",
    rule=_mod_unit,
    domain=(Domain("mod by zero", lambda v: v == 0, "mod(x, {})", arg=1),),
    arity=2,
    jumps=_mod_jumps,
    mathcad=("mod",),
)


def round_numpy(x, n=0.0):
    """Round half away from zero to ``n`` decimals (Mathcad's round, Excel's ROUND). A value
    within 4 units in the last place below a half is taken as the half it was written as
    (2.675 to 2 decimals is 2.68, as in Excel and LibreOffice, though the double nearest to
    2.675 is below it); numpy's round goes half to even and is not used."""
    x, n = np.asarray(x, dtype=float), np.asarray(n, dtype=float)
    with np.errstate(all="ignore"):
        k = np.clip(n, -308, 308)
        scale = 10.0 ** np.abs(k)
        y = np.where(k >= 0, np.abs(x) * scale, np.abs(x) / scale)
        r = np.floor(y)
        r = r + (y - r >= 0.5 - np.where(y < 2.0**40, 4 * np.spacing(y), 0.0))
        out = np.where(k >= 0, r / scale, r * scale) * np.sign(x) + 0.0
        out = np.where(y >= 2.0**52, x, out)  # no fraction left at this scale
        out = np.where(n < -308, 0.0, out)
        out = np.where(n == np.floor(n), out, np.nan)
    return out if out.ndim else float(out)


def _excel_round(args: list[str]) -> tuple[str, int]:
    return f"ROUND({args[0]}, {args[1] if len(args) > 1 else 0})", PREC["atom"]


def _round_sympy(sp, x, n=0):
    scale = sp.Integer(10) ** n
    return sp.sign(x) * sp.floor(sp.Abs(x) * scale + sp.Rational(1, 2)) / scale


_simple(
    "round",
    round_numpy,
    _excel_round,
    _round_sympy,
    "round(x): nearest integer, a half away from zero; round(x, n): to n decimals "
    "(x a plain number)",
    rule=_integer_unit,
    domain=(
        Domain(
            "round to a number of decimals that is not an integer",
            lambda v: v != np.floor(v),
            "round(x, {})",
            arg=1,
        ),
    ),
    arity=(1, 2),
    jumps=_half_jumps,
    mathcad=("round",),
    excel_import=("ROUND",),
)
_simple(
    "trunc",
    np.trunc,
    "TRUNC",
    lambda sp, x: sp.sign(x) * sp.floor(sp.Abs(x)),
    "integer part, toward zero (x a plain number)",
    rule=_integer_unit,
    jumps=_integer_jumps,
    mathcad=("trunc",),
    excel_import=("TRUNC",),
    vba=("fix",),
)

# -- sum(EXPR, I, A, B): a built-in that binds a variable ------------------------------------
#: Most terms of sum(); Excel gets the terms written out up to MAX_EXCEL_TERMS.
MAX_TERMS = 1_000_000
MAX_EXCEL_TERMS = 64


def _sum_unit(ctx: UnitContext, name: str, args: tuple) -> ty.T:
    if len(args) == 1:  # sum(v): the elements of a vector or matrix
        if args[0].shape is None:
            raise TemplateError("sum(v) takes a vector or matrix; or write sum(EXPR, I, A, B)")
        return ty.TFunc(args[0].unit, func=name, args=args)
    if len(args) != 4:
        raise TemplateError(
            f"sum() takes 1 argument (a vector) or 4 (EXPR, I, A, B), got {len(args)}"
        )
    body, var, a, b = args
    if var.unit.dimensionality or var.unit != ctx.dimensionless:
        raise UnitError(f"sum(): the index {var.name} must be a plain number (integers A..B)")
    a = ctx.plain(a, "sum(): the first index")
    b = ctx.plain(b, "sum(): the last index")
    if sum_kind(body.unit) == "absolute":  # as sum(v) and Mathcad: absolute ones add in kelvin
        body = ctx.convert(body, registry().kelvin, "sum()")
    # a sum of vectors or matrices (of one shape, or of a run-time array) has their shape
    return ty.TFunc(body.unit, func=name, args=(body, var, a, b), shape=body.shape)


#: terms of the live form of a sum or product whose bounds depend on inputs: an edit that
#: asks for more (or for a bound that is not an integer) shows #N/A
MAX_LIVE_TERMS = 32


def live_terms(body, lo: str, hi: str, op: str, empty: str) -> str:
    """EXPR at lo, lo + 1, ... up to hi, for bounds that follow the inputs: MAX_LIVE_TERMS
    terms, each ``IF(lo+k<=hi, EXPR(lo+k), empty)`` (Excel computes only the branch it takes,
    so a term past hi is never evaluated), joined by ``op``."""
    lo, hi = f"({lo})", f"({hi})"
    at = [lo] + [f"({lo}+{k})" for k in range(1, MAX_LIVE_TERMS)]
    terms = [f"IF({x}<={hi},{body(x)},{empty})" for x in at]
    guard = f"OR({hi}-{lo}+1>{MAX_LIVE_TERMS},{lo}<>INT({lo}),{hi}<>INT({hi}))"
    return f"IF({guard},NA(),{op.join(terms)})"


def sum_index(value, which: str) -> int:
    x = float(np.asarray(value, dtype=float).flat[0])
    if not math.isfinite(x) or x != math.floor(x):
        raise InputError(f"sum(): the {which} index must be an integer, got {x:g}")
    return int(x)


def _bounds(value, which: str) -> np.ndarray:
    """The bound of every row (a table's rows may each have their own)."""
    v = np.atleast_1d(np.asarray(value, dtype=float))
    bad = v[~np.isfinite(v) | (v != np.floor(v))]
    if bad.size:
        raise InputError(f"sum(): the {which} index must be an integer, got {bad[0]:g}")
    return v.astype(np.int64)


def _sum_numpy(fn, a=None, b=None, *, shapes=None):
    if shapes is not None:  # sum(v)
        from .matrix import reduce

        return reduce("sum", fn, matrix=(True,))
    lo, hi = _bounds(a, "first"), _bounds(b, "last")
    first, last = int(lo.min()), int(hi.max())
    if last - first + 1 > MAX_TERMS:
        raise LimitError(f"sum(): {last - first + 1} terms (limit {MAX_TERMS})")
    same = lo.size == hi.size == 1 or (np.all(lo == lo[0]) and np.all(hi == hi[0]))
    out, size = 0.0, 0.0
    for i in range(first, last + 1):  # each term is a numpy evaluation over the sheet's arrays
        term = fn(float(i))
        # bounds that vary over a table's rows: the term counts only where i is in a row's range
        term = term if same else np.where((lo <= i) & (i <= hi), term, 0 * term)
        out, size = out + term, size + np.abs(term)
    # EXPR as workbook.numerics.bound.Bound: the estimate is kept (of real terms: the rounding check
    # of EXPR runs in real mpmath)
    if hasattr(fn, "record_series") and not np.iscomplexobj(out):
        fn.record_series(lo, hi, np.asarray(out, dtype=float), size, np.maximum(hi - lo + 1, 0))
    return out


def _sum_excel(body, args=None, consts=None, *, shapes=None) -> tuple[str, int]:
    if shapes is not None:  # sum(v): body is the printed vector
        return f"SUM({body[0]})", PREC["atom"]
    lo, hi = consts
    if lo is None or hi is None:  # bounds that follow the inputs
        return live_terms(body, args[0], args[1], "+", "0"), PREC["atom"]
    lo, hi = sum_index(lo, "first"), sum_index(hi, "last")
    if hi < lo:
        return "0", PREC["atom"]
    if hi - lo + 1 > MAX_EXCEL_TERMS:
        raise NotLive(f"sum() of {hi - lo + 1} terms (written out up to {MAX_EXCEL_TERMS})")
    terms = [body(str(i) if i >= 0 else f"({i})") for i in range(lo, hi + 1)]
    if body.typed.complex:  # complex terms: Excel's IMSUM of them
        return f"IMSUM({', '.join(terms)})", PREC["atom"]
    return "(" + ")+(".join(terms) + ")", PREC["+"]


def _sum_sympy(sp, body, var, a, b):
    return sp.Sum(body, (var, a, b)).doit()


register(
    Builtin(
        "sum",
        (1, 4),
        _sum_unit,
        _sum_numpy,
        _sum_excel,
        _sum_sympy,
        doc="sum(EXPR, I, A, B): EXPR summed over the integers I = A..B (0 if B < A); "
        "sum(v): the sum of the elements of a vector or matrix",
        binds=(0, 1),
        estimate="iterative",
        complex="complex",
        complex_excel=_sum_excel,
        mathml="<munderover><mo>\u2211</mo><mrow>{1}<mo>=</mo>{2}</mrow>{3}</munderover>{0:group}",
        arrays=True,
        mathcad_operator="summation",
    )
)
