"""Round trip: edit the Inputs sheet of a generated workbook, run again with --inputs.

The reference is the API: ``sheet.with_inputs(R3=...)`` must give what the regenerated
workbook holds, cell for cell (cached values read with openpyxl).
"""

import shutil

import numpy as np
import openpyxl
import pytest
from helpers.sheets import write_template

import workbook
from workbook.cli import main
from workbook.roundtrip import changed_inputs, read_inputs, with_inputs_from


def _row(ws, name: str) -> int:
    for row in range(2, ws.max_row + 1):
        if ws.cell(row, 1).value == name:
            return row
    raise KeyError(name)


def edit(src, dst, **changes):
    """Copy ``src`` and set Inputs values (value or (value, unit)) with openpyxl."""
    shutil.copy(src, dst)
    wb = openpyxl.load_workbook(dst)
    ws = wb["Inputs"]
    for name, value in changes.items():
        row = _row(ws, name)
        if isinstance(value, tuple):
            ws.cell(row, 2).value, ws.cell(row, 3).value = value
        else:
            ws.cell(row, 2).value = value
    wb.save(dst)
    return dst


def table_values(path, sheet_name: str, title: str) -> np.ndarray:
    """The cached values of the table under ``title`` (until the first empty row)."""
    ws = openpyxl.load_workbook(path, data_only=True)[sheet_name]
    rows = list(ws.iter_rows(values_only=True))
    start = next(i for i, r in enumerate(rows) if r[0] == title) + 2
    out = []
    for r in rows[start:]:
        if r[0] is None:
            break
        out.append([v for v in r if v is not None])
    return np.array(out, dtype=float)


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    path = tmp_path_factory.mktemp("rt") / "concave-cam.xlsx"
    assert main(["run", "concave-cam", "--out", str(path)]) == 0
    return path


@pytest.mark.slow
def test_edited_R3_gives_what_with_inputs_gives(tmp_path, generated, concave, capsys):
    edited = edit(generated, tmp_path / "edited.xlsx", R3=45)
    out = tmp_path / "again.xlsx"
    assert main(["run", "concave-cam", "--inputs", str(edited), "--out", str(out)]) == 0
    expected = concave.with_inputs(R3="45 mm")
    for name, title in (
        ("flank_AB", "Concave flank AB: phi := 0, 5 .. 22"),
        ("nose_BB", "Nose BB': phi := 22, 27 .. 82"),
    ):
        got = table_values(out, "Listing", title)
        want = expected.table(name).to_numpy()
        assert got.shape == want.shape
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)
    # the new workbook shows the edited input, and its About sheet a command without the file
    wb = openpyxl.load_workbook(out, data_only=True)
    assert wb["Inputs"].cell(_row(wb["Inputs"], "R3"), 2).value == 45
    about = {r[0]: r[1] for r in wb["About"].iter_rows(values_only=True) if r[0]}
    assert about["Regenerate with"] == 'workbook run concave-cam --set R3="45.0 mm"'
    # R3 = 45 mm moves the flank: the lift at 20 deg is not the template's any more
    assert expected.evaluate("h1", 20).magnitude != pytest.approx(
        concave.evaluate("h1", 20).magnitude, abs=1e-3
    )


@pytest.mark.slow
def test_a_changed_unit_is_converted(tmp_path, generated, concave):
    edited = edit(generated, tmp_path / "cm.xlsx", R3=(4.5, "cm"), omega=(1000, "rpm"))
    sheet = with_inputs_from(concave, edited)
    assert sheet.values["R3"].to("mm").magnitude == pytest.approx(45.0, rel=1e-15)
    assert sheet.values["omega"].to("1/s").magnitude == pytest.approx(1000 * 2 * np.pi / 60)
    assert set(changed_inputs(concave, edited)) == {"R3", "omega"}


def test_unchanged_workbook_changes_nothing(generated, concave):
    assert changed_inputs(concave, generated) == {}
    values = read_inputs(concave, generated)
    assert set(values) == set(concave.spec.inputs)
    assert values["phi_n"].magnitude == 38  # a plain number shown with the label deg


