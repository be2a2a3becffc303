"""The distribution built-ins (dnorm, pnorm, qnorm, dt, ..., qunif) against mpmath at 50 digits,
their Excel forms against the `formulas` package, their unit rules and domains."""

from __future__ import annotations

import math
import re

import mpmath
import numpy as np
import pytest

from workbook import WorkbookError
from workbook.functions.distributions import NAMES
from workbook.numerics.registry import REGISTRY

mp = mpmath.mp


def _t_cdf(x, d):
    tail = mpmath.betainc(d / 2, mpmath.mpf(1) / 2, 0, d / (d + x * x), regularized=True) / 2
    return 1 - tail if x >= 0 else tail


def _t_pdf(x, d):
    c = mpmath.gamma((d + 1) / 2) / (mpmath.sqrt(d * mpmath.pi) * mpmath.gamma(d / 2))
    return c * (1 + x * x / d) ** (-(d + 1) / 2)


def _chisq_cdf(x, d):
    return mpmath.gammainc(d / 2, 0, x / 2, regularized=True) if x > 0 else mpmath.mpf(0)


def _chisq_pdf(x, d):
    if x < 0:
        return mpmath.mpf(0)
    return x ** (d / 2 - 1) * mpmath.exp(-x / 2) / (2 ** (d / 2) * mpmath.gamma(d / 2))


def _f_cdf(x, d1, d2):
    if x <= 0:
        return mpmath.mpf(0)
    return mpmath.betainc(d1 / 2, d2 / 2, 0, d1 * x / (d1 * x + d2), regularized=True)


def _lnorm_pdf(x, mu, s):
    if x <= 0:
        return mpmath.mpf(0)
    return mpmath.exp(-((mpmath.log(x) - mu) ** 2) / (2 * s * s)) / (
        x * s * mpmath.sqrt(2 * mpmath.pi)
    )


def _lnorm_cdf(x, mu, s):
    return mpmath.ncdf(mpmath.log(x), mu, s) if x > 0 else mpmath.mpf(0)


def _gamma_pdf(x, s):
    if x < 0:
        return mpmath.mpf(0)
    return x ** (s - 1) * mpmath.exp(-x) / mpmath.gamma(s)


def _gamma_cdf(x, s):
    return mpmath.gammainc(s, 0, x, regularized=True) if x > 0 else mpmath.mpf(0)


def _beta_pdf(x, a, b):
    if x < 0 or x > 1:
        return mpmath.mpf(0)
    return x ** (a - 1) * (1 - x) ** (b - 1) / mpmath.beta(a, b)


def _beta_cdf(x, a, b):
    return mpmath.betainc(a, b, 0, min(max(x, 0), 1), regularized=True)


def _weibull_pdf(x, s):
    return s * x ** (s - 1) * mpmath.exp(-(x**s)) if x >= 0 else mpmath.mpf(0)


def _weibull_cdf(x, s):
    return -mpmath.expm1(-(x**s)) if x > 0 else mpmath.mpf(0)


def _logis_pdf(x, loc, s):
    e = mpmath.exp(-(x - loc) / s)
    return e / (s * (1 + e) ** 2)


def _logis_cdf(x, loc, s):
    return 1 / (1 + mpmath.exp(-(x - loc) / s))


def _cauchy_pdf(x, loc, s):
    return 1 / (mpmath.pi * s * (1 + ((x - loc) / s) ** 2))


def _cauchy_cdf(x, loc, s):
    return mpmath.mpf(1) / 2 + mpmath.atan((x - loc) / s) / mpmath.pi


def _binom_pmf(k, n, p):
    if k < 0 or k > n:
        return mpmath.mpf(0)
    return mpmath.binomial(n, k) * p**k * (1 - p) ** (n - k)


def _binom_cdf(k, n, p):
    return mpmath.fsum(_binom_pmf(mpmath.mpf(j), n, p) for j in range(int(min(k, n)) + 1))


