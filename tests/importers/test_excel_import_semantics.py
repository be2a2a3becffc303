"""`workbook import`: Excel's own semantics where a translation could go wrong silently — a
spilled range (``C1#``, ``ANCHORARRAY``) is every cell of the array, a text the language
cannot hold is listed, and the CSV of cached texts follows the one rule of
``language.csvcells.csv_text`` (workbooks the tests build, with the values Excel would cache)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from helpers.excel_import import import_and_check

xlsxwriter = pytest.importorskip("xlsxwriter")

from workbook.cli import main  # noqa: E402
from workbook.excelimport.writer import csv_text, uncompared  # noqa: E402


@pytest.mark.slow
def test_a_spilled_range_is_every_cell_of_the_array(tmp_path, capsys):
    path = tmp_path / "spill.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("S")
    for r, row in enumerate([[1, 2, 5], [3, 4, -6]]):
        ws.write_row(r, 0, row)
    # [[1, 2], [3, 4]] * [5, -6] = [-7, -9], shown in E1:E2
    ws.write_array_formula("E1:E2", "{=MMULT(A1:B2,C1:C2)}", None, -7)
    ws.write_number("E2", -9)
    ws.write_formula("F1", "=MIN(_xlfn.ANCHORARRAY(E1))", None, -9)  # =MIN(E1#)
    ws.write_formula("F2", "=MAX(_xlfn.ANCHORARRAY(E1))", None, -7)
    wb.close()
    report, text = import_and_check(path, tmp_path, capsys)
    assert "ANCHORARRAY" in text
    assert (report["printed"], report["reproduced"], report["failed"]) == (4, 4, 0)


@pytest.mark.slow
def test_a_spilled_range_of_a_plain_cell_is_listed(tmp_path, capsys):
    path = tmp_path / "nospill.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("S")
    ws.write_number("A1", 3)
    ws.write_formula("B1", "=MIN(_xlfn.ANCHORARRAY(A1))", None, 3)
    wb.close()
    report, text = import_and_check(path, tmp_path, capsys)
    assert "the spilled range" in text and "no array formula" in text
    assert (report["printed"], report["failed"], report["not_computable"]) == (1, 0, 1)


@pytest.mark.slow
def test_a_text_with_a_caret_is_kept_as_it_is(tmp_path, capsys):
    path = tmp_path / "caret.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("S")
    ws.write_string("A1", "As (in^2)")
    ws.write_formula("B1", "=A1", None, "As (in^2)")
    ws.write_formula("B2", '="m^2"', None, "m^2")
    wb.close()
    report, text = import_and_check(path, tmp_path, capsys)
    assert (report["printed"], report["failed"], report["not_computable"]) == (2, 0, 0)


@pytest.mark.parametrize(
    ("text", "escaped"),
    [
        ("=cmd|' /C calc'!A0", True),
        ("-", True),  # Excel reads a cell that starts with - as a formula
        ("+5", True),
        (" @SUM(A1)", True),
        ("\tx", True),
        ("DL", False),
        ("5 - 3", False),
    ],
)
def test_cached_texts_follow_the_csv_rule_of_the_outputs(text, escaped):
    assert (csv_text(text) == "'" + text) is escaped
    # the reader of printed values takes the escape off ("+5" is not compared: a number's text)
    assert uncompared(text) is None or uncompared(text).endswith("reads as a number: not compared")


def test_a_cached_text_the_escape_would_not_give_back_is_not_compared():
    assert uncompared("'=x") is not None and uncompared("'x") is None


def test_a_cached_text_on_two_lines_is_one_csv_line():
    assert csv_text("a\nb") == "a b"
    assert uncompared("a\nb") is not None


@pytest.mark.slow
def test_texts_joined_as_excel_writes_them(tmp_path, capsys):
    path = tmp_path / "joins.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("J")
    ws.write_number("A1", 12.34567)
    ws.write_string("A2", "kips")
    ws.write_number("A3", 0.00001)
    ws.write_number("A4", 2)
    ws.write_formula("B1", '=ROUND(A1,2)&" "&A2', None, "12.35 kips")
    ws.write_formula("B2", '=IF(A4<>0,IF(A4=1," + "&A2," + "&A4&" "&A2),"")', None, " + 2 kips")
    ws.write_formula("B3", '=CONCATENATE("x = ",A1/3)', None, "x = 4.11522333333333")
    ws.write_formula("B4", '=_xlfn.CONCAT(A1:A2,C9,"!")', None, "12.34567kips!")  # C9 empty
    ws.write_formula("B5", '="d = "&A3', None, "d = 1E-05")  # Excel's exponent: refused
    ws.write_formula("B6", '="ok? "&(A4>1)', None, "ok? TRUE")  # TRUE/FALSE: refused
    ws.write_formula("B7", '="a"&CHAR(10)&"b"', None, "a\nb")  # a line break: refused
    ws.write_formula("B8", '=LEN(B1)&""', None, "10")  # LEN not mapped: refused
    wb.close()
    report, text = import_and_check(path, tmp_path, capsys)
    assert "concat(" in text and "num2str(" in text
    assert "joins TRUE/FALSE" in text and "CHAR(10)" in text
    # B1 to B4 reproduced (B2, " + 2 kips", escaped in the CSV and read back); B5 has no
    # value (Excel writes 1E-05, num2str another text); B6 to B8 listed
    assert (report["printed"], report["reproduced"], report["failed"]) == (8, 4, 0)
    assert report["not_computable"] == 4


def test_num2str_of_a_number_that_is_not_finite_has_no_text(tmp_path):
    import workbook

    path = tmp_path / "t.toml"
    path.write_text('[definitions.t]\nexpr = "concat(\\"x = \\", num2str(1/0))"\n')
    with pytest.raises(workbook.WorkbookError, match="not a finite number"):
        workbook.load(str(path)).evaluate("t")


@pytest.mark.slow
def test_match_index_and_hlookup_as_excel_finds_them(tmp_path, capsys):
    path = tmp_path / "lookups.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("L")
    for r, (key, name, value) in enumerate(
        [(10, "Steel", 1.5), (20, "Wood", 2.5), (30, "Ice", 3.5)]
    ):
        ws.write_row(r, 0, [key, name, value])  # A1:C3
    ws.write_row(4, 0, [3, 2, 1])  # A5:C5, descending
    ws.write_row(5, 0, [7, 8, 9])  # A6:C6
    ws.write_string("E1", "wood")
    ws.write_number("E2", 25)
    ws.write_formula("F1", "=MATCH(20,A1:A3,0)", None, 2)
    ws.write_formula("F2", "=MATCH(E2,A1:A3)", None, 2)  # the last key at most 25
    ws.write_formula("F3", "=MATCH(2.5,A5:C5,-1)", None, 1)  # the last key at least 2.5
    ws.write_formula("F4", "=MATCH(E1,B1:B3,0)", None, 2)  # texts without case
    ws.write_formula("F5", "=INDEX(C1:C3,MATCH(E2,A1:A3,1))", None, 2.5)
    ws.write_formula("F6", "=INDEX(A1:C3,3,2)", None, "Ice")
    ws.write_formula("F7", "=HLOOKUP(2,A5:C6,2,FALSE)", None, 8)
    ws.write_formula("F8", "=INDEX(C1:C3,MATCH(E1,B1:B3,0))", None, 2.5)
    ws.write_formula("F9", '=MATCH("W*",B1:B3,0)', None, 2)  # a pattern: listed
    ws.write_formula("F10", "=MATCH(F6,B1:B3,0)", None, 3)  # a text not known: listed
    wb.close()
    report, text = import_and_check(path, tmp_path, capsys)
    assert "a text with a pattern" in text and "an exact one of a text" in text
    assert (report["printed"], report["reproduced"], report["failed"]) == (10, 8, 0)
    import workbook

    sheet = workbook.load(str(next((tmp_path / "out").glob("*.toml"))))
    names = {d.note.split(": ", 1)[-1]: n for n, d in sheet.spec.definitions.items()}
    size = next(n for n, i in sheet.spec.inputs.items() if "E2" in i.note)
    for x, position in ((35, 3), (10, 1)):
        assert sheet.with_inputs(**{size: x}).evaluate(names["=MATCH(E2,A1:A3)"]).magnitude == (
            position
        )
    with pytest.raises(workbook.WorkbookError, match="not a finite number"):
        sheet.with_inputs(**{size: 5}).evaluate(names["=MATCH(E2,A1:A3)"])  # #N/A in Excel


@pytest.mark.slow
def test_offset_by_a_match_is_the_cell_each_key_reaches(tmp_path, capsys):
    path = tmp_path / "offset.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("O")
    for r, row in enumerate([(0, 0, 0), (3, 0.375, 0.11), (4, 0.5, 0.2), (5, 0.625, 0.31)]):
        ws.write_row(r, 0, row)  # A1:C4: bar sizes, diameters, areas
    ws.write_row(4, 0, ["p1", 1, 1])  # A5: a text key, which a number never equals
    ws.write_number("E1", 4)
    ws.write_formula("F1", "=OFFSET($A$1,MATCH(E1,$A$1:$A$5,0)-1,2)", None, 0.2)
    ws.write_formula("F2", "=OFFSET($A$1,1,MATCH(0.375,$A$2:$C$2,0)-1)", None, 0.375)
    ws.write_formula("F3", "=2*OFFSET($A$1,MATCH(E1,$A$1:$A$4)-1,1)", None, 1.0)
    wb.close()
    report, text = import_and_check(path, tmp_path, capsys)
    assert (report["printed"], report["reproduced"], report["failed"]) == (3, 3, 0)
    import workbook

    sheet = workbook.load(str(next((tmp_path / "out").glob("*.toml"))))
    names = {d.note.split(": ", 1)[-1]: n for n, d in sheet.spec.definitions.items()}
    size = next(n for n, i in sheet.spec.inputs.items() if "E1" in i.note)
    first = names["=OFFSET($A$1,MATCH(E1,$A$1:$A$5,0)-1,2)"]
    for bar, area in ((5, 0.31), (3, 0.11)):
        assert sheet.with_inputs(**{size: bar}).evaluate(first).magnitude == area
    with pytest.raises(workbook.WorkbookError, match="not a finite number"):
        sheet.with_inputs(**{size: 7}).evaluate(first)  # no such key: #N/A in Excel
    assert (
        sheet.with_inputs(**{size: 4.5})
        .evaluate(names["=2*OFFSET($A$1,MATCH(E1,$A$1:$A$4)-1,1)"])
        .magnitude
        == 1.0
    )


@pytest.mark.slow
def test_iferror_of_a_division_is_its_alternative_where_a_divisor_is_zero(tmp_path, capsys):
    path = tmp_path / "iferror.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("E")
    ws.write_row(0, 0, [6, 0, 3])  # A1:C1
    ws.write_formula("D1", "=IFERROR((A1/B1)*(C1-1),0)", None, 0)
    ws.write_formula("D2", "=IFERROR(A1/(C1-1),-1)", None, 3)
    ws.write_formula("D3", "=IFERROR(A1*C1,5)", None, 18)
    ws.write_formula("D4", "=IFERROR(SQRT(-A1),5)", None, 5)  # a root of a negative number
    ws.write_formula("D5", "=IFERROR(LN(B1)*2+C1^-1,7)", None, 7)  # a logarithm of 0
    ws.write_formula("D6", "=IFERROR(B1^0,9)", None, 9)  # 0^0 is #NUM! in Excel
    ws.write_formula("D7", "=IFERROR(ACOS(A1),5)", None, 5)  # an arc cosine beyond 1
    ws.write_formula("D8", "=IFERROR(ATAN(A1/B1)*180/PI(),0)", None, 0)
    ws.write_formula("D9", "=IFERROR(ASIN(C1/A1),5)", None, math.asin(0.5))
    ws.write_formula("D10", "=IFERROR(ATAN2(B1,B1),7)", None, 7)  # #DIV/0! at the origin
    ws.write_formula("D11", "=IFERROR(EXP(A1*200),1)", None, 1)  # beyond the largest number
    ws.write_formula("D12", "=IFERROR(SIN(C1)+COS(A1)+TAN(B1),2)", None, math.sin(3) + math.cos(6))
    ws.write_formula("D13", "=IFERROR(FACT(A1),5)", None, 720)  # other functions: listed
    wb.close()
    report, text = import_and_check(path, tmp_path, capsys)
    assert "the language has no error value to catch" in text.replace("\n# ", " ")
    assert (report["printed"], report["reproduced"], report["failed"]) == (13, 12, 0)
    import workbook

    sheet = workbook.load(str(next((tmp_path / "out").glob("*.toml"))))
    name = next(n for n, d in sheet.spec.definitions.items() if "=IFERROR((A1/B1)" in d.note)
    assert sheet.with_inputs(B1=2).evaluate(name).magnitude == 6.0
    name = next(n for n, d in sheet.spec.definitions.items() if "=IFERROR(LN(B1)" in d.note)
    expected = math.log(2) * 2 + 1 / 3
    assert sheet.with_inputs(B1=2).evaluate(name).magnitude == pytest.approx(expected)
    name = next(n for n, d in sheet.spec.definitions.items() if "=IFERROR(B1^0" in d.note)
    assert sheet.with_inputs(B1=2).evaluate(name).magnitude == 1.0
    name = next(n for n, d in sheet.spec.definitions.items() if "=IFERROR(ATAN(" in d.note)
    assert sheet.with_inputs(B1=6).evaluate(name).magnitude == pytest.approx(45.0)


SUB = """Attribute VB_Name = "Macros"
Sub Fill()
    Range("B2").Value = 5
    Sheets("S").Cells(3, 2) = 7
    If Range("B4") = 1 Then Range("C9") = 0
