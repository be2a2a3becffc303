"""Hostile worksheets: each is refused at load or stopped by a documented limit, with a message.

Every case runs the real command line in a fresh process (forked from one interpreter that
imported the engine, tests/helpers/guard_server.py) with an address-space limit
(RLIMIT_AS), a CPU-time limit and a wall-clock timeout. An audit hook (PEP 578) installed
before the command runs records every file opened for writing, every file read outside the
Python installation, the package and the case's folder, every import of a module that could
reach the system, and every process start; none may happen.
"""

from __future__ import annotations

import json
import time

import pytest
from helpers.hostile import WALL_SECONDS, guarded, program
from helpers.paths import ROOT

from workbook import limits as file_limits
from workbook.compute import excelform
from workbook.engine import numeric, runtime, sheet
from workbook.language import expr, odes, ranges, template, typecheck
from workbook.numerics import derivative
from workbook.sweep.driver import MAX_SWEEP_POINTS
from workbook.sweep.grid import MAX_CASES

HEAD = '[inputs]\nR1 = "20 mm"\n\n[arguments]\nx = { unit = "" }\n\n[definitions]\n'
TABLE = '\n[[tables]]\nname = "t"\nrange = "x := 0 .. 3"\ncolumns = { s = "" }\n'


def define(expression: str) -> str:
    """A sheet whose definition s is ``expression``, shown in a table so that it is computed."""
    return HEAD + "s = " + json.dumps(expression) + "\n" + TABLE


