"""The numpy back end against mpmath at 50 digits, for every built-in function and operator.

Each function and operator is a one-line worksheet function; the engine evaluates it over a
few hundred points of its domain, and every value is compared with mpmath's, computed at the
same double-precision arguments with 50 significant digits and rounded once. Arithmetic
must be correctly rounded; functions within a few units in the last place.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
from helpers.sheets import write_template

import workbook
from workbook.functions.distributions import NAMES as DISTRIBUTIONS
from workbook.functions.special import NAMES as SPECIAL
from workbook.numerics.registry import REGISTRY

mp = mpmath.mp

ULPS = 4  # numpy promises up to 4 ulp on some CPUs (SIMD loops); 1.2 at most measured here


def _points(lo: float, hi: float, n: int = 200, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.concatenate([np.linspace(lo, hi, n // 2), rng.uniform(lo, hi, n - n // 2)])


def _sign(x):
    return mpmath.sign(x)


def _remainder(u, v):
    """u - v*trunc(u/v): the sign of u, as Mathcad's mod (mpmath.fmod takes that of v)."""
    q = u / v
    return u - v * (mpmath.floor(q) if q >= 0 else mpmath.ceil(q))


def _round(u, n: int):
    """Half away from zero to n decimals, of the exact value of u (not numpy's half to even)."""
    scale = mpmath.mpf(10) ** n
    return _sign(u) * mpmath.floor(abs(u) * scale + mpmath.mpf(0.5)) / scale


# built-in name -> (worksheet expression of u[, v], mpmath reference, domain of u[, v])
FUNCTIONS = {
    "sin": ("sin(u)", mpmath.sin, (-20, 20)),
    "cos": ("cos(u)", mpmath.cos, (-20, 20)),
    "tan": ("tan(u)", mpmath.tan, (-1.5, 1.5)),
    "sec": ("sec(u)", mpmath.sec, (-1.5, 1.5)),
    "csc": ("csc(u)", mpmath.csc, (0.05, 3.1)),
    "cot": ("cot(u)", mpmath.cot, (0.05, 3.1)),
    "asin": ("asin(u)", mpmath.asin, (-1, 1)),
    "acos": ("acos(u)", mpmath.acos, (-1, 1)),
    "atan": ("atan(u)", mpmath.atan, (-50, 50)),
    "atan2": ("atan2(u, v)", lambda x, y: mpmath.atan2(y, x), (-3, 3), (-3, 3)),  # x first
    "sinh": ("sinh(u)", mpmath.sinh, (-20, 20)),
    "cosh": ("cosh(u)", mpmath.cosh, (-20, 20)),
    "tanh": ("tanh(u)", mpmath.tanh, (-5, 5)),
    "coth": ("coth(u)", mpmath.coth, (0.05, 5)),
    "sech": ("sech(u)", mpmath.sech, (-20, 20)),
    "csch": ("csch(u)", mpmath.csch, (0.05, 20)),
    "asinh": ("asinh(u)", mpmath.asinh, (-50, 50)),
    "acosh": ("acosh(u)", mpmath.acosh, (1, 50)),
    "atanh": ("atanh(u)", mpmath.atanh, (-0.99, 0.99)),
    "asec": ("asec(u)", mpmath.asec, (1, 50)),
    "acsc": ("acsc(u)", mpmath.acsc, (1, 50)),
    "acoth": ("acoth(u)", mpmath.acoth, (1.01, 50)),
    "asech": ("asech(u)", mpmath.asech, (0.01, 1)),
    "acsch": ("acsch(u)", mpmath.acsch, (0.05, 50)),
    "sqrt": ("sqrt(u)", mpmath.sqrt, (0, 1e6)),
    "exp": ("exp(u)", mpmath.exp, (-50, 50)),
    "ln": ("ln(u)", mpmath.ln, (1e-6, 1e6)),
    "log10": ("log10(u)", mpmath.log10, (1e-6, 1e6)),
    "abs": ("abs(u)", abs, (-5, 5)),
    "sign": ("sign(u)", _sign, (-5, 5)),
    "floor": ("floor(u)", mpmath.floor, (-5, 5)),
    "ceil": ("ceil(u)", mpmath.ceil, (-5, 5)),
    "min": ("min(u, v, 0.5)", lambda u, v: min(u, v, mpmath.mpf(0.5)), (-3, 3), (-3, 3)),
    "max": ("max(u, v)", max, (-3, 3), (-3, 3)),
    "mod": ("mod(u, v)", lambda u, v: _remainder(u, v), (-20, 20), (0.3, 7)),
    "round": ("round(u, 2)", lambda u: _round(u, 2), (-50, 50)),
    "trunc": ("trunc(u)", lambda u: _sign(u) * mpmath.floor(abs(u)), (-5, 5)),
    # of complex numbers u + v i (a real part of the complex results, as ulps are of reals)
    "Re": ("Re(u + v*1i)", lambda u, v: mpmath.re(mpmath.mpc(u, v)), (-5, 5), (-5, 5)),
    "Im": ("Im(u + v*1i)", lambda u, v: mpmath.im(mpmath.mpc(u, v)), (-5, 5), (-5, 5)),
    "arg": ("arg(u + v*1i)", lambda u, v: mpmath.arg(mpmath.mpc(u, v)), (-5, 5), (-5, 5)),
    "conj": ("Im(conj(u - v*1i))", lambda u, v: v, (-5, 5), (-5, 5)),
    "polar": ("Im(polar(u, v))", lambda u, v: u * mpmath.sin(v), (0, 5), (-3, 3)),
}

