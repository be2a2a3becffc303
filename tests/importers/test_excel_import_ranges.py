"""`workbook import`: ranges that hold texts beside numbers given to VBA, SUMIF by a text
criterion, MMULT in an array formula, and cells that read one cell of an array formula
(workbooks the tests build, with the values Excel would cache, computed here by hand)."""

from __future__ import annotations

import json
import math

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

xlsxwriter = pytest.importorskip("xlsxwriter")

from workbook.cli import main  # noqa: E402

MODULE = """Attribute VB_Name = "Loads"
Option Explicit

Function DeadLoad(loads As Range) As Double
    Dim i As Long, t As Double
    For i = 1 To loads.Rows.Count
        If loads(i, 2) = "D" Then t = t + loads(i, 1)
    Next i
    DeadLoad = t
End Function

Function Factored(loads As Range, combo As Range) As Double
    Dim i As Long, f As Double, t As Double
    For i = 1 To loads.Rows.Count
        Select Case loads(i, 2)
            Case Is = "D"
                f = combo(1, 1)
            Case Is = "L"
                f = combo(1, 2)
            Case Else
                f = 0
        End Select
        t = t + f * loads(i, 1)
    Next i
    Factored = t
End Function

Function Dens(x As Double) As Double
    Dim rho
    If x < 0 Then
        rho = CVErr(xlErrValue)
    Else
        rho = 2 * x
    End If
    Dens = rho + 1
End Function

Function Halve(x As Double) As Double
    Dim lo, hi, mid
    hi = x
    Do While Abs(hi - lo) > 0.5
        mid = (lo + hi) / 2
        hi = mid
    Loop
    Halve = hi
End Function

Function Coef(n As Long) As Double
    Dim c
    If n = 1 Then
        c = Array(1, 2, 3)
    Else
        c = Array(4, 5)
    End If
    Coef = c(UBound(c))
End Function

Function Doubled(loads As Range) As Double
    Doubled = loads(1, 2) * 2
End Function

Function Weighted(xs As Range) As Double
    Dim v() As Variant, i As Long, t As Double
    If xs.Rows.Count = 1 And xs.Columns.Count = 1 Then
        ReDim v(1 To 1) As Variant
        v(1) = xs.Cells(1, 1).Value
    Else
        v = Application.Transpose(xs)
    End If
    If xs.Columns.Count > xs.Rows.Count Then
        v = Application.Transpose(Application.Transpose(xs))
    End If
    For i = 1 To UBound(v)
        t = t + i * v(i)
    Next i
    Weighted = t
End Function
"""

LOADS = [(1.5, "D"), (2.0, "L"), (4.0, "d"), (3.0, "=B2")]  # B5 reads B2's text