def _pois_pmf(k, lam):
    return mpmath.exp(-lam) * lam**k / mpmath.factorial(k) if k >= 0 else mpmath.mpf(0)


def _pois_cdf(k, lam):
    return mpmath.fsum(_pois_pmf(mpmath.mpf(j), lam) for j in range(int(k) + 1))


def _geom_pmf(k, p):
    return p * (1 - p) ** k if k >= 0 else mpmath.mpf(0)


def _geom_cdf(k, p):
    return 1 - (1 - p) ** (k + 1) if k >= 0 else mpmath.mpf(0)


def _smallest(cdf):
    """A discrete quantile by its definition: the engine's k is the smallest whole k >= 0 with
    cdf(k) >= p (checked here: cdf(k - 1) < p <= cdf(k)), so the reference is k itself."""

    def q(p, *params, start):
        k = mpmath.mpf(start)
        assert k >= 0 and k == mpmath.floor(k), (p, params, k)
        assert cdf(k, *params) >= p, (p, params, k)
        assert k == 0 or cdf(k - 1, *params) < p, (p, params, k)
        return k

    return q


def _quantile(cdf):
    """The inverse of ``cdf`` by mpmath's root finder from the engine's value."""

    def q(p, *params, start):
        return mpmath.findroot(lambda x: cdf(x, *params) - p, mpmath.mpf(start), tol=1e-40)

    return q


# name -> (mpmath reference, points: (x or p, parameters...), relative tolerance)
_X = [-3.5, -1.2, -0.3, 0.0, 0.4, 1.7, 4.2]
_POS = [0.05, 0.4, 1.0, 2.3, 6.5, 15.0]
_P = [1e-6, 0.01, 0.2, 0.45, 0.7, 0.93, 0.999]
CASES = {
    "dnorm": (lambda x, m, s: mpmath.npdf(x, m, s), [(x, 0.3, 1.7) for x in _X], 1e-14),
    "pnorm": (lambda x, m, s: mpmath.ncdf(x, m, s), [(x, 0.3, 1.7) for x in _X], 1e-14),
    "qnorm": (
        lambda p, m, s: m + s * mpmath.sqrt(2) * mpmath.erfinv(2 * p - 1),
        [(p, 0.3, 1.7) for p in _P],
        1e-14,
    ),
    "dt": (_t_pdf, [(x, d) for x in _X for d in (1, 2.5, 7)], 1e-14),
    "pt": (_t_cdf, [(x, d) for x in _X for d in (1, 2.5, 7)], 1e-14),
    "qt": (_quantile(_t_cdf), [(p, d) for p in _P for d in (1, 2.5, 7)], 5e-14),
    "dchisq": (_chisq_pdf, [(x, d) for x in [-1.0, *_POS] for d in (1, 3, 4.5)], 1e-14),
    "pchisq": (_chisq_cdf, [(x, d) for x in [-1.0, *_POS] for d in (1, 3, 4.5)], 1e-14),
    "qchisq": (_quantile(_chisq_cdf), [(p, d) for p in _P for d in (1, 3, 4.5)], 1e-14),
    "pF": (_f_cdf, [(x, a, b) for x in [-1.0, *_POS] for a, b in ((1, 3), (4, 7.5))], 1e-14),
    "qF": (
        _quantile(_f_cdf),
        [(p, a, b) for p in _P for a, b in ((1, 3), (4, 7.5))],
        1e-14,
    ),
    "pexp": (
        lambda x, r: -mpmath.expm1(-r * x) if x >= 0 else mpmath.mpf(0),
        [(x, r) for x in [-1.0, *_POS] for r in (0.2, 3)],
        1e-14,
    ),
    "dexp": (
        lambda x, r: r * mpmath.exp(-r * x) if x >= 0 else mpmath.mpf(0),
        [(x, r) for x in [-1.0, *_POS] for r in (0.2, 3)],
        1e-14,
    ),
    "qexp": (lambda p, r: -mpmath.log1p(-p) / r, [(p, r) for p in _P for r in (0.2, 3)], 1e-14),
    "dunif": (
        lambda x, a, b: 1 / (b - a) if a <= x <= b else mpmath.mpf(0),
        [(x, -1, 2.5) for x in [*_X, 2.5]],
        1e-15,
    ),
    "qunif": (lambda p, a, b: a + p * (b - a), [(p, -1, 2.5) for p in [0.0, *_P, 1.0]], 1e-15),
    "punif": (
        lambda x, a, b: min(max((x - a) / (b - a), 0), 1),
        [(x, -1, 2.5) for x in _X],
        1e-15,
    ),
}

