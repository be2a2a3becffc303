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


@pytest.mark.slow  # the formulas package takes seconds to load
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


@pytest.mark.slow  # the formulas package takes seconds to load
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


@pytest.mark.slow  # the formulas package takes seconds to load
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


@pytest.mark.slow
def test_average_of_a_row_with_empty_and_text_cells_is_checked(tmp_path, capsys):
    """The same rule, fast: Excel's cached values (written as Excel computes them: the mean
    of the numbers only) are reproduced by the imported sheet."""
    xlsxwriter = pytest.importorskip("xlsxwriter")
    from workbook.cli import main

    path = tmp_path / "avg.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("S")
    row = [4, None, "n/a", 10, None, 7]
    for k, v in enumerate(row):
        if v is not None:
            ws.write(0, k, v)
    numbers = [v for v in row if isinstance(v, int)]
    ws.write_formula("H1", "=AVERAGE(A1:F1)", None, sum(numbers) / len(numbers))
    ws.write_formula("I1", "=COUNT(A1:F1)+MIN(A1:F1)", None, len(numbers) + min(numbers))
    for r in range(2, 6):
        ws.write(r, 0, r * 1.5)
        ws.write_formula(r, 1, f"=5*A{r + 1}/SUM($A$3:$A$6)", None, 5 * r / sum(range(2, 6)))
    wb.close()
    assert main(["import", str(path), "--out", str(tmp_path / "o")]) == 0
    code, report = _check(tmp_path / "o" / "avg.toml", capsys)
    assert (code, report["printed"], report["reproduced"]) == (0, 6, 6)


def _check(toml: Path, capsys) -> tuple[int, dict]:
    import json

    from workbook.cli import main

    capsys.readouterr()
    code = main(["check", str(toml), "--json"])
    return code, json.loads(capsys.readouterr().out)


@pytest.mark.slow
def test_a_cached_text_that_reads_as_a_formula_is_escaped(tmp_path, capsys):
    xlsxwriter = pytest.importorskip("xlsxwriter")
    from workbook.cli import main

    path = tmp_path / "evil.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("S")
    ws.write("A1", 2)
    ws.write_formula("B1", '=IF(A1>1,"=cmd| /C calc!A0","y")', None, "=cmd| /C calc!A0")
    ws.write_formula("B4", '=IF(A1>1,"x","y")', None, "'=x")  # an apostrophe: not compared
    ws.write_formula("B5", "=A1*4", None, "=A1*4")  # its own formula: saved uncomputed
    ws.write_formula("B2", "=A1*3", None, 6)
    ws.write_formula("B3", '=CONVERT(A1,"m","ft")', None, "+cmd|' /C calc'!A0")
    wb.close()
    assert main(["import", str(path), "--out", str(tmp_path / "o")]) == 0
    texts = "".join(p.read_text() for p in (tmp_path / "o").glob("*.csv"))
    assert "=cmd" in texts  # written, escaped
    for line in texts.splitlines():
        for cell in line.split(","):
            assert not cell.startswith(("=", "+", "-", "@")), line
    code, report = _check(tmp_path / "o" / "evil.toml", capsys)
    # B1 (its text escaped in the CSV, read back without the escape) and B2 reproduced; B3
    # failed (the formula gives a number, its cached value is a text); B4 (a text the escape
    # would not give back) and B5 (its cached value is its own formula) not computable
    assert (report["printed"], report["reproduced"], report["failed"]) == (5, 2, 1)
    assert any("own formula" in f["name"] for f in report["failures"])
    assert code == 1
    assert any("apostrophe" in f["name"] for f in report["failures"])


@pytest.mark.slow
def test_a_difference_of_nearly_equal_numbers_has_their_tolerance(tmp_path, capsys):
    xlsxwriter = pytest.importorskip("xlsxwriter")
    from workbook.cli import main

    path = tmp_path / "cancel.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("S")
    ws.write("A1", 12345678.9)
    ws.write("A2", 0.1)
    ws.write_formula("B1", "=A1+A2", None, 12345679.0)
    # Excel shows 0 where the subtraction cancels; the engine gives about 1.9e-9
    ws.write_formula("C1", "=B1-A1-A2", None, 0)
    ws.write_formula("C2", "=A2*2", None, 0.2000001)  # a wrong cached value stays wrong
    wb.close()
    assert main(["import", str(path), "--out", str(tmp_path / "o")]) == 0
    assert (tmp_path / "o" / "cancel.excel.cancel-e8.csv").is_file()
    code, report = _check(tmp_path / "o" / "cancel.toml", capsys)
    assert (report["printed"], report["reproduced"], report["failed"]) == (3, 2, 1)
    assert [f["name"] for f in report["failures"]] == ["C2"]


