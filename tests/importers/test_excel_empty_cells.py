"""`workbook import`: an empty cell equals "" and 0, a cell holding 0 is not "", a text is not
0 — a workbook the test writes with openpyxl, its values computed by LibreOffice Calc."""

from __future__ import annotations

import pytest
from helpers.excel_import import import_and_check
from helpers.recalc import recalculate, soffice

openpyxl = pytest.importorskip("openpyxl")

#: what A1..A4 hold: 0, a number, a text, nothing
HELD = [0, 5, "abc", None]
#: formulas of the cell in column A of their row (``{a}``)
FORMULAS = [
    '=IF({a}="","",{a}*2)',
    '=IF({a}="",-1,{a}*2)',
    "=IF({a}=0,1,2)",
    '={a}=""',
    '={a}<>""',
    '=IF({a}="x",1,2)',
    '={a}&"|"',
    "=COUNT({a}:{a})",
]


def _write(path) -> None:
    wb = openpyxl.Workbook()
    ws = wb.active
    ws.title = "S"
    for row, held in enumerate(HELD, start=1):
        if held is not None:
            ws.cell(row, 1, held)
        for col, formula in enumerate(FORMULAS, start=2):
            text = formula.format(a=f"A{row}")
            if held == "abc" and "*2" in text:
                text = text.replace(f"A{row}*2", "7")  # a text in arithmetic is #VALUE!
            ws.cell(row, col, text)
    ws["K1"] = "=A4*3+A1"  # the empty cell in arithmetic too
    wb.save(path)


@pytest.mark.slow
@pytest.mark.skipif(soffice() is None, reason="LibreOffice is not installed")
def test_empty_zero_text_and_number_compared_with_texts_as_excel(tmp_path, capsys):
    source = tmp_path / "empty.xlsx"
    _write(source)
    computed = recalculate(source, tmp_path / "lo")  # LibreOffice's values, as Excel's
    report, text = import_and_check(computed, tmp_path, capsys)
    assert report["failed"] == 0
    assert report["reproduced"] == report["printed"] > 30
    import workbook

    sheet = workbook.load(str(next((tmp_path / "out").glob("*.toml"))))
    notes = {n: i.note for n, i in sheet.spec.inputs.items()}
    assert not any("S!A4" in note for note in notes.values())  # the empty cell: no input
    zero = next(n for n, note in notes.items() if "S!A1" in note)
    values = openpyxl.load_workbook(computed, data_only=True)["S"]
    defs = sheet.spec.definitions

    def named(cell: str) -> str:
        return next(n for n, d in defs.items() if d.note.startswith(f"S!{cell}:"))

    # the input that holds 0, given 5, computes as LibreOffice did for the cell holding 5
    five = sheet.with_inputs(**{zero: 5})
    for col in "BCDEFGHI":
        got = five.evaluate(named(f"{col}1"))
        want = values[f"{col}2"].value
        if isinstance(want, str):
            assert got == want
        else:
            assert getattr(got, "magnitude", got) == pytest.approx(float(want))
