"""One budget of time and memory per command: array growth refused before the memory is
taken, work stopped along the way when the command's time is spent, program indices that no
array has refused, file system errors and signals on output, and a fuzz test of programs.

The cases a user meets run the real command line: in a fresh guarded process
(tests/hardening/test_hostile.py's guard: an address-space limit of 1.5 GiB, so that growth
allocated before it is counted would end in a MemoryError, not in the message), or in this
process with a short ``--time-limit`` where the budget is what is tested. No timing is asserted.
"""

from __future__ import annotations

import contextlib
import errno
import io
import os
import re
import signal
import time
from pathlib import Path

import pytest
from helpers.hostile import guarded, program
from helpers.paths import ROOT
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import workbook
from workbook import limits, limits_time
from workbook.cli import main
from workbook.engine import runtime
from workbook.errors import InputError, LimitError, OutOfBudget
from workbook.functions import matrix

BUDGET = "0.3"  # seconds: the short budget of the in-process cases


def run_cli(cwd: Path, *args: str):
    """``workbook *args`` in this process, in ``cwd``: (status, stdout, stderr)."""
    out, err, old = io.StringIO(), io.StringIO(), os.getcwd()
    try:
        os.chdir(cwd)
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(list(args))
    finally:
        os.chdir(old)
    return code, out.getvalue(), err.getvalue()


def spent(seconds: float, source: str) -> str:
    """The regex of the budget a message names: its CPU time or, on a busy machine, the
    wall-clock cap of WALL_FACTOR times it."""
    cpu = f"{seconds:g} s of CPU time"
    factor = limits_time.WALL_FACTOR
    wall = f"{factor * seconds:g} s of wall-clock time, {factor:g} times its {cpu}"
    return rf"ran past the time budget of this command \(({cpu}|{wall}), {re.escape(source)};"


def one_paragraph(err: str) -> None:
    assert err.startswith("workbook: ") and "Traceback" not in err, err
    assert len(err.strip().splitlines()) == 1, err


def leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.rglob("*") if ".partial" in p.name)


# -- growth counted before the memory is taken -----------------------------------------------

DOUBLINGS = "".join(
    f'd{k} = "concat(d{k - 1}, d{k - 1})"\n' for k in range(1, 41)
)  # a text of 2^41 characters by 40 definitions
GROWTH = {
    "stack_of_itself": (
        program("v := [1, 2]\nfor k in 1 .. n\n    v := stack(v, v)\nrows(v)", "p(40)"),
        "stack() would make an array of 16,777,216 elements",
    ),
    "augment_of_itself": (
        program("v := [1, 2]\nfor k in 1 .. n\n    v := augment(v, v)\ncols(v)", "p(40)"),
        "augment() would make an array of 16,777,216 elements",
    ),
    "nested_in_itself_twice": (  # shared, so cheap to hold; written out, 2^60 numbers
        program("v := [1, 2]\nfor k in 1 .. n\n    v := [v, v]\nrows(v)", "p(60)"),
        "their elements counted whole) would make an array of 16,777,216 elements",
    ),
    "grown_past_any_array": (
        program("w := 0\nw[rows(w) + n*1e300] := 1\nrows(w)", "p(1)"),
        "element index 1e+300 would make an array of 1e+300 elements",
    ),
    "outer_product_in_a_program": (
        program("for k in 0 .. n\n    v[k] := k\nM := v*transpose(v)\nM[1, 1]", "p(4000)"),
        "a product of a vector of 4001 by a 1x4001 matrix would make an array of "
        "16,008,001 elements",
    ),
    "stack_in_a_formula": (
        '[definitions]\ns = "max(stack(identity(2000), identity(2000), identity(2000)))"\n',
        "stack() would make an array of 12,000,000 elements",
    ),
    "concat_of_itself": (
        '[definitions]\nd0 = "concat(\\"ab\\", \\"cd\\")"\n' + DOUBLINGS,
        "concat() would make a text of 16,777,216 characters",
    ),
}


