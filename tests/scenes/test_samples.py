"""Statistics of samples (Var, Stdev, corr, cvar, slope, intercept, skew, kurt, gmean, hmean,
Rank): against the values Mathcad Prime stored in statistics-functions.mcdx (../shared, skipped
when absent), against Excel's formulas computed in mpmath at 50 digits, units and refusals."""

from __future__ import annotations

import json
import subprocess
import sys

import mpmath
import numpy as np
import pytest
from helpers.paths import SHARED
from helpers.sheets import definitions

from workbook.errors import WorkbookError

PRIME = SHARED / "mathcad-prime"
needs_corpus = pytest.mark.skipif(not PRIME.is_dir(), reason=f"{PRIME} is absent")

X = [2.323, 1.988, 3.476, -1.186, 2.425, 2.334, 0.758, 0.25, 3.052, 1.209, 1.186, 1.878]
Y = [4.1, 3.2, 6.5, -2.0, 4.4, 4.9, 1.1, 0.7, 6.0, 2.2, 2.5, 3.3]


def _vector(values) -> str:
    return "[" + ", ".join(repr(v) for v in values) + "]"


@needs_corpus
def test_reproduce_mathcads_stored_values(sheet_from):
    lister, sheet = PRIME / "mcdx_results.py", PRIME / "statistics-functions.mcdx"
    out = subprocess.run(
        [sys.executable, str(lister), "--json", str(sheet)],
        capture_output=True, text=True, check=True, timeout=120,
    )  # fmt: skip
    items = {item["text"]: item for item in json.loads(out.stdout)["items"]}
    data = next(t for t in items if t.startswith("DATA := ["))
    rows = [
        [float(x) for x in r.split(",")] for r in data.split(":= ", 1)[1].strip("[]").split(";")
    ]
    v1, v2 = [r[1] for r in rows], [r[2] for r in rows]
    got = sheet_from(
        definitions(
            {
                "V1": _vector(v1),
                "V2": _vector(v2),
                "c": "cvar(V1, V2)",
                "a": "fit_slope(V1, V2)",
                "r": "corr(V1, V2)",
                "R1": "Rank(V1)",
                "R2": "Rank(V2)",
                "rr": "corr(Rank(V1), Rank(V2))",
            }
        )
    )

    def stored(text: str):
        value = items[text]["value"]
        if "elements" in value:
            return np.array([float(e["real"]) for e in value["elements"]])
        return float(value["real"])

    def ours(name: str):
        return np.asarray(got.evaluate(name).magnitude, dtype=float).reshape(-1)

    assert ours("c")[0] == pytest.approx(stored("cvar(V_1, V_2) ="), rel=1e-12)
    assert ours("a")[0] == pytest.approx(stored("a ="), rel=1e-12)
    assert ours("r")[0] == pytest.approx(stored("r := corr(V_1, V_2) ="), rel=1e-12)
    assert np.array_equal(ours("R1"), stored("Rank1 := Rank(V_1) ="))
    assert np.array_equal(ours("R2"), stored("Rank2 := Rank(V_2) ="))
    assert ours("rr")[0] == pytest.approx(stored("corr(Rank1, Rank2) ="), rel=1e-12)