_LN = ((0.3, 1.7), (-1, 0.4))
_LS = ((0.3, 1.7), (-2, 0.25))
_BETA = ((2.5, 3), (0.5, 0.7), (1, 1))
_UNIT = [-0.5, 0.0, 0.05, 0.3, 0.5, 0.8, 0.999, 1.0, 1.5]
_K = [-1, 0, 1, 3, 7, 10, 11, 25]
_BINOM = ((10, 0.3), (25, 0.02), (6, 0), (4, 1))
_PQ = [0.0, *_P, 1.0]


def _finite(points, pdf):
    """The points where the density is finite (x^(s - 1) at 0 for a shape below 1 is not)."""
    return [pt for pt in points if not (pt[0] in (0, 1) and pdf and min(pt[1:]) < 1)]


CASES |= {
    "dlnorm": (_lnorm_pdf, [(x, m, s) for x in [-1.0, 0.0, *_POS] for m, s in _LN], 1e-14),
    "plnorm": (_lnorm_cdf, [(x, m, s) for x in [-1.0, 0.0, *_POS] for m, s in _LN], 1e-14),
    "qlnorm": (_quantile(_lnorm_cdf), [(p, m, s) for p in _P for m, s in _LN], 1e-14),
    "dgamma": (
        _gamma_pdf,
        _finite([(x, s) for x in [-1.0, 0.0, *_POS] for s in (0.5, 1, 3.7)], True),
        1e-14,
    ),
    "pgamma": (_gamma_cdf, [(x, s) for x in [-1.0, 0.0, *_POS] for s in (0.5, 1, 3.7)], 1e-14),
    "qgamma": (_quantile(_gamma_cdf), [(p, s) for p in _P for s in (0.5, 1, 3.7)], 1e-14),
    "dbeta": (_beta_pdf, _finite([(x, a, b) for x in _UNIT for a, b in _BETA], True), 1e-14),
    "pbeta": (_beta_cdf, [(x, a, b) for x in _UNIT for a, b in _BETA], 1e-14),
    "qbeta": (_quantile(_beta_cdf), [(p, a, b) for p in _P for a, b in _BETA], 1e-14),
    "dweibull": (
        _weibull_pdf,
        _finite([(x, s) for x in [-1.0, 0.0, *_POS[:-1]] for s in (0.7, 1, 2.5)], True),
        1e-14,
    ),
    "pweibull": (
        _weibull_cdf,
        [(x, s) for x in [-1.0, 0.0, *_POS[:-1]] for s in (0.7, 1, 2.5)],
        1e-14,
    ),
    "qweibull": (_quantile(_weibull_cdf), [(p, s) for p in _P for s in (0.7, 1, 2.5)], 1e-14),
    "dlogis": (_logis_pdf, [(x, m, s) for x in _X for m, s in _LS], 1e-14),
    "plogis": (_logis_cdf, [(x, m, s) for x in _X for m, s in _LS], 1e-14),
    "qlogis": (_quantile(_logis_cdf), [(p, m, s) for p in _P for m, s in _LS], 1e-14),
    "dcauchy": (_cauchy_pdf, [(x, m, s) for x in _X for m, s in _LS], 1e-14),
    "pcauchy": (_cauchy_cdf, [(x, m, s) for x in _X for m, s in _LS], 1e-14),
    "qcauchy": (_quantile(_cauchy_cdf), [(p, m, s) for p in _P for m, s in _LS], 1e-14),
    "dbinom": (_binom_pmf, [(k, n, p) for k in _K for n, p in _BINOM], 1e-14),
    "pbinom": (_binom_cdf, [(k, n, p) for k in _K for n, p in _BINOM], 1e-14),
    "qbinom": (_smallest(_binom_cdf), [(q, n, p) for q in _PQ for n, p in _BINOM], 0),
    "dpois": (_pois_pmf, [(k, lam) for k in [*_K, 40] for lam in (0.3, 2.5, 12)], 5e-14),
    "ppois": (_pois_cdf, [(k, lam) for k in [*_K, 40] for lam in (0.3, 2.5, 12)], 1e-14),
    "qpois": (_smallest(_pois_cdf), [(q, lam) for q in _PQ[:-1] for lam in (0.3, 2.5, 12)], 0),
    "dgeom": (_geom_pmf, [(k, p) for k in [*_K, 40] for p in (0.02, 0.3, 1)], 1e-14),
    "pgeom": (_geom_cdf, [(k, p) for k in [*_K, 40] for p in (0.02, 0.3, 1)], 1e-14),
    "qgeom": (_smallest(_geom_cdf), [(q, p) for q in _PQ[:-1] for p in (0.02, 0.3, 1)], 0),
}