SMALL_LIMIT = 100_000  # elements: the default run's limit, so that each case is quick


@pytest.mark.parametrize(
    "name",
    [pytest.param(n, marks=pytest.mark.slow) if "outer" in n else n for n in sorted(GROWTH)],
)  # the outer product's vector of 4,001 takes over a second to type and fill
def test_growth_is_refused_before_the_memory_is_taken(tmp_path, monkeypatch, name):
    text, expected = GROWTH[name]
    if name == "stack_in_a_formula":  # three of 200 x 200 are above the small limit too
        text = text.replace("2000", "200")
    monkeypatch.setattr(limits, "MAX_ARRAY_ELEMENTS", SMALL_LIMIT)
    monkeypatch.setattr(limits, "MAX_TEXT_CHARS", SMALL_LIMIT)
    made = []
    real = limits.check_elements

    def counted(count, what):  # every array is checked before it is made, none above
        real(count, what)
        made.append(count)

    for module in (runtime, matrix):
        monkeypatch.setattr(module, "check_elements", counted)
    (tmp_path / "g.toml").write_text(text, encoding="utf-8")
    code, _, err = run_cli(tmp_path, "run", "g.toml", "--out", "g.xlsx")
    assert code == 2, err
    one_paragraph(err)
    assert expected.split(" would make")[0] in err and "in '" in err, err
    unit = "characters" if "concat" in name else "elements"
    assert f"(limit {SMALL_LIMIT:,} {unit})" in err, err
    assert max(made, default=0) <= SMALL_LIMIT
    assert not (tmp_path / "g.xlsx").exists() and leftovers(tmp_path) == []


@pytest.mark.slow  # each in a fresh guarded process, at the real limit (about 2 s each)
@pytest.mark.parametrize("name", sorted(GROWTH))
def test_growth_is_refused_within_the_memory_guard(tmp_path, name):
    # 1.5 GiB of address space: growth made before it is counted ends in a MemoryError
    text, expected = GROWTH[name]
    out = guarded(tmp_path, text)
    assert out.returncode == 2, (out.returncode, out.stderr[-2000:])
    assert expected in out.stderr, out.stderr
    assert "in '" in out.stderr  # the definition is named
    one_paragraph(out.stderr)
    assert [p.name for p in tmp_path.rglob("*") if p.is_file()] == ["hostile.toml"]


def test_growth_within_the_limit_is_computed(sheet_from):
    # the same programs, a few doublings: the values, not refusals
    sheet = sheet_from(
        program("v := [1, 2]\nfor k in 1 .. n\n    v := stack(v, v)\nrows(v)", "p(20)")
        + '\nt = "q(3)"\n"q(n)" = { program = """\nv := [1, 2]\nfor k in 1 .. n\n'
        '    v := [v, v]\nrows(v)\n""" }\n',
        name="g",
    )
    assert float(sheet.evaluate("s").magnitude) == 2 * 2**20
    assert float(sheet.evaluate("t").magnitude) == 2


# -- program indices that no array has -------------------------------------------------------

INDICES = {
    "1e300": "the index 1e300 is beyond any array",
    "0/0": "the index 0 / 0 = nan is not a finite number",
    "1/0": "the index 1 / 0 = inf is not a finite number",
    "2^2000": "the index 2^2000 = inf is not a finite number",
    "-1": "element index -1 is out of range (below the origin 0)",
    "1.5": "the index 1.5 is not a whole number",
    "1/3": "the index 1 / 3 = 0.333333 is not a whole number",
}


@pytest.mark.slow
@pytest.mark.parametrize("index", sorted(INDICES))
@pytest.mark.parametrize("local", ["v := [1, 2]\n", "w := 0\n", ""])
def test_an_index_written_as_numbers_is_refused_at_load(tmp_path, index, local):
    name = local[:1] or "u"
    text = program(f"{local}{name}[{index}] := 2\n{name}[0]*n", "p(1)")
    (tmp_path / "i.toml").write_text(text, encoding="utf-8")
    code, _, err = run_cli(tmp_path, "run", "i.toml", "--out", "i.xlsx")
    assert code == 2, err
    one_paragraph(err)
    assert INDICES[index].replace("1e300", "1e+300") in err, err
    assert "i.toml:5, in 'p'" in err and f"program line {2 if local else 1}" in err, err
    assert not (tmp_path / "i.xlsx").exists()