DEEP = 5000
HOSTILE = {
    # expressions that try to reach Python
    "attribute": (define("R1.__class__"), "Attribute is not allowed"),
    "attribute_chain": (
        define("x.__class__.__bases__[0].__subclasses__()"),
        "only plain function calls",
    ),
    "import_call": (define("__import__('os').system('touch pwned')"), "only plain function calls"),
    "import_statement": (define("import os"), "cannot parse"),
    "dunder_name": (define("__builtins__"), "name '__builtins__' is not allowed"),
    "dunder_function": (define("__import__('os')"), "only plain function calls"),
    "eval_call": (define("eval('1')"), "unknown function 'eval'"),
    "open_call": (define("open('/etc/passwd')"), "unknown function 'open'"),
    "lambda": (define("lambda: 1"), "Lambda is not allowed"),
    "lambda_call": (define("(lambda: 1)()"), "only plain function calls"),
    "list_comprehension": (define("[x for x in range(10**9)]"), "ListComp is not allowed"),
    "generator": (define("max(x for x in range(10**9))"), "GeneratorExp is not allowed"),
    "set_comprehension": (define("{x for x in R1}"), "SetComp is not allowed"),
    "subscript": (define("R1[0]"), "is not a vector or matrix; it cannot be indexed"),
    "slice": (define("R1[::-1]"), "no slices"),
    "walrus": (define("(y := 1)"), "NamedExpr is not allowed"),
    "conditional": (define("1 if R1 > 0 else 'a'"), "gives text on one side"),
    "keyword_argument": (define("max(a=1)"), "keyword arguments are not allowed"),
    "starred": (define("max(*R1)"), "starred arguments are not allowed"),
    "string_repeat": (define("'a' * 10**9"), "text can only be compared"),
    "string_format": (define("'%s' % R1"), "% between two values is not an operator"),
    "fstring": (define("f'{R1.__class__}'"), "JoinedStr is not allowed"),
    "bytes": (define("b'abc'"), "is not allowed"),
    "tuple": (define("(1, 2)"), "Tuple is not allowed"),
    "dict": (define("{'a': 1}"), "Dict is not allowed"),
    "bit_shift": (define("1 << 100000"), "operator LShift not allowed"),
    "matmul": (define("R1 @ R1"), "operator MatMult not allowed"),
    # numbers and sizes
    "power_tower": (define("10**10**10"), "is not a finite number"),
    "power_tower_caret": (define("10^10^10"), "is not a finite number"),
    "power_of_length": (define("R1^(10^10)"), "out of range"),
    "huge_literal": (define("9" * 4000), "too large"),
    "too_long": (define("+".join(["x"] * 15000)), f"limit {expr.MAX_TEXT}"),
    "parentheses_deep": (define("(" * DEEP + "1" + ")" * DEEP), f"limit {expr.MAX_DEPTH}"),
    "unary_deep": (define("-" * DEEP + "1"), "nested"),
    "not_deep": (
        HEAD + '"f(x)" = ["1 if ' + "not " * 2000 + 'x > 0", "2 otherwise"]\n' + TABLE,
        "nested",
    ),
    "sum_deep": (define("+".join(["1"] * 3000)), "nested too deeply"),
    "sum_201_terms": (define("+".join(["1"] * 202)), f"nested more than {expr.MAX_DEPTH} deep"),
    "call_deep": (define("abs(" * DEEP + "1" + ")" * DEEP), f"limit {expr.MAX_DEPTH}"),
    "toml_arrays_deep": ("a = " + "[" * 100_000 + "]" * 100_000 + "\n", "nested too deeply"),
    "toml_tables_deep": ("a = " + "{b = " * 100_000 + "1" + "}" * 100_000 + "\n", "nested"),
    "template_too_big": (
        HEAD + "".join(f'd{i} = "{i} + R1 * 0"\n' for i in range(200_000)),
        f"limit {template.MAX_TEMPLATE_BYTES:,}",
    ),
    "definition_chain": (
        HEAD
        + "".join(f'"f{i}(x)" = "f{i + 1}(x) + 1"\n' for i in range(3000))
        + '"f3000(x)" = "x"\n'
        + '\n[[tables]]\nname = "t"\nrange = "x := 0 .. 3"\ncolumns = { f0 = "" }\n',
        f"more than {typecheck.MAX_CHAIN} deep",
    ),
    "definition_chain_in_order": (  # typed one by one, but inlined into one Excel formula
        HEAD
        + '"f0(x)" = "x"\n'
        + "".join(f'"f{i}(x)" = "f{i - 1}(x) + 1"\n' for i in range(1, 400))
        + '\n[[tables]]\nname = "t"\nrange = "x := 0 .. 3"\ncolumns = { f399 = "" }\n',
        "hostile.toml:410, in 'table t': limit exceeded: nested too deeply for the engine",
    ),
    "range_1e10_points": (
        HEAD + 's = "1"\n\n[[tables]]\nname = "t"\nrange = "x := 0, 1 .. 1e10"\n'
        'columns = { "2*x" = "" }\n',
        f"range has 10,000,000,001 points (limit {ranges.MAX_RANGE_POINTS:,})",
    ),
    "range_infinite_points": (
        HEAD + 's = "1"\n\n[[tables]]\nname = "t"\nrange = "x := 0, 1e-300 .. 1e300"\n'
        'columns = { "2*x" = "" }\n',
        f"points (limit {ranges.MAX_RANGE_POINTS:,})",
    ),
    "chart_range_1e10": (
        HEAD + '"y(x)" = "x"\n\n[[charts]]\nname = "c"\nrange = "x := 0 .. 1e10"\n'
        'series = [{ y = "y" }]\n',
        "points (limit",
    ),
    # files and modules outside the worksheet
    "printed_absolute": (
        HEAD + 's = "1"\n\n[[printed]]\nfile = "/etc/passwd"\n',
        "must be a file name beside the template",
    ),
    "printed_parent": (
        HEAD + 's = "1"\n\n[[printed]]\nfile = "../../../../etc/passwd"\n',
        "must be a file name beside the template",
    ),
    "sheet_name_escapes": (
        '[sheet]\nname = "../../escaped"\n' + define("R1"),
        "must be letters, digits",
    ),
    "block_os_system": (
        '[blocks]\nrun = "os.system"\n\n' + define("run(1)"),
        "no block module 'os'",
    ),
    "block_builtins": (
        '[blocks]\nrun = "builtins.eval"\n\n' + define("run(1)"),
        "no block module 'builtins'",
    ),
    "block_helper_not_registered": (
        '[blocks]\nrun = "coupling.linear_system"\n\n' + define("run(1)"),
        "has no registered block 'linear_system'",
    ),
    "block_dotted": (
        '[blocks]\nrun = "os.path.join"\n\n' + define("run(1)"),
        "a block is named as 'module.function'",
    ),
    "table_block_os": (
        HEAD + 's = "1"\n\n[[tables]]\nname = "b"\nblock = "os.system"\n',
        "no block module 'os'",
    ),
    "findings_block_os": (
        HEAD + 's = "1"\n\n[[findings]]\nblock = "subprocess.run"\n',
        "subprocess.run could not run",
    ),
}