def test_every_distribution_is_tested_here():
    assert set(CASES) == NAMES and NAMES <= set(REGISTRY)


@pytest.fixture(scope="module")
def sheet(load_text):
    lines = ["[arguments]", *(f'{v} = {{ unit = "" }}' for v in "uvw"), "", "[definitions]"]
    for name in CASES:
        params = ("u", "v", "w")[: REGISTRY[name].arity]
        lines.append(f'"f_{name}({", ".join(params)})" = "{name}({", ".join(params)})"')
    return load_text("\n".join(lines) + "\n", name="t")


@pytest.mark.parametrize("name", sorted(CASES))
def test_distribution_agrees_with_mpmath(sheet, name):
    reference, points, rel = CASES[name]
    worst = 0.0
    with mp.workdps(50):
        for point in points:
            got = float(sheet.evaluate(f"f_{name}", *point).magnitude)
            args = [mpmath.mpf(a) for a in point]
            if name[0] == "q" and name not in ("qnorm", "qexp", "qunif"):
                want = reference(*args, start=got)
            else:
                want = reference(*args)
            err = abs(mpmath.mpf(got) - want) / max(abs(want), mpmath.mpf(1e-300))
            if want == 0:
                err = abs(got)
            worst = max(worst, float(err))
    print(f"{name}: largest relative difference from mpmath {worst:.2e}")
    assert worst <= rel, f"{name}: {worst:.2e}"


TEMPLATE = """
[inputs]
x = "0.7"
p = "0.3"
mu = "0.3"
sigma = "1.7"
d = "3"
d2 = "5"
r = "2.5"
a = "-1"
b = "2.5"
half = "2.5"

[definitions]
"""

