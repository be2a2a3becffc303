"""The cells that VBA Subs (macros run by a button) write, read from their source (never run).

A Sub's result is a value it writes into cells (``Range("B5").Value = x``,
``Sheets("Calc").Cells(3, 2) = y``): no formula computes it. Only writes whose address is
written in the code are found; a write without its sheet (the active sheet) counts for a
workbook of one sheet only, else it names no cell."""

from __future__ import annotations

import re

from .vba import Module

_SHEET = r"(?:(?:Worksheets|Sheets)\(\s*\"([^\"]+)\"\s*\)\s*\.\s*)?"
_RANGE = re.compile(
    _SHEET + r"Range\(\s*\"\$?([A-Z]{1,3})\$?(\d+)(?::\$?([A-Z]{1,3})\$?(\d+))?\"\s*\)"
    r"(?:\s*\.\s*(?:Value2?|Text))?\s*=(?!=)",
    re.I,
)
_CELLS = re.compile(_SHEET + r"Cells\(\s*(\d+)\s*,\s*(\d+)\s*\)(?:\s*\.\s*Value2?)?\s*=(?!=)", re.I)
#: at most this many cells of one written range are named
MAX_WRITTEN = 10_000


def cells_written(modules: list[Module], sheets: list[str]) -> dict[tuple[str, int, int], str]:
    """{(sheet, row, column): the name of the first Sub that writes the cell's value}."""
    from openpyxl.utils import column_index_from_string

    out: dict[tuple[str, int, int], str] = {}
    by_lower = {s.lower(): s for s in sheets}

    def add(sheet_text: str | None, r1: int, c1: int, r2: int, c2: int, sub: str) -> None:
        if sheet_text is None:
            if len(sheets) != 1:
                return
            sheet = sheets[0]
        else:
            sheet = by_lower.get(sheet_text.lower())
            if sheet is None:
                return
        if (r2 - r1 + 1) * (c2 - c1 + 1) > MAX_WRITTEN:
            return
        for r in range(r1, r2 + 1):
            for c in range(c1, c2 + 1):
                out.setdefault((sheet, r, c), sub)

    for mod in modules:
        for proc in mod.procedures:
            if proc.kind != "Sub":
                continue
            for _, line in proc.lines:
                text = line.strip()
                for m in _RANGE.finditer(text):
                    if not _statement_start(text[: m.start()]):
                        continue
                    c1, r1 = column_index_from_string(m.group(2).upper()), int(m.group(3))
                    c2 = column_index_from_string(m.group(4).upper()) if m.group(4) else c1
                    r2 = int(m.group(5)) if m.group(5) else r1
                    add(m.group(1), min(r1, r2), min(c1, c2), max(r1, r2), max(c1, c2), proc.name)
                for m in _CELLS.finditer(text):
                    if not _statement_start(text[: m.start()]):
                        continue
                    r, c = int(m.group(2)), int(m.group(3))
                    add(m.group(1), r, c, r, c, proc.name)
    return out


def _statement_start(before: str) -> bool:
    """Whether a match after ``before`` starts a statement (an assignment, not a comparison in
    a condition, nor a member of a With block's object)."""
    before = before.rstrip()
    return (
        before == "" or before.endswith(":") or re.search(r"(?i)\b(then|else)$", before) is not None
    )
