"""One angle rule everywhere: range bounds go through the typer's conversion as arguments of a
call do, and the two slips of Mathcad users with angles are reported as warnings."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest
from helpers.sheets import write_template

import workbook

SHEET = """
[sheet]
title = "angles"

[inputs]
theta = { value = "30 deg" }
R = { value = "10 mm" }
turns = { value = "2" }

[arguments]
phi = { unit = "deg" }
psi = { unit = "deg", plain = true }

[definitions]
"y(phi)" = { expr = "R*sin(phi)", unit = "mm" }
"w(psi)" = { expr = "R*sin(psi * 1 deg)", unit = "mm" }
at_half_pi = { expr = "y(pi/2)", unit = "mm" }

[[tables]]
name = "radians"
range = "phi := 0, pi/6 .. pi"
columns = { "y(phi)" = "mm" }

[[tables]]
name = "degrees"
range = "phi := 0, 30 .. 180"
columns = { "y(phi)" = "mm" }

[[tables]]
name = "quantities"
range = "phi := 0 deg, 45 deg .. 360 deg * turns"
columns = { "y(phi)" = "mm" }

[[tables]]
name = "plain"
range = "psi := 0, 30 .. 180"
columns = { "w(psi)" = "mm" }
"""


def test_pi_in_range_bounds_is_radians_as_in_a_call(sheet):
    """phi := 0, pi/6 .. pi is 0, 30 .. 180 degrees, as y(pi/2) reads pi/2 as 90 degrees."""
    radians = sheet.table("radians")
    degrees = sheet.table("degrees")
    assert len(radians) == len(degrees) == 7
    np.testing.assert_allclose(radians.iloc[:, 0], np.arange(0, 181, 30), rtol=1e-14)
    np.testing.assert_allclose(radians.iloc[:, 1], degrees.iloc[:, 1], rtol=1e-13, atol=1e-14)
    assert sheet.evaluate("at_half_pi").to("mm").magnitude == pytest.approx(10.0, rel=1e-15)


def test_quantities_and_plain_arguments_in_range_bounds(sheet):
    quantities = sheet.table("quantities")
    np.testing.assert_allclose(quantities.iloc[:, 0], np.arange(0, 721, 45), rtol=1e-15)
    plain = sheet.table("plain")  # psi is a plain number of degrees: 0, 30 .. 180
    np.testing.assert_allclose(plain.iloc[:, 0], np.arange(0, 181, 30), rtol=1e-15)
    expected = [10 * math.sin(math.radians(a)) for a in range(0, 181, 30)]
    np.testing.assert_allclose(plain.iloc[:, 1], expected, rtol=1e-13, atol=1e-14)


SLIPS = """
[sheet]
title = "slips"

[inputs]
theta = { value = "30 deg" }
R = { value = "10 mm" }

[arguments]
phi = { unit = "deg" }

[definitions]
a = { expr = "R*sin(theta*pi/180)", unit = "mm" }
b = "cos(90)"
"c(phi)" = { expr = "R*sin(pi/180*phi)", unit = "mm" }
fine = "sin(theta) + cos(1.2) + tan(theta/2)"
"""


def test_the_two_slips_are_warnings(sheet_from):
    sheet = sheet_from(SLIPS)
    found = {f.what: f for f in sheet.check().findings if f.topic == "angles"}
    assert set(found) == {
        "'a': sin() of an angle in degrees multiplied by pi/180",
        "'b': cos(90) reads 90 as radians",
        "'c': sin() of an angle in degrees multiplied by pi/180",
    }
    assert all(f.verdict == "warning" for f in found.values())
    # the values are as written, not changed: the finding says what they are
    assert sheet.evaluate("a").to("mm").magnitude == pytest.approx(
        10 * math.sin(math.radians(30) * math.pi / 180), rel=1e-14
    )
    assert sheet.evaluate("b").magnitude == pytest.approx(math.cos(90.0), rel=1e-14)


def test_no_warning_without_degrees(sheet_from):
    text = '[inputs]\nx = { value = "2" }\n\n[definitions]\nb = "cos(90*x)"\nc = "sin(90)"\n'
    sheet = sheet_from(text)
    assert not [f for f in sheet.check().findings if f.topic == "angles"]


@pytest.mark.slow
def test_run_prints_the_warnings_and_exits_0(tmp_path):
    write_template(tmp_path, SLIPS, "slips.toml")
    code = "import sys; from workbook.cli import main; sys.exit(main())"
    done = subprocess.run(
        [sys.executable, "-c", code, "run", "slips.toml", "--out", "slips.xlsx"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    assert "warning: [angles] 'a': sin() of an angle in degrees multiplied by pi/180" in (
        done.stderr
    )
    assert "cos(90 deg)" in done.stderr


# -- a log-spaced range ------------------------------------------------------------------------

LOG = """
[sheet]
title = "a low-pass filter"

[inputs]
R = { value = "10 ohm" }
C = { value = "1 uF" }
n = { value = "7" }

[arguments]
f = { unit = "Hz" }

[definitions]
"gain(f)" = "1/sqrt(1 + (2*pi*f*R*C)^2)"

