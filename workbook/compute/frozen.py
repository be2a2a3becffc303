"""Nothing silently stale: the cells of a workbook that cannot follow an edit of its inputs.

A value written as a number where its formula cannot be live (a [[solve]] unknown, an ODE
state, a sum whose bounds depend on inputs, an array known only when its program runs, a
live formula the check refused) is *frozen*: it keeps the value it had when the workbook was
written. :func:`mark` gives each frozen cell a visible style and (where it has none) a
comment, finds the live formulas that read a frozen cell directly or through other live
cells (they follow an edit only in part) and marks them too, and lists both on the Inputs
sheet with the command that regenerates the workbook.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from xlsxwriter.utility import xl_cell_to_rowcol, xl_rowcol_to_cell

from . import livecheck

#: the style roles (workbook.compute.style.FORMATS) of the two kinds of marked cells
FROZEN, STALE = "frozen", "stale"

_WRITES = {"write_number": 3, "write_string": 3, "write_boolean": 3, "write_formula": 3}
_WRITES.update({"write_array_formula": 5, "formula_column": 4})
_NAME = re.compile(r"(?<![\w.$'!])([A-Za-z_][\w.]*)(?![\w.(!])")


@dataclass
class Marked:
    """What :func:`mark` found: frozen cells and the live cells that read them, by name."""

    frozen: dict[tuple[str, int, int], str] = field(default_factory=dict)
    stale: dict[tuple[str, int, int], str] = field(default_factory=dict)  # cell -> its source

    def frozen_names(self) -> list[str]:
        return sorted(set(self.frozen.values()))


def _rectangles(text: str, here: str, names: dict[str, str], column=None) -> list:
    """The cell rectangles (sheet, r0, c0, r1, c1) a formula reads, 0-based; a reference to a
    column's row (``column``: its first row and count) reads the whole column."""
    out = []
    _, refs = livecheck.generic(text)
    texts = [r for r in refs if not r[0].isdigit()]
    stripped = re.sub(r'\{[^{}]*\}|"(?:[^"]|"")*"', "", text)
    for name in _NAME.findall(stripped):
        ref = names.get(name.upper())
        if ref is not None:
            texts.append(ref.lstrip("="))
    for ref in texts:
        sheet, _, cells = ref.rpartition("!")
        sheet = sheet.strip("'") or here
        a, _, b = cells.replace("$", "").partition(":")
        r0, c0 = xl_cell_to_rowcol(a)
        r1, c1 = xl_cell_to_rowcol(b) if b else (r0, c0)
        if column is not None and r0 == livecheck.SENTINEL - 1:
            r0, r1 = column
        out.append((sheet, r0, c0, r1, c1))
    return out


def _hits(rects: list, marked: dict[str, dict[int, set[int]]]):
    """The first marked cell inside the rectangles, or None."""
    for sheet, r0, c0, r1, c1 in rects:
        cols = marked.get(sheet)
        if not cols:
            continue
        for c in range(c0, c1 + 1):
            rows = cols.get(c)
            if rows:
                hit = next((r for r in rows if r0 <= r <= r1), None)
                if hit is not None:
                    return (sheet, hit, c)
    return None


def _stale(log: livecheck.CellLog, frozen: dict) -> dict[tuple[str, int, int], tuple]:
    """Formula cells that read a frozen cell, directly or through other formulas: cell ->
    the frozen cell it comes from."""
    readers = []
    for key, f in log.formulas.items():
        readers.append(([key], _rectangles(f.text, f.sheet, log.names)))
    for c in log.columns:
        cells = [(c.sheet, c.first + i, c.col) for i in range(c.n)]
        text = str(livecheck.SENTINEL).join(c.pieces)
        rows = (c.first, c.first + c.n - 1)
        readers.append((cells, _rectangles(text, c.sheet, log.names, rows)))
    marked: dict[str, dict[int, set[int]]] = {}
    source: dict[tuple[str, int, int], tuple] = {}

    def add(cell, origin) -> None:
        marked.setdefault(cell[0], {}).setdefault(cell[2], set()).add(cell[1])
        source[cell] = origin

    for cell in frozen:
        add(cell, cell)
    stale: dict[tuple[str, int, int], tuple] = {}
    changed = True
    while changed:
        changed = False
        for cells, rects in readers:
            if cells[0] in source:
                continue
            hit = _hits(rects, marked)
            if hit is not None:
                for cell in cells:
                    stale[cell] = source[hit]
                    add(cell, source[hit])
                changed = True
    return stale


