"""Bare numbers next to angles in degrees: added, subtracted, compared (the number takes the
angle's unit), dividing or divided (refused), and plain = true arguments (plain numbers)."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import openpyxl
import pytest

from workbook import WorkbookError

SHEET = """
[sheet]
name = "angles"

[inputs]
R = "10 mm"
right = "90 deg"
tilt = "30 deg"

[arguments]
theta = { unit = "deg" }
phi = { unit = "deg", plain = true }

[definitions]
deg = "pi/180"
"lift(theta)" = { pieces = ["R*sin(theta) if theta <= 90", "R otherwise"], unit = "mm" }
"past(theta)" = { expr = "theta - 90", unit = "deg" }
"back(theta)" = { expr = "180 - theta", unit = "deg" }
"share(theta)" = "theta/right"
"half(theta)" = { expr = "0.5*theta", unit = "deg" }
"inside(theta)" = { pieces = ["1 if 0 < theta < 90", "0 otherwise"] }
"widest(theta)" = { expr = "max(theta, 45)", unit = "deg" }
"mathcad(phi)" = { pieces = ["R*sin(phi*deg) if phi <= 90", "R otherwise"], unit = "mm" }
"ratio(phi)" = "phi/90"
leaning = { pieces = ["1 if tilt < 45", "0 otherwise"] }

[[tables]]
name = "t"
range = "theta := 0, 30 .. 180"
columns = { lift = "mm", past = "deg", "theta + 10" = "deg" }
"""


def _mag(q, unit=""):
    return q.to(unit).magnitude if unit else q.to("").magnitude


def test_a_bare_number_meeting_an_angle_takes_its_unit(sheet):
    x = np.array([0.0, 60.0, 90.0, 91.0, 120.0])
    assert _mag(sheet.evaluate("lift", x), "mm") == pytest.approx(
        [0.0, 10 * math.sin(math.radians(60)), 10.0, 10.0, 10.0], rel=1e-15
    )
    assert _mag(sheet.evaluate("past", 120), "deg") == pytest.approx(30.0, rel=1e-15)
    assert _mag(sheet.evaluate("back", 30), "deg") == pytest.approx(150.0, rel=1e-15)
    assert _mag(sheet.evaluate("inside", x)).tolist() == [0, 1, 0, 0, 0]
    assert _mag(sheet.evaluate("widest", [30, 60]), "deg") == pytest.approx([45, 60])
    assert _mag(sheet.evaluate("leaning")) == 1  # an input in degrees against 45


def test_angles_divided_by_angles_and_scaled_by_numbers(sheet):
    assert _mag(sheet.evaluate("share", 45)) == pytest.approx(0.5, rel=1e-15)
    assert _mag(sheet.evaluate("half", 90), "deg") == pytest.approx(45.0, rel=1e-15)


def test_plain_arguments_stay_plain_numbers(sheet):
    assert _mag(sheet.evaluate("mathcad", 120), "mm") == pytest.approx(10.0)
    assert _mag(sheet.evaluate("ratio", 45)) == pytest.approx(0.5)


def test_the_table_column_uses_degrees(sheet):
    data = sheet.table_data("t")
    theta = data.columns[0].values
    assert data.columns[2].values == pytest.approx(theta - 90)
    assert data.columns[3].values == pytest.approx(theta + 10)


@pytest.mark.parametrize(
    "definition",
    [
        '"bad(theta)" = { expr = "R*theta/90", unit = "mm" }',
        '"bad(theta)" = { expr = "R*(1 - theta/90)", unit = "mm" }',
        '"bad(theta)" = { expr = "theta/90*R", unit = "m" }',
    ],
)
def test_an_angle_divided_by_a_bare_number_and_used_as_a_number_is_refused(sheet_from, definition):
    text = SHEET.replace("[definitions]\n", f"[definitions]\n{definition}\n")
    with pytest.raises(WorkbookError, match="an angle in deg divided by the plain number 90"):
        sheet_from(text, name="bad")


def test_an_angle_divided_by_a_number_stays_an_angle(sheet_from):
    text = SHEET.replace(
        "[definitions]\n",
        '[definitions]\n"halfway(theta)" = { expr = "theta/2", unit = "deg" }\n'
        '"chord(theta)" = { expr = "2*R*sin(theta/2)", unit = "mm" }\n',
    )
    sheet = sheet_from(text, name="ok")
    assert _mag(sheet.evaluate("halfway", 90), "deg") == pytest.approx(45.0, rel=1e-15)
    assert _mag(sheet.evaluate("chord", 60), "mm") == pytest.approx(10.0, rel=1e-15)


def _run(*args, cwd):
    code = "import sys; from workbook.cli import main; sys.exit(main())"
    return subprocess.run(
        [sys.executable, "-c", code, *args], capture_output=True, text=True, cwd=cwd, timeout=300
    )


@pytest.mark.slow
def test_workbook_run(tmp_path):
    (tmp_path / "angles.toml").write_text(SHEET, encoding="utf-8")
    done = _run("run", "angles.toml", "--out", "angles.xlsx", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    ws = openpyxl.load_workbook(tmp_path / "angles.xlsx")["Listing"]
    lift = [ws.cell(r, 2).value for r in range(1, 12)]
    assert any(isinstance(v, str) and "<=90" in v.replace(" ", "") for v in lift), lift
    bad = SHEET.replace(
        "[definitions]\n", '[definitions]\n"bad(theta)" = { expr = "R*theta/90", unit = "mm" }\n'
    )
    (tmp_path / "bad.toml").write_text(bad, encoding="utf-8")
    done = _run("run", "bad.toml", "--out", "bad.xlsx", cwd=tmp_path)
    assert done.returncode == 2
    assert "bad.toml" in done.stderr and "Traceback" not in done.stderr
    assert "divided by the plain number 90" in done.stderr and "plain = true" in done.stderr


# -- a bare number in a slot typed as an angle in degrees --------------------------------------

SLOTS = """
[arguments]
phi = { unit = "deg" }

