"""The row-count guard of a live range table.

A range whose bounds follow the inputs (``x := 0 mm, 5 mm .. L``) is written as live
formulas in a fixed number of rows. An edit that changes how many values the range has
(L from 100 mm to 75 mm: 16 values, not 21) would leave rows beyond the new last value, and
``MIN``/``MAX`` over the column would read them: a wrong number with nothing to show it. So
one cell beside the table counts the range's values at the current inputs as the engine does
(:func:`workbook.language.ranges.range_values`), and is 0 while that count is the number of
rows written, else ``#N/A``; every cell of the range column adds it, so a changed count turns
the column, and every formula that reads it, into ``#N/A`` until the workbook is written again.
"""

from __future__ import annotations

#: the engine's tolerances (language/ranges.py ``_steps``), written into the guard formula
SPAN_RELATIVE, SPAN_ABSOLUTE, ON_STEP = "1E-12", "1E-9", "1E-9"


def stepped_count_formula(first: str, step: str, last: str, rows: int) -> str:
    """``=IF(..., 0, NA())``: 0 while ``first, first + step .. last`` has ``rows`` values
    (the last value always one of them), ``#N/A`` otherwise. The texts are Excel
    expressions in the range variable's unit."""
    span = f"(({last})-({first}))/({step})*(1+{SPAN_RELATIVE})+{SPAN_ABSOLUTE}"
    count = f"(INT({span})+1)"
    on_step = f"ABS(({first})+({step})*({count}-1)-({last}))<={ON_STEP}*MAX(1,ABS({step}))"
    toward = f"(({last})-({first}))*({step})>=0"
    return f"=IF(AND({toward},{count}+IF({on_step},0,1)={rows}),0,NA())"


def log_count_formula(points: str, rows: int) -> str:
    """``=IF(points = rows, 0, NA())`` for a log-spaced range of ``points`` values."""
    return f"=IF(({points})={rows},0,NA())"
