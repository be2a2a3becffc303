"""Nothing lost: an error or Ctrl-C while computing or writing leaves the previous file as it was.

Outputs are written to a temporary file beside the target and moved into place only when
complete (workbook/outputs/atomic.py). These tests force failures in the middle of writing, in the
process (monkeypatching a writer method to raise) and from outside (SIGINT to a subprocess).
"""

from __future__ import annotations

import hashlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers.sheets import SINE

from workbook.cli import main
from workbook.compute import excelform
from workbook.outputs import xlsx

TEMPLATE = (
    SINE
    + 'area = "R^2"\n'
    + """
[[tables]]
name = "t"
range = "phi := 0, 10 .. 90"
columns = { y = "mm" }

[[charts]]
name = "c"
title = "y"
range = "phi := 0 .. 90"
series = [{ y = "y", unit = "mm", name = "y" }]
"""
)


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.fixture
def previous(tmp_path, monkeypatch):
    """A folder with a template and the workbook and CSV from a first, complete run."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.toml").write_text(TEMPLATE, encoding="utf-8")
    assert main(["run", "s.toml", "--out", "out.xlsx", "--csv", "t"]) == 0
    return tmp_path


def leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.endswith(".partial"))


@pytest.mark.slow
@pytest.mark.parametrize(
    "method", ["write_inputs", "write_range_table", "write_charts", "write_about"]
)
@pytest.mark.parametrize("failure", [KeyboardInterrupt, RuntimeError])
def test_failure_while_writing_keeps_the_previous_workbook(previous, monkeypatch, method, failure):
    before = digest(previous / "out.xlsx")
    original = getattr(excelform.ExcelLayout, method)

    def half_then_fail(self, *args, **kwargs):
        original(self, *args, **kwargs)  # something has been written to the temporary file
        raise failure("forced failure in the middle of writing")

    monkeypatch.setattr(excelform.ExcelLayout, method, half_then_fail)
    (previous / "s.toml").write_text(TEMPLATE.replace("10 mm", "12 mm"), encoding="utf-8")
    if failure is KeyboardInterrupt:
        assert main(["run", "s.toml", "--out", "out.xlsx"]) == 130
    else:  # an unexpected exception is an internal error: exit 3, one line
        assert main(["run", "s.toml", "--out", "out.xlsx"]) == 3
    assert digest(previous / "out.xlsx") == before
    assert leftovers(previous) == []


@pytest.mark.slow
@pytest.mark.parametrize("failure", [KeyboardInterrupt, RuntimeError])
def test_failure_while_saving_keeps_the_previous_workbook(previous, monkeypatch, failure):
    """The file itself: half of the laid-out cells written, then a failure."""
    before = digest(previous / "out.xlsx")
    original = xlsx.replay

    def half_then_fail(wb, sheets, ops, formats):
        original(wb, sheets, ops[: len(ops) // 2], formats)
        raise failure("forced failure in the middle of writing")

    monkeypatch.setattr(xlsx, "replay", half_then_fail)
    (previous / "s.toml").write_text(TEMPLATE.replace("10 mm", "12 mm"), encoding="utf-8")
    assert main(["run", "s.toml", "--out", "out.xlsx"]) == (
        130 if failure is KeyboardInterrupt else 3
    )
    assert digest(previous / "out.xlsx") == before
    assert leftovers(previous) == []


def test_failure_while_writing_the_csv_keeps_the_previous_csv(previous, monkeypatch):
    import pandas as pd

    csv = previous / "out.t.csv"
    before_csv = digest(csv)
    original = pd.DataFrame.to_csv

    def half_then_interrupt(self, path, *args, **kwargs):
        original(self.iloc[:3], path, *args, **kwargs)
        raise KeyboardInterrupt

    monkeypatch.setattr(pd.DataFrame, "to_csv", half_then_interrupt)
    assert main(["run", "s.toml", "--out", "out.xlsx", "--csv", "t", "--force"]) == 130
    assert digest(csv) == before_csv
    assert leftovers(previous) == []


def test_bad_input_changes_nothing(previous):
    before = digest(previous / "out.xlsx")
    (previous / "s.toml").write_text(TEMPLATE.replace('"R*sin(phi)"', '"R + phi"'))
    assert main(["run", "s.toml", "--out", "out.xlsx", "--csv", "t", "--force"]) == 2
    assert digest(previous / "out.xlsx") == before
    assert leftovers(previous) == []


# -- Ctrl-C from outside ------------------------------------------------------------------------
CHILD = r"""
import signal, sys, time
from pathlib import Path
# as at a terminal: a shell that starts the test run in the background ignores SIGINT in it
signal.signal(signal.SIGINT, signal.default_int_handler)
from workbook.outputs import xlsx
from workbook.cli import main

stage = sys.argv[1]
def pause(original):
    def run(*args, **kwargs):
        out = original(*args, **kwargs)
        Path("ready").write_text("writing")
        time.sleep(60)  # SIGINT arrives here
        return out
    return run
if stage == "writing":
    xlsx.replay = pause(xlsx.replay)  # the file is being written
else:
    import workbook.compute.checks
    original = workbook.compute.checks.run_checks
    def slow_check(sheet):
        Path("ready").write_text("computing")
        time.sleep(60)
        return original(sheet)
    workbook.compute.checks.run_checks = slow_check
sys.exit(main(["run", "s.toml", "--out", "out.xlsx"]))
"""


@pytest.mark.slow
@pytest.mark.parametrize(
    ("stage", "sig", "status"),
    [
        ("writing", signal.SIGINT, 130),
        ("computing", signal.SIGINT, 130),
        # SIGTERM (as `timeout` sends) ended the process at once: .NAME.partial folders stayed
        ("writing", signal.SIGTERM, 143),
        ("computing", signal.SIGTERM, 143),
    ],
)
def test_sigint_leaves_the_previous_workbook(previous, stage, sig, status):
    before = digest(previous / "out.xlsx")
    (previous / "s.toml").write_text(TEMPLATE.replace("10 mm", "12 mm"), encoding="utf-8")
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD, stage],
        cwd=previous,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        deadline = time.monotonic() + 120
        while not (previous / "ready").exists():
            assert child.poll() is None, child.communicate()
            assert time.monotonic() < deadline, "the child never reached the pause"
            time.sleep(0.05)
        if stage == "writing":  # the temporary file exists beside the target while writing
            assert leftovers(previous), "no temporary file while writing"
        child.send_signal(sig)
        _, err = child.communicate(timeout=60)
    finally:
        if child.poll() is None:
            child.kill()
    assert child.returncode == status, err
    assert "interrupted; no output file was changed" in err and "Traceback" not in err
    assert digest(previous / "out.xlsx") == before
    assert leftovers(previous) == []


def test_new_files_get_the_usual_permissions(previous):
    """The temporary file is made private (0600) by mkstemp; the finished file gets the mode a
    plain write would give it (0666 less the umask), or keeps the mode of the file it replaces."""
    umask = os.umask(0)
    os.umask(umask)
    for name in ("out.xlsx", "out.t.csv"):
        assert os.stat(previous / name).st_mode & 0o777 == 0o666 & ~umask, name
    os.chmod(previous / "out.xlsx", 0o640)
    assert main(["run", "s.toml", "--out", "out.xlsx"]) == 0
    assert os.stat(previous / "out.xlsx").st_mode & 0o777 == 0o640
