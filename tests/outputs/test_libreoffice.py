"""Recalculate generated workbooks in LibreOffice Calc and compare with the engine."""

import os
import shutil

import openpyxl
import pytest
from helpers.recalc import cell_values, formula_values, recalculate, soffice
from helpers.recalculated import assert_same

if soffice() is None and os.environ.get("CI"):
    raise RuntimeError("CI must run the LibreOffice recalculation tests: install libreoffice-calc")
pytestmark = [
    pytest.mark.skipif(soffice() is None, reason="LibreOffice is not installed"),
    pytest.mark.slow,  # each test starts LibreOffice (10 s or more)
]


def test_concave_cam_recalculates_to_engine_values(tmp_path, concave):
    path = concave.write_xlsx(tmp_path / "cc.xlsx")
    n = assert_same(path, recalculate(path, tmp_path / "lo"))
    assert n > 700


def test_changed_input_follows_with_inputs(tmp_path, concave):
    path = concave.write_xlsx(tmp_path / "cc.xlsx")
    edited = tmp_path / "edited.xlsx"
    shutil.copy(path, edited)
    wb = openpyxl.load_workbook(edited)
    ws = wb["Inputs"]
    row = next(r for r in ws.iter_rows() if r[0].value == "R3")
    row[1].value = 40
    wb.save(edited)
    values = cell_values(recalculate(edited, tmp_path / "lo"))
    # the expected values come from the engine with the same input changed
    expected = concave.with_inputs(R3="40 mm")
    reference = formula_values(expected.write_xlsx(tmp_path / "expected.xlsx"))
    listing = [(k, v) for k, (f, v) in reference.items() if k[0] in ("Listing", "Chart data")]
    assert len(listing) == 3 * (6 + 13 + 5 + 105)
    for key, value in listing:
        assert values[key] == pytest.approx(value, rel=1e-9, abs=1e-12), key
    # and they did change
    assert values[("Definitions", "B3")] == pytest.approx(2.0)  # k = (20 + 40)/(40 - 10)


def test_live_verdicts_use_the_absolute_or_the_relative_tolerance(tmp_path):
    """The Checks sheet's pass/FAIL formulas apply the engine's test (checks.within): LibreOffice
    recalculates the same verdicts, including one that passes only by the relative bound."""
    import workbook

    (tmp_path / "p.csv").write_text("name,argument,value,unit\ny,,20.5,mm\nz,,32,mm\n")
    (tmp_path / "d.csv").write_text("name,argument,value,unit\ny,,20.0,mm\nz,,30.06,mm\n")
    (tmp_path / "t.toml").write_text(
        '[inputs]\nR = "10 mm"\n\n[definitions]\ny = "2*R"\nz = "3*R"\n\n'
        '[[printed]]\nfile = "p.csv"\ntolerance = 0.1\nrel_tolerance = 0.03\n\n'
        '[[printed]]\nfile = "d.csv"\n'
    )
    sheet = workbook.load(tmp_path / "t.toml")
    report = sheet.check()
    assert [r.verdict for r in report.rows] == ["pass", "FAIL", "pass", "FAIL"]
    path = sheet.write_xlsx(tmp_path / "t.xlsx", report=report)
    recalculated = recalculate(path, tmp_path / "lo")
    assert_same(path, recalculated)
    verdicts = [cell_values(recalculated)[("Checks", f"J{row}")] for row in range(2, 6)]
    assert verdicts == ["pass", "FAIL", "pass", "FAIL"]
    formula = formula_values(path)[("Checks", "J2")][0]
    assert formula.startswith("=IF(OR(G2<=0.1000000001") and "G2<=0.03*ABS(E2)" in formula


def test_max_over_is_a_live_max_of_the_table_column(tmp_path):
    import workbook

    (tmp_path / "t.toml").write_text(
        '[inputs]\nR = "10 mm"\n\n[arguments]\nphi = { unit = "deg" }\n\n[definitions]\n'
        '"y(phi)" = "R*sin(phi)"\ny_top = "max_over(t, y)"\n\n'
        '[[tables]]\nname = "t"\nrange = "phi := 0, 10 .. 90"\ncolumns = { y = "mm" }\n\n'
        '[[tables]]\nname = "top"\nrange = "k := 1 .. 1"\n'
        'columns = [{ expr = "y_top", unit = "mm" }]\n'
    )
    path = workbook.load(tmp_path / "t.toml").write_xlsx(tmp_path / "t.xlsx")
    formulas = formula_values(path)
    assert formulas[("Definitions", "B2")][0] == "=MAX('Listing'!$B$3:$B$12)"
    edited = tmp_path / "edited.xlsx"
    wb = openpyxl.load_workbook(path)
    wb["Inputs"]["B2"].value = 25
    wb.save(edited)
    values = cell_values(recalculate(edited, tmp_path / "lo"))
    assert values[("Definitions", "B2")] == 25
    assert values[("Listing", "B17")] == 25  # the table that shows it