def build(folder):
    path = folder / "loads.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("Loads")
    ws.write_row(0, 0, ["Load", "Kind", "", "Kind sought"])
    for i, (value, kind) in enumerate(LOADS, start=1):
        ws.write_number(i, 0, value)
        if kind.startswith("="):
            ws.write_formula(i, 1, kind, None, "D")
        else:
            ws.write_string(i, 1, kind)
    ws.write_string(1, 3, "D")  # D2: the criterion
    ws.write_row(0, 6, ["dead", "live"])
    ws.write_row(1, 6, [1.2, 1.6])  # G2:H2, the factors of one combination
    # VBA compares texts with their case (Option Compare Binary): "d" is not "D"
    ws.write_formula("E2", "=DeadLoad(A2:B5)", None, 1.5 + 3.0)
    ws.write_formula("E3", "=Factored(A2:B5,G2:H2)", None, 1.2 * (1.5 + 3.0) + 1.6 * 2.0)
    ws.write_formula("E4", "=Doubled(A2:B5)", None, "#VALUE!")
    # SUMIF compares texts without case: "d" is "D"
    ws.write_formula("E5", "=SUMIF(B2:B5,D2,A2:A5)", None, 1.5 + 4.0 + 3.0)
    # MMULT of [[1, 2], [3, 4]] by [5, 6] shown in E8:E9, and cells that read its cells
    for r, row in enumerate([[1, 2, 5], [3, 4, 6]], start=7):
        ws.write_row(r, 0, row)
    ws.write_array_formula("E8:E9", "{=MMULT(A8:B9,C8:C9)}", None, 17)
    ws.write_number("E9", 39)  # the cached value of the array formula's second cell
    ws.write_formula("F8", "=E9*2", None, 78)
    ws.write_formula("F9", "=MAX(E8,0)", None, 17)  # one cell, not the whole product
    ws.write_array_formula("G8:H9", "{=MINVERSE(A8:B9)}", None, -2)
    for cell, value in (("H8", 1), ("G9", 1.5), ("H9", -0.5)):
        ws.write_number(cell, value)
    ws.write_formula("E6", '=COUNTIF(A2:A5,"<3")', None, 2)  # 1.5 and 2
    ws.write_string("C11", "Shift")
    ws.write_number("D11", 2)
    ws.write_formula("E11", "=OFFSET(A2,D11,0)", None, 4.0)  # A4, where D11 is 2
    for r, (key, value) in enumerate([(10, 1), (20, 2), (30, 3), (40, 4)], start=12):
        ws.write_row(r, 0, [key, value])  # A13:B16
    ws.write_string("C13", "Size")
    ws.write_number("D13", 25)
    ws.write_formula("E13", "=VLOOKUP(D13,A13:B16,2)", None, 2)  # the last key <= 25
    ws.write_formula("E14", "=VLOOKUP(30,A13:B16,2,FALSE)", None, 3)
    ws.write_formula("E17", "=Dens(D11)", None, 5)
    ws.write_formula("E18", "=Dens(-1)", None, "#VALUE!")  # the error value in a local
    ws.write_formula("E19", "=Halve(8)", None, 0.5)  # lo is read while Empty: 0
    ws.write_formula("E20", "=Coef(1)", None, 3)  # arrays of two sizes in one local
    ws.write_formula("E21", "=Coef(2)", None, 5)
    # a column and a row made 1-D arrays by Application.Transpose, and one cell
    ws.write_formula("E22", "=Weighted(A2:A5)", None, 1.5 + 2 * 2.0 + 3 * 4.0 + 4 * 3.0)
    ws.write_formula("E23", "=Weighted(A8:C8)", None, 1 + 2 * 2 + 3 * 5)
    ws.write_formula("E24", "=Weighted(D13)", None, 25)
    wb.close()
    bas = folder / "Loads.bas"
    bas.write_text(MODULE, encoding="utf-8")
    return path, bas


@pytest.fixture(scope="module")
def imported(tmp_path_factory):
    folder = tmp_path_factory.mktemp("ranges")
    path, bas = build(folder)
    out = folder / "out"
    assert main(["import", str(path), "--vba", str(bas), "--out", str(out)]) == 0
    return out / "loads.toml"


def test_every_cached_number_is_reproduced(imported, capsys):
    capsys.readouterr()
    # exit 1: Dens(-1) has no value (a division by zero), as E18 holds #VALUE! in Excel
    assert main(["check", str(imported), "--json"]) == 1
    report = json.loads(capsys.readouterr().out)
    # E2, E3, E5, E6, E11, E13, E14, E17, E19 to E24, F8, F9, the two cells of the MMULT,
    # the four of the MINVERSE and B5's text; E4 and E18 show #VALUE! (not compared)
    assert {k: report[k] for k in ("printed", "reproduced", "failed", "not_computable")} == {
        "printed": 23,
        "reproduced": 23,
        "failed": 0,
        "not_computable": 0,
    }


