"""The columns of a [data] table as vectors: the vector built-ins over measured points against
numpy and scipy, the interpolation built-ins unchanged, and the workbook's formulas (arrays of
the column's numbers) recalculated by the `formulas` package to the engine's values."""

from __future__ import annotations

import math

import formulas
import numpy as np
import openpyxl
import pytest
from scipy import stats

import workbook

RNG = np.random.default_rng(20261201)
T = np.round(np.linspace(20.0, 95.0, 16), 6)  # degC
R = np.round(100.0 * (1 + 0.00385 * (T - 20.0)) + RNG.normal(0.0, 0.05, T.size), 6)  # ohm

SHEET = """
[data.pt100]
file = "pt100.csv"
columns = { T = "degC", R = "ohm" }

[inputs]
T_op = "50 degC"

[definitions]
n = "rows(R)"
slope = { expr = "fit_slope(T - 20 degC, R)", unit = "ohm/K" }
R20 = { expr = "fit_intercept(T - 20 degC, R)", unit = "ohm" }
alpha = { expr = "slope/R20", unit = "1/K" }
r = "corr(T - 20 degC, R)"
R_sum = { expr = "sum(R)", unit = "ohm" }
R_mean = { expr = "mean(R)", unit = "ohm" }
R_max = { expr = "max(R)", unit = "ohm" }
R_sd = { expr = "stdev(R)", unit = "ohm" }
R_Sd = { expr = "Stdev(R)", unit = "ohm" }
R_3 = { expr = "R[3]", unit = "ohm" }
worst = { expr = "max(abs(R - (R20 + slope*(T - 20 degC))))", unit = "ohm" }
T_top = { expr = "max(T)", unit = "degC" }
R_op = { expr = "linterp(T, R, T_op)", unit = "ohm" }
R_op_c = { expr = "cspline(T, R, T_op)", unit = "ohm" }
"""


@pytest.fixture(scope="module")
def sheet(load_text, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("pt100")
    rows = "\n".join(f"{float(t)!r},{float(r)!r}" for t, r in zip(T, R))
    (tmp / "pt100.csv").write_text(f"# a PT100, measured\nT,R\n{rows}\n", encoding="utf-8")
    return load_text(SHEET, name="t", folder=tmp), tmp


def _expected() -> dict[str, float]:
    fit = stats.linregress(T - 20.0, R)
    slope, r20 = fit.slope, fit.intercept
    return {
        "n": T.size,
        "slope": slope,
        "R20": r20,
        "alpha": slope / r20,
        "r": fit.rvalue,
        "R_sum": math.fsum(R),
        "R_mean": float(np.mean(R)),
        "R_max": float(np.max(R)),
        "R_sd": float(np.std(R)),  # stdev divides by N (Mathcad's), Stdev by N - 1
        "R_Sd": float(np.std(R, ddof=1)),
        "R_3": R[3],
        "worst": float(np.max(np.abs(R - (r20 + slope * (T - 20.0))))),
        "T_top": float(np.max(T) + 273.15),  # a built-in of an absolute temperature: in K
        "R_op": float(np.interp(50.0, T, R)),
    }


def test_the_vector_built_ins_take_a_column(sheet):
    sh, _ = sheet
    for name, want in _expected().items():
        got = sh.evaluate(name)
        unit = {"T_top": "K"}.get(name)
        value = got.to(unit).magnitude if unit else got.magnitude
        assert math.isclose(float(value), float(want), rel_tol=1e-11, abs_tol=1e-12), name


def test_cspline_over_the_columns_still_interpolates(sheet):
    from scipy.interpolate import CubicSpline

    sh, _ = sheet
    want = float(CubicSpline(T, R, bc_type="not-a-knot")(50.0))
    assert sh.evaluate("R_op_c").to("ohm").magnitude == pytest.approx(want, rel=1e-12)


@pytest.mark.slow
def test_the_workbook_recalculates_the_regression(sheet):
    sh, tmp = sheet
    path = sh.write_xlsx(tmp / "pt100.xlsx")
    results = openpyxl.load_workbook(path)["Results"]
    rows = {r[0].value: r[0].row for r in results.iter_rows(min_row=2) if r[0].value}
    book = openpyxl.load_workbook(path)
    cells = [str(getattr(c.value, "text", c.value)) for ws in book for row in ws for c in row]
    assert any("SLOPE({" in f for f in cells), cells  # the column's numbers, live
    solution = formulas.ExcelModel().loads(str(path)).finish().calculate()
    values = {}
    for key, ranges in solution.items():
        book_sheet, _, cell = key.rpartition("!")
        if book_sheet.split("]", 1)[-1].strip("'").upper() == "RESULTS" and ":" not in cell:
            values[cell.upper()] = ranges.value[0, 0]
    for name in ("n", "slope", "R20", "alpha", "r", "R_sum", "R_mean", "R_max", "R_3", "worst"):
        want = float(sh.evaluate(name).magnitude)
        got = float(values[f"B{rows[name]}"])
        assert math.isclose(got, want, rel_tol=1e-11, abs_tol=1e-12), name


def test_a_column_of_another_table_and_a_wrong_unit_are_refused(sheet_from, tmp_path):
    (tmp_path / "a.csv").write_text("x,y\n0,1\n1,2\n", encoding="utf-8")
    text = """
[data.a]
file = "a.csv"
columns = { x = "s", y = "m" }

[definitions]
bad = "sum(x) + 1 m"
"""
    with pytest.raises(workbook.WorkbookError, match="cannot add"):
        sheet_from(text)


@pytest.mark.slow
def test_libreoffice_recalculates_the_regression(sheet, tmp_path):
    from helpers.recalc import cell_values, recalculate, soffice

    if soffice() is None:
        pytest.skip("LibreOffice is not installed")
    sh, tmp = sheet
    path = sh.write_xlsx(tmp / "pt100-lo.xlsx")
    results = openpyxl.load_workbook(path)["Results"]
    rows = {r[0].value: r[0].row for r in results.iter_rows(min_row=2) if r[0].value}
    values = cell_values(recalculate(path, tmp_path))
    for name in ("n", "slope", "R20", "alpha", "r", "R_sum", "R_mean", "R_max", "R_3", "worst"):
        want = float(sh.evaluate(name).magnitude)
        got = float(values[("Results", f"B{rows[name]}")])
        assert math.isclose(got, want, rel_tol=1e-11, abs_tol=1e-12), name
