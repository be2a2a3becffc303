"""Excel tables (ListObjects) and their structured references.

A formula that reads a table by its columns (``Table4[[#This Row],[Diameter (in)]]``,
``Table3[Density (kg/m3)]``, ``Table4[[#Headers],[Segment]:[Area (m2)]]``) is written here with
the A1 references Excel means by them, from the table's own extent and column names (as the
file stores them), before the formula is parsed: a column's data is its cells between the
header row and the totals row (absolute: ``$C$7:$C$2000``), ``[#This Row]`` the cell of the
formula's own row (``$C7``: a reference whose row moves as the formula is filled down), so
that everything after reads an ordinary reference. Column names are matched without case, as
Excel does, and ``'`` escapes ``[ ] # '`` in them. What this does not read with certainty (a
name that is no table's column, ``[#This Row]`` from a row outside the table's data, which
Excel reads by implicit intersection or shows as ``#VALUE!``) leaves the formula as it is,
with the reason, and it is listed.
"""

from __future__ import annotations

import re
from dataclasses import dataclass


@dataclass(frozen=True)
class Table:
    name: str
    sheet: str
    r1: int
    c1: int
    r2: int
    c2: int
    headers: int  # header rows (0 or 1)
    totals: int  # totals rows (0 or 1)
    columns: tuple[str, ...]

    @property
    def data(self) -> tuple[int, int]:
        return self.r1 + self.headers, self.r2 - self.totals

    def column(self, name: str) -> int:
        want = name.casefold()
        for k, c in enumerate(self.columns):
            if c.casefold() == want:
                return self.c1 + k
        raise StructuredProblem(f"the table {self.name} has no column {name!r}")


class StructuredProblem(Exception):
    """A structured reference this translation does not read with certainty."""


def read_tables(wb) -> dict[str, Table]:
    """{name folded: Table} of every worksheet's tables (openpyxl's ``ws.tables``)."""
    from openpyxl.utils.cell import range_boundaries

    out: dict[str, Table] = {}
    for ws in wb.worksheets:
        tables = getattr(ws, "tables", {}) or {}
        for name in list(tables.keys()):
            t = tables[name]
            try:
                c1, r1, c2, r2 = range_boundaries(str(t.ref))
            except (TypeError, ValueError):
                continue
            columns = tuple(str(c.name or "") for c in (t.tableColumns or []))
            if None in (c1, r1, c2, r2) or len(columns) != c2 - c1 + 1:
                continue
            headers = 1 if t.headerRowCount is None else int(t.headerRowCount)
            totals = int(t.totalsRowCount or 0)
            out[str(t.displayName or name).casefold()] = Table(
                str(t.displayName or name), ws.title, r1, c1, r2, c2, headers, totals, columns
            )
    return out


_SPECIALS = {"#all", "#data", "#headers", "#totals", "#this row"}
_NAME_START = re.compile(r"(?<![\w.!$'\]])([A-Za-z_\\][\w.]*)\[")


def rewrite(formula: str, sheet: str, row: int, tables: dict[str, Table]) -> str:
    """The formula with its structured references as A1 references (raises
    StructuredProblem for one that is not read with certainty)."""
    if "[" not in formula or not tables:
        return formula
    out, i = [], 0
    in_text = False
    while i < len(formula):
        ch = formula[i]
        if ch == '"':
            in_text = not in_text
            out.append(ch)
            i += 1
            continue
        if in_text:
            out.append(ch)
            i += 1
            continue
        m = _NAME_START.match(formula, i) if (i == 0 or not _word(formula[i - 1])) else None
        if m and m.group(1).casefold() in tables:
            table = tables[m.group(1).casefold()]
            end = _closing(formula, m.end() - 1)
            spec = formula[m.end() : end]
            out.append(_a1(table, spec, sheet, row))
            i = end + 1
            continue
        out.append(ch)
        i += 1
    return "".join(out)