[data.table]
file = "angles.csv"
columns = { A = "deg", Y = "mm" }

[definitions]
"f(phi)" = "sin(phi)"
"g(phi)" = "cos(phi)"
call = "f(90)"
call_pi = "f(pi/2)"
top = { expr = "argmax(f(phi), phi, 0, 180)", unit = "deg" }
low = { expr = "argmin(g(phi), phi, 90, 270)", unit = "deg" }
half = { expr = "root(g(phi), phi, 0, 120)", unit = "deg" }
near = { expr = "root(g(phi), phi, 80)", unit = "deg" }
area = { expr = "integral(f(phi), phi, 0, 180)", unit = "rad" }
area_pi = { expr = "integral(f(phi), phi, 0, pi)", unit = "rad" }
peak = "maximum(f(phi), phi, 0, 180)"
at45 = { expr = "linterp(A, Y, 45)", unit = "mm" }
"""


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        ("call", 1.0),
        ("call_pi", 1.0),
        ("top", 90.0),
        ("low", 180.0),
        ("half", 90.0),
        ("near", 90.0),
        ("area", 2.0),
        ("area_pi", 2.0),
        ("peak", 1.0),
        ("at45", 45.0),
    ],
)
def test_a_bare_number_where_an_angle_in_degrees_is_wanted_is_in_degrees(
    sheet_from, tmp_path, name, expected
):
    """A bound, a guess, a function's argument, the x of linterp: 180 is 180 deg (it was read
    as 180 rad: argmax of sin over [0, 180] gave 5490 deg); pi/2 stays radians."""
    (tmp_path / "angles.csv").write_text("A,Y\n0,0\n90,90\n", encoding="utf-8")
    sheet = sheet_from(SLOTS, name="slots")
    assert sheet.evaluate(name).magnitude == pytest.approx(expected, rel=1e-8, abs=1e-9)