@pytest.mark.slow
@pytest.mark.parametrize(
    "index, message",
    [
        ("n*1e300", "element index 1e+300 is out of range"),  # was -9223372036854775808
        ("(n - 1)/0", "element index nan is not an integer"),  # was a ValueError, exit 3
        ("-5*n", "element index -5 is out of range"),
        ("n/3", "element index 0.333333 is not an integer"),
    ],
)
@pytest.mark.parametrize("local", ["v := [1, 2]\n", "w := 0\n"])
def test_an_index_known_when_the_program_runs_is_an_error_of_its_value(
    tmp_path, index, message, local
):
    # in an array of a size known at load, and in a run-time array (grown as it runs)
    name = local[0]
    at = index if name == "v" else f"rows(w) + {index}" if "1e300" not in index else index
    text = program(f"{local}{name}[{at}] := 2\n{name}[0]*n", "p(1)")
    (tmp_path / "i.toml").write_text(text, encoding="utf-8")
    sheet = workbook.load(tmp_path / "i.toml")
    if name == "w" and "1e300" in index:  # a run-time array grown to it: the memory budget
        with pytest.raises(OutOfBudget, match="would make an array of 1e.300 elements"):
            sheet.evaluate("s")
        return
    with pytest.raises(InputError, match=re.escape(message)):
        sheet.evaluate("s")
    code, _, err = run_cli(tmp_path, "run", "i.toml", "--out", "i.xlsx")
    assert code in (0, 1), err  # a value that fails: listed, never an internal error
    assert "Traceback" not in err and "internal error" not in err


# -- one time budget, checked along the way --------------------------------------------------

ODE_HEAD = '[inputs]\nw = "1 1/s"\n\n[arguments]\nt = { unit = "s" }\n\n'
SLOW_WORK = {
    # every row sums up to its own index: 5e9 additions
    "quadratic_table": (
        '[arguments]\ni = { unit = "" }\n\n[definitions]\n"s(i)" = "sum(k, k, 1, i)"\n\n'
        '[[tables]]\nname = "t"\nrange = "i := 1 .. 100000"\ncolumns = { s = "" }\n',
        "in 'table t'",
        "table t: column 's'",
    ),
    "program_appending_to_itself": (
        program("v := [1, 2]\nfor k in 1 .. n\n    v := stack(v, [k])\nrows(v)", "p(1e6)"),
        "in 's'",
        "the program of 'p' (line 2)",
    ),
    "forced_rk45_on_a_stiff_problem": (
        ODE_HEAD + '[definitions]\ne = "y(1000 s)"\n\n[[ode]]\nname = "stiff"\n'
        'time = "t := 0 .. 1000"\nmethod = "RK45"\nstates = [{ name = "y", unit = "", '
        'initial = "1", derivative = "-1e6*w*(y - cos(w*t))" }]\n',
        "",
        "ode 'stiff'",
    ),
    "dop853_over_1e7_s_at_rtol_1e-12": (
        ODE_HEAD + '[definitions]\ne = "x(1e7 s)"\n\n[[ode]]\nname = "osc"\n'
        'time = "t := 0 .. 1e7"\nmethod = "DOP853"\nrtol = "1e-12"\nstates = ['
        '{ name = "x", unit = "", initial = "1", derivative = "v*w" }, '
        '{ name = "v", unit = "", initial = "0", derivative = "-x*w" }]\n',
        "",
        "ode 'osc'",
    ),
    "radau_with_1500_states": (
        ODE_HEAD + '[definitions]\nA = "-identity(1500)"\ne = "u(100 s)[0]"\n\n[[ode]]\n'
        'name = "big"\ntime = "t := 0 .. 100"\nmethod = "Radau"\nstates = [{ name = "u", '
        'unit = "", initial = "diag(identity(1500))", derivative = "w*(A*u + sin(u))" }]\n',
        "",
        "ode 'big'",
    ),
}


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(SLOW_WORK))
def test_work_past_the_budget_stops_the_command(tmp_path, name):
    text, definition, work = SLOW_WORK[name]
    (tmp_path / "w.toml").write_text(text, encoding="utf-8")
    code, _, err = run_cli(tmp_path, "run", "w.toml", "--out", "w.xlsx", "--time-limit", BUDGET)
    assert code == 2, err
    one_paragraph(err)
    assert re.search(re.escape(work) + " " + spent(float(BUDGET), "--time-limit"), err), err
    assert definition in err and "--time-limit SECONDS" in err, err
    assert not (tmp_path / "w.xlsx").exists() and leftovers(tmp_path) == []
    assert limits_time.current() is None  # the budget ends with the command