End Sub
"""


@pytest.mark.slow
def test_a_value_a_sub_writes_is_not_computable_with_the_sub_named(tmp_path, capsys):
    path = tmp_path / "macro.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("S")
    ws.write_number("A1", 1)
    ws.write_formula("B2", "=A1*2", None, 5)  # the Sub wrote 5 over the formula's 2
    ws.write_number("B3", 7)  # written by the Sub, read by a formula
    ws.write_formula("B4", "=A1", None, 1)  # compared in a condition, never written
    ws.write_formula("B5", "=B3+1", None, 8)
    wb.close()
    bas = tmp_path / "Macros.bas"
    bas.write_text(SUB, encoding="utf-8")
    out = tmp_path / "out"
    assert main(["import", str(path), "--vba", str(bas), "--out", str(out)]) == 0
    capsys.readouterr()
    main(["check", str(out / "macro.toml"), "--json"])
    report = json.loads(capsys.readouterr().out)
    text = (out / "macro.toml").read_text(encoding="utf-8")
    assert "written by the macro Sub Fill (its value is the macro's result" in text.replace(
        "\n# ", " "
    )
    assert "S!B3; written by the macro Sub Fill" in text
    assert (report["printed"], report["reproduced"], report["failed"]) == (3, 2, 0)
    assert report["not_computable"] == 1


_SPREAD = """
Function Spread(a As Double, b As Double) As Variant
    On Error GoTo fail
    Spread = Ratio(a, b)
    Exit Function