def test_arithmetic_on_a_text_of_a_range_is_an_error(imported):
    import workbook

    sheet = workbook.load(str(imported))
    doubled = next(n for n, d in sheet.spec.definitions.items() if "Doubled(" in d.text)
    with pytest.raises(workbook.WorkbookError, match="arithmetic on the text 'D'"):
        sheet.evaluate(doubled)


def test_a_cell_of_an_array_formula_is_read_as_its_element(imported):
    text = imported.read_text(encoding="utf-8")
    assert "_at(1)*2" in text and "max(" in text and "_at(0), 0)" in text


def test_sumif_whose_criterion_is_a_pattern_is_listed(tmp_path):
    path = tmp_path / "pattern.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("Loads")
    for i, (value, kind) in enumerate([(1.0, "DL"), (2.0, "LL")]):
        ws.write_number(i, 0, value)
        ws.write_string(i, 1, kind)
    ws.write_string("D1", "D*")
    ws.write_formula("E1", "=SUMIF(B1:B2,D1,A1:A2)", None, 1.0)
    wb.close()
    out = tmp_path / "out"
    assert main(["import", str(path), "--out", str(out)]) == 0
    head = (out / "pattern.toml").read_text(encoding="utf-8").split("[sheet]")[0]
    assert "SUMIF whose criterion 'D*' is a pattern or an operator" in head


def test_offset_is_the_cell_it_reached_and_an_error_elsewhere(imported):
    import workbook

    sheet = workbook.load(str(imported))
    name = next(n for n, d in sheet.spec.definitions.items() if "OFFSET" in d.note)
    assert sheet.evaluate(name).magnitude == 4.0
    with pytest.raises(workbook.WorkbookError, match="not a finite number"):
        sheet.with_inputs(Shift=1).evaluate(name)  # Excel would show A3: never A4's number


def test_a_range_several_formulas_read_is_one_definition(imported):
    text = imported.read_text(encoding="utf-8")
    assert text.count("[definitions.range_Loads_A2_B5]") == 1
    assert text.count("range_Loads_A2_B5") == 4  # its definition and the three calls


def test_vlookup_is_guarded_by_its_keys_ascending(imported):
    import workbook

    sheet = workbook.load(str(imported))
    name = next(n for n, d in sheet.spec.definitions.items() if "VLOOKUP(D13" in d.note)
    assert sheet.evaluate(name).magnitude == 2
    assert sheet.with_inputs(Size=40).evaluate(name).magnitude == 4
    with pytest.raises(workbook.WorkbookError, match="not a finite number"):
        sheet.with_inputs(Size=5).evaluate(name)  # below the first key: #N/A in Excel
    key = next(n for n, i in sheet.spec.inputs.items() if "A14" in i.note)
    with pytest.raises(workbook.WorkbookError, match="not a finite number"):
        sheet.with_inputs(**{key: 35}).evaluate(name)  # keys not ascending: Excel's search


def test_an_error_value_in_a_local_gives_no_value(imported):
    import workbook

    sheet = workbook.load(str(imported))
    given = next(n for n, d in sheet.spec.definitions.items() if "=Dens(D11)" in d.note)
    failing = next(n for n, d in sheet.spec.definitions.items() if "=Dens(-1)" in d.note)
    assert sheet.evaluate(given).magnitude == 5
    with pytest.raises(workbook.WorkbookError, match="not a finite number"):
        sheet.evaluate(failing)  # Excel shows #VALUE!: VBA stops at the error value's use


