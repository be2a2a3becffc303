"""The corpus of bad inputs: every file in tests/bad_inputs/ is run through the real command line.

Each corpus file is a template whose header comments say how to run it and what must happen:

    # expect: exit 2: <substring of the error message>
    # where: <line> <definition>     (optional: the message names FILE:LINE and 'definition';
    #                                  `-` for no line or no definition)
    # args: run FILE --set R1=40 kg   (optional; default `run FILE`; FILE is the corpus file)
    # setup: dir out.xlsx | text out.xlsx   (optional: make a folder or a text file first)

The command runs from an empty temporary folder: in this process by default (the command
line's ``main``; milliseconds a case), and in a fresh interpreter in the slow run (about a
second a case), which must print the same. Every case must exit with the expected status,
print one paragraph on stderr starting with ``workbook:``, name the template file (and line
and definition when given), and show no Python traceback; `--debug` must show one.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import os
import re
import shlex
import shutil
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import pytest
from helpers.paths import TESTS

CORPUS = TESTS / "bad_inputs"
CODE = "import sys; from workbook.cli import main; sys.exit(main())"


@dataclass
class Case:
    path: Path
    status: int
    expect: str
    args: list[str]
    line: int | None = None
    definition: str | None = None
    setup: tuple[str, str] | None = None


def read_case(path: Path) -> Case:
    text = path.read_bytes().decode("utf-8", errors="replace")
    head = dict(
        (m.group(1), m.group(2).strip())
        for m in re.finditer(r"^# (expect|args|where|setup): (.*)$", text, flags=re.M)
    )
    m = re.match(r"exit (\d+): (.+)$", head["expect"])
    assert m, f"{path.name}: bad '# expect:' header"
    case = Case(path, int(m.group(1)), m.group(2), shlex.split(head.get("args", "run FILE")))
    if "where" in head:
        line, definition = head["where"].split(maxsplit=1)
        case.line = None if line == "-" else int(line)
        case.definition = None if definition == "-" else definition
    if "setup" in head:
        kind, name = head["setup"].split()
        case.setup = (kind, name)
    return case


CASES = sorted(CORPUS.glob("*.toml"))


def _args(case: Case, cwd: Path) -> list[str]:
    template = cwd / case.path.name
    if not template.exists():
        shutil.copyfile(case.path, template)
    return [template.name if a == "FILE" else a for a in case.args]


def run_case(case: Case, cwd: Path, *extra: str) -> subprocess.CompletedProcess:
    """The command line in a fresh interpreter."""
    return subprocess.run(
        [sys.executable, "-c", CODE, *extra, *_args(case, cwd)],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=120,
    )


def run_in_process(case: Case, cwd: Path) -> subprocess.CompletedProcess:
    """The command line's ``main`` in this process, from ``cwd``, with its output captured."""
    import warnings

    from workbook.cli import main

    args = _args(case, cwd)
    out, err = io.StringIO(), io.StringIO()
    here = os.getcwd()
    os.chdir(cwd)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            with warnings.catch_warnings():  # main() sets filters for the process
                try:
                    code = main(args)
                except SystemExit as exc:  # argparse refuses the arguments
                    code = exc.code
    finally:
        os.chdir(here)
    return subprocess.CompletedProcess(args, code, out.getvalue(), err.getvalue())


def test_corpus_is_large_enough():
    assert len(CASES) >= 40


def _run_one(path: Path, root: Path, run=run_in_process):
    case = read_case(path)
    cwd = root / path.stem
    cwd.mkdir()
    before = None
    if case.setup:
        kind, name = case.setup
        target = cwd / name
        if kind == "dir":
            target.mkdir()
        else:
            target.write_text("notes that are not a workbook\n")
            before = hashlib.sha256(target.read_bytes()).hexdigest()
    return case, cwd, before, run(case, cwd)


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """All cases, one after the other in this process."""
    root = tmp_path_factory.mktemp("bad_inputs")
    done = [_run_one(p, root) for p in CASES]
    return {case.path.stem: (case, cwd, before, out) for case, cwd, before, out in done}


