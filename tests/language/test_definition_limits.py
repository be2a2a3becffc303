"""Definitions that declare what their values must meet (positive, min, max), and the
templates' physical limits at extreme inputs."""

from __future__ import annotations

import contextlib
import io
import os

import pytest
from helpers.sheets import write_template

from workbook.cli import main
from workbook.errors import DomainError, UnitError

SHEET = """
[inputs]
d = "40 mm"
d_stem = "8 mm"
L = "900 mm"

[arguments]
x = { unit = "mm" }

[definitions]
A_port = { expr = "pi/4*(d^2 - d_stem^2)", unit = "mm^2", positive = true }
gap = { expr = "d - d_stem", unit = "mm", min = "0" }
L_max = { expr = "L", unit = "mm", max = "1 m" }
"f(x)" = { expr = "d - x", unit = "mm", min = "0 mm" }

[[tables]]
name = "t"
range = "x := 0, 10 .. 60"
columns = { f = "mm" }
"""


def _cli(tmp_path, *args) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(list(args))
    finally:
        os.chdir(cwd)
    return code, out.getvalue(), err.getvalue()


def test_values_inside_their_limits_are_numbers(sheet_from):
    sheet = sheet_from(SHEET)
    assert sheet.evaluate("A_port").to("mm^2").magnitude == pytest.approx(1206.3715789784806)
    assert sheet.evaluate("L_max").to("mm").magnitude == 900


def test_a_scalar_outside_its_limit_is_an_error_naming_it(sheet_from):
    sheet = sheet_from(SHEET).with_inputs(d_stem="50 mm")
    with pytest.raises(DomainError, match=r"A_port = -706\.858 mm\^2 breaks its declared limit"):
        sheet.evaluate("A_port")
    with pytest.raises(DomainError, match=r"gap = -10 mm breaks its declared limit \(at least 0"):
        sheet.evaluate("gap")


def test_a_limit_in_another_unit_is_converted(sheet_from):
    sheet = sheet_from(SHEET).with_inputs(L="1.5 m")
    with pytest.raises(DomainError, match=r"L_max = 1500 mm breaks its declared limit"):
        sheet.evaluate("L_max")
    assert sheet.with_inputs(L="1 m").evaluate("L_max").to("mm").magnitude == 1000


def test_a_function_names_the_arguments_where_it_breaks_its_limit(sheet_from):
    sheet = sheet_from(SHEET)
    with pytest.raises(DomainError, match=r"f = -10 mm for x = 50 mm breaks its declared"):
        sheet.evaluate("f", 50)
    col = sheet.table_data("t").columns[1]
    assert sorted(col.failed) == [5, 6]  # 50 and 60 mm: error cells, the other rows values
    assert col.values[:5].tolist() == [40, 30, 20, 10, 0]


def test_a_limit_of_another_dimension_is_refused_at_load(sheet_from):
    text = SHEET.replace('max = "1 m"', 'max = "1 s"')
    with pytest.raises(UnitError, match="the limit 1 s is"):
        sheet_from(text)


@pytest.mark.slow
def test_run_stops_at_a_negative_port_area_of_the_valve(tmp_path):
    code, out, err = _cli(tmp_path, "run", "cam-wear-valve", "--set", "d_stem=50 mm")
    assert code != 0 and "reproduced" not in out
    assert "A_port = -706.858 mm^2 breaks its declared limit (positive)" in err


@pytest.mark.slow
def test_the_valve_at_89_degrees_names_the_value_that_fails(tmp_path):
    code, _, err = _cli(tmp_path, "run", "cam-wear-valve", "--set", "alpha=89 deg")
    assert code == 1
    assert "fail: [failed values] phi_lim has no value" in err


def test_a_sweep_checks_the_limits_case_by_case(tmp_path):
    """The vector sweep computes scalar definitions without a Sheet; one with declared limits
    makes the cases run one by one, so a case that breaks them fails instead of a number."""
    code, out, _ = _cli(
        tmp_path,
        "sweep",
        str(write_template(tmp_path, SHEET)),
        "--vary",
        "d_stem=30mm..50mm:3",
        "--output",
        "A=2*A_port",
        "--out",
        "s.csv",
    )
    assert code == 0 and "serial" in out and "2 failed" in out
    rows = (tmp_path / "s.csv").read_text().splitlines()
    assert rows[1].startswith("30.0,1099.557428756")
    assert rows[3].startswith("50.0,,A_port = -706.858 mm^2 breaks its declared limit")