# operator -> (worksheet expression, mpmath reference, domains, exact: correctly rounded)
OPERATORS = {
    "add": ("u + v", lambda u, v: u + v, (-1e3, 1e3), (-1e-3, 1e-3), True),
    "sub": ("u - v", lambda u, v: u - v, (-1e3, 1e3), (-1e3, 1e3), True),
    "mul": ("u*v", lambda u, v: u * v, (-1e3, 1e3), (-1e-3, 1e3), True),
    "div": ("u/v", lambda u, v: u / v, (-1e3, 1e3), (0.1, 1e3), True),
    "neg": ("-u", lambda u: -u, (-1e3, 1e3), True),
    "pow": ("u^v", mpmath.power, (1e-3, 10), (-5, 5), False),
    "square": ("u^2", lambda u: u**2, (-1e3, 1e3), True),
    "half": ("u^0.5", mpmath.sqrt, (0, 1e3), True),
    "cube_of_negative": ("u^3", lambda u: u**3, (-10, 0), False),
    "reciprocal": ("u^-1", lambda u: 1 / u, (0.1, 1e3), False),
    "fourth": ("u^4", lambda u: u**4, (-10, 10), False),
    "three_halves": ("u^1.5", lambda u: u ** mpmath.mpf(1.5), (0, 1e3), False),
    "neg_pow": ("-u^2", lambda u: -(u**2), (-10, 10), True),
}

# comparisons and logic through a piecewise function: 1 where the condition holds, else 0
CONDITIONS = {
    "lt": ("u < v", lambda u, v: u < v),
    "le": ("u <= v", lambda u, v: u <= v),
    "gt": ("u > v", lambda u, v: u > v),
    "ge": ("u >= v", lambda u, v: u >= v),
    "eq": ("u == v", lambda u, v: u == v),
    "ne": ("u != v", lambda u, v: u != v),
    "chain": ("-1 <= u < v <= 2", lambda u, v: -1 <= u < v <= 2),
    "and_or_not": ("(u > 0 and v > 0) or not u > -1", lambda u, v: (u > 0 < v) or u <= -1),
}


def _template() -> str:
    lines = ["[arguments]", 'u = { unit = "" }', 'v = { unit = "" }', "", "[definitions]"]
    for name, (text, _, *domains) in FUNCTIONS.items():
        lines.append(f'"f_{name}({_params(domains)})" = "{text}"')
    for name, (text, _, *domains, _exact) in OPERATORS.items():
        lines.append(f'"f_{name}({_params(domains)})" = "{text}"')
    for name, (cond, _) in CONDITIONS.items():
        lines.append(f'"c_{name}(u, v)" = ["1 if {cond}", "0 otherwise"]')
    return "\n".join(lines) + "\n"