@pytest.mark.slow
def test_a_date_or_a_text_with_a_quote_is_listed_never_a_stand_in(tmp_path, capsys):
    import datetime

    path = tmp_path / "odd.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("Odd")
    ws.write_datetime("A1", datetime.datetime(2024, 1, 31), wb.add_format({"num_format": "d"}))
    ws.write_formula("B1", "=A1+1", None, 45323)
    ws.write_string("A2", 'say "hi"')
    ws.write_formula("B2", '=IF(A2="x",1,2)', None, 2)
    ws.write_number("A3", 3)
    ws.write_formula("B3", "=A3*2", None, 6)
    wb.close()
    out = tmp_path / "out"
    assert main(["import", str(path), "--out", str(out)]) == 0
    text = (out / "odd.toml").read_text(encoding="utf-8")
    head = text.split("[sheet]")[0]
    assert "a datetime, not a number" in head and "a text with a quote" in head
    assert 'value = "0"' not in text and 'expr = "\\"\\""' not in text  # no stand-ins
    capsys.readouterr()
    main(["check", str(out / "odd.toml"), "--json"])
    report = json.loads(capsys.readouterr().out)
    # B3 reproduced; B1 and B2, not translated, are counted as not computable with the reason
    assert (report["printed"], report["reproduced"], report["failed"]) == (3, 1, 0)
    assert report["not_computable"] == 2


BOUNDS = """Attribute VB_Name = "Bounds"
Function First(v() As Variant) As Double
    First = v(1)
End Function

Function Second(v) As Double
    Second = v(2)
End Function

Function Mixed(v() As Variant) As Double
    Mixed = v(1)
End Function

Function FromOne(x As Double) As Double
    Dim a(1 To 3) As Variant
    a(1) = x
    a(2) = 2 * x
    a(3) = 3 * x
    FromOne = First(a) + 10 * Second(a) + 100 * Mixed(a)
End Function

Function FromZero(x As Double) As Double
    Dim b(2) As Variant
    b(0) = x
    b(1) = 2 * x
    b(2) = 3 * x
    FromZero = Mixed(b)
End Function

Function OnlyOne(x As Double) As Double
    Dim c(1 To 2) As Variant
    c(1) = x
    c(2) = 5 * x
    OnlyOne = First(c) + Second(c)
End Function
"""


def test_an_array_parameter_takes_the_lower_bound_its_callers_give(tmp_path, capsys):
    """VBA indexes an array argument by the bounds the caller gave it: v(1) of an array
    dimensioned (1 To 3) is its first element, of one dimensioned (2) its second. A
    parameter given arrays of one lower bound is indexed from it; one given arrays of
    different lower bounds (Mixed) is listed, never indexed from a guessed bound."""
    path = tmp_path / "bounds.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("B")
    ws.write_number("A1", 1.5)
    ws.write_formula("B1", "=OnlyOne(A1)", None, 1.5 + 7.5)  # c(1) + c(2)
    ws.write_formula("B2", "=FromOne(A1)", None, 1.5 + 10 * 3.0 + 100 * 1.5)
    ws.write_formula("B3", "=FromZero(A1)", None, 3.0)  # b(1) of b(0 To 2)
    wb.close()
    bas = tmp_path / "Bounds.bas"
    bas.write_text(BOUNDS, encoding="utf-8")
    out = tmp_path / "out"
    assert main(["import", str(path), "--vba", str(bas), "--out", str(out)]) == 0
    text = (out / "bounds.toml").read_text(encoding="utf-8")
    assert "the array parameter v is given arrays of different" in text.replace("\n# ", " ")
    capsys.readouterr()
    main(["check", str(out / "bounds.toml"), "--json"])
    report = json.loads(capsys.readouterr().out)
    # B1 reproduced; B2 and B3 call Mixed, not translated
    assert {k: report[k] for k in ("printed", "reproduced", "failed")} == {
        "printed": 3,
        "reproduced": 1,
        "failed": 0,
    }


