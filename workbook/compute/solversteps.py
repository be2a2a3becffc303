"""Helper cells of the live forms of roots and extrema: a root's bisection steps on the
sheet 'Solver steps' (:class:`HelperCells`, one block a definition) and, for a table column,
one chain a table row on 'Solver rows' (:class:`RowSteps`); their cached values are the
engine's own steps, recorded while it evaluates the definition with the live forms."""

from __future__ import annotations

import numpy as np

from ..errors import NotLive, WorkbookError
from ..language import typed as ty
from .excelsheets import MAX_COLS, ROW_TOKEN, col_letter, write_labels


class HelperCells:
    """Cells of the 'Solver steps' sheet that a live form needs (a root's bisection steps).

    ``helpers(title, rows, headers)`` reserves a block under a title and returns a
    :class:`HelperBlock`, whose cells are live formulas with cached values;
    ``helpers.value(t, env)`` is the engine's value of a typed tree, for those values."""

    SHEET = "Solver steps"

    def __init__(self, writer, what: str, typed: ty.T | None = None):
        self.writer, self.what, self.typed = writer, what, typed
        self._chains: dict | None = None

    def chain(self, expr: ty.T) -> dict:
        """The engine's steps of the live form of ``expr`` in this definition (or NotLive)."""
        if self.typed is None:
            raise NotLive("no helper cells here")
        if self._chains is None:
            self._chains = _recorded_chains(self.writer, self.typed, {})
        return _one_chain(self._chains, expr, ())

    def value(self, t: ty.T, env: dict) -> float:
        """The engine's value of a typed tree (for a helper cell's cached value)."""
        return float(self.writer.sheet.evaluator.compile(t)(env))

    def __call__(self, title: str, rows: int, headers: list[str]) -> HelperBlock:
        ws = self.writer.ws(self.SHEET)
        start = self.writer.rows[self.SHEET]
        ws.write_string(start, 0, f"{self.what}: {title}", self.writer.fmt["title"])
        write_labels(ws, start + 1, 1, headers, self.writer.fmt["header"])
        self.writer.rows[self.SHEET] = start + rows + 3
        return HelperBlock(ws, self.SHEET, start + 2)


class RowSteps:
    """Helper cells of the live roots and extrema of one table column: blocks of columns on
    the sheet 'Solver rows' whose row i is the table's row i, so that one formula a column,
    with the table's row number (``ROW_TOKEN``) filled in, serves every row.

    ``chain(expr)`` is the engine's bisection chain of the root of EXPR in every row (the
    cached values); ``block(title, headers)`` reserves a block (NotLive beyond
    ``MAX_CELLS``); the blocks are written by :meth:`write` once the column's formula is
    printed (a column that is not live leaves no helper cells)."""

    per_row = True
    SHEET = "Solver rows"
    FIRST_COL = 1  # B
    #: helper cells of all row-wise blocks of a workbook (543 table rows of one root, 361 of
    #: one extremum)
    MAX_CELLS = 100_000

    def __init__(self, writer, table_sheet: str, first: int, n: int, var_ref, typed, env):
        self.writer, self.first, self.n = writer, first, n
        self.var_ref, self.typed, self.env = var_ref, typed, env
        self.table_ref = f"'{table_sheet}'!{var_ref}"  # the variable seen from the steps sheet
        self.blocks: list[RowBlock] = []
        self._chains: dict | None = None

    def chain(self, expr: ty.T) -> dict:
        """The engine's steps of the live form of ``expr`` (a root's, an extremum's), every
        row (or NotLive)."""
        if self._chains is None:
            self._chains = _recorded_chains(self.writer, self.typed, self.env)
        return _one_chain(self._chains, expr, (self.n,))

    def block(self, title: str, headers: list[str]) -> RowBlock:
        col = self.writer.step_col + sum(len(b.headers) for b in self.blocks)
        cells = self.n * len(headers) + self.writer.step_cells
        cells += sum(self.n * len(b.headers) for b in self.blocks)
        if cells > self.MAX_CELLS or col + len(headers) > MAX_COLS:
            rows = self.MAX_CELLS // len(headers)
            raise NotLive(
                f"a root or extremum in a table column is live as {len(headers)} helper cells a "
                f"row on the "
                f"sheet '{self.SHEET}', up to {self.MAX_CELLS:,} cells in a workbook ({rows} "
                f"rows of one root); this table has {self.n:,} rows: its values are written "
                "as numbers"
            )
        block = RowBlock(self, col, title, headers)
        self.blocks.append(block)
        return block

    def write(self) -> None:
        """Write the reserved blocks (the column's formula is printed: it is live)."""
        if not self.blocks:
            return
        w = self.writer
        ws = w.ws(self.SHEET)
        for b in self.blocks:
            ws.write_string(self.first - 2, b.col, b.title, w.fmt["title"])
            write_labels(ws, self.first - 1, b.col, b.headers, w.fmt["header"])
            for j, (formula, values) in enumerate(b.cells):
                pieces = formula.replace(self.var_ref, self.table_ref).split(ROW_TOKEN)
                values = np.broadcast_to(np.asarray(values, dtype=float), (self.n,)).tolist()
                w.log.column(ws.name, b.col + j, self.first, self.n, pieces)
                for i in range(self.n):
                    row = self.first + i
                    ws.write_formula(row, b.col + j, str(row + 1).join(pieces), None, values[i])
            w.step_col = b.col + len(b.headers)
            w.step_cells += self.n * len(b.headers)
            w.formula_cells += self.n * len(b.headers)


