"""Filled-down columns: a run of cells whose formulas are one formula copied down (as Excel's
fill translates it) becomes one function of the row, ``NAME(i_row)``, over a range variable.

A reference that moves with the row reads element ``i_row`` of a column: a vector of the
column's numbers when they are constants, or the function of another run of the same rows;
a reference that does not move is the cell's name. A run whose formula reads its own column
(a running total), a moving range, or a column that is neither is left to cell-by-cell
translation.
"""

from __future__ import annotations

from dataclasses import dataclass

from .criteria import FUNCTIONS as CRITERIA

MIN_RUN = 3
ROW = "i_row"


@dataclass
class Run:
    sheet: str
    col: int
    first: int
    last: int
    name: str = ""
    moving: dict | None = None  # (sheet, row, col) of the first row's moving refs -> column key

    @property
    def count(self) -> int:
        return self.last - self.first + 1

    def keys(self):
        return [(self.sheet, r, self.col) for r in range(self.first, self.last + 1)]


def _leaves(tree) -> list:
    kind, name, payload = tree
    if kind == "leaf":
        return [payload] if name == "Range" else []
    return [leaf for arg in payload for leaf in _leaves(arg)]


def _calls(tree, names: tuple[str, ...]) -> bool:
    kind, fname, payload = tree
    if kind == "leaf":
        return False
    return (kind == "fn" and fname.upper() in names) or any(_calls(a, names) for a in payload)


def find_runs(book, cells, parsed, ref_of) -> list[Run]:
    """The runs of filled-down formulas (at least MIN_RUN rows), in reading order."""
    from openpyxl.formula.translate import Translator
    from openpyxl.utils import get_column_letter

    by_col: dict[tuple[str, int], list] = {}
    for c in cells:
        if c.array is None and (c.sheet, c.row, c.col) in parsed:
            by_col.setdefault((c.sheet, c.col), []).append(c)
    runs = []
    for (sheet, col), column in by_col.items():
        column.sort(key=lambda c: c.row)
        start = 0
        while start < len(column):
            first = column[start]
            end = start
            origin = f"{get_column_letter(col)}{first.row}"
            while end + 1 < len(column) and column[end + 1].row == column[end].row + 1:
                nxt = column[end + 1]
                try:
                    moved = Translator("=" + first.formula, origin=origin).translate_formula(
                        f"{get_column_letter(col)}{nxt.row}"
                    )
                except Exception:  # noqa: BLE001 - a formula openpyxl cannot move
                    break
                if moved != "=" + nxt.formula:
                    break
                end += 1
            if end - start + 1 >= MIN_RUN:
                run = Run(sheet, col, first.row, column[end].row)
                if _moving(run, parsed, ref_of):
                    runs.append(run)
            start = end + 1
    return runs


def _moving(run: Run, parsed, ref_of) -> bool:
    """Find the references that move with the row; False if the run cannot be one function."""
    if _calls(parsed[(run.sheet, run.first, run.col)].tree, (*CRITERIA, "OFFSET", "MATCH")):
        return False  # what they read is found when each cell's formula is translated
    a = _leaves(parsed[(run.sheet, run.first, run.col)].tree)
    b = _leaves(parsed[(run.sheet, run.first + 1, run.col)].tree)
    if len(a) != len(b):
        return False
    moving = {}
    for ta, tb in zip(a, b):
        try:
            ra, rb = ref_of(ta, run.sheet), ref_of(tb, run.sheet)
        except Exception:  # noqa: BLE001 - a reference the cell translation refuses
            return False
        if (ra.sheet, ra.r1, ra.c1, ra.r2, ra.c2) == (rb.sheet, rb.r1, rb.c1, rb.r2, rb.c2):
            if ra.sheet == run.sheet and ra.c1 <= run.col <= ra.c2 and ra.r2 >= run.first:
                return False  # reads its own column
            continue
        if not ra.single or (rb.sheet, rb.r1, rb.c1) != (ra.sheet, ra.r1 + 1, ra.c1):
            return False
        if ra.sheet == run.sheet and ra.c1 == run.col:
            return False  # a running total: each row reads the one before
        moving[(ra.sheet, ra.r1, ra.c1)] = (ra.sheet, ra.c1, ra.r1 - run.first)
    run.moving = moving
    return True
