"""Inputs that only a [[solve]] block, a [[checks]] entry, an [[ode]] or a result uses are used;
only an input nothing reads is listed as unused (check) and labelled so (Inputs sheet)."""

from __future__ import annotations

import openpyxl

SHEET = """
[inputs]
R = "2 m"
f_y = "235 MPa"
sigma = "120 MPa"
k = "2 1/s"
c = "3"
spare = "1 m"

[arguments]
t = { unit = "s" }

[[solve]]
unknowns = { x = "1 m" }
equations = ["x^2 == R^2"]

[definitions]
twice = "2*c"

[[ode]]
name = "decay"
time = "t := 0 .. 1"
states = [{ name = "y", unit = "m", initial = "1", derivative = "-k*y" }]

[[checks]]
what = "stress against yield"
ok = "sigma <= f_y"
"""


def test_inputs_of_solves_checks_odes_and_results_are_used(sheet_from):
    sheet = sheet_from(SHEET)
    assert sheet.unused_inputs() == ["spare"]
    assert sheet.check().unused_inputs == ["spare"]


def test_the_inputs_sheet_labels_only_the_unused_input(sheet_from, tmp_path):
    sheet = sheet_from(SHEET)
    sheet.write_xlsx(tmp_path / "t.xlsx")
    ws = openpyxl.load_workbook(tmp_path / "t.xlsx")["Inputs"]
    notes = {r[0].value: r[3].value or "" for r in ws.iter_rows(min_row=2) if r[0].value}
    labelled = [n for n, note in notes.items() if "not used by any output" in note]
    assert labelled == ["spare"]
