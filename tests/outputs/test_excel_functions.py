"""The one table of Excel functions, checked against xlsxwriter and openpyxl (which we did not
write), and the defined names derived from it: function names and Excel's built-in names
(Print_Area, Auto_Open...) renamed like any other collision, read back from the workbook."""

from __future__ import annotations

import re

import openpyxl
import pytest
import xlsxwriter
from openpyxl.utils.formulas import FORMULAE

from workbook.functions import excel_names
from workbook.functions.excel_functions import CLASSIC, FUNCTIONS, stored
from workbook.functions.excel_names import BUILTIN_NAMES, ExcelNames


@pytest.fixture(scope="module")
def worksheet(tmp_path_factory):
    book = xlsxwriter.Workbook(tmp_path_factory.mktemp("x") / "prefixes.xlsx")
    yield book.add_worksheet()
    book.close()


def test_the_prefix_of_every_function_is_xlsxwriters(worksheet):
    """xlsxwriter, asked to prefix newer functions, stores each as the table says (but for
    two classic functions that the patterns of its earlier versions misread: their dot
    matches any character, so NORMSDIST( becomes _xlfn.NORM.DIST(; the writer never asks it
    to prefix)."""
    differ = {}
    for name, f in FUNCTIONS.items():
        got = worksheet._prepare_formula(f"={name}(1)", expand_future_functions=True)
        if got != f"{f.stored}(1)":
            differ[name] = got
    misread = {"NORMSDIST": "_xlfn.NORM.DIST(1)", "NORMSINV": "_xlfn.NORM.INV(1)"}
    assert differ.items() <= misread.items()
    assert stored("norm.dist") == "_xlfn.NORM.DIST"
    assert stored("FILTER") == "_xlfn._xlws.FILTER"


def test_the_dynamic_array_functions_are_xlsxwriters():
    from xlsxwriter import worksheet as xw

    if hasattr(xw, "FUTURE_FUNCTIONS"):  # a table of kinds (recent xlsxwriter)
        theirs = {n for n, kind in xw.FUTURE_FUNCTIONS.items() if kind > 0}
    else:  # a pattern (earlier versions)
        theirs = {n for n in FUNCTIONS if xw.re_dynamic_function.search(f"{n}(")}
    dynamic = {n for n, f in FUNCTIONS.items() if f.kind == "dynamic"}
    assert dynamic == theirs
    assert {"FILTER", "SEQUENCE", "XLOOKUP"} <= dynamic


def test_the_classic_functions_are_openpyxls_and_unprefixed(worksheet):
    assert set(FORMULAE) == CLASSIC
    for name in CLASSIC:  # the writer's shortcut relies on this
        assert worksheet._prepare_formula(f"={name}(1)") == f"{name}(1)"
    assert FUNCTIONS["NORM.DIST"].kind == "future" and "NORM.DIST" not in CLASSIC


def test_reserved_names_derive_from_the_table():
    for name in ("rate", "Phi", "delta", "norm", "T_TEST", "xlookup", "Print_Area", "AUTO_OPEN"):
        assert excel_names.needs_change(name) == (
            name.lower() in {n.lower() for n in FUNCTIONS} | {n.lower() for n in BUILTIN_NAMES}
        ), name
    assert excel_names.needs_change("rate") and excel_names.needs_change("Print_Titles")
    assert excel_names.needs_change("norm.dist")  # not a worksheet name, but reserved
    assert not excel_names.needs_change("rate2") and not excel_names.needs_change("Print_Area2")
    names = ExcelNames(["Auto_Open", "auto_open_", "Print_Area", "radius"])
    assert names.mapping == {
        "Auto_Open": "Auto_Open_2",
        "auto_open_": "auto_open_",
        "Print_Area": "Print_Area_",
        "radius": "radius",
    }
    assert "built-in name" in names.why("Print_Area")


SHEET = """
[sheet]
name = "reserved-names"

[inputs]
Auto_Open = "2 m"
Print_Area = "3 m"
Criteria = "4"
Database = "5"
rate = "0.5"
Sheet_Title = "7"

[definitions]
Extract = "Auto_Open*Print_Area*Criteria*Database*rate*Sheet_Title"
"""


def test_reserved_names_are_renamed_in_the_written_workbook(sheet_from, tmp_path):
    sheet = sheet_from(SHEET, name="reserved")
    out = tmp_path / "reserved.xlsx"
    sheet.write_xlsx(out)
    book = openpyxl.load_workbook(out)
    defined = set(book.defined_names)
    for name in ("Auto_Open", "Print_Area", "Criteria", "Database", "rate", "Sheet_Title"):
        assert name not in defined and f"{name}_" in defined, name
        assert "!" in book.defined_names[f"{name}_"].attr_text
    assert "Extract_" in defined and "Extract" not in defined
    formulas = [
        c.value
        for ws in book.worksheets
        for row in ws.iter_rows()
        for c in row
        if isinstance(c.value, str) and c.value.startswith("=")
    ]
    product = next(f for f in formulas if "Auto_Open_" in f)
    for name in ("Auto_Open", "Print_Area", "Criteria", "Database", "rate", "Sheet_Title"):
        assert re.search(rf"\b{name}_\b", product), product
    assert sheet.evaluate("Extract").to("m^2").magnitude == pytest.approx(2 * 3 * 4 * 5 * 0.5 * 7)