def _word(ch: str) -> bool:
    return ch.isalnum() or ch in "_.!$'\\]"


def _closing(text: str, start: int) -> int:
    """The index of the ``]`` that closes the ``[`` at ``start`` (``'`` escapes one
    character)."""
    depth, i = 0, start
    while i < len(text):
        ch = text[i]
        if ch == "'":
            i += 2
            continue
        if ch == "[":
            depth += 1
        elif ch == "]":
            depth -= 1
            if depth == 0:
                return i
        i += 1
    raise StructuredProblem("a structured reference without its closing ]")


def _unescape(name: str) -> str:
    return re.sub(r"'(.)", r"\1", name)


def _items(spec: str) -> list[tuple[str, str]]:
    """[(separator before, item)] of a specifier's bracketed items: ``[#Headers],[A]:[B]``."""
    items, i, sep = [], 0, ","
    if spec.strip().startswith(("[", "@")):  # spaces may stand between items, not in a name
        spec = spec.strip()
    if spec.startswith("@"):  # [@Col] or [@[Col]]: this row
        items.append((",", "#this row"))
        spec = spec[1:].strip()
        if not spec:
            return items
        if not spec.startswith("["):
            return items + [(",", _unescape(spec))]
    if not spec.startswith("["):
        return [(",", _unescape(spec) if spec.casefold() not in _SPECIALS else spec.casefold())]
    while i < len(spec):
        ch = spec[i]
        if ch.isspace():
            i += 1
            continue
        if ch in ",:":
            sep = ch
            i += 1
            continue
        if ch != "[":
            raise StructuredProblem(f"the structured reference [{spec}]")
        end = _closing(spec, i)
        item = spec[i + 1 : end]
        items.append((sep, item.casefold() if item.casefold() in _SPECIALS else _unescape(item)))
        sep = ","
        i = end + 1
    return items


def _a1(table: Table, spec: str, sheet: str, row: int) -> str:
    from openpyxl.utils import get_column_letter

    specials, columns = [], []
    for sep, item in _items(spec):
        if item in _SPECIALS:
            specials.append(item)
        elif sep == ":" and columns:
            lo = columns.pop()
            hi = table.column(item)
            columns.append((min(lo[0], hi), max(lo[1], hi)))
        else:
            c = table.column(item)
            columns.append((c, c))
    if len(columns) > 1:
        raise StructuredProblem("a structured reference to columns apart")
    c1, c2 = columns[0] if columns else (table.c1, table.c2)
    d1, d2 = table.data
    key = frozenset(specials) or frozenset({"#data"})
    this_row = False
    if key == {"#this row"}:
        if table.sheet != sheet or not d1 <= row <= d2:
            raise StructuredProblem(
                f"[#This Row] of the table {table.name} from a row outside its data"
            )
        r1 = r2 = row
        this_row = True
    elif key == {"#all"}:
        r1, r2 = table.r1, table.r2
    elif key == {"#data"}:
        r1, r2 = d1, d2
    elif key == {"#headers"} and table.headers:
        r1 = r2 = table.r1
    elif key == {"#totals"} and table.totals:
        r1 = r2 = table.r2
    elif key == {"#headers", "#data"}:
        r1, r2 = table.r1, d2
    elif key == {"#data", "#totals"}:
        r1, r2 = d1, table.r2
    else:
        raise StructuredProblem(f"the structured reference {table.name}[{spec}]")
    if r1 > r2:
        raise StructuredProblem(f"the table {table.name} has no such rows")
    where = "" if table.sheet == sheet else "'" + table.sheet.replace("'", "''") + "'!"
    if this_row:
        cells = [f"${get_column_letter(c)}{row}" for c in (c1, c2)]
    else:
        cells = [f"${get_column_letter(c)}${r}" for c, r in ((c1, r1), (c2, r2))]
    if cells[0] == cells[1]:
        return where + cells[0]
    return f"{where}{cells[0]}:{cells[1]}"