def test_live_integral_follows_an_input_change(tmp_path):
    """integral() is a live Gauss-Legendre SUMPRODUCT: LibreOffice's value after an edit is
    the engine's new value, within the difference the cell's comment states."""
    import re

    import workbook

    (tmp_path / "q.toml").write_text(
        '[inputs]\nR = "50 mm"\nu_max = "2 m/s"\n\n[arguments]\nr = { unit = "mm" }\n\n'
        "[definitions]\n"
        '"u(r)" = { expr = "u_max*(1 - (r/R)^2)*exp(-r/R)", unit = "m/s" }\n'
        'Q = { expr = "integral(2*pi*r*u(r), r, 0, R)", unit = "L/s" }\n'
        'Q2 = { expr = "integral(2*pi*r*u(r), r, 0, R/2)", unit = "L/s" }\n\n'
        '[[tables]]\nname = "flow"\nrange = "k := 1 .. 1"\n'
        'columns = [{ expr = "Q", unit = "L/s" }, { expr = "Q2", unit = "L/s" }]\n'
    )
    sheet = workbook.load(tmp_path / "q.toml")
    path = sheet.write_xlsx(tmp_path / "q.xlsx")
    wb = openpyxl.load_workbook(path)
    defs = wb["Definitions"]
    rows = {defs.cell(r, 1).value: r for r in range(2, defs.max_row + 1)}
    assert "SUMPRODUCT" in defs.cell(rows["Q"], 2).value
    stated = re.search(r"by ([0-9.e+-]+) ", defs.cell(rows["Q"], 2).comment.text).group(1)
    inputs = wb["Inputs"]
    row = next(r for r in inputs.iter_rows() if r[0].value == "R")
    row[1].value = 80
    wb.save(tmp_path / "edited.xlsx")
    values = cell_values(recalculate(tmp_path / "edited.xlsx", tmp_path / "lo"))
    new = sheet.with_inputs(R="80 mm")
    for name in ("Q", "Q2"):
        want = new.evaluate(name).to("L/s").magnitude
        got = values[("Definitions", f"B{rows[name]}")]
        assert got == pytest.approx(want, rel=1e-9, abs=10 * float(stated) + 1e-12), name
        assert got != pytest.approx(sheet.evaluate(name).to("L/s").magnitude, rel=1e-3)


def test_live_root_follows_an_input_change(tmp_path):
    """root(EXPR, X, A, B) of a scalar definition is live as bisection steps in helper cells:
    after an edit LibreOffice finds the engine's new root; a bracket without a sign change
    shows #N/A, not a number."""
    import workbook

    (tmp_path / "r.toml").write_text(
        '[inputs]\neps = "0.05 mm"\nD = "100 mm"\nRe_op = "100000"\n\n'
        '[arguments]\nRe = { unit = "" }\nf = { unit = "" }\n\n[definitions]\n'
        '"colebrook(f, Re)" = "1/sqrt(f) + 2*log10(eps/(3.7*D) + 2.51/(Re*sqrt(f)))"\n'
        'f_op = "root(colebrook(f, Re_op), f, 0.005, 0.1)"\n\n'
        '[[tables]]\nname = "op"\nrange = "k := 1 .. 1"\ncolumns = [{ expr = "f_op" }]\n'
    )
    sheet = workbook.load(tmp_path / "r.toml")
    path = sheet.write_xlsx(tmp_path / "r.xlsx")
    wb = openpyxl.load_workbook(path)
    cell = wb["Definitions"]["B2"]
    assert wb["Definitions"]["A2"].value == "f_op" and "Solver steps" in cell.value
    row = next(r for r in wb["Inputs"].iter_rows() if r[0].value == "Re_op")
    for value, expected in ((1e6, sheet.with_inputs(Re_op="1e6")), (10.0, None)):
        row[1].value = value
        wb.save(tmp_path / "edited.xlsx")
        got = cell_values(recalculate(tmp_path / "edited.xlsx", tmp_path / f"lo{value:g}"))
        if expected is None:  # Re = 10: no root in [0.005, 0.1]
            assert got[("Definitions", "B2")] == "#N/A"
        else:
            want = expected.evaluate("f_op").magnitude
            assert got[("Definitions", "B2")] == pytest.approx(want, rel=1e-12)
            assert want != pytest.approx(sheet.evaluate("f_op").magnitude, rel=1e-3)