def _recorded_chains(writer, typed: ty.T, env: dict) -> dict:
    """The steps of every live root and extremum met evaluating ``typed`` in ``env`` with
    the live forms (workbook.numerics), by id of their EXPR."""
    from ..functions.numerical import live_forms, recording_chains

    with recording_chains() as found:
        try:
            fn = writer.sheet.evaluator.compile(typed)
            fn(env)  # the engine's values of extrema, to compare with their live forms
            with live_forms():
                fn(env)
        except WorkbookError as err:
            why = f"the live form's steps leave the expression's domain ({err.message})"
            raise NotLive(why) from None
    return found


def _one_chain(found: dict, expr: ty.T, shape: tuple) -> dict:
    """The one chain of ``expr`` in ``found``, each array of ``shape`` or one value."""
    got = found.get(id(expr), [])
    arrays = []
    if len(got) == 1:
        for v in got[0][1].values():
            arrays.extend(v if isinstance(v, list) else [v])
    if len(got) != 1 or any(np.shape(v) not in ((), (1,), shape) for v in arrays):
        raise NotLive(
            "a root or extremum solved more than once for each value of this formula (called "
            "twice, or inside another built-in): its values are written as numbers"
        )
    if not all(np.isfinite(v).all() for v in arrays):
        raise NotLive("the live form's steps leave the expression's domain")
    engine = found.get(("engine", id(expr)))
    return {**got[0][1], "engine": engine[0] if engine and len(engine) == 1 else None}


class RowBlock:
    """Columns of 'Solver rows' for one root or extremum of a table column: ``ref(j)`` is column j's
    cell in the current table row; ``write(j, formula, values)`` sets its formula (in the
    row's terms) and the cached value of every row."""

    def __init__(self, steps: RowSteps, col: int, title: str, headers: list[str]):
        self.steps, self.col, self.title, self.headers = steps, col, title, headers
        self.cells: list[tuple[str, object]] = [("", 0.0)] * len(headers)

    def ref(self, j: int) -> str:
        return f"'{self.steps.SHEET}'!${col_letter(self.col + j)}${ROW_TOKEN}"

    def write(self, j: int, formula: str, values) -> None:
        self.cells[j] = (formula, values)


class HelperBlock:
    """A block of helper cells: ``ref(i, j)`` is the absolute reference of row i, column j."""

    def __init__(self, ws, sheet: str, first: int):
        self.ws, self.sheet, self.first = ws, sheet, first

    def ref(self, i: int, j: int) -> str:
        return f"'{self.sheet}'!${col_letter(j + 1)}${self.first + i + 1}"

    def write(self, i: int, j: int, formula: str, value: float) -> None:
        self.ws.write_formula(self.first + i, j + 1, formula, None, value)