#: Cases that take more than about 5 s (a 3,000-deep chain typed through): the slow run's.
SLOW_HOSTILE = {"definition_chain"}


@pytest.mark.parametrize(
    "name",
    [pytest.param(n, marks=pytest.mark.slow) if n in SLOW_HOSTILE else n for n in sorted(HOSTILE)],
)
def test_hostile_worksheet_is_refused(tmp_path, name):
    text, expected = HOSTILE[name]
    if name == "findings_block_os":  # a findings block that cannot be found is reported
        out = guarded(tmp_path, text, "check", "hostile.toml")
        assert out.returncode in (0, 1), out.stderr
        assert expected in out.stdout and "Traceback" not in out.stderr, out.stdout + out.stderr
    else:
        out = guarded(tmp_path, text)
        assert out.returncode == 2, (out.returncode, out.stderr[-2000:])
        assert expected in out.stderr, out.stderr[-2000:]
        assert out.stderr.startswith("workbook: ") and "Traceback" not in out.stderr, out.stderr
        assert len(out.stderr.strip().splitlines()) == 1
        assert len(out.stderr) < 600, out.stderr  # one readable paragraph, even for huge input
        written = [p.name for p in tmp_path.rglob("*") if p.is_file()]
        assert written == ["hostile.toml"], written  # not even an empty or partial workbook
    # Nothing written, read, imported or started. Ranges and block tables are evaluated while
    # the workbook is written: there the temporary file beside the target is made and removed
    # (a table the check computes fails before the file, and only its folder is removed).
    temporary = [e for e in out.events if e.endswith(".partial None") and str(tmp_path) in e]
    cleanup = ("os.remove", "os.rmdir", "shutil.rmtree")  # the temporary file and its folder
    rest = [e for e in out.events if e not in temporary and not (temporary and e in cleanup)]
    rest = [] if set(rest) <= {"os.rmdir", "shutil.rmtree"} else rest
    assert rest == [], out.events


def test_guard_sees_a_write(tmp_path):
    """The audit hook works: an ordinary run writes its workbook, and the hook reports it."""
    out = guarded(tmp_path, define("2*R1/R1 + 1"))
    assert out.returncode == 0, out.stderr
    assert any("hostile.xlsx" in e for e in out.events), out.events


def test_limits_are_documented():
    doc = str(ROOT / "docs" / "language.md")
    text = open(doc, encoding="utf-8").read()
    limits = text[text.index("## Limits") :]
    for value in (
        expr.MAX_TEXT,
        expr.MAX_DEPTH,
        ranges.MAX_RANGE_POINTS,
        template.MAX_TEMPLATE_BYTES,
        typecheck.MAX_CHAIN,
        numeric.MAX_RECURSIVE_CALLS,
        runtime.MAX_NESTING,
        runtime.MAX_RUNTIME_ELEMENTS,
        excelform.MAX_ARRAY_CELLS,
        derivative.MAX_DIFF_NODES,
        sheet.MAX_FAMILY_CELLS,
        MAX_CASES,
        MAX_SWEEP_POINTS,
        file_limits.MAX_SHARED_STRINGS,
        file_limits.MAX_STYLES_BYTES,
        file_limits.MAX_MATRIX_WORK,
        file_limits.MAX_TABLE_CELLS,
        odes.MAX_STEPS,
    ):
        assert f"{value:,}" in limits or str(value) in limits, value