@pytest.mark.slow
@pytest.mark.parametrize(
    "change, message",
    [
        ({"R3": (45, "kg")}, "Inputs!B"),
        ({"R3": -5}, "must be positive"),
        ({"R3": "forty"}, "cannot read"),
        ({"R3": (45, None)}, "dimensionless, but R3 is [length]"),
    ],
)
def test_bad_edits_are_refused_like_set(tmp_path, generated, capsys, change, message):
    edited = edit(generated, tmp_path / "bad.xlsx", **change)
    out = tmp_path / "never.xlsx"
    assert main(["run", "concave-cam", "--inputs", str(edited), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert message in err and "bad.xlsx" in err
    assert not out.exists()


@pytest.mark.slow
def test_unknown_rows_and_missing_files(tmp_path, generated, capsys):
    edited = tmp_path / "extra.xlsx"
    shutil.copy(generated, edited)
    wb = openpyxl.load_workbook(edited)
    wb["Inputs"].insert_rows(2)
    wb["Inputs"]["A2"], wb["Inputs"]["B2"], wb["Inputs"]["C2"] = "R9", 1, "mm"
    wb.save(edited)
    assert (
        main(["run", "concave-cam", "--inputs", str(edited), "--out", str(tmp_path / "x.xlsx")])
        == 2
    )
    assert "'R9' is not an input of concave-cam" in capsys.readouterr().err
    assert main(["run", "concave-cam", "--inputs", str(tmp_path / "nope.xlsx")]) == 2
    assert "no such file" in capsys.readouterr().err
    (tmp_path / "text.xlsx").write_text("not a workbook")
    assert main(["run", "concave-cam", "--inputs", str(tmp_path / "text.xlsx")]) == 2
    assert "cannot read it as an xlsx workbook" in capsys.readouterr().err


@pytest.mark.slow
def test_set_wins_over_the_edited_file(tmp_path, generated, concave):
    edited = edit(generated, tmp_path / "e.xlsx", R3=45)
    out = tmp_path / "o.xlsx"
    assert (
        main(
            ["run", "concave-cam", "--inputs", str(edited), "--set", "R3=55 mm", "--out", str(out)]
        )
        == 0
    )
    wb = openpyxl.load_workbook(out, data_only=True)
    assert wb["Inputs"].cell(_row(wb["Inputs"], "R3"), 2).value == 55


SOLVER = """
[sheet]
title = "steady weight angle (a root: values, not formulas)"

[inputs]
m = "0.7 kg"
c1 = { value = "3000 N/m", positive = true }
phi20 = "0.5236 rad"
lam_st = "1 mm"
O1O = "42 mm"
OC = "36 mm"
OC1 = "52 mm"
OB = "15 mm"
O1B = "40 mm"
tan_gamma = "0.3333333333333333"
M_D0 = "1.2 N*m"

[arguments]
omega1 = { unit = "rad/s" }
phi = { unit = "rad" }

[definitions]
"Fc(phi, omega1)" = { unit = "N*m", expr = "2*m*omega1^2*(O1O - OC*cos(phi))*OC*sin(phi)" }
"Fs(phi)" = { unit = "N*m", expr = "8*c1*(lam_st + OC1*(cos(phi20) - cos(phi)))*OC1*sin(phi)" }
"F(phi, omega1)" = { unit = "N*m", expr = "Fc(phi, omega1) - Fs(phi) - M_D0*OB/O1B*tan_gamma" }
"phi2(omega1)" = { unit = "rad", expr = "root(F(phi, omega1), phi, phi20, pi + 0*phi20) - phi20" }

[[tables]]
name = "steady"
title = "phi2 over omega1"
range = "omega1 := 60, 70 .. 110"
columns = { phi2 = "rad" }
"""


@pytest.mark.slow
def test_the_parts_that_are_not_formulas_are_regenerated(tmp_path):
    path = write_template(tmp_path, SOLVER, "solver.toml")
    first = tmp_path / "first.xlsx"
    assert main(["run", str(path), "--out", str(first)]) == 0
    edited = edit(first, tmp_path / "edited.xlsx", c1=2000)
    out = tmp_path / "again.xlsx"
    assert main(["run", str(path), "--inputs", str(edited), "--out", str(out)]) == 0
    sheet = workbook.load(path)
    want = sheet.with_inputs(c1="2000 N/m").table("steady").to_numpy()
    got = table_values(out, "Listing", "phi2 over omega1")
    np.testing.assert_allclose(got, want, rtol=1e-14)
    old = table_values(first, "Listing", "phi2 over omega1")
    assert np.all(got[1:, 1] > old[1:, 1])  # a softer spring: the weights swing out further


@pytest.mark.slow
def test_a_workbook_saved_by_libreoffice_reads_back(tmp_path, generated, concave):
    recalc = pytest.importorskip("helpers.recalc")
    if recalc.soffice() is None:
        pytest.skip("LibreOffice is not installed")
    edited = edit(generated, tmp_path / "edited.xlsx", R3=45)
    saved = recalc.recalculate(edited, tmp_path / "lo")
    assert changed_inputs(concave, saved) == {"R3": "45.0 mm"}
    # and LibreOffice's recalculated listing is what with_inputs computes
    got = table_values(saved, "Listing", "Concave flank AB: phi := 0, 5 .. 22")
    want = concave.with_inputs(R3="45 mm").table("flank_AB").to_numpy()
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9)
