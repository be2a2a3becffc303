"""`workbook import`: Excel tables' structured references, CONVERT, and texts beside numbers
(comparisons and IF by Excel's rules) — workbooks the tests build with xlsxwriter, their cached
values as Excel computes them."""

from __future__ import annotations

import pytest
from helpers.excel_import import import_and_check

xlsxwriter = pytest.importorskip("xlsxwriter")

from workbook.excelimport.convert import convert  # noqa: E402
from workbook.excelimport.formula_terms import FormulaProblem  # noqa: E402
from workbook.excelimport.tables import StructuredProblem, Table, rewrite  # noqa: E402

LOADS = Table("Loads", "S", 2, 2, 6, 5, 1, 1, ("Span (m)", "w'k", "M", "Size "))


@pytest.mark.parametrize(
    ("formula", "row", "a1"),
    [
        ("Loads[[#This Row],[Span (m)]]*2", 4, "$B4*2"),
        ("SUM(Loads[M])", 9, "SUM($D$3:$D$5)"),
        ("SUM(loads[m])", 9, "SUM($D$3:$D$5)"),  # without case, as Excel
        ("Loads[@[w''k]]", 3, "$C3"),  # ' escapes ' in a column name
        ("SUM(Loads[[#Headers],[Span (m)]:[M]])", 9, "SUM($B$2:$D$2)"),
        ("SUM(Loads[[#Data],[#Totals],[M]])", 9, "SUM($D$3:$D$6)"),
        ("Loads[[#Totals],[M]]", 9, "$D$6"),
        ("SUM(Loads[#All])", 9, "SUM($B$2:$E$6)"),
        ("Loads[Size ]", 9, "$E$3:$E$5"),  # a name's own spaces are kept
        ("Loads[[#This Row], [Size ]]", 4, "$E4"),
        ('"Loads[M]"&Loads[[#This Row],[M]]', 5, '"Loads[M]"&$D5'),  # never inside a text
    ],
)
def test_structured_references_are_the_cells_excel_means(formula, row, a1):
    assert rewrite(formula, "S", row, {"loads": LOADS}) == a1


def test_a_structured_reference_not_read_with_certainty_is_refused():
    with pytest.raises(StructuredProblem, match="no column"):
        rewrite("Loads[Width]", "S", 3, {"loads": LOADS})
    with pytest.raises(StructuredProblem, match="outside its data"):
        rewrite("Loads[[#This Row],[M]]", "S", 9, {"loads": LOADS})  # implicit intersection
    assert rewrite("Other[M]", "S", 3, {"loads": LOADS}) == "Other[M]"  # no such table


def test_another_sheets_table_is_read_with_its_sheet():
    assert rewrite("SUM(Loads[M])", "T", 1, {"loads": LOADS}) == "SUM('S'!$D$3:$D$5)"


@pytest.mark.parametrize(
    ("source", "target", "x", "value"),
    [
        ("in", "mm", 2.5, 63.5),
        ("ft", "m", 1.0, 0.3048),
        ("lbm", "kg", 1.0, 0.45359237),
        ("psi", "kPa", 1.0, 6.894757293168361),
        ("cm2", "m2", 3.0, 3e-4),
        ("gal", "L", 1.0, 3.785411784),
        ("C", "F", 100.0, 212.0),
        ("F", "C", -40.0, -40.0),
        ("kel", "cel", 0.0, -273.15),
        ("hr", "sec", 2.0, 7200.0),
        ("HP", "kW", 1.0, 0.7456998715822702),
    ],
)
def test_convert_has_excels_factors(source, target, x, value):
    assert eval(convert(repr(x), source, target).replace("^", "**")) == pytest.approx(value, 1e-12)


@pytest.mark.parametrize(
    ("source", "target"),
    [("mmHg", "Pa"), ("m", "kg"), ("C", "m"), ("Km", "m"), ("kin", "m"), ("bar", "Pa")],
)
def test_convert_refuses_what_it_does_not_know_or_excel_refuses(source, target):
    with pytest.raises(FormulaProblem):
        convert("1", source, target)