fail:
    If Err.Number = xlErrDiv0 Then
        Spread = 0
    Else
        Err.Raise Err.Number
    End If
End Function

Function Ratio(a As Double, b As Double) As Double
    If b = 0 Then Err.Raise {raised}
    Ratio = a / b
End Function
"""


@pytest.mark.parametrize(
    ("raised", "listed"),
    [("5", False), ("xlErrNA", False), ("Excel.xlErrDiv0", True), ("2007", True),
     ("vbObjectError + 7", True)],
)  # fmt: skip
def test_a_handler_branch_for_an_error_value_no_raise_gives_is_never_taken(raised, listed):
    from workbook.excelimport.book import translate_vba

    info = translate_vba(_SPREAD.format(raised=raised))["Spread"]
    assert (info.problem is not None) == listed
    if listed:
        assert "does more than give an error value" in info.problem


@pytest.mark.slow
def test_a_lookup_that_finds_no_key_is_the_alternative_of_iferror(tmp_path, capsys):
    path = tmp_path / "miss.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("M")
    for r, (key, value) in enumerate([(10, 1.5), (20, 2.5), (30, 3.5), ("x", 9.0)]):
        ws.write_row(r, 0, [key, value])  # A1:B4
    ws.write_number("D1", 20)
    ws.write_number("D2", 25)
    ws.write_formula("E1", "=IFERROR(VLOOKUP(D1,$A$1:$B$4,2,FALSE),-1)", None, 2.5)
    ws.write_formula("E2", "=IFERROR(VLOOKUP(D2,$A$1:$B$4,2,FALSE),-1)", None, -1)
    ws.write_formula("E3", "=IF(ISERROR(MATCH(D2,A1:A4,0)),0,MATCH(D2,A1:A4,0))", None, 0)
    ws.write_formula("E4", '=IFERROR(VLOOKUP("x",$A$1:$B$4,2,FALSE),0)', None, 9)
    ws.write_formula("E5", "=IFERROR(VLOOKUP(D1,$A$1:$B$4,2,TRUE),0)", None, 2.5)  # listed
    ws.write_formula("E6", "=IF(ISERR(VLOOKUP(D2,$A$1:$B$4,2,FALSE)),1,0)", None, 0)  # listed
    wb.close()
    report, text = import_and_check(path, tmp_path, capsys)
    # E1 to E4 reproduced; E5 (an approximate lookup) and E6 (ISERR: #N/A is none) listed
    assert (report["printed"], report["reproduced"], report["failed"]) == (6, 4, 0)
    import workbook

    sheet = workbook.load(str(next((tmp_path / "out").glob("*.toml"))))
    names = {d.note.split(": ", 1)[0].split("!")[-1]: n for n, d in sheet.spec.definitions.items()}
    d2 = next(n for n, i in sheet.spec.inputs.items() if i.note.endswith("D2"))
    assert sheet.with_inputs(**{d2: 30}).evaluate(names["E2"]).magnitude == 3.5
    assert sheet.with_inputs(**{d2: 30}).evaluate(names["E3"]).magnitude == 3


@pytest.mark.slow
def test_an_aggregate_of_if_in_an_array_formula_leaves_out_the_false_elements(tmp_path, capsys):
    formulas = pytest.importorskip("formulas")
    path = tmp_path / "select.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("A")
    values = [3.0, -1.0, 0.5, 7.0, -4.0]
    ws.write_column("A1", values)
    ws.write_column("B1", [1, 0, 1, 1, 0])
    ws.write_number("D1", 10)
    cases = {
        "C1": "{=D1-MIN(IF(A1:A5>0,A1:A5))}",
        "C2": "{=MAX(IF(B1:B5=0,A1:A5))}",
        "C3": "{=SUM(IF(A1:A5>1,A1:A5))}",
        "C4": "{=AVERAGE(IF(B1:B5=1,A1:A5))}",
        "C5": "{=COUNT(IF(A1:A5<0,A1:A5))}",
        "C6": "{=MIN(IF(A1:A5>100,A1:A5))}",  # none selected: 0
    }
    expected = {}
    for cell, formula in cases.items():
        fn = formulas.Parser().ast(formula[1:-1])[1].compile()
        inputs = {
            "A1:A5": np.array([[v] for v in values]),
            "B1:B5": np.array([[v] for v in [1, 0, 1, 1, 0]]),
            "D1": np.array([[10.0]]),
        }
        expected[cell] = float(np.asarray(fn(*[inputs[k] for k in fn.inputs])).ravel()[0])
        ws.write_array_formula(f"{cell}:{cell}", formula, None, expected[cell])
    wb.close()
    assert expected == {"C1": 9.5, "C2": -1.0, "C3": 10.0, "C4": 3.5, "C5": 2.0, "C6": 0.0}
    report, text = import_and_check(path, tmp_path, capsys)
    assert (report["printed"], report["reproduced"], report["failed"]) == (6, 6, 0)
    import workbook

    sheet = workbook.load(str(next((tmp_path / "out").glob("*.toml"))))
    first = next(n for n, i in sheet.spec.inputs.items() if i.note.endswith("A1"))
    names = {d.note.split(": ", 1)[0].split("!")[-1]: n for n, d in sheet.spec.definitions.items()}
    assert sheet.with_inputs(**{first: 0.25}).evaluate(names["C1"]).magnitude == 9.75
