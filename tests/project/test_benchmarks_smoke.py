"""The benchmarks at tiny sizes (so they cannot rot), and the limits they rely on.

The timing targets are not asserted here: the full run (`python benchmarks/run.py`) checks
them. These tests only show that every benchmark runs and measures the same thing on both
sides, that over-long tables are refused with a pointer to CSV, and that a template's unit
check happens once, at load.
"""

import subprocess
import sys

import numpy as np
import pytest
from helpers.paths import ROOT

import workbook
from workbook.errors import LimitError
from workbook.language import typecheck as tc

BENCH = ROOT / "benchmarks"
sys.path.insert(0, str(BENCH))

import bench_builtins  # noqa: E402
import bench_coldstart  # noqa: E402
import bench_evaluate  # noqa: E402
import bench_import  # noqa: E402
import bench_livecheck  # noqa: E402
import bench_load  # noqa: E402
import bench_write  # noqa: E402


def _check(results, n):
    assert len(results) == n
    for r in results:
        assert r.value > 0 and r.target > 0
        assert f"target <= {r.target:g}" in r.line()


@pytest.mark.slow
@pytest.mark.skipif(not bench_import.FOLDERS[0].is_dir(), reason="../shared/mathcad is absent")
def test_import_bench_tiny():
    _check(bench_import.run(reps=1, only={"wind-load"}), 1)


@pytest.mark.slow
def test_livecheck_bench_tiny():
    _check(bench_livecheck.run(n=20, rows=20, reps=1, templates=["concave-cam"]), 4)


@pytest.mark.slow
def test_builtins_bench_tiny():
    _check(bench_builtins.run(n=200, reps=1), 4)


def test_evaluate_bench_tiny():
    _check(bench_evaluate.run(n=500, reps=1), 3)


def test_plain_numpy_matches_the_sheet():
    """The hand-written side computes what the template does (else the ratio means nothing)."""
    sheet = workbook.load("concave-cam")
    phi = np.array([0.0, 5.0, 22.0, 47.0, 82.0, 83.0, 104.0])
    for e, p in zip(bench_evaluate.engine_hvj(sheet, phi), bench_evaluate.plain_hvj(phi)):
        np.testing.assert_allclose(e, p, rtol=1e-12, atol=1e-12)
    # one printed value of the paper, as an anchor: h1(5) = 0.202 mm (Mathcad listing)
    assert bench_evaluate.h1(np.array([5.0]))[0] == pytest.approx(0.202, abs=5e-4)


@pytest.mark.slow
def test_write_bench_tiny():
    _check(bench_write.run(n=30, reps=1), 2)


@pytest.mark.slow
def test_coldstart_bench_tiny():
    _check(bench_coldstart.run(reps=1), 2)  # the ratio, and the Mathcad sheet alone


@pytest.mark.slow
def test_load_bench_tiny():
    _check(bench_load.run(reps=1), 1)


@pytest.mark.slow
def test_run_quick():
    out = subprocess.run(
        [sys.executable, str(BENCH / "run.py"), "--quick", "--only", "evaluate", "--only", "write"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.count("target <=") == 5  # evaluate: 3 lines, write: 2
    assert "cores" in out.stdout.splitlines()[0]


BIG = """
[inputs]
a = "20 mm"
[arguments]
i = { unit = "" }
[definitions]
"y(i)" = { expr = "a*(1 + i/1000)", unit = "mm" }
[[tables]]
name = "big"
title = "too long for Excel"
range = "i := 0, 1 .. 1048576"
columns = { y = "mm" }
"""


@pytest.mark.slow
def test_table_beyond_excel_rows_is_refused_with_csv_offer(tmp_path):
    path = tmp_path / "big.toml"
    path.write_text(BIG, encoding="utf-8")
    sheet = workbook.load(path)
    target = tmp_path / "big.xlsx"
    with pytest.raises(LimitError) as err:
        sheet.write_xlsx(target)
    text = str(err.value)
    assert "1,048,577 rows" in text and "1,048,576" in text and "CSV" in text
    assert not target.exists()
    assert not list(tmp_path.glob("*.xlsx*")), "no temporary file is left behind"
    out = subprocess.run(
        [sys.executable, "-m", "workbook.cli", "run", str(path), "--out", str(target)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert out.returncode == 2
    assert "CSV" in out.stderr and "--csv" in out.stderr and "Traceback" not in out.stderr


def test_unit_check_happens_once_at_load(monkeypatch, tmp_path):
    calls = {"typed_body": 0, "visit": 0}
    for name in calls:
        original = getattr(tc.Typer, name)

        def counted(self, *args, _name=name, _original=original, **kw):
            calls[_name] += 1
            return _original(self, *args, **kw)

        monkeypatch.setattr(tc.Typer, name, counted)
    sheet = workbook.load("concave-cam")
    n_defs = len(sheet.spec.definitions)
    assert calls["typed_body"] == n_defs  # every definition typed, each once
    after_load = dict(calls)
    phi = np.linspace(0, 104, 1001)
    for _ in range(3):
        for name in ("h", "v", "j"):
            sheet.evaluate(name, phi=phi)
        sheet.evaluate("h1", phi=phi[phi <= 22])
        sheet.evaluate("j3", phi=phi[phi >= 82])
        sheet.evaluate("k")
    other = sheet.with_inputs(R3="40 mm")
    other.evaluate("h", phi=phi)
    assert calls == after_load  # evaluation does no unit inference at all
    # (findings blocks may build variant sheets, e.g. with the true pi: their own unit check)
    report = sheet.check()
    before = calls["typed_body"]
    other.table("flank_AB")
    sheet.write_xlsx(tmp_path / "cam.xlsx", report=report)
    assert calls["typed_body"] == before  # tables and the writer retype no definition
