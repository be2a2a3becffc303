"""`workbook import`: SUMIF, SUMIFS, COUNTIF, COUNTIFS, AVERAGEIF and AVERAGEIFS with Excel's
criteria, each cached value computed by the `formulas` package (an evaluator of Excel's
formulas independent of the import), and the criteria whose match is not certain listed."""

from __future__ import annotations

import numpy as np
import pytest

xlsxwriter = pytest.importorskip("xlsxwriter")
formulas = pytest.importorskip("formulas")

from helpers.excel_import import check_counts, import_book  # noqa: E402

import workbook  # noqa: E402

# A1:A6 numbers (A5 a formula), B1:B6 load kinds (B6 reads B1's text), D1 the kind sought
NUMBERS = [-1.5, 2.0, -3.0, 4.0, 0.5, -6.0]
KINDS = ["DL", "LL", "dl", "W1", "LL", "DL"]  # W1 is a text, not a number
FORMULAS = [
    '=SUMIFS(A1:A6,B1:B6,D1,A1:A6,"<0")',
    '=SUMIFS(A1:A6,B1:B6,"<>DL",A1:A6,">=0.5")',
    '=SUMIF(A1:A6,"<0")',
    '=SUMIF(B1:B6,"ll",A1:A6)',
    '=COUNTIFS(B1:B6,D1,A1:A6,"<=-1.5")',
    '=COUNTIF(A1:A6,">0")',
    '=COUNTIF(B1:B6,"<>LL")',
    '=AVERAGEIFS(A1:A6,B1:B6,"DL")',
    '=AVERAGEIF(B1:B6,"LL",A1:A6)',
    "=SUMIFS(A1:A6,A1:A6,D2)",
    "=COUNTIF(A1:A6,A5)",
    '=SUMIF(B1:B6,"w1",A1:A6)',
]


def excel(formula: str, numbers, kinds, sought=("DL", 4.0)) -> float:
    """The value the `formulas` package computes for ``formula`` over the cells."""
    fn = formulas.Parser().ast(formula)[1].compile()
    cells = {
        "A1:A6": np.array([[x] for x in numbers]),
        "B1:B6": np.array([[k] for k in kinds], dtype=object),
        "D1": np.array([[sought[0]]], dtype=object),
        "D2": np.array([[sought[1]]]),
        "A5": np.array([[numbers[4]]]),
    }
    return float(np.asarray(fn(*[cells[k] for k in fn.inputs])).ravel()[0])


def build(path, numbers=NUMBERS, kinds=KINDS, extra=()):
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("Loads")
    for i, (x, k) in enumerate(zip(numbers, kinds)):
        if i == 4:
            ws.write_formula(i, 0, "=A2/4", None, x)
        else:
            ws.write_number(i, 0, x)
        if i == 5:
            ws.write_formula(i, 1, "=B1", None, k)
        else:
            ws.write_string(i, 1, k)
    ws.write_string("D1", "DL")
    ws.write_number("D2", 4.0)
    for k, f in enumerate(FORMULAS):
        ws.write_formula(k, 5, f, None, excel(f, numbers, kinds))
    for k, (f, cached) in enumerate(extra):
        ws.write_formula(k, 7, f, None, cached)
    wb.close()


@pytest.fixture(scope="module")
def imported(tmp_path_factory):
    folder = tmp_path_factory.mktemp("criteria")
    build(folder / "loads.xlsx", extra=[(f, 0.0) for f, _ in UNCERTAIN])
    return import_book(folder / "loads.xlsx")


def test_every_cached_value_is_reproduced(imported, capsys):
    status, counts = check_counts(imported, capsys)
    assert status == 1
    # the twelve formulas and A5's and B6's cells; the five of UNCERTAIN are listed
    assert counts == {"printed": 21, "reproduced": 14, "failed": 0, "not_computable": 7}


def test_a_comparison_with_a_number_is_live(imported):
    sheet = workbook.load(str(imported))
    defs = sheet.spec.definitions.items()
    names = {d.note.split(": ", 1)[1]: n for n, d in defs if ": =" in d.note}
    A1 = next(n for n, d in sheet.spec.inputs.items() if d.note == "Loads!A1")
    for x in (5.0, -2.0):  # A1 no longer below 0, or below -1.5 no longer
        numbers = [x, *NUMBERS[1:]]
        edited = sheet.with_inputs(**{A1: x})
        for f in FORMULAS:
            got = edited.evaluate(names[f]).magnitude
            assert got == pytest.approx(excel(f, numbers, KINDS)), f


# formulas whose criteria are not certain, each listed with its reason (H1:H7)
UNCERTAIN = [
    ('=SUMIF(C1:C3,"<0",A1:A3)', "SUMIF over an empty cell"),
    ('=SUMIF(B1:B6,"D*",A1:A6)', "SUMIF whose criterion 'D*' is a pattern or an operator"),
    ('=SUMIFS(A1:A6,B1:B5,"DL")', "SUMIFS whose ranges differ in size"),
    ('=COUNTIF(B1:B6,">DL")', "COUNTIF whose criterion '>DL' orders texts"),
    ("=SUMIFS(A1:A6,B1:B6,B6)", "SUMIFS whose criterion is a formula that gives no number"),
    ("=COUNTIFS(A1:A6,C1)", "COUNTIFS whose criterion is an empty cell"),
    ('=SUMIF(B1:B6,"1-Jan",A1:A6)', "SUMIF whose criterion '1-Jan' reads as a number"),
]


def test_an_uncertain_criterion_is_listed(imported):
    head = imported.read_text(encoding="utf-8").split("[sheet]")[0].replace("\n# ", " ")
    for formula, reason in UNCERTAIN:
        assert f"{formula}: {reason}" in head


def test_countif_not_empty_counts_the_cells_that_hold_something(tmp_path, capsys):
    path = tmp_path / "filled.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("F")
    ws.write_column("A1", [0, 0.17, None, "p1", None, 3])  # A3, A5 empty
    ws.write_number("B1", 2)
    ws.write_formula("B2", "=B1*2", None, 4)  # a formula that gives a number: not empty
    ws.write_formula("C1", '=COUNTIF(A1:A6,"<>")', None, 4)
    ws.write_formula("C2", '=COUNTIF(A1:B2,"<>")', None, 4)
    ws.write_formula("B3", '=IF(B1>1,"","x")', None, "")
    ws.write_formula("C3", '=COUNTIF(B1:B3,"<>")', None, 2)  # B3 gives "": listed
    wb.close()
    status, counts = check_counts(import_book(path), capsys)
    assert counts == {"printed": 4, "reproduced": 3, "failed": 0, "not_computable": 1}