@pytest.mark.slow
def test_a_sweep_of_ten_thousand_listed_values_stops_at_the_budget(tmp_path):
    (tmp_path / "s.toml").write_text(
        '[inputs]\nR = "40 mm"\n\n[arguments]\nx = { unit = "" }\n\n[definitions]\n'
        '"f(x)" = { program = """\nacc := 0\nfor k in 1 .. 200\n    acc := acc + k*x\n'
        'acc*R\n""" }\na = "f(1)"\n\n[sweep]\noutputs = { a = "a" }\n',
        encoding="utf-8",
    )
    values = ",".join(f"{40 + k * 1e-3:.4f}mm" for k in range(10_000))
    code, _, err = run_cli(
        tmp_path, "sweep", "s.toml", "--vary", f"R={values}", "--mode", "serial",
        "--out", "s.csv", "--time-limit", BUDGET,
    )  # fmt: skip
    assert code == 2, err
    assert re.search(spent(0.3, "--time-limit"), err), err
    assert "Traceback" not in err and not (tmp_path / "s.csv").exists()


@pytest.mark.slow
def test_the_budget_is_set_by_the_sheet_only_downwards(tmp_path):
    slow = SLOW_WORK["program_appending_to_itself"][0]
    (tmp_path / "w.toml").write_text("[sheet]\ntime_limit = 0.1\n\n" + slow, encoding="utf-8")
    code, _, err = run_cli(tmp_path, "run", "w.toml", "--out", "w.xlsx")
    assert code == 2 and re.search(spent(0.1, "[sheet] time_limit"), err), err
    (tmp_path / "w.toml").write_text("[sheet]\ntime_limit = 100\n\n" + slow, encoding="utf-8")
    code, _, err = run_cli(tmp_path, "run", "w.toml", "--out", "w.xlsx")
    assert code == 2 and "may lower the time budget (at most 20 s), not raise it" in err, err
    one_paragraph(err)
    # the command line wins over the sheet (here: a lower budget than the sheet's)
    (tmp_path / "w.toml").write_text("[sheet]\ntime_limit = 10\n\n" + slow, encoding="utf-8")
    code, _, err = run_cli(tmp_path, "run", "w.toml", "--out", "w.xlsx", "--time-limit", "0.1")
    assert code == 2 and re.search(spent(0.1, "--time-limit"), err), err


@pytest.mark.slow
@pytest.mark.parametrize("value", ["0", "-1", "abc", "nan", "inf", "3601"])
def test_a_time_limit_outside_its_caps_is_refused(tmp_path, value):
    (tmp_path / "a.toml").write_text('[definitions]\ns = "1"\n', encoding="utf-8")
    code, _, err = run_cli(tmp_path, "run", "a.toml", "--out", "a.xlsx", "--time-limit", value)
    assert code == 2 and "--time-limit" in err and "at most 3600" in err, err
    one_paragraph(err)


