"""Probability distributions as Mathcad names them: ``dX`` the density, ``pX`` the cumulative
probability, ``qX`` the quantile (its inverse), for the normal (``norm``), Student's t (``t``),
chi-squared (``chisq``), exponential (``exp``) and uniform (``unif``) distributions, and
``pF``/``qF`` (F).

Every argument is a plain number (SciPy computes them). In Excel each is its worksheet function
(``_xlfn.NORM.DIST`` ...) or a formula of classic ones; Excel reads degrees of freedom as
integers (it truncates 2.5 to 2), so a number of degrees of freedom that is not an integer
gives ``#N/A`` there, never another distribution's value.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..errors import NotLive, NotSymbolic
from ..language import typed as ty
from ..language.expr import PREC
from .entry import Builtin, Domain, UnitContext, register
from .excel_functions import stored


def _plain_numbers(ctx: UnitContext, name: str, args: tuple) -> ty.T:
    """Every argument a plain number, and the result."""
    plain = tuple(ctx.plain(a, f"{name}()") for a in args)
    return ty.TFunc(ctx.dimensionless, func=name, args=plain)


def _stats():
    import scipy.stats

    return scipy.stats


# -- numpy (SciPy) --------------------------------------------------------------------------------
def _norm(kind: str):
    def f(x, mu, sigma):
        return getattr(_stats().norm, kind)(x, mu, sigma)

    return f


def _t(kind: str):
    def f(x, d):
        return getattr(_stats().t, kind)(x, d)

    return f


def _chisq(kind: str):
    def f(x, d):
        return getattr(_stats().chi2, kind)(x, d)

    return f


def _f(kind: str):
    def f(x, d1, d2):
        return getattr(_stats().f, kind)(x, d1, d2)

    return f


def _exp(kind: str):
    def f(x, r):
        r = np.asarray(r, dtype=float)
        scale = np.where(r > 0, 1 / np.where(r > 0, r, 1.0), np.nan)
        return getattr(_stats().expon, kind)(x, 0.0, scale)

    return f


def _unif(kind: str):
    def f(x, a, b):
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        width = np.where(b > a, b - a, np.nan)
        return getattr(_stats().uniform, kind)(x, a, width)

    return f


# -- Excel ----------------------------------------------------------------------------------------
def _constant(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _integer(text: str) -> bool:
    try:
        value = float(text)
    except ValueError:
        return False
    return np.isfinite(value) and value == int(value)


def _whole(formula: str, *degrees: str) -> str:
    """``formula`` where every number of degrees of freedom is an integer, else #N/A (Excel
    would truncate them); a constant that is not an integer has no live formula."""
    for d in degrees:
        if _constant(d) and not _integer(d):
            raise NotLive(
                f"Excel truncates degrees of freedom to an integer ({d}): written as a value"
            )
    check = [f"INT({d})={d}" for d in degrees if not _constant(d)]
    if not check:
        return formula
    condition = check[0] if len(check) == 1 else f"AND({', '.join(check)})"
    return f"IF({condition}, {formula}, NA())"


def _call(function: str, *args: str) -> str:
    return f"{stored(function)}({', '.join(args)})"


def _density_of_positive(formula: str, x: str) -> str:
    """A density of a distribution of x >= 0: 0 below 0 (Excel's functions give #NUM!)."""
    return f"IF(({x})<0, 0, {formula})"


def _excel(kind: str, family: str) -> Callable[[list[str]], tuple[str, int]]:
    def printed(args: list[str]) -> tuple[str, int]:
        return _EXCEL[family](kind, *args), PREC["atom"]

    return printed


def _excel_norm(kind, x, mu, sigma):
    if kind == "ppf":
        return _call("NORM.INV", x, mu, sigma)
    return _call("NORM.DIST", x, mu, sigma, "TRUE" if kind == "cdf" else "FALSE")


def _excel_t(kind, x, d):
    if kind == "ppf":
        return _whole(_call("T.INV", x, d), d)
    return _whole(_call("T.DIST", x, d, "TRUE" if kind == "cdf" else "FALSE"), d)


def _excel_chisq(kind, x, d):
    if kind == "ppf":
        return _whole(_call("CHISQ.INV", x, d), d)
    if kind == "cdf":
        return _whole(_call("CHISQ.DIST", f"MAX({x}, 0)", d, "TRUE"), d)
    return _whole(_density_of_positive(_call("CHISQ.DIST", x, d, "FALSE"), x), d)


def _excel_f(kind, x, d1, d2):
    if kind == "ppf":
        return _whole(_call("F.INV", x, d1, d2), d1, d2)
    return _whole(_call("F.DIST", f"MAX({x}, 0)", d1, d2, "TRUE"), d1, d2)


def _excel_exp(kind, x, r):
    if kind == "ppf":  # Excel has no EXPON.INV
        return f"IF(({r})>0, -LN(1-({x}))/({r}), NA())"
    if kind == "cdf":
        return _call("EXPON.DIST", f"MAX({x}, 0)", r, "TRUE")
    return _density_of_positive(_call("EXPON.DIST", x, r, "FALSE"), x)


def _excel_unif(kind, x, a, b):
    if kind == "ppf":
        value = f"IF(AND(({x})>=0, ({x})<=1), ({a})+({x})*(({b})-({a})), NA())"
    elif kind == "cdf":
        value = f"MIN(MAX((({x})-({a}))/(({b})-({a})), 0), 1)"
    else:
        value = f"IF(AND(({x})>=({a}), ({x})<=({b})), 1/(({b})-({a})), 0)"
    return f"IF(({b})>({a}), {value}, NA())"


_EXCEL = {
    "norm": _excel_norm,
    "t": _excel_t,
    "chisq": _excel_chisq,
    "F": _excel_f,
    "exp": _excel_exp,
    "unif": _excel_unif,
}


# -- SymPy: the normal distribution and the exponential quantile have closed forms ----------------
def _sympy(family: str, kind: str):
    def convert(sp, *args):
        if family == "norm":
            x, mu, sigma = args
            z = (x - mu) / sigma
            if kind == "cdf":
                return (1 + sp.erf(z / sp.sqrt(2))) / 2
            if kind == "pdf":
                return sp.exp(-(z**2) / 2) / (sigma * sp.sqrt(2 * sp.pi))
            return mu + sigma * sp.sqrt(2) * sp.erfinv(2 * x - 1)
        if family == "exp" and kind == "ppf":
            p, r = args
            return -sp.log(1 - p) / r
        raise NotSymbolic(why)

    why = f"{_NAME[kind]}{family}() has no formula for SymPy"
    if not (family == "norm" or (family == "exp" and kind == "ppf")):
        convert.refusal = why  # read by workbook.numerics.symbolic.refusal, without SymPy
    return convert


# -- the entries ----------------------------------------------------------------------------------
_NAME = {"pdf": "d", "cdf": "p", "ppf": "q"}
_WHAT = {"pdf": "density", "cdf": "cumulative probability", "ppf": "quantile (inverse of p{})"}

# family -> (numpy hook maker, parameters, description, parameter checks (index, bad, text))
_FAMILIES = {
    "norm": (_norm, "mu, sigma", "normal distribution of mean mu and standard deviation sigma",
             ((2, lambda v: v <= 0, "a standard deviation that is not positive"),)),
    "t": (_t, "d", "Student's t distribution of d degrees of freedom",
          ((1, lambda v: v <= 0, "degrees of freedom that are not positive"),)),
    "chisq": (_chisq, "d", "chi-squared distribution of d degrees of freedom",
              ((1, lambda v: v <= 0, "degrees of freedom that are not positive"),)),
    "F": (_f, "d1, d2", "F distribution of d1 and d2 degrees of freedom",
          ((1, lambda v: v <= 0, "degrees of freedom that are not positive"),
           (2, lambda v: v <= 0, "degrees of freedom that are not positive"))),
    "exp": (_exp, "r", "exponential distribution of rate r",
            ((1, lambda v: v <= 0, "a rate that is not positive"),)),
    "unif": (_unif, "a, b", "uniform distribution on [a, b] (a < b)", ()),
}  # fmt: skip

#: The built-ins of this module, by family: d (density), p (probability), q (quantile).
KINDS: dict[str, tuple[str, ...]] = {
    "norm": ("pdf", "cdf", "ppf"),
    "t": ("pdf", "cdf", "ppf"),
    "chisq": ("pdf", "cdf", "ppf"),
    # Mathcad's dF is not a built-in: a template names a function of its own so
    "F": ("cdf", "ppf"),
    "exp": ("pdf", "cdf", "ppf"),
    "unif": ("pdf", "cdf", "ppf"),
}


def _domains(family: str, kind: str, name: str, params: str) -> tuple[Domain, ...]:
    first = "p" if kind == "ppf" else "x"
    shown = [first, *params.split(", ")]
    out = []
    for index, bad, text in _FAMILIES[family][3]:
        call = ", ".join("{}" if k == index else s for k, s in enumerate(shown))
        out.append(Domain(f"{name} with {text}", bad, f"{name}({call})", arg=index))
    if kind == "ppf":
        inside = (lambda v: (v <= 0) | (v >= 1)) if family in ("norm", "t") else None
        inside = inside or (lambda v: (v < 0) | (v > 1))
        call = ", ".join(["{}", *shown[1:]])
        out.append(Domain(f"{name} of a probability outside (0, 1)", inside, f"{name}({call})"))
    return tuple(out)


def _register() -> None:
    for family, kinds in KINDS.items():
        make, params, what, _checks = _FAMILIES[family]
        arity = 1 + len(params.split(", "))
        for kind in kinds:
            name = _NAME[kind] + family
            first = "p" if kind == "ppf" else "x"
            register(
                Builtin(
                    name,
                    arity,
                    _plain_numbers,
                    make(kind),
                    _excel(kind, family),
                    _sympy(family, kind),
                    _domains(family, kind, name, params),
                    doc=f"{name}({first}, {params}): the {_WHAT[kind].format(family)} of the "
                    f"{what} (Mathcad's {name})",
                    mathcad=(name,),
                )
            )


_register()

#: The names of the distribution built-ins (dnorm, pnorm, qnorm, dt, ...).
NAMES = frozenset(_NAME[k] + family for family, kinds in KINDS.items() for k in kinds)
