"""Optional parts: `workbook run` computes, imports and writes only what is asked for."""

import subprocess
import sys

import openpyxl
import pytest

import workbook
from workbook.cli import main
from workbook.errors import InputError, TemplateError

HEAVY = ("sympy", "mpmath", "pandas")
RUN_AND_LIST_MODULES = """
import sys
from workbook.cli import main
rc = main(["run", "concave-cam", "--out", sys.argv[1], *sys.argv[2:]])
print(rc, ",".join(m for m in {heavy!r} if m in sys.modules) or "-")
"""


def _fresh_run(out, *extra) -> tuple[int, str]:
    code = RUN_AND_LIST_MODULES.format(heavy=HEAVY)
    done = subprocess.run(
        [sys.executable, "-c", code, str(out), *extra], capture_output=True, text=True, check=True
    )
    rc, modules = done.stdout.splitlines()[-1].split()
    return int(rc), modules


def _about(path) -> dict:
    return {r[0]: r[1] for r in openpyxl.load_workbook(path)["About"].iter_rows(values_only=True)}


@pytest.mark.slow
def test_plain_run_leaves_out_the_hand_checks_and_their_imports(tmp_path):
    rc, modules = _fresh_run(tmp_path / "cc.xlsx")
    assert rc == 0 and modules == "-"
    wb = openpyxl.load_workbook(tmp_path / "cc.xlsx")
    assert "Hand checks" not in wb.sheetnames and "Derivatives" not in wb.sheetnames
    topics = {r[0] for r in wb["Checks"].iter_rows(values_only=True)}
    assert "relations" not in topics and "stability" not in topics
    about = _about(tmp_path / "cc.xlsx")
    left_out = "left out (not computed); add it with --part hand-checks"
    assert about["Part hand-checks"].endswith(left_out)
    assert about["Regenerate with"] == "workbook run concave-cam"


@pytest.mark.slow
def test_part_adds_the_hand_checks(tmp_path):
    rc, modules = _fresh_run(tmp_path / "cc.xlsx", "--part", "hand-checks")
    # the relations need sympy (and with it mpmath); the hand checks are template formulas
    assert rc == 0 and set(modules.split(",")) == {"sympy", "mpmath"}
    wb = openpyxl.load_workbook(tmp_path / "cc.xlsx")
    assert {"Hand checks", "Derivatives"} <= set(wb.sheetnames)
    topics = {r[0] for r in wb["Checks"].iter_rows(values_only=True)}
    assert {"relations", "joins", "stability", "derivatives"} <= topics
    about = _about(tmp_path / "cc.xlsx")
    assert about["Part hand-checks"].endswith(": included")
    assert about["Regenerate with"] == "workbook run concave-cam --part hand-checks"


@pytest.mark.slow
def test_parts_do_not_change_the_main_tables(tmp_path):
    plain = workbook.load("concave-cam")
    whole = plain.with_parts("all")
    for table in ("flank_AB", "nose_BB", "flank_BA", "curves"):
        a, b = plain.table_data(table), whole.table_data(table)
        for ca, cb in zip(a.columns, b.columns, strict=True):
            assert (ca.values == cb.values).all()
    assert [r.computed for r in plain.check().rows] == [r.computed for r in whole.check().rows]


@pytest.mark.slow
def test_selection_survives_new_inputs():
    sheet = workbook.load("concave-cam", parts="all")
    assert sheet.with_inputs(R3="45 mm").parts == {"hand-checks"}
    assert workbook.load("concave-cam").with_inputs(R3="45 mm").left_out == ["hand-checks"]
    assert len(sheet.with_parts().spec.relations) == 0
    assert len(sheet.spec.relations) == 7


@pytest.mark.slow
def test_unknown_part_is_an_input_error(tmp_path, capsys):
    with pytest.raises(InputError, match=r"no part 'nope' \(parts: hand-checks; or 'all'\)"):
        workbook.load("concave-cam", parts="nope")
    assert main(["run", "concave-cam", "--part", "nope", "--out", str(tmp_path / "x.xlsx")]) == 2
    assert "no part 'nope'" in capsys.readouterr().err
    assert not (tmp_path / "x.xlsx").exists()