@pytest.mark.slow
def test_a_table_read_by_its_columns(tmp_path, capsys):
    path = tmp_path / "table.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("S")
    data = [[1, 2], [3, 4], [5, 6]]
    columns = [{"header": "Span (m)"}, {"header": "w'k"}, {"header": "M"}]
    ws.add_table("B2:D5", {"name": "Loads", "data": data, "columns": columns})
    for r, (a, b) in enumerate(data):
        ws.write_formula(2 + r, 3, "=Loads[@[Span (m)]]*Loads[@[w''k]]^2", None, a * b * b)
    ws.write_formula("F2", "=SUM(Loads[M])", None, 4 + 48 + 180)
    ws.write_formula("F3", "=SUM(Loads)", None, 1 + 2 + 4 + 3 + 4 + 48 + 5 + 6 + 180)
    ws.write_formula("F4", '=CONVERT(SUM(Loads[[#Data],[M]])/232,"ft","in")', None, 12)
    ws.write_formula("F5", "=Loads[[#Totals],[M]]+1", None, 1)  # the table has no totals row
    wb.close()
    report, text = import_and_check(path, tmp_path, capsys)
    assert "SUM($D$3:$D$5)" in text
    assert (report["printed"], report["reproduced"], report["failed"]) == (7, 6, 0)


@pytest.mark.slow
def test_texts_beside_numbers_by_excels_rules(tmp_path, capsys):
    path = tmp_path / "kinds.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("S")
    ws.write("A1", 2.5)
    ws.write("A2", "Steel")  # A3 is empty
    ws.write_formula("B2", '=IF(A1="","",A1*2)', None, 5)  # a number is never ""
    ws.write_formula("B3", '=IF(A2="steel",1,0)', None, 1)  # texts equal without case
    ws.write_formula("B4", '=IF(A1<"a",7,8)', None, 7)  # a number orders before a text
    ws.write_formula("B5", '=IF(A1=0,"-",A1-1)', None, 1.5)  # the number's branch
    ws.write_formula("B6", '=IF(A1>2,"big",A1)', None, "big")  # the text's branch
    ws.write_formula("B7", '=A3=""', None, True)  # an empty cell equals ""
    ws.write_formula("B8", '=IF(A2="STEEL",A1,0)*2', None, 5)
    ws.write_formula("B9", '=IF(A2&""="steel",1,0)', None, 1)  # a computed text: listed
    wb.close()
    report, text = import_and_check(path, tmp_path, capsys)
    assert "A1*0 == 1" in text and "num2str(1/0)" in text
    assert "does not tell case apart" in text
    assert (report["printed"], report["reproduced"], report["failed"]) == (8, 7, 0)


@pytest.mark.slow
def test_an_if_of_two_kinds_whose_rows_differ_is_listed(tmp_path, capsys):
    path = tmp_path / "rows.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("S")
    for r, x in enumerate([1, 0, 2, 3]):
        ws.write(r, 0, x)
        ws.write_formula(r, 1, f'=IF(A{r + 1}=0,"-",10/A{r + 1})', None, "-" if x == 0 else 10 / x)
    wb.close()
    report, text = import_and_check(path, tmp_path, capsys)
    assert report["failed"] == 0
    assert report["reproduced"] + report["not_computable"] == 4