def _params(domains) -> str:
    return ", ".join(("u", "v")[: len(domains)])


@pytest.fixture(scope="module")
def sheet(load_text):
    return load_text(_template(), name="t")


def _ulps(got: float, want) -> float:
    """Distance in units in the last place of the double nearest to ``want``."""
    ref = float(want)
    if got == ref:
        return 0.0
    return float(abs(mpmath.mpf(got) - want) / math.ulp(ref if ref else 5e-324))


def _compare(sheet, name, reference, domains, ulps, names=("u", "v")):
    args = {n: _points(*d, seed=i) for i, (n, d) in enumerate(zip(names, domains))}
    n = len(next(iter(args.values())))
    got = np.broadcast_to(sheet.evaluate(name, **args).magnitude, n)
    worst = 0.0
    with mp.workdps(50):
        for i, value in enumerate(got):
            want = reference(*(mpmath.mpf(float(a[i])) for a in args.values()))
            worst = max(worst, _ulps(float(value), mpmath.mpf(want)))
    print(f"{name}: at most {worst:.2f} ulp from mpmath")
    assert worst <= ulps, f"{name}: {worst:.1f} ulp from mpmath"


def test_every_builtin_function_is_covered():
    # built-ins that bind a variable (sum) have tests of their own
    # (tests/numerics/test_builtins.py), so have those of vectors and matrices
    # (tests/language/test_arrays.py); min and max take both
    # (linterp and cspline read [data] tables: tests/numerics/test_numerical_builtins.py; the
    # distributions, from SciPy, have theirs: tests/numerics/test_distributions.py)
    scalar = {n for n, b in REGISTRY.items() if not (b.binds or b.arrays or b.data_args)}
    scalar -= DISTRIBUTIONS | {n for n, b in REGISTRY.items() if b.texts}  # test_texts.py
    scalar -= SPECIAL  # against mpmath at 50 digits: tests/numerics/test_special_functions.py
    assert set(FUNCTIONS) == scalar | {"min", "max"}


@pytest.mark.parametrize("name", FUNCTIONS)
def test_function_agrees_with_mpmath(sheet, name):
    _, reference, *domains = FUNCTIONS[name]
    _compare(sheet, f"f_{name}", reference, domains, ULPS)


@pytest.mark.parametrize("name", OPERATORS)
def test_operator_agrees_with_mpmath(sheet, name):
    _, reference, *domains, exact = OPERATORS[name]
    _compare(sheet, f"f_{name}", reference, domains, 0.5 if exact else ULPS)


@pytest.mark.parametrize("name", CONDITIONS)
def test_condition_agrees_with_python(sheet, name):
    _, reference = CONDITIONS[name]
    u = np.concatenate([_points(-3, 3, 60), [0.0, 1.0, -1.0, 2.0]])
    v = np.concatenate([_points(-3, 3, 60, seed=1), [0.0, 1.0, -1.0, 2.0]])
    u, v = np.meshgrid(np.round(u, 1), np.round(v, 1))  # rounding makes ties happen
    got = sheet.evaluate(f"c_{name}", u=u.ravel(), v=v.ravel()).magnitude
    want = [1.0 if reference(a, b) else 0.0 for a, b in zip(u.ravel(), v.ravel())]
    assert got.tolist() == want


def test_angle_factor_agrees_with_mpmath(tmp_path):
    """Degrees enter sin() through one conversion factor, pi/180 rounded once."""
    path = write_template(
        tmp_path, '[arguments]\nphi = { unit = "deg" }\n[definitions]\n"s(phi)" = "sin(phi)"\n'
    )
    _compare(
        workbook.load(path),
        "s",
        lambda phi: mpmath.sin(phi * mpmath.pi / 180),
        [(-80, 80)],
        ULPS,
        names=("phi",),
    )