def test_work_that_no_check_reaches_is_stopped_by_the_alarm(monkeypatch):
    monkeypatch.setattr(limits_time, "GRACE_SECONDS", 0.05)

    def spin():
        while True:
            pass

    start = time.monotonic()
    with pytest.raises(OutOfBudget, match=r"the command ran past the time budget .*0.2 s"):
        with limits_time.command_budget(0.2):
            spin()
    assert time.monotonic() - start >= 0.2  # not before the budget and its grace
    assert signal.getitimer(signal.ITIMER_REAL)[0] == 0  # no alarm left behind


def test_a_time_limit_inside_the_budget_is_the_nearer_of_the_two(monkeypatch):
    monkeypatch.setattr(limits_time, "GRACE_SECONDS", 0.05)

    def spin(seconds):
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            pass

    with limits_time.command_budget(30):
        with pytest.raises(LimitError, match="inner took more than 0.1 s"):
            with limits_time.within_seconds(0.1, "inner"):
                spin(30)
        assert 29 < limits_time.remaining() <= 30  # the budget is still armed (CPU time)
        assert signal.getitimer(signal.ITIMER_REAL)[0] > 0
    with pytest.raises(OutOfBudget, match="ran past the time budget"):
        with limits_time.command_budget(0.2):
            with limits_time.within_seconds(30, "inner"):
                spin(30)
    assert signal.getitimer(signal.ITIMER_REAL)[0] == 0


def test_an_error_estimate_within_the_budget_is_shortened_not_fatal():
    with limits_time.command_budget(10):
        assert limits_time.within_budget(30) <= 10 - limits_time.GRACE_SECONDS
        assert limits_time.within_budget(1) == 1
    assert limits_time.within_budget(30) == 30  # outside a command: as asked


# -- output onto a full disk or a read-only folder -------------------------------------------

TABLE = (
    '[arguments]\ni = { unit = "" }\n\n[definitions]\n"s(i)" = "i^2"\n\n'
    '[[tables]]\nname = "t"\nrange = "i := 1 .. 2000"\ncolumns = { s = "" }\n'
)


@pytest.fixture
def written(tmp_path):
    (tmp_path / "t.toml").write_text(TABLE, encoding="utf-8")
    code, _, err = run_cli(tmp_path, "run", "t.toml", "--out", "o.xlsx", "--csv", "t")
    assert code == 0, err
    return tmp_path, (tmp_path / "o.xlsx").read_bytes(), (tmp_path / "o.t.csv").read_bytes()


def _no_space(*args, **kwargs):
    raise OSError(errno.ENOSPC, "No space left on device")


@pytest.mark.slow
@pytest.mark.parametrize("where", ["xlsx", "csv"])
def test_a_full_disk_is_one_paragraph_and_changes_nothing(written, monkeypatch, where):
    import pandas as pd
    import xlsxwriter.workbook

    folder, xlsx_before, csv_before = written
    if where == "xlsx":  # the zip file being saved (xlsxwriter wraps the OSError)
        monkeypatch.setattr(xlsxwriter.workbook.ZipFile, "write", _no_space)
    else:
        monkeypatch.setattr(pd.DataFrame, "to_csv", _no_space)
    unraisable = []
    monkeypatch.setattr("sys.unraisablehook", unraisable.append)
    code, _, err = run_cli(folder, "run", "t.toml", "--out", "o.xlsx", "--csv", "t", "--force")
    assert code == 2, err
    one_paragraph(err)
    target = "o.xlsx" if where == "xlsx" else "o.t.csv"
    assert f"{target}: No space left on device; the disk is full" in err, err
    assert ".partial" not in err
    assert (folder / "o.xlsx").read_bytes() == xlsx_before
    assert (folder / "o.t.csv").read_bytes() == csv_before
    assert leftovers(folder) == []


def _mount(folder: Path, options: str) -> bool:
    import subprocess

    folder.mkdir()
    done = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(folder)], capture_output=True
    )
    return done.returncode == 0


