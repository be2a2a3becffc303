"""What `workbook run` prints and what the report shows, for people: every result, arrays as
aligned rows, units typeset, a negative substituted value in parentheses."""

from __future__ import annotations

import html
import re

import pytest
from helpers.sheets import write_template

from workbook.cli import main, matrix_lines
from workbook.compute.computed import compute
from workbook.outputs.report import render

MANY = '[inputs]\nx = "2 mm"\n\n[definitions]\n' + "".join(
    f'd{i:02d} = "x*{i}"\n' for i in range(30)
)


@pytest.mark.slow
def test_run_prints_every_result_and_first_n_on_request(tmp_path, capsys):
    path = write_template(tmp_path, MANY)
    assert main(["run", str(path), "--out", str(tmp_path / "m.xlsx")]) == 0
    out = capsys.readouterr().out
    for i in range(30):
        assert f"  d{i:02d} = {2 * i} mm" in out
    assert "more on the Results sheet" not in out
    assert main(["run", str(path), "--out", str(tmp_path / "m.xlsx"), "--first", "5"]) == 0
    out = capsys.readouterr().out
    assert "  d04 = 8 mm" in out and "d05" not in out
    assert "  ... and 25 more on the Results sheet" in out


@pytest.mark.slow
def test_a_negative_first_is_refused(tmp_path, capsys):
    path = write_template(tmp_path, MANY)
    assert main(["run", str(path), "--out", str(tmp_path / "m.xlsx"), "--first", "-1"]) == 2
    assert "--first -1" in capsys.readouterr().err


def test_matrix_lines_align_the_columns():
    lines = matrix_lines("  M = ", [[4.0, 1.25], [-2.0, 3000.0], [0.5, -0.0]], "N/mm")
    assert lines == [
        "  M = [   4  1.25 ] N/mm",
        "      [  -2  3000 ]",
        "      [ 0.5     0 ]",
    ]
    assert matrix_lines("v = ", [[1.0], [22.0]], "") == ["v = [  1 ]", "    [ 22 ]"]
    assert matrix_lines("t = ", [["OK"], [1.0]], "") == ['t = [ "OK" ]', "    [    1 ]"]


def _text(fragment: str) -> str:
    """The report's text as read on the page (tags dropped, spaces joined)."""
    body = html.unescape(re.sub(r"<[^>]+>", "", fragment))
    return re.sub(r"\s+", "", body)


@pytest.fixture(scope="module")
def report(load_text):
    text = """
[sheet]
title = "a wall"

[inputs]
T_in = "22 degC"
T_out = "-8 degC"
h = "25 W/(m^2*K)"
d = "12 um"
R = "4.7 ohm"

[definitions]
dT = "T_in - T_out"
q = { expr = "h*dT", unit = "W/m^2" }
"""
    sheet = load_text(text, name="t")
    return render(compute(sheet))


def test_the_report_typesets_units(report):
    page = _text(report)
    for shown in ("22°C", "−8°C", "W/(m2⋅K)", "12µm", "4.7Ω", "30Δ°C", "750W/m2"):
        assert shown in page, shown
    assert "degC" not in page and "delta_degC" not in page and "ohm" not in page


def test_a_negative_substituted_value_is_in_parentheses(report):
    assert "=22°C−(−8°C)" in _text(report)