@pytest.mark.slow
def test_a_table_of_a_left_out_part_names_the_part(tmp_path, capsys):
    with pytest.raises(InputError, match="in the optional part hand-checks of concave-cam"):
        workbook.load("concave-cam").table("stability")
    out = tmp_path / "cc.xlsx"
    assert main(["run", "concave-cam", "--csv", "stability", "--out", str(out)]) == 2
    assert "add it with --part hand-checks" in capsys.readouterr().err
    assert not out.exists()
    args = ["run", "concave-cam", "--part", "hand-checks", "--csv", "stability", "--out", str(out)]
    assert main(args) == 0
    assert (tmp_path / "cc.stability.csv").read_text().startswith("e,phi [deg],")


BASE = """
[inputs]
R = "10 mm"
S = "2 mm"

[arguments]
phi = { unit = "deg" }

[definitions]
"y(phi)" = "R*sin(phi)"
"""


def test_undeclared_part_names_the_line(sheet_from):
    text = BASE + '\n[[tables]]\nname = "t"\npart = "study"\nrange = "phi := 0 .. 9"\n'
    text += 'columns = { y = "mm" }\n'
    with pytest.raises(TemplateError, match="part = 'study' is not declared") as err:
        sheet_from(text)
    assert err.value.line == text.splitlines().index('name = "t"') + 1


def test_bad_part_name(sheet_from):
    text = BASE + '\n[parts]\nall = "everything"\n'
    with pytest.raises(TemplateError, match="not 'all'"):
        sheet_from(text)


@pytest.mark.parametrize(
    "extra,message",
    [
        (  # a chart drawing a block table of a part must be in the part
            '[[tables]]\nname = "b"\npart = "study"\nblock = "wear.measured_lift"\n\n'
            '[[charts]]\nname = "c"\n'
            'series = [{ table = "b", x = "phi [deg]", y = "h measured [mm]" }]\n',
            'give the chart part = "study" too',
        ),
        (  # units are checked in every part, chosen or not
            '[[tables]]\nname = "t"\npart = "study"\nrange = "phi := 0 .. 9"\n'
            'columns = { "y(phi) + 1" = "mm" }\n',
            "unit",
        ),
    ],
)
def test_a_part_is_checked_at_load_even_when_left_out(sheet_from, extra, message):
    text = BASE + '\n[parts]\nstudy = "a study"\n\n' + extra
    with pytest.raises(workbook.WorkbookError, match=message):
        sheet_from(text)


def test_an_input_used_only_by_a_part_is_not_unused(sheet_from):
    text = BASE + (
        '\n[parts]\nstudy = "a study"\n\n[[tables]]\nname = "t"\npart = "study"\n'
        'range = "phi := 0 .. 9"\ncolumns = { "y(phi) + S" = "mm" }\n'
    )
    sheet = sheet_from(text)
    assert sheet.spec.tables == [] and sheet.unused_inputs() == []


SCENE_PARTS = {
    "concave-cam": {"hand-checks"},
    "concave-cam-geometry": {"hand-checks"},
    "r0-synthesis": {"studies"},
    "advance-coupling": {"studies"},
    "cam-wear-valve": {"studies"},
}


@pytest.mark.parametrize("name", sorted(SCENE_PARTS))
def test_scene_parts_are_left_out_by_default(name):
    plain = workbook.load(name)
    whole = plain.with_parts("all")
    assert set(plain.full_spec.parts) == SCENE_PARTS[name] == set(plain.left_out)
    assert whole.left_out == []
    for section in ("tables", "charts", "printed", "relations"):
        in_part = [x for x in getattr(whole.spec, section) if x.part]
        assert all(x.part is None for x in getattr(plain.spec, section))
        assert len(getattr(plain.spec, section)) + len(in_part) == len(getattr(whole.spec, section))
    assert all("part" not in f for f in plain.spec.findings)


@pytest.mark.slow  # seconds of CPU: run by CI with the slow tests
def test_coupling_without_its_studies(tmp_path):
    out = tmp_path / "ac.xlsx"
    assert main(["run", "advance-coupling", "--out", str(out)]) == 0
    wb = openpyxl.load_workbook(out)
    assert "Solvers" not in wb.sheetnames and {"Families", "Dynamics"} <= set(wb.sheetnames)
    topics = {r[0] for r in wb["Checks"].iter_rows(values_only=True)}
    assert "solver choice" not in topics and "dynamics" in topics