@pytest.mark.slow  # mounts file systems (root only) and runs the command line in a new process
@pytest.mark.parametrize(
    "options, message",
    [
        ("size=64k", "No space left on device; the disk is full"),
        ("size=64k,ro", "Read-only file system; write elsewhere"),
    ],
)
def test_a_real_full_or_read_only_disk(tmp_path, options, message):
    import subprocess
    import sys

    disk = tmp_path / "disk"
    if not _mount(disk, options):
        pytest.skip("cannot mount a tmpfs here (needs root)")
    try:
        (tmp_path / "t.toml").write_text(TABLE.replace("2000", "200000"), encoding="utf-8")
        root = ROOT
        done = subprocess.run(
            [sys.executable, "-c", "import sys; from workbook.cli import main; sys.exit(main())",
             "run", "t.toml", "--out", str(disk / "o.xlsx")],
            cwd=tmp_path, capture_output=True, text=True, timeout=300,
            env=dict(os.environ, PYTHONPATH=str(root)),
        )  # fmt: skip
        assert done.returncode == 2, done.stderr
        lines = [ln for ln in done.stderr.splitlines() if not ln.startswith("workbook: writing")]
        assert len(lines) == 1 and message in lines[0], done.stderr
        assert f"cannot write {disk / 'o.xlsx'}" in lines[0], done.stderr
        assert "Traceback" not in done.stderr and "Exception ignored" not in done.stderr
        assert list(disk.iterdir()) == []
    finally:
        import subprocess as sp

        sp.run(["umount", str(disk)], capture_output=True)


# -- signals while writing -------------------------------------------------------------------


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_an_interrupt_raised_where_python_drops_it_is_raised_again(sig):
    # a weakref callback is where Python prints an exception and goes on: the interrupt
    # raised there comes back as the same signal at the next point that can raise
    import weakref

    from workbook.outputs.atomic import Terminated, sigterm_as_interrupt

    class Referent:
        pass

    expected = Terminated if sig == signal.SIGTERM else KeyboardInterrupt

    def dropped(_ref):
        raise expected

    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(expected), sigterm_as_interrupt():
            thing = Referent()
            ref = weakref.ref(thing, dropped)
            del thing
            for _ in range(1000):
                time.sleep(0.001)
            pytest.fail("the interrupt was lost")
    finally:
        signal.signal(signal.SIGINT, previous)
    assert ref() is None


@pytest.mark.slow  # writes a table of 200,000 rows several times, in new processes
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_a_signal_at_any_point_of_writing_changes_nothing(tmp_path, sig):
    import subprocess
    import sys

    root = ROOT
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    env = dict(os.environ, PYTHONPATH=str(root), TMPDIR=str(scratch))
    code = "import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); "
    code += "from workbook.cli import main; sys.exit(main())"
    (tmp_path / "t.toml").write_text(TABLE.replace("2000", "200000"), encoding="utf-8")
    args = [sys.executable, "-c", code, "run", "t.toml", "--out", "o.xlsx", "--csv", "t"]
    first = subprocess.run(args, cwd=tmp_path, env=env, capture_output=True, timeout=600)
    assert first.returncode == 0, first.stderr
    before = {n: (tmp_path / n).read_bytes() for n in ("o.xlsx", "o.t.csv")}
    interrupted = 0
    # the signal at fractions of the time the writing takes, from its first progress line;
    # each run's table is another, so that a complete run changes both files
    for k, fraction in enumerate((0.0, 0.2, 0.4, 0.6, 0.8, 0.95), 1):
        (tmp_path / "t.toml").write_text(
            TABLE.replace("2000", "200000").replace("i^2", f"i^2 + {k}"), encoding="utf-8"
        )
        child = subprocess.Popen(
            [*args, "--force", "--time-limit", "600"],
            cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        )  # fmt: skip
        try:
            line = child.stderr.readline()  # "workbook: writing table t: ..." (computed)
            assert "writing table t" in line, line
            time.sleep(fraction * 6.0)
            child.send_signal(sig)
            _, err = child.communicate(timeout=300)
        finally:
            if child.poll() is None:
                child.kill()
        now = {n: (tmp_path / n).read_bytes() for n in ("o.xlsx", "o.t.csv")}
        assert "Traceback" not in err, err
        # 0: it ended before the signal; -sig: the signal came after the command had ended
        # (its handler is then Python's default again): both new
        if child.returncode in (0, -sig):
            assert all(now[n] != before[n] for n in now), (fraction, child.returncode, err)
            assert leftovers(tmp_path) == [] and list(scratch.iterdir()) == [], fraction
            before = now
            continue
        assert child.returncode == (143 if sig == signal.SIGTERM else 130), err
        interrupted += 1
        if "interrupted after writing" in err:  # held while they were moved: both new
            assert all(now[n] != before[n] for n in now), err
            before = now
        else:
            assert "interrupted; no output file was changed" in err, err
            assert now == before, fraction
        assert leftovers(tmp_path) == [] and list(scratch.iterdir()) == [], fraction
    assert interrupted, "every run ended before its signal: nothing was tested"