def test_against_excels_formulas_in_mpmath(sheet_from):
    mpmath.mp.dps = 50
    x, y = [mpmath.mpf(repr(v)) for v in X], [mpmath.mpf(repr(v)) for v in Y]
    n = len(x)
    mx, my = sum(x) / n, sum(y) / n
    sxx = sum((a - mx) ** 2 for a in x)
    sxy = sum((a - mx) * (b - my) for a, b in zip(x, y))
    syy = sum((b - my) ** 2 for b in y)
    s = mpmath.sqrt(sxx / (n - 1))
    want = {
        "v": sxx / (n - 1),
        "sd": s,
        "r": sxy / mpmath.sqrt(sxx * syy),
        "c": sxy / n,
        "a": sxy / sxx,
        "b": my - sxy / sxx * mx,
        "sk": n / mpmath.mpf((n - 1) * (n - 2)) * sum(((a - mx) / s) ** 3 for a in x),
        "ku": mpmath.mpf(n * (n + 1))
        / ((n - 1) * (n - 2) * (n - 3))
        * sum(((a - mx) / s) ** 4 for a in x)
        - mpmath.mpf(3 * (n - 1) ** 2) / ((n - 2) * (n - 3)),
        "g": mpmath.exp(sum(mpmath.log(b) for b in y if b > 0) / sum(1 for b in y if b > 0)),
        "h": sum(1 for b in y if b > 0) / sum(1 / b for b in y if b > 0),
    }
    positive = _vector([v for v in Y if v > 0])
    got = sheet_from(
        definitions({
            "X": _vector(X), "Y": _vector(Y), "P": positive,
            "v": "Var(X)", "sd": "Stdev(X)", "r": "corr(X, Y)", "c": "cvar(X, Y)",
            "a": "fit_slope(X, Y)", "b": "fit_intercept(X, Y)", "sk": "skew(X)", "ku": "kurt(X)",
            "g": "gmean(P)", "h": "hmean(P)",
        })
    )  # fmt: skip
    for name, value in want.items():
        assert float(got.evaluate(name).magnitude) == pytest.approx(float(value), rel=1e-13), name
    # equal values share their mean rank
    ties = sheet_from(definitions({"R": "Rank([3, 1, 3, 2])"}))
    assert np.array_equal(np.asarray(ties.evaluate("R").magnitude).reshape(-1), [3.5, 1, 3.5, 2])


def test_units(sheet_from):
    got = sheet_from(
        definitions(
            {
                "x": "[1, 2, 4] * 1 m",
                "t": "[2, 3, 7] * 1 s",
                "a": "fit_slope(x, t)",
                "b": "fit_intercept(x, t)",
                "c": "cvar(x, t)",
                "r": "corr(x, t)",
                "v": "Var(x)",
                "sd": "Stdev(x)",
            }
        )
    )
    assert str(got.evaluate("a").units) == "second / meter"
    assert str(got.evaluate("b").units) == "second"
    assert str(got.evaluate("c").units) == "meter * second"
    assert str(got.evaluate("r").units) == "dimensionless"
    assert got.evaluate("v").to("m^2").magnitude == pytest.approx(7 / 3)
    assert got.evaluate("sd").to("m").magnitude == pytest.approx((7 / 3) ** 0.5)


@pytest.mark.parametrize(
    "expr, message",
    [
        ("corr([1, 2, 3], [1, 2])", "3 and 2 elements"),
        ("corr([1, 1, 1], [1, 2, 3])", "every value of the sample is the same"),
        ("gmean([1, -2, 3])", "must be positive"),
        ("kurt([1, 2, 3])", "at least 4 values"),
        ("Var([5])", "at least 2 values"),
    ],
)
def test_refusals(sheet_from, expr, message):
    with pytest.raises(WorkbookError, match=message):
        sheet_from(definitions({"X": expr})).evaluate("X")


@pytest.mark.slow
def test_excel_forms_recalculate_in_libreoffice(sheet_from, tmp_path):
    """The workbook's live formulas (VAR.S, CORREL, COVARIANCE.P, SLOPE(y, x), ...), recalculated
    by LibreOffice, give the engine's values."""
    from helpers.recalc import cell_values, recalculate, soffice

    if soffice() is None:
        pytest.skip("LibreOffice is not installed")
    names = {
        "v": "Var(x)", "s": "Stdev(x)", "r": "corr(x, y)", "c": "cvar(x, y)",
        "a": "fit_slope(x, y)", "b": "fit_intercept(x, y)", "sk": "skew(x)", "ku": "kurt(x)",
        "g": "gmean(y)", "h": "hmean(y)",
    }  # fmt: skip
    sheet = sheet_from(definitions({"x": "[1, 2, 3, 4, 10]", "y": "[2, 4, 5, 4, 5]", **names}))
    xlsx = tmp_path / "s.xlsx"
    sheet.write_xlsx(xlsx)
    values = cell_values(recalculate(xlsx, tmp_path / "recalc"))
    rows = {values[("Results", f"A{r}")]: values[("Results", f"B{r}")] for r in range(2, 12)}
    for name in names:
        assert rows[name] == pytest.approx(float(sheet.evaluate(name).magnitude), rel=1e-12), name
