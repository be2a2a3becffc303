"""Built-in constants pi, e and g: values, Excel, SymPy, and a worksheet's own names first."""

from __future__ import annotations

import math

import formulas
import openpyxl
import pytest
import scipy.constants

from workbook.errors import TemplateError
from workbook.functions.constants import CONSTANTS

SHEET = """
[sheet]
title = "constants"

[inputs]
mass = { value = "3 kg" }

[arguments]
x = { unit = "" }

[definitions]
weight = { expr = "mass*g", unit = "N" }
growth = "e^2"
circle = "2*pi"
"slope(x)" = "diff(e^x, x)"
at_one = "slope(1)"
"""


@pytest.fixture(scope="module")
def written(load_text, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("constants")
    sheet = load_text(SHEET, name="t")
    return sheet, sheet.write_xlsx(tmp / "constants.xlsx")


def test_the_constants_are_registry_entries():
    assert set(CONSTANTS) == {"pi", "e", "g"}
    assert CONSTANTS["g"].value == scipy.constants.g  # standard gravity, 9.80665 m/s^2
    assert CONSTANTS["e"].value == math.e and CONSTANTS["pi"].value == math.pi


def test_values_against_scipy_and_math(written):
    sheet, _ = written
    assert sheet.evaluate("weight").to("N").magnitude == pytest.approx(
        3 * scipy.constants.g, rel=1e-15
    )
    assert sheet.evaluate("growth").magnitude == pytest.approx(math.exp(2), rel=1e-15)
    assert sheet.evaluate("circle").magnitude == pytest.approx(2 * math.pi, rel=1e-15)
    assert sheet.evaluate("at_one").magnitude == pytest.approx(math.e, rel=1e-14)  # SymPy's E


def test_excel_formulas_recalculate_to_the_engine(written):
    sheet, path = written
    ws = openpyxl.load_workbook(path)["Results"]
    rows = {r[0].value: r[0].row for r in ws.iter_rows(min_row=2) if r[0].value}
    formula = {n: ws[f"B{rows[n]}"].value for n in ("weight", "growth", "circle")}
    assert formula == {"weight": "=mass*9.80665", "growth": "=EXP(1)^2", "circle": "=2*PI()"}
    solution = formulas.ExcelModel().loads(str(path)).finish().calculate()
    values = {}
    for key, ranges in solution.items():
        book_sheet, _, cell = key.rpartition("!")
        if book_sheet.split("]", 1)[-1].strip("'").upper() == "RESULTS" and ":" not in cell:
            values[cell.upper()] = ranges.value[0, 0]
    for name in formula:
        engine = float(sheet.evaluate(name).magnitude)
        assert float(values[f"B{rows[name]}"]) == pytest.approx(engine, rel=1e-14), name


OWN = """
[sheet]
title = "an eccentric cam"

[inputs]
e = { value = "6 mm", note = "eccentricity" }
R = { value = "20 mm" }

[definitions]
g = { expr = "R - e", unit = "mm", note = "a gap, not gravity" }
reach = { expr = "R + e", unit = "mm" }
"""


def test_a_worksheet_may_define_its_own_e_and_g(sheet_from, tmp_path):
    sheet = sheet_from(OWN)
    assert sheet.evaluate("reach").to("mm").magnitude == pytest.approx(26.0)
    assert sheet.evaluate("g").to("mm").magnitude == pytest.approx(14.0)
    path = sheet.write_xlsx(tmp_path / "own.xlsx")
    about = {r[0]: r[1] for r in openpyxl.load_workbook(path)["About"].iter_rows(values_only=True)}
    note = about["Built-in constants"]
    assert "e is this worksheet's own, not 2.71828" in note
    assert "g is this worksheet's own, not 9.80665 m/s^2" in note


def test_an_argument_named_e_is_not_eulers_number_outside_its_function(sheet_from):
    text = """
[arguments]
e = { unit = "" }

[definitions]
"f(e)" = "2*e"
wrong = "e + 1"
"""
    with pytest.raises(TemplateError, match="'e' is an argument"):
        sheet_from(text)