@pytest.mark.slow
def test_texts_a_formula_can_give_are_compared_without_case(tmp_path, capsys):
    path = tmp_path / "regime.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("S")
    ws.write_column("A1", [2000, 9000])  # Reynolds numbers; A3 is empty
    for r, re_ in enumerate([2000, 9000]):
        n = r + 1
        regime = "TURBULENT" if re_ > 4000 else "LAMINAR"
        ws.write_formula(f"B{n}", f'=IF(A{n}>4000,"TURBULENT","LAMINAR")', None, regime)
        f = 16 / re_ if regime == "LAMINAR" else "n/a"
        ws.write_formula(f"C{n}", f'=IF(B{n}="laminar",16/A{n},"n/a")', None, f)
        ws.write_formula(f"D{n}", f'=IF(B{n}<>"Laminar",1,2)', None, 2 if f != "n/a" else 1)
        ws.write_formula(f"E{n}", f'=IF(B{n}="transition",1,2)', None, 2)
    ws.write_formula("B3", '=IF(A3="","",A3*2)', None, "")  # Excel caches ""
    ws.write_formula("C3", '=IF(B3="",0,IF(A1=0,0,A1*3))', None, 0)  # a nested IF
    ws.write_formula("D3", '=IF(A1="","",IF(A1>0,A1*3,0))', None, 6000)
    wb.close()
    report, text = import_and_check(path, tmp_path, capsys)
    assert 'B1 == \\"LAMINAR\\"' in text
    assert (report["printed"], report["reproduced"], report["failed"]) == (10, 10, 0)


@pytest.mark.slow
def test_lookups_of_texts_that_never_change_are_the_cells_excel_finds(tmp_path, capsys):
    path = tmp_path / "species.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("S")
    ws.write_row("A1", ["(SPECIES)", "(MW)", "(TC, K)"])
    rows = [["CH4(g)", 16.04, 190.6], ["C2H6(g)", 30.07, 305.3]] + [
        [f"X{i}", i, i] for i in range(300)
    ]
    for r, row in enumerate(rows):
        ws.write_row(r + 1, 0, row)
    n = len(rows) + 1
    ws.write("E1", "c2h6(G)")  # Excel compares texts without case
    ws.write("F1", "(tc, k)")
    ws.write_formula("G1", f"=VLOOKUP(E1,A2:C{n},MATCH(F1,A1:C1,0),0)", None, 305.3)
    ws.write_formula("G2", f'=2*VLOOKUP("CH4(g)",A2:C{n},2,FALSE)', None, 32.08)
    ws.write_formula("G3", '=HLOOKUP(F1,A1:C3,MATCH("c2h6(g)",A1:A3,0),0)', None, 305.3)
    ws.write_formula("G4", '=VLOOKUP(E1&"",A2:C3,MATCH(F1&"",A1:C1,0),0)', None, 305.3)
    wb.close()
    report, text = import_and_check(path, tmp_path, capsys)
    assert (report["printed"], report["reproduced"], report["failed"]) == (4, 3, 0)
    import workbook

    sheet = workbook.load(str(next((tmp_path / "out").glob("*.toml"))))
    name = next(n for n, d in sheet.spec.definitions.items() if "=VLOOKUP(E1,A2" in d.note)
    assert sheet.with_inputs(C3=300).evaluate(name).magnitude == 300  # the cell stays live


@pytest.mark.slow
def test_sumproduct_reads_texts_and_empty_cells_as_excel_does(tmp_path, capsys):
    path = tmp_path / "sumproduct.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("S")
    ws.write_column("A1", [2, "n/a", 4, 5])  # A2 is a text
    ws.write_column("B1", [10, 20, 30])  # B4 is empty
    ws.write_formula("C1", "=A1*3", None, 6)
    ws.write_formula("D1", "=SUMPRODUCT(A1:A4,B1:B4)", None, 140)  # 2*10 + 0 + 4*30 + 0
    ws.write_formula("D2", "=SUMPRODUCT(C1:C1,B1:B1)*2", None, 120)
    ws.write_formula("D3", "=SUMPRODUCT(A1:A4,B1:B3)", None, "#VALUE!")
    ws.write_formula("D4", "=SUMPRODUCT(A1:A3)", None, 6)
    wb.close()
    report, text = import_and_check(path, tmp_path, capsys)
    assert "different sizes" in text
    assert (report["printed"], report["reproduced"], report["failed"]) == (4, 4, 0)
    import workbook

    sheet = workbook.load(str(next((tmp_path / "out").glob("*.toml"))))
    name = next(
        n for n, d in sheet.spec.definitions.items() if "=SUMPRODUCT(A1:A4,B1:B4)" in d.note
    )
    inputs = {n for n in sheet.spec.inputs}
    empty = next(n for n in inputs if "B4" in sheet.spec.inputs[n].note)
    assert sheet.with_inputs(**{empty: 2}).evaluate(name).magnitude == 150