# -- fuzz: generated programs end in exit 0, 1 or 2, within the budget ------------------------


FUZZ_EXAMPLES = int(os.environ.get("FUZZ_PROGRAMS", "300"))
NUMBERS = ["0", "1", "2", "-1", "1.5", "1e300", "0/0", "1/0", "2^2000", "1e6", "n", "k"]
ARRAYS = ["v", "[1, 2]", "stack(v, v)", "augment(v, v)", "[v, v]", "stack(v, [k])", "w"]
CALLS = ["rows(v)", "cols(v)", "max(v)", "v[{i}]", "w[{i}]", "length(v)"]


@st.composite
def expressions(draw, depth: int = 0):
    kind = draw(st.integers(0, 3 if depth < 2 else 1))
    if kind == 0:
        return draw(st.sampled_from(NUMBERS))
    if kind == 1:
        return draw(st.sampled_from(ARRAYS))
    if kind == 2:
        return draw(st.sampled_from(CALLS)).format(i=draw(st.sampled_from(NUMBERS)))
    op = draw(st.sampled_from(["+", "-", "*", "/", "^"]))
    return f"({draw(expressions(depth + 1))} {op} {draw(expressions(depth + 1))})"


@st.composite
def blocks(draw, indent: str = "", depth: int = 0):
    lines = []
    for _ in range(draw(st.integers(1, 3))):
        kind = draw(st.integers(0, 5 if depth < 2 else 2))
        name = draw(st.sampled_from(["v", "w", "acc"]))
        if kind == 0:
            lines.append(f"{indent}{name} := {draw(expressions())}")
        elif kind == 1:
            index = draw(st.sampled_from(NUMBERS + ["rows(v)", "rows(w) + 1", "k*1e6"]))
            lines.append(f"{indent}{name}[{index}] := {draw(expressions())}")
        elif kind == 2:
            lines.append(f"{indent}{draw(st.sampled_from(['break', 'continue', 'return v']))}")
        elif kind == 3:
            last = draw(st.sampled_from(["3", "n", "1e6", "1e300", "0/0", "-5"]))
            lines.append(f"{indent}for k in 1 .. {last}")
            lines.extend(draw(blocks(indent + "    ", depth + 1)))
        elif kind == 4:
            lines.append(f"{indent}while {draw(expressions())} > 0")
            lines.extend(draw(blocks(indent + "    ", depth + 1)))
        else:
            lines.append(f"{indent}if {draw(expressions())} > 1")
            lines.extend(draw(blocks(indent + "    ", depth + 1)))
    return lines


def _run_program(body: list[str], budget: str) -> None:
    import tempfile

    text = program("v := [1, 2]\nw := 0\nacc := 0\n" + "\n".join(body) + "\nv", "p(3)")
    with tempfile.TemporaryDirectory() as folder:
        (Path(folder) / "f.toml").write_text(text, encoding="utf-8")
        start = time.monotonic()
        code, _, err = run_cli(
            Path(folder), "run", "f.toml", "--out", "f.xlsx", "--time-limit", budget
        )
        elapsed = time.monotonic() - start
    assert code in (0, 1, 2), (code, err, text)  # never 3: an internal error
    assert "Traceback" not in err and "internal error" not in err, (err, text)
    if code == 2:
        one_paragraph(err)
    assert elapsed < float(budget) + 30, (elapsed, text)  # a hang guard, not a timing claim
    assert limits_time.current() is None


