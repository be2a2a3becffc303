"""[[solve]] solutions carry an error estimate with the condition number, and are results."""

from __future__ import annotations

import contextlib
import io
import os

import numpy as np
import pytest
from helpers.sheets import write_template

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


def test_an_ill_conditioned_system_warns_with_an_estimate_above_its_error(sheet_from):
    sheet = sheet_from(SHEET)
    p = sheet.evaluate("p").magnitude
    solved = sheet.solution(sheet.spec.solves[0])
    assert solved.condition > 1e9  # exact: 4e10 for the relative residuals
    assert solved.errors["p"] >= abs(p - 1.0)  # the exact solution is p = q = 1
    found = {f.topic: f for f in sheet.check().findings}
    assert found["solve p, q"].verdict == "warning"
    assert "ill-conditioned" in found["solve p, q"].note


def test_a_well_conditioned_system_is_for_information(sheet_from):
    sheet = sheet_from(SHEET)
    x = sheet.evaluate("x").to("m").magnitude
    solved = sheet.solution(sheet.spec.solves[1])
    assert solved.condition < 10
    assert x == pytest.approx(1.91067297825, abs=1e-10)
    assert solved.errors["x"] < 1e-12
    found = {f.topic: f for f in sheet.check().findings}
    assert found["solve x, y"].verdict == "info"
    assert found["solve x, y"].what.startswith("x = 1.910672978 m (error estimate")


@pytest.mark.slow
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


def test_the_results_sheet_and_the_report_show_the_block(sheet_from, tmp_path):
    import openpyxl

    from workbook.compute.computed import compute
    from workbook.outputs.report import write_report

    sheet = sheet_from(SHEET)
    sheet.write_xlsx(tmp_path / "s.xlsx")
    rows = {
        r[0]: r
        for r in openpyxl.load_workbook(tmp_path / "s.xlsx")["Results"].iter_rows(values_only=True)
    }
    assert rows["x"][1] == pytest.approx(1.91067297825, abs=1e-10) and rows["x"][2] == "m"
    assert rows["x"][3] == "Given x^2 + y^2 == R^2; y == x*tan(theta): Find(x, y)"
    assert "condition number 1.51" in rows["x"][4]
    html = write_report(compute(sheet), tmp_path / "s.html")[0].read_text(encoding="utf-8")
    assert "<div class='definition given'>" in html and "guesses: x = 1 m, y = 0.5 m" in html
    assert "Find(x, y): x = 1.91067" in html and "condition number 1.8e+10" in html


FOUR_BAR = """
[inputs]
a = "40 mm"
b = "120 mm"
c = "80 mm"
d = "100 mm"

[arguments]
th2 = { unit = "deg" }

[[solve]]
parameters = ["th2"]
unknowns = { th3 = "20 deg", th4 = "60 deg" }
equations = [
  "a*cos(th2) + b*cos(th3) == d + c*cos(th4)",
  "a*sin(th2) + b*sin(th3) == c*sin(th4)",
]

[definitions]
th4_at_90 = { expr = "th4(90 deg)", unit = "deg" }

[[tables]]
name = "positions"
range = "th2 := 0, 30 .. 180"
columns = { th3 = "deg", th4 = "deg" }
"""


def freudenstein(th2: np.ndarray, a=40.0, b=120.0, c=80.0, d=100.0) -> np.ndarray:
    """Both closed-form output angles of a four-bar linkage (Freudenstein's equation)."""
    k1, k2, k3 = d / a, d / c, (a**2 - b**2 + c**2 + d**2) / (2 * a * c)
    big_a = np.cos(th2) - k1 - k2 * np.cos(th2) + k3
    big_b = -2 * np.sin(th2)
    big_c = k1 - (k2 + 1) * np.cos(th2) + k3
    root = np.sqrt(big_b**2 - 4 * big_a * big_c)
    return np.array([2 * np.arctan2(-big_b + s * root, 2 * big_a) for s in (1, -1)])


def test_a_block_with_parameters_is_a_function_over_a_table(sheet_from):
    sheet = sheet_from(FOUR_BAR)
    table = sheet.table("positions")
    th2 = np.radians(table["th2 [deg]"].to_numpy())
    th4 = np.radians(table["th4 [deg]"].to_numpy())
    exact = freudenstein(th2)
    off = np.min(np.abs(np.angle(np.exp(1j * (exact - th4)))), axis=0)
    assert np.max(off) < 1e-9  # the branch the guesses lead to, to the sheet's tolerance
    at_90 = sheet.evaluate("th4_at_90").to("rad").magnitude
    assert at_90 == pytest.approx(th4[3], abs=1e-12)
    assert sheet.evaluate("th3", 90).to("deg").magnitude == pytest.approx(
        table["th3 [deg]"][3], abs=1e-9
    )


def test_an_unknown_of_a_block_with_parameters_is_used_as_a_function(sheet_from):
    from workbook.errors import TemplateError

    text = FOUR_BAR.replace('"th4(90 deg)"', '"th4"')
    with pytest.raises(TemplateError, match=r"it is a function, write th4\(th2\)"):
        sheet_from(text)


def test_inputs_of_a_block_with_parameters_are_used(sheet_from):
    text = FOUR_BAR.replace('d = "100 mm"', 'd = "100 mm"\nspare = "1 mm"')
    sheet = sheet_from(text)
    assert sheet.unused_inputs() == ["spare"]


def test_the_estimate_of_an_unknown_in_degc_is_a_difference(sheet_from, tmp_path):
    import openpyxl

    text = (
        '[inputs]\nT0 = "20 degC"\nk = "0.5 1/K"\n\n[[solve]]\nunknowns = { T = "30 degC" }\n'
        'equations = ["k*(T - T0) == 2"]\n\n[definitions]\nTT = { expr = "T", unit = "degC" }\n'
    )
    sheet = sheet_from(text)
    assert sheet.evaluate("T").magnitude == pytest.approx(24.0, rel=1e-12)
    found = {f.topic: f for f in sheet.check().findings}
    assert "degC (error estimate" in found["solve T"].what
    assert found["solve T"].what.rstrip(")").endswith("delta_degC")
    book = openpyxl.load_workbook(sheet.write_xlsx(tmp_path / "t.xlsx"))
    notes = [c.value for row in book["Results"].iter_rows() for c in row if c.value]
    assert any(str(v).startswith("error estimate") and " Δ°C," in str(v) for v in notes)
