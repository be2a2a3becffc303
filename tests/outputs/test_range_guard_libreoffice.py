"""Random sheets of live stepped ranges whose last value is an input, written, edited on the
Inputs sheet and recalculated by LibreOffice: where the edit keeps the number of values, every
range cell and every max/min over its table is the engine's at the edited inputs; where it
changes it, the guard, the range cells and the max/min are #N/A, never a number. Slow: each
example starts LibreOffice."""

from __future__ import annotations

import math

import openpyxl
import pytest
from helpers.recalc import cell_values, recalculate, soffice
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from workbook.language.ranges import range_values

pytestmark = [
    pytest.mark.skipif(soffice() is None, reason="LibreOffice is not installed"),
    pytest.mark.slow,
]

TABLES = 4
table = st.tuples(
    st.integers(-20, 20),  # first value, mm
    st.sampled_from([0.5, 1.0, 2.5, 5.0]),  # step, mm
    st.floats(5, 60).map(lambda v: round(v, 1)),  # the last value as written, mm
    st.sampled_from([-1.0, -0.3, 0.0, 0.2, 1.0])  # the edit, in steps: on the step or off it
    | st.floats(-3, 3).map(lambda v: round(v, 2)),
)


def _sheet(tables) -> str:
    lines = ["[inputs]"] + [f'L{k} = "{t[0] + t[2]} mm"' for k, t in enumerate(tables)]
    lines += ["[arguments]", 'x = { unit = "mm" }', "[definitions]"]
    lines += ['"f(x)" = "x^2/(1 mm) - 3*x"']
    for k in range(len(tables)):
        lines += [
            f'top{k} = {{ expr = "max_over(t{k}, f)", unit = "mm" }}',
            f'low{k} = {{ expr = "min_over(t{k}, f)", unit = "mm" }}',
        ]
    for k, (first, step, _, _) in enumerate(tables):
        lines += [
            "[[tables]]",
            f'name = "t{k}"',
            f'range = "x := {first} mm, {first + step} mm .. L{k}"',
            'columns = { f = "mm" }',
            f'sheet = "T{k}"',
        ]
    return "\n".join(lines) + "\n"


FIXTURES = [HealthCheck.function_scoped_fixture]  # tmp_path is shared: each example overwrites


@settings(max_examples=4, deadline=None, suppress_health_check=FIXTURES)
@given(tables=st.lists(table, min_size=TABLES, max_size=TABLES))
def test_an_edit_that_changes_the_row_count_is_na_never_a_number(tmp_path, sheet_from, tables):
    sheet = sheet_from(_sheet(tables))
    out = sheet.write_xlsx(tmp_path / "r.xlsx", force=True)
    book = openpyxl.load_workbook(out)
    ws = book["Inputs"]
    edited = {}
    for r in range(2, ws.max_row + 1):
        name = ws.cell(r, 1).value
        if isinstance(name, str) and name.startswith("L") and name[1:].isdigit():
            first, step, last, edit = tables[int(name[1:])]
            # never below the second value: the engine refuses a last value behind the first
            ws.cell(r, 2).value = edited[name] = max(first + last + edit * step, first + step)
    book.save(tmp_path / "edited.xlsx")
    got = cell_values(recalculate(tmp_path / "edited.xlsx", tmp_path / "lo"))
    engine = sheet.with_inputs(**{n: f"{v!r} mm" for n, v in edited.items()})
    results = {got.get(("Results", f"A{r}")): got.get(("Results", f"B{r}")) for r in range(2, 40)}
    for k, (first, step, last, _) in enumerate(tables):
        rows = len(range_values(first, first + step, first + last))
        now = len(range_values(first, first + step, edited[f"L{k}"]))
        cells = [got.get((f"T{k}", f"A{r}")) for r in range(3, 3 + rows)]
        aggregates = [results[f"top{k}"], results[f"low{k}"]]
        if now != rows:
            assert got.get((f"T{k}", "C1")) == "#N/A", (k, tables[k], rows, now)
            assert all(v == "#N/A" for v in cells + aggregates), (k, cells, aggregates)
            continue
        assert got.get((f"T{k}", "C1")) == 0, (k, tables[k])
        want = range_values(first, first + step, edited[f"L{k}"])
        assert all(math.isclose(a, b, rel_tol=1e-9, abs_tol=1e-12) for a, b in zip(cells, want))
        for name, value in zip((f"top{k}", f"low{k}"), aggregates):
            expected = float(engine.evaluate(name).to("mm").magnitude)
            assert math.isclose(value, expected, rel_tol=1e-9, abs_tol=1e-12), (name, value)
