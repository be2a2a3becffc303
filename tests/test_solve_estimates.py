"""[[solve]] solutions carry an error estimate with the condition number, and are results."""

from __future__ import annotations

import contextlib
import io
import os

import pytest
from conftest import write_template

import workbook
from workbook.cli import main

SHEET = """
[[solve]]
unknowns = { p = "0", q = "0" }
equations = ["p + q == 2", "p + (1 + 1e-10)*q == 2 + 1e-10"]

[[solve]]
unknowns = { x = "1 m", y = "0.5 m" }
equations = ["x^2 + y^2 == R^2", "y == x*tan(theta)"]

[inputs]
R = "2 m"
theta = "0.3"
"""


def test_an_ill_conditioned_system_warns_with_an_estimate_above_its_error(tmp_path):
    sheet = workbook.load(write_template(tmp_path, SHEET))
    p = sheet.evaluate("p").magnitude
    solved = sheet._memo[("solve", 0)]
    assert solved.condition > 1e9  # exact: 4e10 for the relative residuals
    assert solved.errors["p"] >= abs(p - 1.0)  # the exact solution is p = q = 1
    found = {f.topic: f for f in sheet.check().findings}
    assert found["solve p, q"].verdict == "warning"
    assert "ill-conditioned" in found["solve p, q"].note


def test_a_well_conditioned_system_is_for_information(tmp_path):
    sheet = workbook.load(write_template(tmp_path, SHEET))
    x = sheet.evaluate("x").to("m").magnitude
    solved = sheet._memo[("solve", 1)]
    assert solved.condition < 10
    assert x == pytest.approx(1.91067297825, abs=1e-10)
    assert solved.errors["x"] < 1e-12
    found = {f.topic: f for f in sheet.check().findings}
    assert found["solve x, y"].verdict == "info"
    assert found["solve x, y"].what.startswith("x = 1.910672978 m (error estimate")


def test_run_prints_the_unknowns_as_results(tmp_path):
    path = write_template(tmp_path, SHEET)
    out, err = io.StringIO(), io.StringIO()
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(["run", str(path), "--out", "s.xlsx"])
    finally:
        os.chdir(cwd)
    assert code == 0
    assert "  x = 1.91067 m" in out.getvalue() and "  y = 0.59104 m" in out.getvalue()
    assert "warning: [solve p, q]" in err.getvalue()


def test_the_results_sheet_and_the_report_show_the_block(tmp_path):
    import openpyxl

    from workbook.report import write_report

    sheet = workbook.load(write_template(tmp_path, SHEET))
    sheet.write_xlsx(tmp_path / "s.xlsx")
    rows = {
        r[0]: r
        for r in openpyxl.load_workbook(tmp_path / "s.xlsx")["Results"].iter_rows(values_only=True)
    }
    assert rows["x"][1] == pytest.approx(1.91067297825, abs=1e-10) and rows["x"][2] == "m"
    assert rows["x"][3] == "Given x^2 + y^2 == R^2; y == x*tan(theta): Find(x, y)"
    assert "condition number 1.51" in rows["x"][4]
    html = write_report(sheet, tmp_path / "s.html")[0].read_text(encoding="utf-8")
    assert "<div class='definition given'>" in html and "guesses: x = 1 m, y = 0.5 m" in html
    assert "Find(x, y): x = 1.91067" in html and "condition number 1.8e+10" in html
