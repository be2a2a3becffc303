"""Excel's own rules in imported cell formulas, each against the ``formulas`` package (an
independent Excel evaluator) recalculating a small workbook the test writes with openpyxl:
empty and text cells in SUM, AVERAGE, COUNT, MIN, MAX, STDEV; absolute and mixed references
under fill-down; defined names that are constants, ranges or formulas; DDE names refused."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

openpyxl = pytest.importorskip("openpyxl")
formulas = pytest.importorskip("formulas")


def _excel_values(path: Path) -> dict[tuple[str, str], object]:
    """{(sheet, A1): value} of every formula cell, as the formulas package computes them."""
    solution = formulas.ExcelModel().loads(str(path)).finish().calculate()
    out = {}
    for key, value in solution.items():
        m = re.fullmatch(r"'\[[^\]]+\]([^']+)'!([A-Z]+\d+)", str(key))
        if m:
            v = value.value[0, 0] if hasattr(value, "value") else value
            out[(m.group(1).upper(), m.group(2))] = v
    return out


def _engine_values(path: Path, tmp: Path) -> dict[tuple[str, str], float]:
    """{(sheet, A1): value} of every translated formula cell, as the engine computes it."""
    import workbook
    from workbook.excelimport.book import translate_book
    from workbook.excelimport.writer import write

    tr = translate_book(path, [])
    result = write(tr, tmp, force=True)
    sheet = workbook.load(str(result.toml))
    out = {}
    for d in tr.definitions:
        if d.problem:
            continue
        keys = d.run.keys() if d.run is not None else [(d.cell.sheet, d.cell.row, d.cell.col)]
        for k, (s, r, c) in enumerate(keys):
            from openpyxl.utils import get_column_letter

            try:
                q = sheet.evaluate(d.name, i_row=k) if d.run is not None else sheet.evaluate(d.name)
                value = float(q.magnitude)
            except workbook.WorkbookError:
                value = math.nan  # an error value
            out[(s.upper(), f"{get_column_letter(c)}{r}")] = value
    return out


def _compare(path: Path, tmp: Path, expected_cells: set[str]) -> None:
    excel = _excel_values(path)
    ours = _engine_values(path, tmp)
    assert expected_cells <= {a for _, a in ours}, sorted(expected_cells - {a for _, a in ours})
    for key, value in ours.items():
        want = excel[key]
        if isinstance(want, (int, float)) and not isinstance(want, bool):
            assert value == pytest.approx(float(want), rel=1e-12), key
        else:  # an Excel error value (#DIV/0!): the engine has no value either
            assert math.isnan(value), (key, want, value)


def test_lists_leave_out_empty_and_text_cells(tmp_path):
    wb = openpyxl.Workbook()
    ws = wb.active
    ws.title = "S"
    ws["A1"], ws["B1"], ws["C1"], ws["E1"] = 4, 6, "kN", 10  # D1 empty
    for col, fn in zip("FGHIJKLMN", ("AVERAGE", "SUM", "COUNT", "MIN", "MAX", "STDEV",
                                      "STDEVP", "VAR", "MEDIAN")):  # fmt: skip
        ws[f"{col}1"] = f"=1*{fn}(A1:E1)"
    ws["F2"] = "=AVERAGE(D1)"  # of nothing: #DIV/0!
    ws["G2"] = "=SUM(C1:D1)+MAX(C1:D1)"  # of nothing: 0
    ws["H2"] = "=AVERAGE(A1, D1, 2)"  # a single empty cell is left out too
    path = tmp_path / "lists.xlsx"
    wb.save(path)
    _compare(path, tmp_path / "out", {"F1", "G1", "H1", "K1", "N1", "F2", "G2", "H2"})


def test_fill_down_keeps_absolute_and_mixed_references(tmp_path):
    wb = openpyxl.Workbook()
    ws = wb.active
    ws.title = "S"
    for r in range(3, 8):
        ws[f"A{r}"] = r * 1.5
        ws[f"B{r}"] = f"=5*A{r}/SUM($A$3:$A$7)"
        ws[f"C{r}"] = f"=A{r}*$A$3+A$3-$A{r}"
    path = tmp_path / "fill.xlsx"
    wb.save(path)
    _compare(path, tmp_path / "out", {f"B{r}" for r in range(3, 8)} | {"C7"})


def test_defined_names_constants_ranges_and_formulas(tmp_path):
    from openpyxl.workbook.defined_name import DefinedName

    wb = openpyxl.Workbook()
    ws = wb.active
    ws.title = "S"
    ws["A3"], ws["A4"] = 4.5, 6
    for name, text in (("k", "0.25"), ("r", "S!$A$3"), ("f", "S!$A$4*2+k")):
        wb.defined_names[name] = DefinedName(name, attr_text=text)
    ws["D3"] = "=k*r+f"
    path = tmp_path / "names.xlsx"
    wb.save(path)
    _compare(path, tmp_path / "out", {"D3"})


def test_a_dde_name_is_listed_and_the_import_goes_on(tmp_path):
    from openpyxl.workbook.defined_name import DefinedName

    from workbook.cli import main

    wb = openpyxl.Workbook()
    ws = wb.active
    ws["A1"], ws["B1"] = 2, "=A1*3"
    wb.defined_names["evil"] = DefinedName("evil", attr_text="cmd|' /C calc'!A0")
    path = tmp_path / "dde.xlsx"
    wb.save(path)
    assert main(["import", str(path), "--out", str(tmp_path / "o")]) == 0
    toml = (tmp_path / "o" / "dde.toml").read_text()
    assert "the defined name evil: a DDE or external link" in toml
