"""atan2(x, y), x first as Mathcad's atan2 and Excel's ATAN2: the engine against Python's
math.atan2(y, x) and mpmath in the four quadrants, the workbook's ATAN2(x, y) recalculated by
the `formulas` package, and an Excel workbook's ATAN2 imported in the same order."""

from __future__ import annotations

import math

import formulas
import mpmath
import openpyxl
import pytest

import workbook
from workbook.cli import main

POINTS = [(3.0, 4.0), (-3.0, 4.0), (-3.0, -4.0), (3.0, -4.0), (0.0, 2.0), (-2.0, 0.0)]

SHEET = (
    "[inputs]\n"
    + "".join(f'px_{i} = "{x} ohm"\npy_{i} = "{y} ohm"\n' for i, (x, y) in enumerate(POINTS))
    + "\n[definitions]\n"
    + "".join(
        f'phi_{i} = {{ expr = "atan2(px_{i}, py_{i})", unit = "deg" }}\n'
        for i in range(len(POINTS))
    )
    + 'mixed = { expr = "atan2(1 m, 500 mm)", unit = "rad" }\n'
)


@pytest.fixture(scope="module")
def sheet(load_text, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("atan2")
    return load_text(SHEET, name="t", folder=tmp), tmp


def test_x_comes_first_in_every_quadrant(sheet):
    sh, _ = sheet
    for i, (x, y) in enumerate(POINTS):
        got = sh.evaluate(f"phi_{i}").to("deg").magnitude
        assert got == pytest.approx(math.degrees(math.atan2(y, x)), rel=1e-14, abs=1e-14)
        exact = float(mpmath.degrees(mpmath.atan2(mpmath.mpf(y), mpmath.mpf(x))))
        assert got == pytest.approx(exact, rel=1e-14, abs=1e-14)
    assert sh.evaluate("mixed").to("rad").magnitude == pytest.approx(math.atan2(0.5, 1.0))


def test_the_workbook_writes_atan2_x_first(sheet):
    sh, tmp = sheet
    path = sh.write_xlsx(tmp / "atan2.xlsx")
    book = openpyxl.load_workbook(path)
    cells = [str(getattr(c.value, "text", c.value)) for ws in book for row in ws for c in row]
    assert any(c.startswith("=ATAN2(px_1, py_1)") for c in cells), cells  # x first


@pytest.mark.slow
def test_the_workbook_recalculates_atan2_to_the_engine(sheet):
    sh, tmp = sheet
    path = sh.write_xlsx(tmp / "atan2-recalc.xlsx")
    results = openpyxl.load_workbook(path)["Results"]
    rows = {r[0].value: r[0].row for r in results.iter_rows(min_row=2) if r[0].value}
    solution = formulas.ExcelModel().loads(str(path)).finish().calculate()
    values = {}
    for key, ranges in solution.items():
        book_sheet, _, cell = key.rpartition("!")
        if book_sheet.split("]", 1)[-1].strip("'").upper() == "RESULTS" and ":" not in cell:
            values[cell.upper()] = ranges.value[0, 0]
    for i in range(len(POINTS)):
        want = sh.evaluate(f"phi_{i}").to("deg").magnitude
        assert float(values[f"B{rows[f'phi_{i}']}"]) == pytest.approx(want, rel=1e-13, abs=1e-13)


def test_an_excel_atan2_is_imported_in_its_order(tmp_path):
    xlsxwriter = pytest.importorskip("xlsxwriter")
    book = tmp_path / "angle.xlsx"
    wb = xlsxwriter.Workbook(str(book))
    ws = wb.add_worksheet("Angle")
    ws.write("A1", "R")
    ws.write("B1", 40.0)
    ws.write("A2", "X")
    ws.write("B2", -91.7)
    ws.write("A3", "phi")
    ws.write_formula("B3", "=ATAN2(B1,B2)", None, math.atan2(-91.7, 40.0))
    wb.close()
    out = tmp_path / "out"
    assert main(["import", str(book), "--out", str(out)]) == 0
    text = (out / "angle.toml").read_text(encoding="utf-8")
    imported = workbook.load(str(out / "angle.toml"))
    (name,) = [n for n, d in imported.spec.definitions.items() if "atan2" in d.text]
    assert float(imported.evaluate(name).magnitude) == pytest.approx(
        math.atan2(-91.7, 40.0), rel=1e-14
    ), text


@pytest.mark.slow
def test_a_symbolic_derivative_that_keeps_atan2_keeps_its_order(sheet_from):
    """SymPy's atan2 takes y first: a derivative read back from it is the language's
    atan2(x, y) again (d/dx of x*atan2(x, 1) holds atan2(x, 1) itself)."""
    text = (
        '[arguments]\nx = { unit = "" }\n\n[definitions]\n"f(x)" = "x*atan2(x, 1)"\n'
        '"g(x)" = "diff(f(x), x)"\n'
    )
    sheet = sheet_from(text)
    for x in (-2.0, -0.3, 0.7, 5.0):
        want = float(mpmath.diff(lambda t: t * mpmath.atan2(1, t), x))
        assert float(sheet.evaluate("g", x).magnitude) == pytest.approx(want, rel=1e-13)
