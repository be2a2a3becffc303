"""[[checks]]: findings written in the worksheet, typed at load, computed at check time."""

from __future__ import annotations

import openpyxl
import pytest

import workbook
from workbook.cli import main

BASE = """
[inputs]
F = "12 kN"
L = "2 m"
W = "50000 mm^3"
f_y = "235 MPa"

[definitions]
M = "F*L/4"
sigma = { expr = "M/W", unit = "MPa" }

[arguments]
x = { unit = "m" }
"""


def sheet_with(tmp_path, checks: str, extra: str = ""):
    path = tmp_path / "beam.toml"
    path.write_text(BASE + extra + checks, encoding="utf-8")
    return path


def findings(path):
    return {f.what: f for f in workbook.load(path).check().findings}


def test_value_condition_and_placeholders_against_hand_numbers(tmp_path):
    path = sheet_with(
        tmp_path,
        """
[[checks]]
topic = "bending"
what = "M = {M:kN*m}, sigma = {sigma}, {{braces}}"
value = "sigma"
unit = "N/mm^2"
ok = "sigma <= f_y"
""",
    )
    (f,) = findings(path).values()
    m = 12 * 2 / 4  # kN*m
    sigma = m * 1e6 / 50000  # N*mm / mm^3
    assert f.what == f"M = {m:.6g} kN*m, sigma = {sigma:.6g} MPa, {{braces}}"
    assert f.value == pytest.approx(sigma, rel=1e-14)
    assert (f.unit, f.verdict, f.topic) == ("N/mm^2", "ok", "bending")


def test_a_choice_input_in_a_placeholder_is_its_text(tmp_path):
    choice = '[inputs.mode]\nvalue = "simple"\noptions = ["simple", "fixed"]\n'
    path = sheet_with(tmp_path, '[[checks]]\nwhat = "{mode} beam"\nvalue = "M"\n', choice)
    assert list(findings(path)) == ["simple beam"]
    with pytest.raises(workbook.errors.TemplateError, match="is a text, it has no unit"):
        workbook.load(sheet_with(tmp_path, '[[checks]]\nwhat = "{mode:mm}"\nvalue = "M"\n', choice))


def test_condition_false_gives_otherwise_and_inputs_change_only_that_line(tmp_path):
    path = sheet_with(
        tmp_path,
        """
[[checks]]
what = "at 24 kN"
value = "sigma"
ok = "sigma <= f_y"
inputs = { F = "24 kN" }

[[checks]]
what = "as given"
value = "sigma"
ok = "sigma <= f_y"
otherwise = "warning"
""",
    )
    got = findings(path)
    assert got["at 24 kN"].verdict == "fail"
    assert got["at 24 kN"].value == pytest.approx(240.0, rel=1e-14)
    assert got["as given"].verdict == "ok"
    assert got["as given"].value == pytest.approx(120.0, rel=1e-14)


def test_example_only_lines_leave_with_changed_inputs(tmp_path):
    path = sheet_with(
        tmp_path,
        """
[[checks]]
what = "listed example"
value = "M"
example_only = true
""",
    )
    sheet = workbook.load(path)
    assert [f.what for f in sheet.check().findings] == ["listed example"]
    assert sheet.check().findings[0].verdict == "info"
    assert sheet.with_inputs(F="13 kN").check().findings == []


def test_a_value_that_cannot_be_computed_is_the_otherwise_verdict_with_the_reason(tmp_path):
    path = sheet_with(
        tmp_path,
        """
[[checks]]
what = "root of nothing"
value = "root(x^2 + L^2, x, 0, L)"
otherwise = "warning"
""",
    )
    (f,) = findings(path).values()
    assert f.verdict == "warning" and f.value is None
    assert "sign" in f.note


def test_a_failing_check_makes_run_exit_1_and_is_on_the_checks_sheet(tmp_path, capsys):
    path = sheet_with(
        tmp_path,
        """
[[checks]]
topic = "bending"
what = "stress at three times the load"
value = "sigma"
ok = "sigma <= f_y"
inputs = { F = "36 kN" }
""",
    )
    out = tmp_path / "beam.xlsx"
    assert main(["run", str(path), "--out", str(out)]) == 1
    assert "stress at three times the load" in capsys.readouterr().err
    cells = [c.value for row in openpyxl.load_workbook(out)["Checks"].iter_rows() for c in row]
    assert "stress at three times the load" in cells