[[tables]]
name = "bode"
range = "f := logspace(10 Hz, 10 MHz, n)"
columns = { "gain(f)" = "" }
"""


def test_a_log_spaced_range_is_mathcads_logspace(sheet_from):
    sheet = sheet_from(LOG)
    table = sheet.table("bode")
    np.testing.assert_allclose(table.iloc[:, 0], np.logspace(1, 7, 7), rtol=1e-14)
    assert table.iloc[0, 0] == 10.0 and table.iloc[-1, 0] == 1e7  # the bounds exactly
    expected = 1 / np.sqrt(1 + (2 * np.pi * np.logspace(1, 7, 7) * 10 * 1e-6) ** 2)
    np.testing.assert_allclose(table.iloc[:, 1], expected, rtol=1e-13)
    assert len(sheet.with_inputs(n="13").table("bode")) == 13


def test_a_log_spaced_range_in_the_workbook_recalculates(sheet_from, tmp_path):
    import formulas
    import openpyxl

    sheet = sheet_from(LOG)
    path = sheet.write_xlsx(tmp_path / "bode.xlsx")
    ws = openpyxl.load_workbook(path, data_only=True)["Listing"]
    header = next(r for r in range(1, 10) if ws.cell(r, 1).value == "f [Hz]")
    xs = [ws.cell(header + 1 + i, 1).value for i in range(7)]
    np.testing.assert_allclose(xs, np.logspace(1, 7, 7), rtol=1e-14)  # not FIRST+i*STEP
    # its points are an input: formulas FIRST*(LAST/FIRST)^(i/(n-1)) and a guard of n
    formulas_ws = openpyxl.load_workbook(path)["Listing"]
    assert formulas_ws.cell(header + 2, 1).value.startswith("=(10)*((10000000)/(10))^(1/6)")
    solution = formulas.ExcelModel().loads(str(path)).finish().calculate()
    got = {}
    for key, ranges in solution.items():
        book_sheet, _, cell = key.rpartition("!")
        if book_sheet.split("]", 1)[-1].strip("'").upper() == "LISTING" and ":" not in cell:
            got[cell.upper()] = ranges.value[0, 0]
    for i, want in enumerate(sheet.table("bode").iloc[:, 1]):
        assert float(got[f"B{header + 1 + i}"]) == pytest.approx(want, rel=1e-12)
        assert float(got[f"A{header + 1 + i}"]) == pytest.approx(xs[i], rel=1e-12)


@pytest.mark.parametrize(
    "range_text,message",
    [
        ("f := logspace(0 Hz, 10 MHz, 7)", "above zero"),
        ("f := logspace(10 Hz, 10 MHz, 2.5)", "whole number >= 2 of points"),
        ("f := logspace(10 Hz, 10 MHz)", r"write logspace\(first, last, points\)"),
    ],
)
def test_log_spaced_range_mistakes(sheet_from, range_text, message):
    text = LOG.replace("f := logspace(10 Hz, 10 MHz, n)", range_text)
    with pytest.raises(workbook.WorkbookError, match=message):
        sheet_from(text).table("bode")


def test_a_program_loop_is_not_log_spaced(tmp_path):
    from workbook.language.ranges import parse_range

    with pytest.raises(workbook.WorkbookError, match="for tables, charts and sweep outputs"):
        parse_range("k := logspace(1, 100, 3)")


RATIOS = """
[inputs]
th = "45 deg"
a = "20 mm"
b = "10 mm"
T = "10 degC"
K = "100 K"
p = "15 %"

[definitions]
"""


@pytest.mark.parametrize(
    "written,computed",
    [
        ("(20 mm / 10 mm) + th", "a/b + th"),
        ("th - 20 mm/10 mm", "th - a/b"),
        ("(10 degC / 100 K) - (0.5 - th)", "T/K - (0.5 - th)"),
        ("max(4 m/2 m, th)", "max(a/b, th)"),
        ("15 %*100 + th", "p*100 + th"),
        ("-(20 mm/10 mm) + th", "-(a/b) + th"),
    ],
)
def test_a_ratio_of_written_quantities_is_radians_as_a_ratio_of_inputs(
    sheet_from, written, computed
):
    # a ratio of literals was folded into a constant that looked bare, and was read as
    # degrees next to an angle: (20 mm / 10 mm) + th was 47 deg, a/b + th 2 rad + 45 deg
    text = RATIOS + f'w = "{written}"\nc = "{computed}"\n'
    sheet = sheet_from(text)
    w, c = sheet.evaluate("w"), sheet.evaluate("c")
    assert math.isclose(w.to("rad").magnitude, c.to("rad").magnitude, rel_tol=1e-14)


def test_bare_numbers_next_to_an_angle_are_still_degrees(sheet_from):
    text = RATIOS + 'w = "2 + th"\nv = "(90/2) + th"\n'
    sheet = sheet_from(text)
    assert math.isclose(sheet.evaluate("w").to("deg").magnitude, 47.0, rel_tol=1e-14)
    assert math.isclose(sheet.evaluate("v").to("deg").magnitude, 90.0, rel_tol=1e-14)