@pytest.mark.slow
@settings(
    max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    base=st.integers(-2, 3),
    size=st.integers(1, 4),
    data=st.data(),
)
def test_array_bounds_across_calls_are_vbas(tmp_path_factory, base, size, data):
    """Random lower bounds and indices of an array one VBA function dimensions and another
    reads: the value is VBA's (element i of an array dimensioned base To base + size - 1)."""
    pick = data.draw(st.integers(base, base + size - 1))
    module = (
        'Attribute VB_Name = "Pick"\n'
        "Function Element(v() As Variant, i As Long) As Double\n"
        "    Element = v(i)\nEnd Function\n\n"
        "Function Make(x As Double, i As Long) As Double\n"
        f"    Dim a({base} To {base + size - 1}) As Variant, k As Long\n"
        f"    For k = {base} To {base + size - 1}\n"
        f"        a(k) = x * (k - ({base}) + 1)\n"
        "    Next k\n"
        "    Make = Element(a, i) + 1000 * LBound(a)\nEnd Function\n"
    )
    expected = 2.5 * (pick - base + 1) + 1000 * base
    folder = tmp_path_factory.mktemp("bounds")
    path = folder / "pick.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("P")
    ws.write_number("A1", 2.5)
    ws.write_number("A2", pick)
    ws.write_formula("B1", "=Make(A1,A2)", None, expected)
    wb.close()
    bas = folder / "Pick.bas"
    bas.write_text(module, encoding="utf-8")
    out = folder / "out"
    assert main(["import", str(path), "--vba", str(bas), "--out", str(out)]) == 0
    import workbook

    sheet = workbook.load(str(out / "pick.toml"))
    name = next(n for n, d in sheet.spec.definitions.items() if "=Make" in d.note)
    assert sheet.evaluate(name).magnitude == pytest.approx(expected, rel=1e-12)


def test_a_vba_local_named_as_a_filled_down_column_is_renamed(tmp_path, capsys):
    """A filled-down column named x (its header) and a VBA local x: the local is another
    name of the program, so both are computed."""
    path = tmp_path / "column.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("C")
    ws.write_string("A1", "x")
    for r in range(1, 4):
        ws.write_formula(r, 0, f"=B{r + 1}*2", None, 2.0 * r)
        ws.write_number(r, 1, r)
    ws.write_formula("C2", "=Shape(B2,B3)", None, 2.0 + math.log(0.5))
    wb.close()
    bas = tmp_path / "Shape.bas"
    bas.write_text(
        'Attribute VB_Name = "S"\nPublic Function Shape(ByVal w, ByVal l)\n'
        "x = Log(w / l)\nShape = x + 2\nEnd Function\n",
        encoding="utf-8",
    )
    out = tmp_path / "out"
    assert main(["import", str(path), "--vba", str(bas), "--out", str(out)]) == 0
    capsys.readouterr()
    main(["check", str(out / "column.toml"), "--json"])
    report = json.loads(capsys.readouterr().out)
    assert (report["printed"], report["reproduced"]) == (4, 4)