@pytest.mark.slow  # seconds of CPU: run by CI with the slow tests
def test_solver_step_cap_stops_a_billion_steps():
    """A solver asked for 10^9 steps on a stiff problem with an explicit method stops at its
    documented budget (wall clock, then the step cap) with a reason, not after hours."""
    import numpy as np

    from workbook.engine.oderun import run_ode

    def stiff(t, y):  # y' = -1e6 (y - cos t): RK45 needs ~1e6 steps per unit of time
        return -1e6 * (y - np.cos(t))

    start = time.monotonic()
    run = run_ode(stiff, (0.0, 1e4), [0.0], method="RK45", max_steps=10**9, max_time=2.0)
    assert time.monotonic() - start < 30
    assert run.stop_reason == "time budget" and "wall-clock budget of 2 s" in run.notes[0]
    capped = run_ode(stiff, (0.0, 1e4), [0.0], method="RK45", max_steps=2000, max_time=60)
    assert capped.stop_reason == "step cap" and capped.nsteps == 2000


@pytest.mark.slow
def test_solver_loop_asked_for_billions_of_steps(tmp_path):
    """The r0-synthesis VBA loop (workbook/blocks/r0.py) with dr = 1e-9 mm would need ~3e10
    steps: it is refused before it starts, by its step cap, under the same guard."""
    pytest.importorskip("workbook.blocks.r0")
    out = guarded(tmp_path, "", "run", "r0-synthesis", "--set", "dr=1e-9 mm", "--out", "r0.xlsx")
    assert out.returncode == 2, out.stderr
    assert "limit exceeded" in out.stderr and "steps of dr = 1e-09 mm" in out.stderr
    assert "r0-synthesis.toml:" in out.stderr and "in 'r0_loop'" in out.stderr
    assert "Traceback" not in out.stderr and out.elapsed < WALL_SECONDS
    assert not (tmp_path / "r0.xlsx").exists()
    temporary = [e for e in out.events if e.endswith(".partial None") and str(tmp_path) in e]
    cleanup = ("os.remove", "os.rmdir", "shutil.rmtree")  # and the writer's scratch folder
    assert [e for e in out.events if e not in temporary and e not in cleanup] == [], out.events


# -- programs and run-time arrays at their bounds ------------------------------------------


NEST_IN_ITSELF = program("T := [1, 2]\nfor k in 1 .. n\n    T := [T, 1]\nT", "p(8000)")
GROW_BY_MILLIONS = program("w := 0\nfor k in 1 .. n\n    w[rows(w) + 1e6] := k\nrows(w)", "p(1e3)")
RUNTIME_HOSTILE = {
    # freeing or printing 8,000 nested arrays overflowed the C stack (SIGSEGV)
    "nested_in_itself": (NEST_IN_ITSELF, 1, f"arrays nested more than {runtime.MAX_NESTING} deep"),
    # the memory budget: the command stops before the array is made (exit 2, nothing written)
    "grown_by_millions": (GROW_BY_MILLIONS, 2, f"limit {runtime.MAX_RUNTIME_ELEMENTS:,} elements"),
    # xlsxwriter drops cells past the grid: the defined name pointed outside it, exit 0
    "past_the_last_column": (
        program("for k in 1 .. n\n    w[k] := k\ntranspose(w)", "p(20001)"),
        2,
        "1 x 20,002 (20,002 elements)",
    ),
    "past_the_last_row": (
        program("w[n] := 1\nw", "p(2000000)"),
        2,
        "2,000,001 x 1 (2,000,001 elements)",
    ),
    "too_many_cells_to_write": (
        '[definitions]\nI = "identity(2000)"\n',
        2,
        f"at most {excelform.MAX_ARRAY_CELLS:,} cells",
    ),
    "branching_recursion": (
        program("return n if n < 2\np(n - 1) + p(n - 2)", "p(30)"),
        1,
        f"more than {numeric.MAX_RECURSIVE_CALLS:,} times in one call",
    ),
}


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(RUNTIME_HOSTILE))
def test_a_program_at_its_bounds_is_stopped_with_a_message(tmp_path, name):
    text, status, expected = RUNTIME_HOSTILE[name]
    out = guarded(tmp_path, text)
    assert out.returncode == status, (out.returncode, out.stderr[-2000:])
    # exit 1: run writes the workbook, lists the scalar in error and names it as a failed value
    shown = out.stdout if status == 1 else out.stderr
    assert expected in shown, (out.stdout[-2000:], out.stderr[-2000:])
    assert "Traceback" not in out.stderr
    if status == 2:
        assert [p.name for p in tmp_path.rglob("*") if p.is_file()] == ["hostile.toml"]