EXCEL_CASES = {
    "c_dnorm": "dnorm(x, mu, sigma)",
    "c_pnorm": "pnorm(x, mu, sigma)",
    "c_qnorm": "qnorm(p, mu, sigma)",
    "c_dt": "dt(-x, d)",
    "c_pt": "pt(-x, d)",
    "c_qt": "qt(p, d)",
    "c_dchisq": "dchisq(x, d)",
    "c_pchisq": "pchisq(x, d)",
    "c_qchisq": "qchisq(p, d)",
    "c_pF": "pF(x, d, d2)",
    "c_qF": "qF(p, d, d2)",
    "c_pexp": "pexp(x, r)",
    "c_qexp": "qexp(p, r)",
    "c_punif": "punif(x, a, b)",
    "c_dexp": "dexp(x, r)",
    "c_dunif": "dunif(x, a, b) + 10*dunif(b + x, a, b)",
    "c_qunif": "qunif(p, a, b)",
    # below zero: 0, as mpmath above (Excel's own functions give #NUM!)
    "c_below": "dchisq(-x, d) + 10*pchisq(-x, d) + 100*pF(-x, d, d2) + 1000*pexp(-x, r) "
    "+ 10000*dexp(-x, r)",
    "c_constants": "pt(0.4, 4) + qchisq(0.6, 2)",
    "c_dlnorm": "dlnorm(x, mu, sigma)",
    "c_plnorm": "plnorm(x, mu, sigma)",
    "c_qlnorm": "qlnorm(p, mu, sigma)",
    "c_dgamma": "dgamma(x, r)",
    "c_pgamma": "pgamma(x, r)",
    "c_qgamma": "qgamma(p, r)",
    "c_dbeta": "dbeta(x, r, d)",
    "c_pbeta": "pbeta(x, r, d)",
    "c_qbeta": "qbeta(p, r, d)",
    "c_dweibull": "dweibull(x, r)",
    "c_pweibull": "pweibull(x, r)",
    "c_qweibull": "qweibull(p, r)",
    "c_dlogis": "dlogis(x, mu, sigma)",
    "c_plogis": "plogis(x, mu, sigma)",
    "c_qlogis": "qlogis(p, mu, sigma)",
    "c_dcauchy": "dcauchy(x, mu, sigma)",
    "c_pcauchy": "pcauchy(x, mu, sigma)",
    "c_qcauchy": "qcauchy(p, mu, sigma)",
    "c_dbinom": "dbinom(d, 10, p)",
    "c_pbinom": "pbinom(d, d2, p)",
    "c_qbinom": "qbinom(p, 12, p)",
    "c_dpois": "dpois(d, r)",
    "c_ppois": "ppois(d, r)",
    "c_dgeom": "dgeom(d, p)",
    "c_pgeom": "pgeom(d, p)",
    # outside the support: 0 (or 1), where Excel's functions give #NUM!
    "c_outside": "dlnorm(-x, mu, sigma) + 2*plnorm(0, mu, sigma) + dgamma(-x, r) "
    "+ 2*pgamma(-x, r) + dbeta(-x, r, d) + dbeta(b, r, d) + 3.5*pbeta(b, r, d) "
    "+ pbeta(-x, r, d) + dweibull(-x, r) + pweibull(-x, r) + 0.5*qbeta(0, r, d) "
    "+ 0.25*qgamma(0, r) + qlnorm(0, mu, sigma)",
    "c_counts": "dbinom(-d, d2, p) + dbinom(d2 + 1, d2, p) + 5*pbinom(d2 + d, d2, p) "
    "+ pbinom(-d, d2, p) + 7*qbinom(0, d2, p) + dpois(-d, r) + ppois(-d, r) + dgeom(-d, p) "
    "+ pgeom(-d, p) + 0.25*pbinom(2, 6, 0.5)",
}

# no Excel function: written as values
NOT_LIVE = {"no_qpois": "qpois(0.99, r)", "no_qgeom": "qgeom(0.9, p)"}


@pytest.fixture(scope="module")
def golden(load_text, tmp_path_factory):
    formulas = pytest.importorskip("formulas")
    from helpers.recalc import formula_values

    tmp = tmp_path_factory.mktemp("dist_xl")
    text = TEMPLATE + "".join(f'{k} = "{v}"\n' for k, v in EXCEL_CASES.items())
    text += 'fractional = "pt(x, half)"\nconst_fraction = "qt(p, 2.5)"\n'
    text += "".join(f'{k} = "{v}"\n' for k, v in NOT_LIVE.items())
    sheet = load_text(text, name="dist")
    path = sheet.write_xlsx(tmp / "dist.xlsx")
    cells = formula_values(path)
    solution = formulas.ExcelModel().loads(str(path)).finish().calculate()
    recalculated = {}
    for key, ranges in solution.items():
        book_sheet, _, cell = key.rpartition("!")
        if ":" in cell or "]" not in book_sheet:
            continue
        recalculated[(book_sheet.split("]", 1)[1].strip("'").upper(), cell)] = ranges.value[0, 0]
    import openpyxl

    written = {
        (ws.title, c.coordinate): c.value
        for ws in openpyxl.load_workbook(path).worksheets
        for row in ws.iter_rows()
        for c in row
    }
    return sheet, cells, recalculated, written