@pytest.mark.slow
@settings(max_examples=3, deadline=None, suppress_health_check=list(HealthCheck), database=None)
@given(blocks())
def test_generated_programs_end_in_exit_0_1_or_2(body):
    _run_program(body, "0.2")


@pytest.mark.slow  # FUZZ_PROGRAMS generated programs (300 unless set), each within 1 s
@settings(
    max_examples=FUZZ_EXAMPLES, deadline=None, suppress_health_check=list(HealthCheck),
    database=None,
)  # fmt: skip
@given(blocks())
def test_generated_programs_many(body):
    _run_program(body, "1")


def test_an_element_set_of_a_number_local_makes_it_a_vector(tmp_path):
    # found by the fuzz test: w := 0 then w[0] := 0 was an IndexError (exit 3); as Mathcad
    # (and a run-time array), setting an element of a number makes it a vector
    path = tmp_path / "n.toml"
    path.write_text(program("w := 5\nw[2] := 7*n\nw", "p(1)"), encoding="utf-8")
    assert workbook.load(path).evaluate("s").magnitude.ravel().tolist() == [0.0, 0.0, 7.0]


@pytest.mark.slow
def test_the_alarm_waits_for_an_import_to_finish(tmp_path, monkeypatch):
    # an alarm raised inside an import left the module half initialised in sys.modules: a
    # later command in the same process failed with an AttributeError (exit 3)
    import sys

    monkeypatch.setattr(limits_time, "GRACE_SECONDS", 0.05)
    monkeypatch.syspath_prepend(str(tmp_path))
    (tmp_path / "slow_module.py").write_text(
        "import time\nend = time.monotonic() + 0.6\nwhile time.monotonic() < end:\n    pass\n"
        "READY = True\n",
        encoding="utf-8",
    )
    with pytest.raises(OutOfBudget):
        with limits_time.command_budget(0.1):
            import slow_module  # noqa: F401 - the alarm comes while it runs

            while True:  # and is raised here, once the import is done
                pass
    assert sys.modules["slow_module"].READY


def test_the_default_budget_grows_with_the_size_of_what_it_is_given():
    from workbook import limits_time as lt

    with lt.command_budget():
        lt.grow_default(100.0, "a large worksheet")
        assert lt.current().seconds == lt.DEFAULT_SECONDS + 100.0
        lt.grow_default(1.0, "a smaller one")  # the largest grant holds
        assert lt.current().seconds == lt.DEFAULT_SECONDS + 100.0
        lt.grow_default(1e9, "a huge one")
        assert lt.current().seconds == lt.MAX_SIZED_SECONDS
    with lt.command_budget(3.0, "--time-limit"):  # a budget the user set is kept
        lt.grow_default(100.0, "a large worksheet")
        assert lt.current().seconds == 3.0


def test_a_worksheet_of_many_definitions_gets_more_time_a_small_one_none(tmp_path):
    from workbook import limits_time as lt

    many = "\n".join(f'd{k} = "{k}*2"' for k in range(2000))
    with lt.command_budget():
        workbook.loads(f"[definitions]\n{many}\n")
        assert lt.current().seconds == pytest.approx(lt.DEFAULT_SECONDS + 2000 * 0.005)
    with lt.command_budget():
        workbook.loads('[definitions]\nx = "2"\n')
        assert lt.current().seconds < lt.DEFAULT_SECONDS + 0.01


def test_the_long_lived_commands_run_without_a_budget():
    import types

    from workbook import cli
    from workbook import limits_time as lt

    seen = []
    for command in ("serve", "lsp", "run"):
        args = types.SimpleNamespace(command=command, debug=False, time_limit=None)
        cli.run_command(lambda a: seen.append(lt.current() is None) or 0, args)
    assert seen == [True, True, False]
