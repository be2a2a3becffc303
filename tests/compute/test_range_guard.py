"""A live range's row-count guard: 0 exactly when the range has as many values at the current
bounds as rows were written (the engine's count, language/ranges.py), else #N/A; a workbook
whose edited bounds change the count shows #N/A in the table and in what reads it."""

from __future__ import annotations

import math

import openpyxl
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from workbook.compute import rangeguard, xleval
from workbook.compute.xleval import XlError
from workbook.errors import WorkbookError
from workbook.language.ranges import log_range_values, range_values


def _guard(formula: str):
    return xleval.compile_formula(formula)(lambda key: pytest.fail(f"reads {key}"))


def _count(first: float, second: float | None, last: float) -> int | None:
    try:
        return len(range_values(first, second, last))
    except WorkbookError:
        return None


bounds = st.floats(-1e3, 1e3, allow_nan=False).map(lambda v: round(v, 2))
steps = st.floats(0.01, 50).map(lambda v: round(v, 2)) | st.sampled_from([0.1, 0.2, 0.3, 1 / 3])


@pytest.mark.slow
@settings(max_examples=300)
@given(first=bounds, step=steps, written=st.floats(0, 500), edited=st.floats(0, 500))
def test_the_guard_counts_a_stepped_range_as_the_engine(first, step, written, edited):
    """Written at one last value, the guard at another is 0 exactly when the engine's count
    is the same, including a last value on the step and one just off it."""
    last_written = first + round(written / step) * step if written > 250 else first + written
    rows = _count(first, first + step, last_written)
    if rows is None or rows > 5000:
        return
    for last in (first + edited, last_written, last_written + step, last_written - step):
        now = _count(first, first + step, last)
        step_text = f"(({first + step!r})-({first!r}))"
        value = _guard(rangeguard.stepped_count_formula(repr(first), step_text, repr(last), rows))
        assert (value == 0) == (now == rows), (first, step, last_written, last, rows, now, value)
        if value != 0:
            assert isinstance(value, XlError) and value == "#N/A"


@pytest.mark.parametrize(
    "first, last, unit_step",
    [(0.0, 10.0, "1"), (0.0, 10.5, "1"), (3.0, -4.0, "(-1)"), (2.0, 2.0, "1")],
)
def test_the_guard_of_a_range_of_unit_steps(first, last, unit_step):
    rows = _count(first, None, last)
    for n in (rows - 1, rows, rows + 1):
        value = _guard(rangeguard.stepped_count_formula(repr(first), unit_step, repr(last), n))
        assert (value == 0) == (n == rows)


def test_a_step_away_from_the_last_value_is_no_count():
    """The engine refuses ``0, 5 .. -2``; the guard of a one-row table is #N/A there."""
    assert _count(0.0, 5.0, -2.0) is None
    assert _guard(rangeguard.stepped_count_formula("0", "((5)-(0))", "-2", 1)) == "#N/A"


def test_the_guard_of_a_log_range():
    rows = len(log_range_values(1.0, 100.0, 7))
    assert _guard(rangeguard.log_count_formula("7", rows)) == 0
    assert _guard(rangeguard.log_count_formula("8", rows)) == "#N/A"


EDITED = """
[inputs]
L = "100 mm"

[arguments]
x = { unit = "mm" }

[definitions]
"f(x)" = "x*(L - x)/L"
low = { expr = "min_over(t, f)", unit = "mm" }

[[tables]]
name = "t"
range = "x := 0 mm, 5 mm .. L"
columns = { f = "mm" }
"""


def test_the_written_guard_holds_at_the_written_inputs(tmp_path, sheet_from):
    """Right of the table's title, 0 (shown as 'rows ok'), and every range cell adds it."""
    book = openpyxl.load_workbook(sheet_from(EDITED).write_xlsx(tmp_path / "t.xlsx"))
    ws = book["Listing"]
    assert ws["C1"].value.startswith("=IF(AND(") and ws["C1"].number_format.endswith('"rows ok"')
    rows = [ws.cell(r, 1).value for r in range(3, 24)]
    assert all(v.endswith("+$C$1") for v in rows) and rows[-1] == "=(L_)+$C$1"
    assert math.isclose(sheet_from(EDITED).evaluate("low").magnitude, 0.0, abs_tol=1e-12)