def _cell(cells, formula_part: str):
    found = [(k, f) for k, (f, _) in cells.items() if formula_part in f]
    assert len(found) == 1, (formula_part, found)
    return found[0]


def test_excel_forms_agree_with_the_formulas_package(golden):
    sheet, cells, recalculated, _ = golden
    for name, text in EXCEL_CASES.items():
        engine = float(sheet.evaluate(name).magnitude)
        row = [k for k, (f, v) in cells.items() if v == pytest.approx(engine, rel=1e-15)]
        assert row, f"{name}: no live formula cell holds {engine}"
        key = row[0]
        got = recalculated[(key[0].upper(), key[1])]
        print(f"{text:40} {cells[key][0]}")
        assert float(got) == pytest.approx(engine, rel=1e-14), (name, cells[key][0])
    formulas_text = " ".join(f for f, _ in cells.values())
    for function in ("NORM.DIST", "NORM.INV", "T.DIST", "T.INV", "CHISQ.DIST", "CHISQ.INV"):
        assert f"_xlfn.{function}(" in formulas_text
    for function in ("F.DIST", "F.INV", "EXPON.DIST"):  # all newer functions: prefixed
        assert f"_xlfn.{function}(" in formulas_text
    newer = ("LOGNORM.DIST", "LOGNORM.INV", "GAMMA.DIST", "GAMMA.INV", "BETA.DIST", "BETA.INV",
             "WEIBULL.DIST", "BINOM.DIST", "BINOM.INV", "POISSON.DIST")  # fmt: skip
    for function in newer:
        assert f"_xlfn.{function}(" in formulas_text
    assert "IF(INT(d_)=d_, " in formulas_text  # a count from a cell: #N/A unless whole


def test_quantiles_without_an_excel_function_are_values(golden):
    """qpois and qgeom have no Excel function: the workbook holds the engine's value."""
    sheet, cells, _, written = golden
    for name in NOT_LIVE:
        value = float(sheet.evaluate(name).magnitude)
        assert value in (6.0, 7.0)
        assert value in written.values()
        assert not any(v == value for _, v in cells.values())


def test_degrees_of_freedom_excel_would_truncate(golden):
    formulas = pytest.importorskip("formulas")
    from workbook.compute.excel import ExcelPrinter

    """Excel truncates degrees of freedom: from a cell, a fraction gives #N/A (never the value
    of another distribution); a constant fraction is written as the value."""
    sheet, cells, recalculated, written = golden
    formula = ExcelPrinter(sheet.typer, {"x": "x_", "half": "half_"}).formula(
        sheet.typer.scalar("fractional"), {}
    )
    assert formula.startswith("=IF(INT(half_)=half_, ")
    fn = formulas.Parser().ast(formula)[1].compile()
    inputs = {"X_": 0.7, "HALF_": 2.5}
    assert str(fn(*[inputs[k] for k in fn.inputs])) == "#N/A"
    # #N/A where the engine has a value: the workbook holds the engine's value (livecheck)
    assert not any("T.DIST(x_, half" in f for f, _ in cells.values())
    assert float(sheet.evaluate("fractional").magnitude) in written.values()
    assert not any("T.INV(p_, 2.5" in f for f, _ in cells.values())
    with mp.workdps(50):
        want = float(_quantile(_t_cdf)(mpmath.mpf(0.3), mpmath.mpf(2.5), start=-0.6))
    assert float(sheet.evaluate("const_fraction").magnitude) == pytest.approx(want, rel=1e-12)
    assert any(v == float(sheet.evaluate("const_fraction").magnitude) for v in written.values())


