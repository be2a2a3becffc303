"""`workbook import`: Excel's ISBLANK, ISNUMBER, ISTEXT, ISNONTEXT, ISLOGICAL, ISERROR and
ISERR where the answer is certain, each cached value written as Excel gives it; where it is
not certain (a range, a cell OFFSET names, an empty cell that is an input, a cell a Sub
writes, a value of unknown kind) the cell is listed with its reason."""

from __future__ import annotations

import csv

import pytest

xlsxwriter = pytest.importorskip("xlsxwriter")

from helpers.excel_import import check_counts  # noqa: E402

from workbook.cli import main  # noqa: E402

#: (cell, formula, Excel's value) of the formulas translated
CERTAIN = [
    ("C1", "=IF(ISBLANK(A1),1,2)", 2),  # a constant number
    ("C2", "=IF(ISBLANK(A3),1,2)", 1),  # an empty cell no other formula reads
    ("C3", "=IF(ISBLANK(A5),1,2)", 2),  # a formula that gives "" is never blank
    ("C4", "=IF(ISBLANK(A2),1,2)", 2),  # a constant text
    ("C5", "=IF(ISNUMBER(A4),A4,0)", 10),  # a formula that gives a number
    ("C6", "=ISTEXT(A2)", True),
    ("C7", "=IF(ISNONTEXT(A1),1,2)", 1),
    ("C8", "=IF(ISNUMBER(A3),1,2)", 2),  # an empty cell is no number
    ("C9", "=IF(ISTEXT(A4),1,2)", 2),
    ("C10", "=IF(ISERROR(A1/A6),-1,A1/A6)", -1),  # A6 is 0: #DIV/0!
    ("C11", "=IF(ISERROR(A1/A7),-1,A1/A7)", 2.5),
    ("C12", "=IF(ISERR(SQRT(A7-A1)),0,1)", 0),  # a root of -3: #NUM!
    ("C13", "=IF(ISBLANK(A1*2),1,2)", 2),  # a value, never a reference
    ("C14", "=IF(ISLOGICAL(A1>2),1,2)", 1),
]
#: (cell, formula, Excel's value, the reason it is listed)
REFUSED = [
    ("E1", "=IF(ISBLANK(A1:A2),1,2)", 2, "ISBLANK of a range"),
    ("E2", "=IF(ISBLANK(OFFSET(A1,A7,0)),1,2)", 1, "ISBLANK of other than a reference to one"),
    ("E3", "=IF(ISBLANK(A8),0,A8)", 0, "the empty cell Info!A8, which is an input"),
    ("E4", "=IF(ISBLANK(A9),1,2)", 1, "an empty cell that the macro Sub Fill writes"),
    ("E5", "=IF(ISBLANK(A10),1,2)", 2, "ISBLANK of a cell that the macro Sub Fill writes"),
    ("E6", "=IF(ISLOGICAL(A11),1,2)", 1, "ISLOGICAL of a TRUE/FALSE cell"),
    ("E7", '=IF(ISNUMBER(IF(A1>2,"a",1)),1,2)', 2, "ISNUMBER of a value whose kind"),
    ("E8", "=IF(ISERROR(MOD(A1,A6)),1,2)", 1, "ISERROR of other than"),
    # A12 gave a number, but its formula may give a text: its cached kind is not enough
    ("E9", "=IF(ISNUMBER(A12),1,2)", 1, "ISNUMBER of a value whose kind"),
]
MODULE = (
    'Attribute VB_Name = "Module1"\n'
    "Sub Fill()\n"
    '    Range("A9").Value = 3\n'
    '    Range("A10").Value = 4\n'
    "End Sub\n"
)


@pytest.fixture(scope="module")
def imported(tmp_path_factory):
    folder = tmp_path_factory.mktemp("isfunctions")
    path = folder / "info.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    ws = wb.add_worksheet("Info")
    ws.write_number("A1", 5)
    ws.write_string("A2", "DL")
    ws.write_formula("A4", "=A1*2", None, 10)
    ws.write_formula("A5", '=""', None, "")
    ws.write_number("A6", 0)
    ws.write_number("A7", 2)
    ws.write_number("A10", 1)
    ws.write_boolean("A11", True)
    ws.write_formula("A12", '=IF(A1>2,A1,"x")', None, 5)
    for cell, formula, value, *_ in CERTAIN + REFUSED:
        ws.write_formula(cell, formula, None, value)
    wb.close()
    bas = folder / "Module1.bas"
    bas.write_text(MODULE, encoding="utf-8")
    out = folder / "out"
    assert main(["import", str(path), "--vba", str(bas), "--out", str(out)]) == 0
    return out / "info.toml"


def test_the_certain_answers_are_reproduced(imported, capsys):
    status, counts = check_counts(imported, capsys)
    assert status == 1
    # A4, A12, the fourteen certain formulas; the nine refused are not computable
    assert counts == {"printed": 25, "reproduced": 16, "failed": 0, "not_computable": 9}


def _listed(toml) -> dict[str, str]:
    path = toml.with_name(toml.stem + ".excel.not-translated.csv")
    with path.open(encoding="utf-8") as fh:
        return {row[0].split(" ")[0]: row[0] for row in csv.reader(fh) if row and "!" in row[0]}


@pytest.mark.parametrize("cell, formula, value, reason", REFUSED, ids=[r[0] for r in REFUSED])
def test_each_uncertain_answer_is_listed_with_its_reason(imported, cell, formula, value, reason):
    assert reason in _listed(imported)[f"Info!{cell}"]


def test_an_empty_cell_read_only_by_isblank_is_no_input(imported):
    import workbook

    sheet = workbook.load(str(imported))
    notes = [d.note for d in sheet.spec.inputs.values()]
    assert not any(n.startswith("Info!A3") for n in notes)
    assert any(n.startswith("Info!A8") for n in notes)  # E3 reads it in arithmetic too
