"""A value whose built-in's error estimate is far above the sheet's tolerance is a warning that
run and check print (workbook.numerics.estimates), never kept silent."""

from __future__ import annotations

import pytest

import workbook
from workbook.numerics.estimates import ESTIMATE_LIMIT

SHEET = """
[sheet]
name = "estimates"

[arguments]
x = {}

[definitions]
smooth = "integral(exp(-x^2), x, 0, 1)"
flat = "maximum(sin(x), x, 0, 3)"
"""


def _estimates(sheet) -> dict:
    return {f.topic: f for f in sheet.check().findings if f.topic.startswith("estimate ")}


def test_certain_values_give_no_estimate_warning(tmp_path):
    sheet = workbook.loads(SHEET, folder=tmp_path)
    assert sheet.evaluate("smooth").magnitude == pytest.approx(0.746824132812427)
    assert _estimates(sheet) == {}


def test_an_estimate_far_above_the_tolerance_is_a_warning_naming_the_definition():
    # the branch and bound of j_exact_max cannot close its gap: its estimate is about the
    # size of the value, which check and run must say
    sheet = workbook.load("concave-cam-geometry")
    found = _estimates(sheet)
    assert "estimate j_exact_max" in found, sorted(found)
    finding = found["estimate j_exact_max"]
    assert finding.verdict == "warning"
    assert "maximum: error estimate" in finding.what
    assert f"over {ESTIMATE_LIMIT:g} times the sheet's tolerance" in finding.note


@pytest.mark.slow
def test_the_findings_do_not_depend_on_what_was_written_before(tmp_path):
    # the writer's own evaluations (live forms) repeat the definitions' built-ins: they must
    # not add findings to the next check
    sheet = workbook.load("concave-cam-geometry")
    before = sorted(_estimates(sheet))
    sheet.write_xlsx(tmp_path / "once.xlsx")
    assert sorted(_estimates(sheet)) == before


def test_a_value_that_is_zero_is_not_measured_against_zero(tmp_path):
    # the integral of a full period of a sine is 0 and a maximum of -(x - 0.3)^2 is 0: their
    # estimates (rounding, and branch and bound's rtol times the function's size) were
    # "relative inf" warnings
    text = """
[arguments]
x = {}

[definitions]
period = "integral(1000*sin(x), x, 0, 2*pi)"
top = "maximum(-(x - 0.3)^2*1000, x, -10, 10)"
"""
    sheet = workbook.loads(text, folder=tmp_path)
    assert abs(sheet.evaluate("period").magnitude) < 1e-9
    assert sheet.evaluate("top").magnitude == pytest.approx(0.0, abs=1e-6)
    assert _estimates(sheet) == {}