@pytest.mark.slow
@settings(
    max_examples=16, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    how=st.sampled_from(["ByVal ", "ByRef ", ""]),
    changes=st.booleans(),
    through=st.booleans(),
    passes=st.sampled_from(["y", "y + 0", "w(1)"]),
)
def test_arguments_passed_by_reference_are_never_a_wrong_number(
    tmp_path_factory, how, changes, through, passes
):
    """VBA passes a variable by reference unless the parameter is ByVal: a callee that
    changes its parameter (itself, or through another function it passes it on to) changes
    the caller's variable. Random such programs: the cell is VBA's value or not computable,
    never another number."""
    change = "    v = v * 3\n" if changes else ""
    inner = f"Function Inner({how}v As Double) As Double\n{change}    Inner = v + 1\nEnd Function\n"
    outer = (
        f"Function Outer({how}v As Double) As Double\n    Outer = Inner(v)\nEnd Function\n"
        if through
        else ""
    )
    called = "Outer" if through else "Inner"
    module = (
        'Attribute VB_Name = "R"\n' + inner + outer + "Function Caller(x As Double) As Double\n"
        "    Dim y As Double, z As Double, w(1 To 2) As Double\n"
        "    y = x\n    w(1) = x\n"
        f"    z = {called}({passes})\n"
        "    Caller = y + 10 * w(1) + 100 * z\nEnd Function\n"
    )
    x = 1.5
    by_ref = how != "ByVal " and passes != "y + 0"
    after = x * 3 if changes else x  # the callee's v after its change
    seen = after if by_ref else x  # what the caller's variable holds after the call
    y = seen if passes == "y" else x
    w1 = seen if passes == "w(1)" else x
    expected = y + 10 * w1 + 100 * (after + 1)
    folder = tmp_path_factory.mktemp("byref")
    path = folder / "r.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("R")
    ws.write_number("A1", x)
    ws.write_formula("B1", "=Caller(A1)", None, expected)
    wb.close()
    bas = folder / "R.bas"
    bas.write_text(module, encoding="utf-8")
    out = folder / "out"
    assert main(["import", str(path), "--vba", str(bas), "--out", str(out)]) == 0
    import contextlib
    import io

    with contextlib.redirect_stdout(io.StringIO()) as text:
        main(["check", str(out / "r.toml"), "--json"])
    report = json.loads(text.getvalue())
    assert report["failed"] == 0, (module, report["failures"])
    assert report["reproduced"] + report["not_computable"] == 1
    if not (changes and by_ref):  # nothing changes the caller's variable: translated
        assert report["reproduced"] == 1, module
    if passes == "y":  # z = Inner(y): y takes Inner's v after the call (Outer's, Inner's)
        assert report["reproduced"] == 1, module


def test_undeclared_variables_given_by_reference_take_the_values_the_callee_gives(tmp_path, capsys):
    """``State = SetTwo(x, A1, B1)`` with A1 and B1 never declared (Empty): SetTwo's values
    of its ByRef parameters are the caller's A1 and B1 after the call."""
    path = tmp_path / "outs.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("O")
    ws.write_number("A1", 1.5)
    ws.write_formula("B1", "=UseTwo(A1)", None, 3.0 + 10 * 4.5)
    wb.close()
    bas = tmp_path / "Outs.bas"
    bas.write_text(
        'Attribute VB_Name = "O"\n'
        "Private Function SetTwo(ByVal x, ByRef a, ByRef b) As Boolean\n"
        "    a = 2 * x\n    b = 3 * x\n    SetTwo = True\nEnd Function\n\n"
        "Function UseTwo(x)\n    State = SetTwo(x, A1, B1)\n    UseTwo = A1 + 10 * B1\n"
        "End Function\n",
        encoding="utf-8",
    )
    out = tmp_path / "out"
    assert main(["import", str(path), "--vba", str(bas), "--out", str(out)]) == 0
    text = (out / "outs.toml").read_text(encoding="utf-8")
    assert '"SetTwo_refs(x, a, b)"' in text
    capsys.readouterr()
    main(["check", str(out / "outs.toml"), "--json"])
    report = json.loads(capsys.readouterr().out)
    assert (report["printed"], report["reproduced"], report["failed"]) == (1, 1, 0)


def test_the_refs_program_gives_the_changed_parameters_at_every_exit():
    from workbook.excelimport.vba import Procedure
    from workbook.excelimport.vbaprogram import FunctionInfo
    from workbook.excelimport.vbarefs import refs_program

    proc = Procedure("Function", "G", "M", [], "Double", False, [])
    info = FunctionInfo(proc, "G", ["x", "a", "b"], refs=[1, 2])
    info.program = "\n".join(
        [
            "G_value := 0",
            "return 1/0 if flag != 0",
            "return (x if x > 0 otherwise -x)",
            "a := 2*x",
            "G_value",
        ]
    )
    assert refs_program(info).split("\n") == [
        "G_value := 0",
        "return [1/0, a, b] if flag != 0",
        "return [(x if x > 0 otherwise -x), a, b]",
        "a := 2*x",
        "[G_value, a, b]",
    ]
