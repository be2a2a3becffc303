"""Probability distributions as Mathcad names them: ``dX`` the density, ``pX`` the cumulative
probability, ``qX`` the quantile (its inverse), for the normal (``norm``), Student's t (``t``),
chi-squared (``chisq``), exponential (``exp``), uniform (``unif``), lognormal (``lnorm``),
gamma (``gamma``: ``dgamma`` ..., not the gamma function), beta (``beta``), Weibull
(``weibull``), logistic (``logis``) and Cauchy (``cauchy``) distributions, ``pF``/``qF`` (F),
and the binomial (``binom``), Poisson (``pois``) and geometric (``geom``) distributions of a
whole number k (``dX`` its probability; a k that is not whole is outside the domain, never
truncated).

Every argument is a plain number (SciPy computes them). In Excel each is its worksheet function
(``_xlfn.NORM.DIST`` ...) or a formula of classic ones; Excel reads degrees of freedom as
integers (it truncates 2.5 to 2), so a number of degrees of freedom that is not an integer
gives ``#N/A`` there, never another distribution's value; so does a count (k, n) that is not
whole. ``qpois`` and ``qgeom`` have no Excel function: they are written as values.
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


def _floats(*args):
    return np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in args))


def _not_whole(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    with np.errstate(invalid="ignore"):
        return ~np.isfinite(v) | (v != np.round(v))


def _lnorm(kind: str):
    def f(x, mu, sigma):
        x, mu, sigma = _floats(x, mu, sigma)
        return getattr(_stats().lognorm, kind)(x, sigma, 0.0, np.exp(mu))

    return f


def _gamma(kind: str):
    def f(x, s):
        return getattr(_stats().gamma, kind)(x, s)

    return f


def _beta(kind: str):
    def f(x, s1, s2):
        return getattr(_stats().beta, kind)(x, s1, s2)

    return f


def _weibull(kind: str):
    def f(x, s):
        return getattr(_stats().weibull_min, kind)(x, s)

    return f


def _logis(kind: str):
    def f(x, loc, s):
        return getattr(_stats().logistic, kind)(x, loc, s)

    return f


def _cauchy(kind: str):
    def f(x, loc, s):
        return getattr(_stats().cauchy, kind)(x, loc, s)

    return f


def _counted(kind: str, distribution: Callable, first, *params):
    """A discrete distribution's value: k a whole number (else not a number, never truncated);
    a quantile is the smallest k >= 0 with pX(k) >= q (SciPy's, which is -1 at q = 0)."""
    first, *params = _floats(first, *params)
    dist = distribution(*params)
    with np.errstate(divide="ignore", invalid="ignore"):
        if kind == "ppf":
            return np.maximum(dist.ppf(first), 0.0)
        bad = _not_whole(first)
        value = getattr(dist, "pmf" if kind == "pdf" else kind)(np.where(bad, 0.0, first))
    return np.where(bad, np.nan, value)


def _binom(kind: str):
    def f(k, n, p):
        value = _counted(kind, lambda n, p: _stats().binom(n, p), k, n, p)
        if kind == "ppf":  # p = 0: pbinom(0) is 1 already (SciPy gives n at q = 1)
            q, n, p = _floats(k, n, p)
            return np.where((p == 0) & (q == 1) & np.isfinite(value), 0.0, value)
        return value

    return f


def _pois(kind: str):
    def f(k, lam):
        def poisson(lam):
            return _stats().poisson(np.where(lam > 0, lam, np.nan))

        return _counted(kind, poisson, k, lam)

    return f


def _geom(kind: str):
    def f(k, p):
        def shifted(p):  # k = 0, 1, 2, ...: the number of failures before the first success
            return _stats().geom(p, loc=-1.0)

        value = _counted(kind, shifted, k, p)
        if kind == "ppf":  # p = 1: k is 0 whatever q (SciPy: -1, and inf at q = 1)
            q, p = _floats(k, p)
            return np.where((p == 1) & (q >= 0) & (q <= 1), 0.0, value)
        return value

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


def _whole(formula: str, *degrees: str, what: str = "degrees of freedom") -> str:
    """``formula`` where every number of degrees of freedom (or count, ``what``) is an integer,
    else #N/A (Excel would truncate them); a constant that is not an integer has no live
    formula."""
    for d in degrees:
        if _constant(d) and not _integer(d):
            raise NotLive(f"Excel truncates {what} to an integer ({d}): written as a value")
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


def _excel_lnorm(kind, x, mu, sigma):
    if kind == "ppf":  # Excel's LOGNORM.INV is #NUM! at 0, where x is 0
        return f"IF(({x})=0, 0, {_call('LOGNORM.INV', x, mu, sigma)})"
    cumulative = "TRUE" if kind == "cdf" else "FALSE"
    return f"IF(({x})<=0, 0, {_call('LOGNORM.DIST', x, mu, sigma, cumulative)})"


def _excel_gamma(kind, x, s):
    if kind == "ppf":
        return _call("GAMMA.INV", x, s, "1")
    if kind == "cdf":
        return _call("GAMMA.DIST", f"MAX({x}, 0)", s, "1", "TRUE")
    return _density_of_positive(_call("GAMMA.DIST", x, s, "1", "FALSE"), x)


def _excel_beta(kind, x, s1, s2):
    if kind == "ppf":  # Excel's BETA.INV is #NUM! at 0, where x is 0
        return f"IF(({x})=0, 0, {_call('BETA.INV', x, s1, s2)})"
    if kind == "cdf":
        return _call("BETA.DIST", f"MIN(MAX({x}, 0), 1)", s1, s2, "TRUE")
    return f"IF(OR(({x})<0, ({x})>1), 0, {_call('BETA.DIST', x, s1, s2, 'FALSE')})"


def _excel_weibull(kind, x, s):
    if kind == "ppf":  # Excel has no WEIBULL.INV
        return f"IF(({s})>0, (-LN(1-({x})))^(1/({s})), NA())"
    if kind == "cdf":
        return _call("WEIBULL.DIST", f"MAX({x}, 0)", s, "1", "TRUE")
    return _density_of_positive(_call("WEIBULL.DIST", x, s, "1", "FALSE"), x)


def _excel_logis(kind, x, loc, s):
    z = f"(({x})-({loc}))/({s})"
    if kind == "ppf":
        value = f"({loc})+({s})*LN(({x})/(1-({x})))"
    elif kind == "cdf":
        value = f"1/(1+EXP(-{z}))"
    else:  # symmetric: exp(-|z|) never overflows
        value = f"EXP(-ABS({z}))/(({s})*(1+EXP(-ABS({z})))^2)"
    return f"IF(({s})>0, {value}, NA())"


def _excel_cauchy(kind, x, loc, s):
    z = f"(({x})-({loc}))/({s})"
    if kind == "ppf":
        value = f"({loc})+({s})*TAN(PI()*(({x})-0.5))"
    elif kind == "cdf":
        value = f"0.5+ATAN({z})/PI()"
    else:
        value = f"1/(PI()*({s})*(1+({z})^2))"
    return f"IF(({s})>0, {value}, NA())"


_COUNT = "a count"


def _excel_binom(kind, k, n, p):
    if kind == "ppf":  # Excel's BINOM.INV(n, p, q) is #NUM! at q = 0, where k is 0
        return _whole(f"IF(({k})=0, 0, {_call('BINOM.INV', n, p, k)})", n, what=_COUNT)
    if kind == "cdf":  # 0 below 0 and 1 above n (Excel: #NUM!)
        value = f"IF(({k})<0, 0, {_call('BINOM.DIST', f'MIN({k}, {n})', n, p, 'TRUE')})"
    else:
        value = f"IF(OR(({k})<0, ({k})>({n})), 0, {_call('BINOM.DIST', k, n, p, 'FALSE')})"
    return _whole(value, k, n, what=_COUNT)


def _excel_pois(kind, k, lam):
    if kind == "ppf":
        raise NotLive("Excel has no inverse of POISSON.DIST: written as a value")
    value = _call("POISSON.DIST", k, lam, "TRUE" if kind == "cdf" else "FALSE")
    return _whole(f"IF(({k})<0, 0, {value})", k, what=_COUNT)


def _excel_geom(kind, k, p):
    if kind == "ppf":
        raise NotLive("Excel has no geometric distribution's quantile: written as a value")
    if kind == "cdf":
        value = f"1-(1-({p}))^(({k})+1)"
    else:
        value = f"({p})*(1-({p}))^({k})"
    value = f"IF(AND(({p})>0, ({p})<=1), IF(({k})<0, 0, {value}), NA())"
    return _whole(value, k, what=_COUNT)


_EXCEL = {
    "norm": _excel_norm,
    "t": _excel_t,
    "chisq": _excel_chisq,
    "F": _excel_f,
    "exp": _excel_exp,
    "unif": _excel_unif,
    "lnorm": _excel_lnorm,
    "gamma": _excel_gamma,
    "beta": _excel_beta,
    "weibull": _excel_weibull,
    "logis": _excel_logis,
    "cauchy": _excel_cauchy,
    "binom": _excel_binom,
    "pois": _excel_pois,
    "geom": _excel_geom,
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
    "lnorm": (_lnorm, "mu, sigma",
              "lognormal distribution whose logarithm has mean mu and standard deviation sigma",
              ((2, lambda v: v <= 0, "a standard deviation that is not positive"),)),
    "gamma": (_gamma, "s", "gamma distribution of shape s and scale 1",
              ((1, lambda v: v <= 0, "a shape that is not positive"),)),
    "beta": (_beta, "s1, s2", "beta distribution on [0, 1] of shapes s1 and s2",
             ((1, lambda v: v <= 0, "a shape that is not positive"),
              (2, lambda v: v <= 0, "a shape that is not positive"))),
    "weibull": (_weibull, "s", "Weibull distribution of shape s and scale 1",
                ((1, lambda v: v <= 0, "a shape that is not positive"),)),
    "logis": (_logis, "l, s", "logistic distribution of location l and scale s",
              ((2, lambda v: v <= 0, "a scale that is not positive"),)),
    "cauchy": (_cauchy, "l, s", "Cauchy distribution of location l and scale s",
               ((2, lambda v: v <= 0, "a scale that is not positive"),)),
    "binom": (_binom, "n, p", "binomial distribution of n trials of probability p (k successes)",
              ((0, _not_whole, "a count that is not a whole number", ("pdf", "cdf")),
               (1, lambda v: _not_whole(v) | (v < 0), "a number of trials that is not a whole "
                "number >= 0"),
               (2, lambda v: (v < 0) | (v > 1), "a probability outside [0, 1]"))),
    "pois": (_pois, "lam", "Poisson distribution of mean lam (k events)",
             ((0, _not_whole, "a count that is not a whole number", ("pdf", "cdf")),
              (1, lambda v: v <= 0, "a mean that is not positive"))),
    "geom": (_geom, "p", "geometric distribution of probability p (k failures before the "
             "first success)",
             ((0, _not_whole, "a count that is not a whole number", ("pdf", "cdf")),
              (1, lambda v: (v <= 0) | (v > 1), "a probability outside (0, 1]"))),
}  # fmt: skip

#: The first argument's name, of dX and pX then of qX: the discrete distributions' count k.
_FIRST = {"binom": ("k", "q"), "pois": ("k", "q"), "geom": ("k", "q")}

#: The built-ins of this module, by family: d (density), p (probability), q (quantile).
KINDS: dict[str, tuple[str, ...]] = {
    "norm": ("pdf", "cdf", "ppf"),
    "t": ("pdf", "cdf", "ppf"),
    "chisq": ("pdf", "cdf", "ppf"),
    # Mathcad's dF is not a built-in: a template names a function of its own so
    "F": ("cdf", "ppf"),
    "exp": ("pdf", "cdf", "ppf"),
    "unif": ("pdf", "cdf", "ppf"),
    "lnorm": ("pdf", "cdf", "ppf"),
    "gamma": ("pdf", "cdf", "ppf"),
    "beta": ("pdf", "cdf", "ppf"),
    "weibull": ("pdf", "cdf", "ppf"),
    "logis": ("pdf", "cdf", "ppf"),
    "cauchy": ("pdf", "cdf", "ppf"),
    "binom": ("pdf", "cdf", "ppf"),
    "pois": ("pdf", "cdf", "ppf"),
    "geom": ("pdf", "cdf", "ppf"),
}


def _first(family: str, kind: str) -> str:
    return _FIRST.get(family, ("x", "p"))[kind == "ppf"]


def _domains(family: str, kind: str, name: str, params: str) -> tuple[Domain, ...]:
    shown = [_first(family, kind), *params.split(", ")]
    out = []
    for index, bad, text, *only in _FAMILIES[family][3]:
        if only and kind not in only[0]:
            continue
        call = ", ".join("{}" if k == index else s for k, s in enumerate(shown))
        out.append(Domain(f"{name} with {text}", bad, f"{name}({call})", arg=index))
    if kind == "ppf":
        open_ = ("norm", "t", "logis", "cauchy")  # infinite at 0 and 1
        inside = (lambda v: (v <= 0) | (v >= 1)) if family in open_ else None
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
            first = _first(family, kind)
            discrete = kind == "pdf" and family in _FIRST  # a probability, not a density
            what_kind = "probability" if discrete else _WHAT[kind].format(family)
            register(
                Builtin(
                    name,
                    arity,
                    _plain_numbers,
                    make(kind),
                    _excel(kind, family),
                    _sympy(family, kind),
                    _domains(family, kind, name, params),
                    doc=f"{name}({first}, {params}): the {what_kind} of the "
                    f"{what} (Mathcad's {name})",
                    mathcad=(name,),
                )
            )


_register()

#: The names of the distribution built-ins (dnorm, pnorm, qnorm, dt, ...).
NAMES = frozenset(_NAME[k] + family for family, kinds in KINDS.items() for k in kinds)
