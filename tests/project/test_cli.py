"""The command line as a user runs it (in a subprocess: exit codes and messages)."""

import subprocess
import sys
import tempfile

import openpyxl
import pytest


def run(*args, cwd=None):
    """Run the installed command line from a folder outside the source tree."""
    code = "import sys; from workbook.cli import main; sys.exit(main())"
    return subprocess.run(
        [sys.executable, "-c", code, *args],
        capture_output=True,
        text=True,
        cwd=cwd or tempfile.gettempdir(),
        timeout=300,
    )


def test_list_names_first():
    out = run("list")
    assert out.returncode == 0
    first = out.stdout.splitlines()[0].split("\t")
    assert first[0] and first[1]
    assert any(line.startswith("concave-cam\t") for line in out.stdout.splitlines())


@pytest.mark.slow
def test_run_writes_default_path(tmp_path):
    out = run("run", "concave-cam", cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    path = tmp_path / "reports" / "concave-cam.xlsx"
    assert path.exists()
    assert "wrote reports/concave-cam.xlsx" in out.stdout
    assert "72 of 72 printed values reproduced" in out.stdout
    wb = openpyxl.load_workbook(path)
    assert wb.sheetnames[:2] == ["Inputs", "Definitions"]
    assert {"Listing", "Charts", "Checks", "About"} <= set(wb.sheetnames)


@pytest.mark.slow
def test_run_with_set_and_out(tmp_path):
    target = tmp_path / "r3.xlsx"
    out = run("run", "concave-cam", "--set", "R3=40 mm", "--out", str(target))
    assert out.returncode == 0, out.stderr
    ws = openpyxl.load_workbook(target)["Inputs"]
    row = next(r for r in ws.iter_rows(values_only=True) if r[0] == "R3")
    assert row[1] == 40 and row[2] == "mm"
    about = openpyxl.load_workbook(target)["About"]
    texts = [c.value for row in about.iter_rows() for c in row if c.value]
    assert any('--set R3="40 mm"' in str(t) for t in texts)


@pytest.mark.slow
def test_check_exit_codes(tmp_path):
    ok = run("check", "concave-cam")
    assert ok.returncode == 0
    assert "misprint" in ok.stdout and "all printed values reproduced" in ok.stdout
    bad = run("check", "concave-cam", "--set", "R3=51 mm")
    assert bad.returncode == 1
    assert "NOT reproduced" in bad.stdout


@pytest.mark.slow
def test_bad_input_exit_2_without_traceback():
    out = run("run", "concave-cam", "--set", "R3=40 kg")
    assert out.returncode == 2
    assert "Traceback" not in out.stderr
    assert "R3" in out.stderr and "[mass]" in out.stderr and "[length]" in out.stderr
    out = run("check", "no-such-template")
    assert out.returncode == 2 and "no template named" in out.stderr


@pytest.mark.slow
def test_export_profile_csv_for_cad(tmp_path):
    out = run(
        "run",
        "reducer-profile",
        "--out",
        str(tmp_path / "r.xlsx"),
        "--export",
        str(tmp_path / "profile.csv"),
    )
    assert out.returncode == 0, out.stderr
    lines = (tmp_path / "profile.csv").read_text().splitlines()
    assert lines[0] == "x_mm,y_mm,z_mm"
    x, y, z = map(float, lines[1].split(","))
    assert (x, y, z) == (46.0, 0.0, 0.0)  # reference example: x_k = 46, y_k = 0 at phi = 0
    undercut = run(
        "run",
        "reducer-profile",
        "--set",
        "rp=7.6 mm",
        "--out",
        str(tmp_path / "u.xlsx"),
        "--export",
        str(tmp_path / "u.csv"),
    )
    assert undercut.returncode == 2 and "undercut" in undercut.stderr
    assert not (tmp_path / "u.csv").exists()
    none = run(
        "run", "concave-cam", "--out", str(tmp_path / "c.xlsx"), "--export", str(tmp_path / "c.csv")
    )
    assert none.returncode == 2 and "has no export" in none.stderr


@pytest.mark.slow
def test_a_bug_in_a_block_is_exit_3_in_one_line(tmp_path, monkeypatch, capsys):
    """An exception that is not a WorkbookError (a bug, not a user mistake): one line, exit 3,
    the previous output untouched; --debug shows the traceback."""
    from workbook import blocks
    from workbook.cli import main

    out = tmp_path / "valve.xlsx"
    args = ["run", "cam-wear-valve", "--out", str(out)]
    assert main(args) == 0
    before = out.read_bytes()
    blocks.get("wear.measured_findings")  # registers the module's blocks

    def broken(sheet):
        return 1 / 0

    monkeypatch.setattr(blocks.get("wear.measured_findings"), "func", broken)
    capsys.readouterr()
    assert main(args) == 3
    err = capsys.readouterr().err
    assert err.startswith("workbook: internal error (ZeroDivisionError: division by zero)")
    assert len(err.strip().splitlines()) == 1
    assert out.read_bytes() == before
    with pytest.raises(ZeroDivisionError):
        main(["--debug", *args])
    with pytest.raises(ZeroDivisionError):  # after the subcommand too, as the message says
        main([*args, "--debug"])