@pytest.mark.slow
def test_the_inverse_of_a_matrix_of_cancelling_cells_carries_their_error(tmp_path):
    """MINVERSE's elements carry |A^-1| size(A) |A^-1|: a matrix whose element is a
    difference of nearly equal numbers (a finite difference) gives an inverse whose cached
    elements are compared with that tolerance, not their own size's."""
    xlsxwriter = pytest.importorskip("xlsxwriter")
    import numpy as np

    from workbook.excelimport.cancellation import decade
    from workbook.excelimport.reader import read_book

    path = tmp_path / "inverse.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("S")
    ws.write_row("D1", [12345678.9, 12345678.5])
    a = np.array([[2.0, 1.0], [1.0, 0.4000000008]])  # B2 = D1 - E1, cached 0.4000000008
    ws.write_row("A1", a[0])
    ws.write("A2", 1.0)
    ws.write_formula("B2", "=D1-E1", None, a[1, 1])
    inverse = np.linalg.inv(a)
    ws.write_array_formula("A4:B5", "{=MINVERSE(A1:B2)}", None, inverse[0, 0])
    wb.close()
    book = read_book(path)
    assert decade(book, "S!B2", a[1, 1]) == 8  # made of numbers of 1.2e7
    own = [decade(book, f"S!{c}", v) for c, v in zip(("A4", "B5"), inverse.diagonal())]
    # |A^-1[i, 1]| * 2.5e7 * |A^-1[1, j]| against elements of size 2 to 10
    sizes = np.abs(inverse)[:, [1]] * 2.47e7 * np.abs(inverse)[[1], :]
    assert own == [int(np.ceil(np.log10(sizes[k, k]))) for k in (0, 1)]


def test_vba_functions_of_thisworkbook_and_what_is_refused():
    from workbook.excelimport.book import translate_vba

    host = (
        'Attribute VB_Name = "ThisWorkbook"\n'
        'Attribute VB_Base = "0{00020819-0000-0000-C000-000000000046}"\n'
    )
    found = translate_vba(
        host + "Public Function Twice(x As Double) As Double\n    Twice = 2 * x\nEnd Function\n",
        "ThisWorkbook",
    )
    assert found["Twice"].problem is None
    found = translate_vba(
        "Function Angle(x As Double, y As Double) As Double\n"
        "    Angle = ThisWorkbook.Application.WorksheetFunction.Atan2(x, y)\nEnd Function\n"
    )
    assert found["Angle"].problem is None  # ThisWorkbook's Application is the Application
    found = translate_vba(
        "Private calls As Long\n\nSub Reset()\n    calls = 0\nEnd Sub\n\n"
        "Function Counted(x As Double) As Double\n    calls = calls + 1\n    Counted = x * calls\n"
        "End Function\n\nFunction Ratio(a As Double, b As Double) As Double\n"
        "    On Error GoTo fail\n    Ratio = a / b\n    Exit Function\nfail:\n    Ratio = 0\n"
        "End Function\n"
    )
    assert "module variable calls, which Reset gives a value" in found["Counted"].problem
    assert "the error path does more than give an error value" in found["Ratio"].problem


@pytest.mark.slow
def test_paramarray_and_a_call_with_too_many_arguments(tmp_path, capsys):
    xlsxwriter = pytest.importorskip("xlsxwriter")
    from workbook.cli import main

    wb = xlsxwriter.Workbook(str(tmp_path / "pa.xlsx"))
    ws = wb.add_worksheet("S")
    ws.write("A1", 2)
    ws.write("A2", 3)
    ws.write_formula("B1", "=Total(10, A1, A2, 4)", None, 10 * (2 + 3 + 4))
    ws.write_formula("B2", "=Total(1, A1)", None, 2)
    ws.write_formula("B3", "=Pair(A1, A2, 5)", None, "#VALUE!")  # one argument too many
    ws.write_formula("B4", "=B3+1", None, "#VALUE!")
    wb.close()
    (tmp_path / "m.bas").write_text(
        'Attribute VB_Name = "M"\n'
        "Function Total(k As Double, ParamArray xs() As Variant) As Double\n"
        "    Dim i As Long, t As Double\n"
        "    For i = LBound(xs) To UBound(xs)\n        t = t + xs(i)\n    Next i\n"
        "    Total = k * t\nEnd Function\n\n"
        "Function Pair(a As Double, b As Double) As Double\n    Pair = a + b\nEnd Function\n"
    )
    out = tmp_path / "o"
    assert main(["import", str(tmp_path / "pa.xlsx"), "--vba", str(tmp_path / "m.bas"),
                 "--out", str(out)]) == 0  # fmt: skip
    assert "Not translated" not in (out / "pa.toml").read_text()
    code, report = _check(out / "pa.toml", capsys)
    assert (report["printed"], report["reproduced"]) == (2, 2)
    assert code == 1  # B3 and B4 have no value, as Excel shows #VALUE!


@pytest.mark.slow
def test_a_sheet_whose_name_starts_with_a_digit(tmp_path):
    xlsxwriter = pytest.importorskip("xlsxwriter")
    from workbook.cli import main

    wb = xlsxwriter.Workbook(str(tmp_path / "digits.xlsx"))
    first, second = wb.add_worksheet("3Stage"), wb.add_worksheet("Länge")
    first.write("A1", 2)
    first.write_formula("B1", "=A1*2", None, 4)
    second.write_formula("A1", "='3Stage'!B1+1", None, 5)
    second.write_formula("A2", "=SUM('3Stage'!A1:B1)", None, 6)
    wb.close()
    assert main(["import", str(tmp_path / "digits.xlsx"), "--out", str(tmp_path / "o")]) == 0
    assert main(["check", str(tmp_path / "o" / "digits.toml")]) == 0