@pytest.fixture(scope="module")
def fresh_results(tmp_path_factory):
    """All cases, each in a fresh interpreter (~1 s), four at a time."""
    root = tmp_path_factory.mktemp("bad_inputs_fresh")
    with ThreadPoolExecutor(4) as pool:
        done = pool.map(lambda p: _run_one(p, root, run_case), CASES)
        return {case.path.stem: (case, cwd, before, out) for case, cwd, before, out in done}


@pytest.mark.slow
@pytest.mark.parametrize("path", CASES, ids=[p.stem for p in CASES])
def test_bad_input(results, path):
    _check(*results[path.stem])


@pytest.mark.slow
@pytest.mark.parametrize("path", CASES, ids=[p.stem for p in CASES])
def test_bad_input_in_a_fresh_interpreter(fresh_results, results, path):
    _check(*fresh_results[path.stem])
    _, _, _, here = results[path.stem]
    _, _, _, fresh = fresh_results[path.stem]
    assert (fresh.returncode, fresh.stderr) == (here.returncode, here.stderr)


def _check(case: Case, cwd: Path, before: str | None, out: subprocess.CompletedProcess):
    err = out.stderr
    assert out.returncode == case.status, (out.returncode, err)
    assert "Traceback" not in err, err
    assert err.startswith("workbook: "), err
    assert len(err.strip().splitlines()) == 1, f"not one paragraph:\n{err}"
    assert case.expect in err, f"expected {case.expect!r} in:\n{err}"
    if case.line is not None or case.definition is not None or "FILE" in case.args:
        if case.path.stem.startswith(("out_", "csv_", "set_no_")):
            pass  # errors about the command line itself, not the template
        else:
            where = case.path.name + (f":{case.line}" if case.line else "")
            assert where in err, f"expected {where!r} in:\n{err}"
    if case.definition:
        assert f"in '{case.definition}'" in err, err
    if before is not None:  # the file that is not a workbook was left alone
        assert hashlib.sha256((cwd / case.setup[1]).read_bytes()).hexdigest() == before
    if case.status == 2 and case.args[0] == "run":  # nothing written, not even a partial file
        written = [p.name for p in cwd.rglob("*") if p.suffix in (".xlsx", ".csv", ".partial")]
        assert written == ([case.setup[1]] if case.setup else []), written


@pytest.mark.slow
def test_debug_shows_the_traceback(tmp_path):
    case = read_case(CORPUS / "unit_sum.toml")
    out = run_case(case, tmp_path, "--debug")
    assert out.returncode != 0
    assert "Traceback" in out.stderr and "UnitError" in out.stderr


@pytest.mark.slow
def test_not_xlsx_is_overwritten_with_force(tmp_path):
    case = read_case(CORPUS / "out_not_xlsx.toml")
    (tmp_path / "out.xlsx").write_text("notes\n")
    case.args.append("--force")
    out = run_case(case, tmp_path)
    assert out.returncode == 0, out.stderr
    assert (tmp_path / "out.xlsx").read_bytes()[:2] == b"PK"


@pytest.mark.slow
def test_failed_check_exits_1(tmp_path):
    (tmp_path / "t.csv").write_text("name,argument,value,unit\nR2,,41,mm\n")
    (tmp_path / "t.toml").write_text(
        '[inputs]\nR1 = "20 mm"\n\n[definitions]\nR2 = "2*R1"\n\n'
        '[[printed]]\nfile = "t.csv"\ntolerance = 0.001\n'
    )
    out = subprocess.run(
        [sys.executable, "-c", CODE, "check", "t.toml"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=120,
    )
    assert out.returncode == 1, out.stderr
    assert "NOT reproduced" in out.stdout
