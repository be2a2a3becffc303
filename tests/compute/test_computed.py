"""The computed-sheet stage: after ``compute``, writing the workbook, the report (HTML) and
the CSV of a template makes no call into typing or evaluation (counted with cProfile), and
what they write is what the stage computed."""

from __future__ import annotations

import cProfile
import pstats

import numpy as np
import pytest

import workbook
from workbook.compute.computed import ComputedSheet, compute
from workbook.outputs.atomic import write_csv
from workbook.outputs.report import render
from workbook.outputs.xlsx import write_workbook

#: the modules that type, evaluate or print formulas: a renderer calls none of them
STAGES_BEFORE = (
    "workbook/language/typecheck.py",
    "workbook/language/typearrays.py",
    "workbook/engine/numeric.py",
    "workbook/numerics/",
    "workbook/program/",
    "workbook/engine/runtime.py",
    "workbook/engine/sheet.py",
    "workbook/engine/solve_blocks.py",
    "workbook/engine/ode.py",
    "workbook/engine/oderun.py",
    "workbook/numerics/symbolic.py",
    "workbook/engine/analysis.py",
    "workbook/compute/declared_checks.py",
    "workbook/compute/excel.py",
    "workbook/compute/excelform.py",
    "workbook/compute/excelchecks.py",
    "workbook/compute/solversteps.py",
    "workbook/compute/livecheck.py",
    "workbook/blocks/",
)

#: what the templates have, small: a root in a definition and in a table column (helper
#: cells), an integral and a maximum (live forms), a matrix, a text, a chart over a range no
#: table has, a chart over a table's columns, a printed value and a declared check
SMALL = """
[inputs]
a = { value = "2 mm", positive = true }
b = { value = "3", note = "a plain number" }

[arguments]
t = { unit = "" }

[definitions]
c = "root(t^2 - b, t, 0, 5)"
area = "integral(sin(t)^2, t, 0, b)"
peak = "maximum(t*exp(-t), t, 0, b)"
M = "[[1, 2], [3, 4]]*a"
verdict = "'ok' if c > 1 otherwise 'low'"
"f(t)" = "a*sin(t) + a*root(x^3 - t - 1, x, 0, 10)"

[[tables]]
name = "curve"
range = "t := 0, 0.5 .. 3"
columns = { f = "mm" }

[[charts]]
name = "lines"
title = "f and its square"
range = "t := 0, 0.25 .. 3"
y_title = "mm"
series = [{ y = "f", unit = "mm", name = "f" }]

[[charts]]
name = "again"
title = "f from the table"
range = "t := 0, 0.5 .. 3"
y_title = "mm"
series = [{ y = "f", unit = "mm", name = "f" }]

[[checks]]
topic = "root"
what = "c = {c} is the square root of b"
value = "c"
ok = "abs(c - sqrt(b)) < 1e-6"
"""


def templates():
    return [pytest.param(name, marks=pytest.mark.slow) for name in workbook.list_templates()]


def calls_into_stages(run) -> dict[str, int]:
    """Calls ``run()`` makes into :data:`STAGES_BEFORE`, by module and function."""
    profile = cProfile.Profile()
    profile.enable()
    try:
        run()
    finally:
        profile.disable()
    found: dict[str, int] = {}
    for (file, _, function), (_, calls, *_) in pstats.Stats(profile).stats.items():
        path = file.replace("\\", "/")
        module = next((m for m in STAGES_BEFORE if f"/{m}" in path), None)
        if module is not None:
            key = f"{module}:{function}"
            found[key] = found.get(key, 0) + calls
    return found


def rendered_without_evaluation(sheet, tmp_path) -> None:
    """Compute ``sheet``, then write its workbook, CSV and report HTML counting the calls."""
    name = sheet.name
    for_workbook = compute(sheet, excel=True)
    for_report = compute(sheet)

    def workbook_and_csv():
        write_workbook(for_workbook, tmp_path / f"{name}.xlsx")
        for t in sheet.spec.tables:
            write_csv(for_workbook.frame(t.name), tmp_path / f"{t.name}.csv")

    assert calls_into_stages(workbook_and_csv) == {}
    assert calls_into_stages(lambda: render(for_report)) == {}
    assert (tmp_path / f"{name}.xlsx").stat().st_size > 0


@pytest.mark.slow
def test_rendering_a_small_sheet_makes_no_call_into_typing_or_evaluation(sheet_from, tmp_path):

    sheet = sheet_from(SMALL)
    rendered_without_evaluation(sheet, tmp_path)
    import openpyxl

    names = openpyxl.load_workbook(tmp_path / f"{sheet.name}.xlsx").sheetnames
    assert {"Solver steps", "Solver rows", "Chart data", "Matrices", "Charts"} <= set(names)


@pytest.mark.parametrize("name", templates())
def test_rendering_a_template_makes_no_call_into_typing_or_evaluation(name, tmp_path):
    rendered_without_evaluation(workbook.load(name), tmp_path)


def test_the_count_sees_evaluation():
    """The same count around computing finds the typer and the evaluator: a renderer that
    evaluated would be seen."""
    sheet = workbook.load("concave-cam")
    found = calls_into_stages(lambda: compute(sheet.with_inputs(R3="41 mm"), excel=True))
    modules = {key.split(":")[0] for key in found}
    assert {
        "workbook/engine/numeric.py",
        "workbook/engine/sheet.py",
        "workbook/compute/excelform.py",
    } <= modules


def test_the_computed_sheet_holds_values_not_the_engine(concave):
    """No Sheet, typer or evaluator inside: a renderer has nothing to evaluate with."""
    from workbook.engine.numeric import Evaluator
    from workbook.engine.sheet import Sheet
    from workbook.language.typecheck import Typer

    computed = compute(concave)
    assert isinstance(computed, ComputedSheet)
    for value in vars(computed).values():
        assert not isinstance(value, (Sheet, Typer, Evaluator))
    h1 = concave.table_data("flank_AB").columns[1]
    assert np.array_equal(computed.table("flank_AB").columns[1].values, h1.values)
    assert computed.scalars["k"].value == concave.scalar_quantity("k")
    x, y = computed.series[("fig4", 0)].x, computed.series[("fig4", 0)].y
    assert len(x) == len(y) > 0


def test_a_value_that_fails_is_kept_as_its_error(tmp_path):
    """The report shows the error of a definition; the workbook raises it where it would
    have been written (exit 2 for bad input)."""
    from helpers.sheets import write_template

    from workbook.errors import WorkbookError

    path = write_template(
        tmp_path,
        """
[inputs]
x = { value = "-1" }

[definitions]
r = "sqrt(x)"
""",
    )
    sheet = workbook.load(path)
    computed = compute(sheet)
    assert isinstance(computed.scalars["r"].error, WorkbookError)
    assert "not computed" in render(computed)
