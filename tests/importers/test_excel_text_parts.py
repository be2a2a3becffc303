"""`workbook import`: LEN, LEFT, RIGHT, MID, UPPER, LOWER and TRIM of texts as strlen, substr,
strupper, strlower and strtrim, each cached value
computed by the `formulas` package (an evaluator of Excel's formulas independent of the
import); of a number (whose text is Excel's display) they are listed."""

from __future__ import annotations

import numpy as np
import pytest

xlsxwriter = pytest.importorskip("xlsxwriter")
formulas = pytest.importorskip("formulas")

from helpers.excel_import import check_counts, import_book  # noqa: E402

FORMULAS = [
    "=LEN(A1)",
    "=LEFT(A1,4)",
    "=LEFT(A1)",
    "=LEFT(A1,40)",
    "=RIGHT(A1,3)",
    "=RIGHT(A1,40)",
    "=MID(A1,2,3)",
    "=MID(A1,B1,2)",
    "=MID(A1,20,2)",
    '=LEFT(A1,2)&"-"&RIGHT(A1,2)',
    "=LEN(A2)",
    "=UPPER(A3)",
    "=LOWER(A3)",
    "=TRIM(A3)",
    '=LEN(TRIM(A3))&" "&LOWER(A2)',
]
TEXTS = {"A1": "Fehler: b", "A2": "DL", "A3": "  Load  case 2 "}
# TRIM as Excel documents it ("removes all spaces from text except for single spaces between
# words"): the `formulas` package keeps the inner run of two spaces, so these are written here
TRIMMED = {"=TRIM(A3)": "Load case 2", '=LEN(TRIM(A3))&" "&LOWER(A2)': "11 dl"}


def excel(formula: str):
    if formula in TRIMMED:
        return TRIMMED[formula]
    fn = formulas.Parser().ast(formula)[1].compile()
    cells = {**TEXTS, "B1": 3.0}
    value = np.asarray(fn(*[np.array([[cells[k]]], dtype=object) for k in fn.inputs])).ravel()[0]
    return value if isinstance(value, str) else float(value)


@pytest.fixture(scope="module")
def imported(tmp_path_factory):
    folder = tmp_path_factory.mktemp("textparts")
    path = folder / "texts.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("Texts")
    ws.write_string("A1", TEXTS["A1"])
    ws.write_formula("A2", '="D"&"L"', None, TEXTS["A2"])  # a text a formula gives
    ws.write_string("A3", TEXTS["A3"])
    ws.write_number("B1", 3.0)
    ws.write_number("B2", 12.5)
    for k, f in enumerate(FORMULAS):
        ws.write_formula(k, 3, f, None, excel(f))
    ws.write_formula("F1", "=LEN(B2)", None, 4)  # a number: the text of its display
    wb.close()
    return import_book(path)


def test_every_cached_value_is_reproduced(imported, capsys):
    status, counts = check_counts(imported, capsys)
    assert status == 1
    # the fifteen formulas but MID(A1,20,2) (an empty text: no cached value), and A2; F1 is
    # listed
    assert counts == {"printed": 16, "reproduced": 15, "failed": 0, "not_computable": 1}


def test_a_position_below_1_is_an_error(imported):
    import workbook

    sheet = workbook.load(str(imported))
    name = next(n for n, d in sheet.spec.definitions.items() if d.note.endswith("=MID(A1,B1,2)"))
    B1 = next(n for n, d in sheet.spec.inputs.items() if d.note.startswith("Texts!B1"))
    assert sheet.with_inputs(**{B1: 1}).evaluate(name) == "Fe"  # Excel's MID(A1,1,2)
    beyond = next(n for n, d in sheet.spec.definitions.items() if d.note.endswith("(A1,20,2)"))
    assert sheet.evaluate(beyond) == excel("=MID(A1,20,2)") == ""
    with pytest.raises(workbook.WorkbookError, match="m must be a whole number at least 0"):
        sheet.with_inputs(**{B1: 0}).evaluate(name)  # #VALUE! in Excel


def test_of_a_number_is_listed(imported):
    head = imported.read_text(encoding="utf-8").split("[sheet]")[0].replace("\n# ", " ")
    assert "=LEN(B2): LEN of other than a text" in head