def mark(layout) -> Marked:
    """Style and comment the frozen cells of ``layout`` (an ExcelLayout, laid out) and the
    live cells that read them; list them on its Inputs sheet."""
    frozen = dict(layout.frozen)
    for cell in layout.refused:
        frozen.setdefault(cell, _where(cell))
    out = Marked(frozen)
    if not frozen:
        return out
    stale = _stale(layout.log, frozen)
    out.stale = {cell: frozen[origin] for cell, origin in stale.items()}
    sheets = {s.name: s.index for s in layout.wb.sheets}
    index = {}
    comments = set()
    for i, (sheet, method, args, _) in enumerate(layout.wb.ops):
        if method in _WRITES:
            index[(sheet, args[0], args[1])] = i
        elif method == "write_comment":
            comments.add((sheet, args[0], args[1]))
    for cells, role in ((frozen, FROZEN), (stale, STALE)):
        for sheet, row, col in cells:
            i = index.get((sheets.get(sheet), row, col))
            if i is not None:
                _restyle(layout.wb.ops, i, role)
    columns = {(c.sheet, c.first, c.col): c for c in layout.log.columns}
    for (sheet, row, col), name in out.stale.items():
        at = (sheets[sheet], row, col)
        column = columns.get((sheet, row, col))
        if column is not None:  # a column: its header says it
            at = (sheets[sheet], row - 1, col)
        elif (sheet, row - 1, col) in out.stale and any(
            c.sheet == sheet and c.col == col and c.first <= row < c.first + c.n
            for c in layout.log.columns
        ):
            continue
        if at in comments:
            continue
        comments.add(at)
        layout.wb.ops.append(
            (
                at[0],
                "write_comment",
                (
                    at[1],
                    at[2],
                    f"Live, but it reads {name}, a value written as a number that does not "
                    f"follow an edit of the inputs: regenerate with {layout.command}.",
                ),
                -1,
            )
        )
    _list_on_inputs(layout, out)
    return out


def _restyle(ops: list, i: int, role: str) -> None:
    sheet, method, args, at = ops[i]
    pos = _WRITES[method]
    args = (*args[:pos], role, *args[pos + 1 :]) if len(args) > pos else (*args, role)
    ops[i] = (sheet, method, args, pos)


def _where(cell: tuple[str, int, int]) -> str:
    return f"'{cell[0]}'!{xl_rowcol_to_cell(cell[1], cell[2])}"


def _list_on_inputs(layout, marked: Marked) -> None:
    """Two lines under the Inputs sheet's note: the frozen results and their command, and
    the live results that read them."""
    ws = layout.sheets.get("Inputs")
    if ws is None:
        return
    row = layout.inputs_end
    names = ", ".join(marked.frozen_names())
    ws.write_string(
        row,
        0,
        f"Frozen (grey): {names}: values written as numbers, which do not follow an edit of "
        f"the inputs. Regenerate them with: {layout.command} --inputs THIS_WORKBOOK.xlsx",
        FROZEN,
    )
    readers = _labels(layout, marked.stale)
    if readers:
        ws.write_string(
            row + 1, 0, f"Live but reading a frozen value (orange): {', '.join(readers)}", STALE
        )


def _labels(layout, cells) -> list[str]:
    """The cells by their worksheet names where they have one, else a table column's cells
    as a range, else their address."""
    original = {excel.upper(): name for name, excel in layout.names.mapping.items()}
    by_cell = {}
    for excel, ref in layout.log.names.items():
        sheet, _, at = ref.lstrip("=").rpartition("!")
        if ":" not in at:
            r, c = xl_cell_to_rowcol(at.replace("$", ""))
            by_cell[(sheet.strip("'"), r, c)] = original.get(excel, excel)
    out = set()
    columns = layout.log.columns
    for cell in cells:
        if cell in by_cell:
            out.add(by_cell[cell])
            continue
        c = next(
            (
                c
                for c in columns
                if (c.sheet, c.col) == (cell[0], cell[2]) and c.first <= cell[1] < c.first + c.n
            ),
            None,
        )
        if c is None:
            out.add(_where(cell))
        else:
            last = xl_rowcol_to_cell(c.first + c.n - 1, c.col)
            out.add(f"'{c.sheet}'!{xl_rowcol_to_cell(c.first, c.col)}:{last}")
    return sorted(out)