def test_a_check_in_a_part_is_left_out_unless_chosen(tmp_path):
    path = sheet_with(
        tmp_path,
        """
[parts]
extra = { title = "More checks" }

[[checks]]
what = "in a part"
value = "M"
part = "extra"
""",
    )
    assert workbook.load(path).check().findings == []
    assert [f.what for f in workbook.load(path, parts="all").check().findings] == ["in a part"]


@pytest.mark.slow
@pytest.mark.parametrize(
    ("check", "message"),
    [
        ('what = "x"\nvalue = "sigma"\nunits = "MPa"', "unknown key 'units'"),
        ('what = "x"\nvalue = "sigma"\nunit = "kN"', "cannot show"),
        ('what = "x"\nok = "sigma"', "ok must be a condition"),
        ('what = "x"\nvalue = "sigma"\notherwise = "bad"', "otherwise = 'bad'"),
        ('what = "x"', "needs value = EXPR, ok = CONDITION or both"),
        ('what = "sigma is {sigmaa}"\nvalue = "M"', "sigma"),
        ('what = "x {M:mm}"\nvalue = "M"', "cannot show"),
        ('what = "x"\nvalue = "M"\ninputs = { G = "1 kN" }', "'G' is not an input"),
        ('what = "x"\nvalue = "M"\ninputs = { F = "1 m" }', "F"),
        ('what = "x"\nvalue = "[1, 2]*M"', "one number"),
    ],
)
def test_mistakes_are_refused_at_load_with_file_and_line(tmp_path, capsys, check, message):
    path = sheet_with(tmp_path, "\n[[checks]]\n" + check + "\n")
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert message in err and str(path) in err
    header = path.read_text().splitlines().index("[[checks]]") + 1
    assert f"{path}:{header}:" in err or f"{path}:{header}, in 'check " in err


def test_example_only_names_the_inputs_of_the_example(tmp_path):
    path = sheet_with(
        tmp_path,
        """
[[checks]]
what = "listed for this load"
value = "M"
example_only = ["F", "L"]

[[checks]]
what = "listed at 24 kN"
value = "M"
inputs = { F = "24 kN" }
example_only = true
""",
    )
    sheet = workbook.load(path)
    both = ["listed for this load", "listed at 24 kN"]
    assert [f.what for f in sheet.check().findings] == both
    assert [f.what for f in sheet.with_inputs(W="1 cm^3").check().findings] == [
        "listed for this load"
    ]
    # the second check sets F itself: another F leaves it
    assert [f.what for f in sheet.with_inputs(F="1 kN").check().findings] == ["listed at 24 kN"]


def test_example_only_with_an_unknown_input_is_refused(tmp_path, capsys):
    path = sheet_with(tmp_path, '\n[[checks]]\nwhat = "x"\nvalue = "M"\nexample_only = ["FF"]\n')
    assert main(["check", str(path)]) == 2
    assert "'FF' is not an input (did you mean F?)" in capsys.readouterr().err


def test_an_input_a_check_or_a_result_uses_is_not_reported_unused(tmp_path):
    path = sheet_with(
        tmp_path,
        """
[[checks]]
what = "stress at {F:kN}"
ok = "sigma <= f_y"
""",
        extra='[inputs.spare]\nvalue = "1 mm"\n',
    )
    # f_y only in the check, F W L through sigma (a result on the Results sheet); spare nowhere
    assert workbook.load(path).unused_inputs() == ["spare"]


def test_a_bare_number_shown_in_degrees_is_degrees(tmp_path):
    path = sheet_with(
        tmp_path, '\n[[checks]]\nwhat = "a right angle: {90:deg}"\nvalue = "90"\nunit = "deg"\n'
    )
    (f,) = findings(path).values()
    assert f.what == "a right angle: 90 deg" and f.value == 90.0