@pytest.mark.slow
def test_a_text_in_arithmetic_is_an_error_value_where_its_branch_is_not_taken(tmp_path, capsys):
    path = tmp_path / "blank.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("S")
    ws.write_column("A1", [2])  # A2 is empty
    ws.write_formula("B1", '=IF(A1="","",A1*3)', None, 6)
    ws.write_formula("B2", '=IF(A2="","",A2*3)', None, "")  # Excel caches ""
    ws.write_formula("C1", "=IF(A2=0,0,B1/B2)", None, 0)  # B2 is "" where it is read
    ws.write_formula("C2", "=B2*2", None, "#VALUE!")
    ws.write("A4", "x5")
    ws.write_formula("C4", "=IF(A1>1,1,A4*2)", None, 1)  # a text with a digit: refused
    wb.close()
    report, text = import_and_check(path, tmp_path, capsys)
    assert "(0 if A2 == 0 otherwise B1/(1/0))" not in text  # the whole division is the error
    assert "otherwise (1/0))" in text
    assert (report["printed"], report["reproduced"], report["failed"]) == (3, 2, 0)


@pytest.mark.slow
def test_a_remainder_that_rounds_to_the_divisor_has_no_value(tmp_path, capsys):
    import math

    path = tmp_path / "mod.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("S")
    ws.write_column("A1", [93.21687266652779, -2.33738085555821e-14, -3.8351626959347677e-13])
    near = math.atan2(-3.8351626959347677e-13, 93.21687266652779) % (2 * math.pi)
    ws.write_formula("B1", "=MOD(ATAN2(A1,A2),2*PI())", None, 0)  # Excel's 0, not 2*PI()
    ws.write_formula("B2", "=MOD(ATAN2(A1,A3),2*PI())", None, near)
    ws.write_formula("B3", "=MOD(-7,3)", None, 2)
    wb.close()
    report, _ = import_and_check(path, tmp_path, capsys)
    assert (report["printed"], report["reproduced"], report["failed"]) == (3, 2, 0)


@pytest.mark.slow
def test_textsplit_of_a_text_that_never_changes_into_a_column(tmp_path, capsys):
    path = tmp_path / "split.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("S")
    pieces = ["x (mm)", "a", "4,1", "", "Ab", "a"]  # an empty piece is kept, case too
    ws.write("A1", ":".join(pieces))
    ws.write("B1", "p;q")
    ws.write_dynamic_array_formula("C1:C6", '=_xlfn.TEXTSPLIT(A1,,":")', None, pieces[0])
    for k, piece in enumerate(pieces[1:], start=1):
        ws.write_string(k, 2, piece)  # the cells of the array: Excel's cached values
    ws.write_dynamic_array_formula("D1:E1", '=_xlfn.TEXTSPLIT(B1,";")', None, "p")
    ws.write_string(0, 4, "q")  # into a row: listed
    ws.write_dynamic_array_formula("D3:D4", '=_xlfn.TEXTSPLIT(A1,,":")', None, pieces[0])
    ws.write_string(3, 3, pieces[1])  # fewer cells than pieces: listed
    wb.close()
    report, text = import_and_check(path, tmp_path, capsys)
    assert "into a row" in text and "not shown in as many cells" in text
    assert report["failed"] == 0
    assert report["reproduced"] == 5  # the column's cells but the empty piece (not counted)
    assert report["printed"] == 9