@pytest.mark.parametrize(
    "text, message",
    [
        ("pnorm(L, 0, 1)", "needs a dimensionless argument"),
        ("qt(0.3, t)", "needs a dimensionless argument"),
        ("pchisq(1)", "takes 2 argument(s), got 1"),
    ],
)
def test_arguments_are_plain_numbers(sheet_from, text, message):
    text = f'[inputs]\nL = "1 m"\nt = "4 s"\n\n[definitions]\nbad = "{text}"\n'
    with pytest.raises(WorkbookError, match=re.escape(message)):
        sheet_from(text)


@pytest.mark.parametrize(
    "text",
    [
        "qnorm(1.3, 0, 1)",
        "pnorm(0.5, 0, -1)",
        "pt(0.5, 0)",
        "qexp(0.5, -2)",
        "plnorm(1, 0, 0)",
        "qgamma(1.2, 2)",
        "dbeta(0.5, -1, 2)",
        "qweibull(0.5, 0)",
        "qlogis(1, 0, 1)",
        "pcauchy(1, 0, -1)",
        "dbinom(2.5, 10, 0.3)",
        "pbinom(2.5, 10, 0.3)",
        "pbinom(2, 10.5, 0.3)",
        "qbinom(0.5, 10, 1.3)",
        "dpois(2.5, 3)",
        "ppois(1, 0)",
        "dgeom(1, 0)",
        "pgeom(1.5, 0.3)",
        "qgeom(-0.1, 0.3)",
    ],
)
def test_outside_the_domain_is_an_error_not_a_number(sheet_from, text):
    with pytest.raises(WorkbookError, match="not a finite number"):
        sheet_from(f'[definitions]\nbad = "{text}"\n').evaluate("bad")


def test_the_normal_density_is_the_derivative_of_its_probability(sheet_from):
    text = '[arguments]\nu = { unit = "" }\n\n[definitions]\n'
    text += '"slope(u)" = "diff(pnorm(u, 0.3, 1.7), u)"\n"dens(u)" = "dnorm(u, 0.3, 1.7)"\n'
    sheet = sheet_from(text)
    u = np.array([-2.0, 0.1, 1.3])
    slope = sheet.evaluate("slope", u).magnitude
    assert slope == pytest.approx(sheet.evaluate("dens", u).magnitude, rel=1e-14)
    assert math.isclose(slope[1], float(mpmath.npdf(0.1, 0.3, 1.7)), rel_tol=1e-14)


@pytest.mark.slow
def test_libreoffice_recalculates_the_distributions(sheet_from, tmp_path):
    """Every distribution cell recalculated by LibreOffice (which reads the _xlfn. names)
    agrees with the engine; a fraction of degrees of freedom from a cell is #N/A there too."""
    from helpers.recalc import cell_values, formula_values, recalculate, soffice

    if soffice() is None:
        pytest.skip("LibreOffice is not installed")
    text = TEMPLATE + "".join(f'{k} = "{v}"\n' for k, v in EXCEL_CASES.items())
    text += 'fractional = "pt(x, half)"\n'
    sheet = sheet_from(text, name="dist")
    path = sheet.write_xlsx(tmp_path / "dist.xlsx")
    cells = formula_values(path)
    again = cell_values(recalculate(path, tmp_path / "out"))
    checked = 0
    for key, (formula, cached) in cells.items():
        if "INT(half)" in formula:
            assert str(again.get(key)) == "#N/A", formula
            continue
        if isinstance(cached, (int, float)):
            assert float(again[key]) == pytest.approx(cached, rel=1e-12, abs=1e-300), formula
            checked += 1
    assert checked >= len(EXCEL_CASES)
