"""The workbook's Excel form, made by the compute stage: every cell of every Excel sheet
(live formulas with their cached values, helper cells of live forms, values with the comment
saying why they are not formulas), the charts and the defined names, laid out and checked by
an independent evaluator (:mod:`workbook.compute.livecheck`) before any file is written.

Layout: Inputs (editable cells with defined names), Definitions (scalar formulas),
one sheet per table group (range tables as live formulas, block tables as values),
Charts, Checks (printed vs computed, findings), About.

:func:`lay_out` reads the values of a :class:`workbook.compute.computed.ComputedSheet` and prints
the formulas of the Sheet's typed trees (the printer inlines functions and computes the cached
values of helper cells); the result, an :class:`ExcelForm`, is what :mod:`workbook.outputs.xlsx`
writes to a file without typing or evaluating anything."""

from __future__ import annotations

import json
import math

import numpy as np
from xlsxwriter.utility import xl_rowcol_to_cell

from ..engine import runtime as rt
from ..errors import LimitError, NotLive, WorkbookError
from ..functions.excel_names import ExcelNames
from ..functions.matrix import numbers
from ..language import expr as ex
from ..language import typed as ty
from ..language import units as un
from ..language.uses import names_used
from ..limits import MAX_TABLE_CELLS
from ..version import __version__
from . import excelchecks, frozen, rangeguard, style
from .excel import ExcelPrinter, cell_value
from .excelsheets import (
    MAX_COLS,
    ROW_TOKEN,
    ColumnCells,
    ExcelForm,
    cells_text,
    chart_label,
    col_letter,
    write_labels,
)
from .livecheck import CellLog, RecordingSheet
from .solversteps import HelperCells, RowSteps

MAX_ROWS = 1_048_576  # rows of an Excel sheet
PROGRESS_CELLS = 200_000  # a table with more cells than this reports its progress on stderr
#: Cells of one vector or matrix written as a block (a 4,000,000-cell identity(2000) took
#: 55 s and 700 MB to write); beyond it, or beyond Excel's grid, it is refused, never cut.
MAX_ARRAY_CELLS = 500_000
MAX_CELL_TEXT = 32_767  # characters of one Excel cell


def _write_value(ws, row: int, col: int, value: float | str, fmt) -> None:
    """A value cell: a number, or a text (a complex number as Excel's text)."""
    if isinstance(value, str):
        ws.write_string(row, col, value, fmt)
    else:
        ws.write_number(row, col, value, fmt)


def _ref(sheet: str, col: int, row: int, absolute: bool = True) -> str:
    d = "$" if absolute else ""
    return f"'{sheet}'!{d}{col_letter(col)}{d}{row + 1}"


def _range_ref(c: ColumnCells) -> list:
    return [c.sheet, c.first_row, c.col, c.last_row, c.col]


class ExcelLayout:
    """Lays out one workbook into an :class:`ExcelForm` (``self.wb``): the values from the
    computed sheet, the formulas printed from the Sheet's typed trees."""

    def __init__(self, computed, sheet, command: str | None = None, refused: dict | None = None):
        self.computed = computed
        self.sheet = sheet
        self.command = command or " ".join(
            ["workbook", "run", sheet.name] + [f"--part {p}" for p in sorted(sheet.parts)]
        )
        self.wb = ExcelForm()
        self.wb.set_properties(
            {
                "title": sheet.spec.title,
                "comments": sheet.spec.source,
                "author": "workbook " + __version__,
            }
        )
        spec = sheet.spec
        scalars = [n for n, d in spec.definitions.items() if not d.is_function]
        self.names = ExcelNames([*spec.inputs, *scalars])
        self.printer = ExcelPrinter(sheet.typer, self.names.mapping)
        self.fmt = {role: role for role in style.FORMATS}  # xlsx.py gives each its format
        self.columns: dict[tuple, ColumnCells] = {}
        self.block_columns: dict[tuple[str, str], ColumnCells] = {}
        self.sheets: dict[str, object] = {}
        self.rows: dict[str, int] = {}
        self.not_live: list[str] = []
        # live approximate forms (integral, root, extrema): where, what, how far from the engine
        self.live_forms: list[tuple[str, str, object, float | None]] = []
        self.formula_cells = 0
        self.table_cells = 0  # cells of the tables written so far (limits.MAX_TABLE_CELLS)
        self.planned: dict[tuple[str, str], ColumnCells] = {}
        # the next free column and the cells used of the row-wise blocks of 'Solver rows'
        self.step_col, self.step_cells = RowSteps.FIRST_COL, 0
        # every cell written, for the independent check of the live formulas (livecheck.py),
        # and the formulas it refused: (Excel sheet, row, col) -> comment
        self.log = CellLog()
        self.refused = refused or {}
        self.verified = None  # the check's outcome (livecheck.Outcome), once made
        # cells written as numbers that cannot follow an edit: (sheet, row, col) -> what
        self.frozen: dict[tuple[str, int, int], str] = {}
        self.inputs_end = 0  # the first free row of the Inputs sheet

    def ws(self, name: str):
        if name not in self.sheets:
            ws = self.wb.add_worksheet(name[:31])
            self.sheets[name] = RecordingSheet(ws, self.log, self.refused)
            self.rows[name] = 0
        return self.sheets[name]

    # -- inputs and definitions -------------------------------------------------------
    def write_inputs(self, needed: set[str]) -> None:
        ws = self.ws("Inputs")
        write_labels(ws, 0, 0, ["Name", "Value", "Unit", "Note"], self.fmt["header"])
        ws.set_column(0, 0, 12)
        ws.set_column(1, 1, 14)
        ws.set_column(2, 2, 10)
        ws.set_column(3, 3, 70)
        row = 1
        unused = set(self.sheet.unused_inputs())  # results, checks, solves and odes use too
        for name, spec in self.sheet.spec.inputs.items():
            value = self.sheet.values[name]
            ws.write_string(row, 0, name)
            if spec.options:
                ws.write_string(row, 1, value, self.fmt["input"])
                ws.data_validation(
                    row, 1, row, 1, {"validate": "list", "source": list(spec.options)}
                )
                unit_text = ""
            else:
                ws.write_number(row, 1, float(value.magnitude), self.fmt["input"])
                unit_text = spec.label or un.pretty(spec.unit)
            ws.write_string(row, 2, unit_text)
            note = spec.note
            if name in unused:
                note = (note + "; " if note else "") + "not used by any output of this workbook"
            ws.write_string(row, 3, note)
            self._define(ws, row, name, f"=Inputs!$B${row + 1}")
            row += 1
        ws.write_string(
            row + 1,
            0,
            "Yellow cells are inputs: change them and the workbook recalculates.",
            self.fmt["note"],
        )
        self.inputs_end = row + 2

    def write_definitions(self, needed: set[str]) -> None:
        defs = [
            d for n, d in self.sheet.spec.definitions.items() if not d.is_function and n in needed
        ]
        matrices, defs = self._arrays_and_numbers(defs)
        if matrices:
            self.write_matrices(matrices)
        if not defs:
            return
        ws = self.ws("Definitions")
        write_labels(
            ws, 0, 0, ["Name", "Value", "Unit", "Formula (worksheet)", "Note"], self.fmt["header"]
        )
        ws.set_column(0, 0, 12)
        ws.set_column(1, 1, 16)
        ws.set_column(3, 3, 50)
        ws.set_column(4, 4, 50)
        for row, d in enumerate(defs, start=1):
            t, q = self._scalar(d.name)
            ws.write_string(row, 0, d.name)
            value = q if t.text or isinstance(q, str) else cell_value(t, q.magnitude)
            with self.printer.context(helpers=HelperCells(self, d.name, t)):
                self._write_cell(ws, row, 1, t, {}, value, self.fmt["number"], d.name)
            ws.write_string(row, 2, un.typeset(t.unit))
            ws.write_string(row, 3, d.text)
            ws.write_string(row, 4, d.note)
            self._define(ws, row, d.name, f"=Definitions!$B${row + 1}")
        self.on_definitions = {d.name for d in defs}

    def _scalar(self, name: str):
        """The typed tree and value of a scalar definition (its error raised)."""
        s = self.computed.scalars[name]
        if s.error is not None:
            raise s.error
        return s.typed, s.value

    def _define(self, ws, row: int, name: str, ref: str) -> None:
        """Give the cell of ``name`` its defined name; a renamed one gets a comment saying why."""
        self.wb.define_name(self.names[name], ref)
        self.log.names[self.names[name].upper()] = ref
        if self.names[name] != name:
            ws.write_comment(row, 0, self.names.why(name))

    def write_results(self) -> None:
        """The Results sheet: every scalar definition (those the tables use refer to the
        Definitions sheet), a live formula where possible, its unit and note. A definition
        that cannot be computed shows the error as text in its cell."""
        defs = [d for d in self.sheet.spec.definitions.values() if not d.is_function]
        matrices, defs = self._arrays_and_numbers(defs)
        written = getattr(self, "on_matrices", set())
        if [d for d in matrices if d.name not in written]:
            self.write_matrices([d for d in matrices if d.name not in written])
        unknowns = [(n, b) for b in self.sheet.spec.solves if not b.parameters for n in b.unknowns]
        if not defs and not unknowns:
            return
        done = getattr(self, "on_definitions", set())
        name = next((n for n in self.sheets if n.casefold() == "results"), "Results")
        ws = self.ws(name)  # below the tables of a "Results" sheet, if the template has one
        start = self.rows[name]
        if start:
            start += 1
            ws.write_string(start, 0, "Scalar results", self.fmt["title"])
            start += 1
        write_labels(
            ws,
            start,
            0,
            ["Name", "Value", "Unit", "Formula (worksheet)", "Note"],
            self.fmt["header"],
        )
        ws.set_column(0, 0, 12)
        ws.set_column(1, 1, 16)
        ws.set_column(3, 4, 50)
        for row, d in enumerate(defs, start=start + 1):
            ws.write_string(row, 0, d.name)
            ws.write_string(row, 3, d.text)
            ws.write_string(row, 4, d.note)
            try:
                t, q = self._scalar(d.name)
            except WorkbookError as err:
                ws.write_string(row, 1, f"error: {err.message}", self.fmt["fail"])
                continue
            unit = un.typeset(t.unit)
            ws.write_string(row, 2, unit)
            value = q if t.text or isinstance(q, str) else cell_value(t, q.magnitude)
            if d.name in done:
                ref = self.names[d.name]
                ws.write_formula(row, 1, f"={ref}", self.fmt["number"], value)
                self.formula_cells += 1
                continue
            with self.printer.context(helpers=HelperCells(self, d.name, t)):
                self._write_cell(ws, row, 1, t, {}, value, self.fmt["number"], d.name)
            self._define(ws, row, d.name, f"='{name}'!$B${row + 1}")
        for row, (unknown, block) in enumerate(unknowns, start=start + 1 + len(defs)):
            self._write_unknown(ws, row, unknown, block)
        self.rows[name] = start + len(defs) + len(unknowns) + 2

    def _write_unknown(self, ws, row: int, unknown: str, block) -> None:
        """An unknown of a [[solve]] block on the Results sheet: its value (a number), its
        unit, the block as Given ... Find, and its error estimate."""
        ws.write_string(row, 0, unknown)
        given = "; ".join(text for _, _, text in block.equations)
        ws.write_string(row, 3, f"Given {given}: Find({', '.join(block.unknowns)})")
        found = self.computed.unknowns[unknown]
        if isinstance(found.error, WorkbookError):
            ws.write_string(row, 1, f"error: {found.error.message}", self.fmt["fail"])
            return
        if found.error is not None:
            raise found.error
        q, solved = found.value, found.solution
        ws.write_number(row, 1, float(q.magnitude), self.fmt["number"])
        ws.write_comment(row, 1, "A value, not a formula: found by a [[solve]] block")
        self.freeze(ws, row, 1, 1, 1, unknown)
        ws.write_string(row, 2, un.typeset(q.units))
        step = un.typeset(un.difference_unit(q.units))  # an error is a difference: delta_degC
        ws.write_string(
            row,
            4,
            f"error estimate {solved.errors.get(unknown, float('nan')):.2g} {step}, "
            f"condition number {solved.condition:.3g}".replace(" ,", ","),
        )

    def write_matrices(self, defs) -> None:
        """Vector and matrix definitions, each a named block of cells: elements written out
        are a formula each; an operation on matrices is one live array formula over the block
        (MMULT, MINVERSE, TRANSPOSE, ...); eigenvalues and the like are numbers."""
        ws = self.ws("Matrices")
        ws.set_column(0, 0, 14)
        row = self.rows.get("Matrices", 0)
        self.on_matrices = getattr(self, "on_matrices", set()) | {d.name for d in defs}
        for d in defs:
            t = self.sheet.defs.scalar(d.name)
            if ty.is_runtime(t.shape):
                row = self._write_runtime(ws, row, d, t)
                continue
            r, c = t.shape
            self._check_block(d, row + 1, r, c)
            value = numbers(self.sheet.scalar_value(d.name, "definition"))
            ws.write_string(row, 0, d.name, self.fmt["header"])
            ws.write_string(row, 1, f"{un.typeset(t.unit) or '1'}   {d.text}   {d.note}".strip())
            top = row + 1
            self._write_block(ws, top, t, value, d.name)
            last = f"{col_letter(c)}${top + r}"
            self._define(ws, row, d.name, f"=Matrices!$B${top + 1}:${last}")
            row = top + r + 1
        self.rows["Matrices"] = row

    def _arrays_and_numbers(self, defs: list) -> tuple[list, list]:
        """Definitions that are vectors or matrices (written as blocks) and those that are
        numbers; a run-time array is one or the other by the value it has when it runs."""
        arrays = []
        for d in defs:
            shape = self._shape(d.name)
            if shape is not None and (
                not ty.is_runtime(shape) or self._runtime_value(d.name) is not None
            ):
                arrays.append(d)
        return arrays, [d for d in defs if d not in arrays]

    def _runtime_value(self, name: str):
        """The array a definition whose size is known only when it runs has (None when it is
        a number, or cannot be computed: then it is written with the scalar results)."""
        try:
            v = rt.value(self.sheet.scalar_value(name, "definition"))
        except WorkbookError:
            return None
        return v if rt.is_array(v) else None

    def _write_runtime(self, ws, row: int, d, t: ty.T) -> int:
        """An array whose size is known only when its program ran: its values (a nested
        array, whose elements are arrays, as a line of text), with a comment."""
        value = self._runtime_value(d.name)
        r, c = value.shape
        if value.dtype != object:
            self._check_block(d, row + 1, r, c)
        ws.write_string(row, 0, d.name, self.fmt["header"])
        ws.write_string(row, 1, f"{un.typeset(t.unit) or '1'}   {d.text}   {d.note}".strip())
        top = row + 1
        if value.dtype == object:
            text = _nested_text(value)
            if len(text) > MAX_CELL_TEXT:  # xlsxwriter would cut it without a word
                raise LimitError(
                    f"{d.name} is a nested array whose text is {len(text):,} characters; an "
                    f"Excel cell holds at most {MAX_CELL_TEXT:,}",
                    file=self.sheet.file,
                    line=d.line,
                    definition=d.name,
                )
            ws.write_string(top, 1, text)
            ws.write_comment(
                top, 1, "A nested array (its elements are arrays): shown as text, not cells"
            )
            self.not_live.append(d.name)
            return top + 2
        for i in range(r):
            for j in range(c):
                ws.write_number(top + i, 1 + j, float(value[i, j]), self.fmt["number"])
        ws.write_comment(
            top, 1, "Values, not formulas: an array whose size is known only when its program runs"
        )
        self.freeze(ws, top, 1, r, c, d.name)
        self.not_live.append(d.name)
        last = f"{col_letter(c)}${top + r}"
        self._define(ws, row, d.name, f"=Matrices!$B${top + 1}:${last}")
        return top + r + 1

    def _check_block(self, d, top: int, r: int, c: int) -> None:
        """Refuse an array of ``r`` x ``c`` cells from row ``top`` that would pass Excel's grid
        (xlsxwriter drops such cells without a word) or :data:`MAX_ARRAY_CELLS`."""
        if top + r <= MAX_ROWS and 1 + c <= MAX_COLS and r * c <= MAX_ARRAY_CELLS:
            return
        raise LimitError(
            f"{d.name} is {r:,} x {c:,} ({r * c:,} elements): a workbook holds an array of at "
            f"most {MAX_ARRAY_CELLS:,} cells within Excel's grid of {MAX_ROWS:,} rows x "
            f"{MAX_COLS:,} columns (this one would start at row {top + 1:,}, column B); it is "
            "refused rather than cut",
            file=self.sheet.file,
            line=d.line,
            definition=d.name,
        )

    def _shape(self, name: str):
        """(rows, columns) of a definition's value, None for a number (or one in error)."""
        try:
            return self.sheet.defs.scalar(name).shape
        except WorkbookError:
            return None

    def _write_block(self, ws, top: int, t: ty.T, value, what: str) -> None:
        r, c = t.shape
        fmt = self.fmt["number"]
        body = t
        while isinstance(body, ty.TScale) and body.factor == 1.0:
            body = body.child
        if isinstance(body, ty.TMatrix):  # written out: one cell per element
            for i, row in enumerate(body.rows):
                for j, e in enumerate(row):
                    v = cell_value(e, value[i, j])
                    if isinstance(e, ty.TConst):
                        _write_value(ws, top + i, 1 + j, v, fmt)
                    else:
                        self._write_cell(ws, top + i, 1 + j, e, {}, v, fmt, what)
            return
        try:
            formula = self.printer.formula(t, {})
        except NotLive as why:
            for i in range(r):
                for j in range(c):
                    _write_value(ws, top + i, 1 + j, cell_value(t, value[i, j]), fmt)
            ws.write_comment(top, 1, f"Values, not formulas: {why}")
            self.not_live.append(what)
            self.freeze(ws, top, 1, r, c, what)
            return
        ws.write_array_formula(top, 1, top + r - 1, c, formula, fmt, float(value[0, 0]))
        for i in range(r):  # the cached values of the other cells of the array
            for j in range(c):
                if i or j:
                    ws.write_number(top + i, 1 + j, float(value[i, j]), fmt)
        self.formula_cells += 1

    def freeze(self, ws, row: int, col: int, rows: int, cols: int, what: str) -> None:
        """Cells written as numbers that cannot follow an edit (see :mod:`.frozen`)."""
        for i in range(rows):
            for j in range(cols):
                self.frozen[(ws.name, row + i, col + j)] = what

    def _write_cell(self, ws, row, col, t: ty.T, subst, value: float, fmt, what: str) -> bool:
        try:
            refused = self.refused.get((ws.name, row, col))
            if refused is not None:
                raise NotLive(refused.removeprefix("A value, not a formula: "))
            formula = self.printer.formula(t, subst)
        except NotLive as why:
            if isinstance(value, str):
                ws.write_string(row, col, value, fmt)
            else:
                ws.write_number(row, col, value, fmt)
            ws.write_comment(row, col, f"A value, not a formula: {why}")
            self.not_live.append(what)
            self.freeze(ws, row, col, 1, 1, what)
            return False
        if formula.array:  # computes with vectors or matrices: an array formula
            ws.write_array_formula(row, col, row, col, formula, fmt, value)
        else:
            ws.write_formula(row, col, formula, fmt, value)
        self.formula_cells += 1
        if not subst:
            self._live_note(ws, row, col, t, {}, value, what)
        return True

    def _live_note(self, ws, row, col, t: ty.T, env: dict, values, what: str, rows=0) -> None:
        """A comment on a live formula that holds an approximate live form (an integral), and
        a line of the Checks sheet's list of live forms."""
        from ..numerics.live import difference

        diff = difference(self.sheet, t, env, values)
        if diff is None:
            return
        ws.write_comment(row, col, diff.note)
        cells = xl_rowcol_to_cell(row, col, row_abs=True, col_abs=True)
        if rows:  # a table column: its cells below the header
            first = xl_rowcol_to_cell(row + 1, col, row_abs=True, col_abs=True)
            cells = f"{first}:{xl_rowcol_to_cell(row + rows, col, row_abs=True, col_abs=True)}"
        where = f"'{ws.name}'!{cells}"
        engine = float(values) if np.ndim(values) == 0 else None  # a column: its header
        self.live_forms.append((where, what, diff, engine))

    # -- range tables -------------------------------------------------------------------
    def plan_range_tables(self) -> None:
        """Register where each range table's columns will be written, so that a definition
        aggregating a column (``max_over(design, S0_req)``) is printed as a live
        ``MAX('Design'!$E$3:$E$103)`` on the Definitions sheet, written before the tables.
        A block table's length is known only once computed, so range tables after one on the
        same sheet are not planned (their aggregates stay values, with a comment)."""
        rows: dict[str, int | None] = {}
        for t in self.sheet.spec.tables:
            if t.sheet in ("Inputs", "Definitions"):
                continue
            start = rows.get(t.sheet, 0)
            if t.computed or start is None:
                rows[t.sheet] = None
                continue
            n = len(self.sheet.range_values(t.range, f"table {t.name}"))
            first = start + 2
            for j, col in enumerate(t.columns, start=1):
                cells = ColumnCells(t.sheet, j, first, first + n - 1, col.title)
                if (t.name, col.text) in self.planned:  # the same text in another unit:
                    continue  # max_over(t, col) reads the first
                self.planned[(t.name, col.text)] = cells
                self.printer.ranges[(t.name, col.text)] = cells_text(cells)
            rows[t.sheet] = first + n + 2

    def write_range_table(self, spec, data=None) -> None:
        """A range table (``data``: its computed values, by default the computed sheet's)."""
        if data is None:
            data = self.computed.table(spec.name)
        n = len(data.columns[0].values)
        ws = self.ws(spec.sheet)
        start = self.rows[spec.sheet]
        if start + n + 3 > MAX_ROWS:
            raise LimitError(
                f"table {spec.name} has {n:,} rows; an Excel sheet holds "
                f"{MAX_ROWS:,}. Write it as CSV instead (workbook run --csv)"
            )
        self._count_table_cells(spec, n, len(data.columns))
        ws.write_string(start, 0, spec.title, self.fmt["title"])
        heads = [un.header(c.title, c.unit, typeset_unit=True) for c in data.columns]
        write_labels(ws, start + 1, 0, heads, self.fmt["header"])
        first = start + 2
        self._write_range_column(ws, spec, first, data.columns[0].values, len(data.columns))
        var_ref = f"$A${ROW_TOKEN}"
        report = n * len(data.columns) > PROGRESS_CELLS
        for j, col in enumerate(data.columns[1:], start=1):
            if report:
                _progress(f"table {spec.name}: column {j} of {len(data.columns) - 1} ({n:,} rows)")
            var_values = data.columns[0].values
            if self._write_column(ws, spec.name, first, j, col, data.var, var_ref, n, var_values):
                env = {data.var: data.columns[0].values}
                what = f"table {spec.name}: {col.title} ({n:,} rows)"
                self._live_note(ws, first - 1, j, col.typed, env, col.values, what, n)
            cells = ColumnCells(spec.sheet, j, first, first + n - 1, col.title)
            planned = self.planned.get((spec.name, col.text))
            is_first = next(c for c in data.columns[1:] if c.text == col.text) is col
            if is_first and planned is not None and planned != cells:  # a MAX(...) points there
                raise RuntimeError(f"table {spec.name} written at {cells}, planned at {planned}")
            self.columns[(spec.range.text, spec.sheet, col.text, str(col.unit))] = cells
        self.columns[(spec.range.text, spec.sheet, data.var, "var")] = ColumnCells(
            spec.sheet, 0, first, first + n - 1, data.var
        )
        ws.set_column(0, len(data.columns) - 1, 13)
        self.rows[spec.sheet] = first + n + 2

    def _write_range_column(self, ws, spec, first: int, values: np.ndarray, width: int) -> None:
        """The range variable's column: numbers for constant bounds; for bounds that depend on
        inputs, formulas ``=FIRST+i*(SECOND-FIRST)`` and ``=LAST`` (the engine's values) plus
        a guard cell right of the title (``width`` columns in): the table follows an edited
        input while the number of rows stays the same, and is ``#N/A`` when it does not."""
        fmt, n = self.fmt["number"], len(values)
        bounds = self._live_bounds(spec.range)
        if bounds is None or isinstance(bounds, str):
            for i in range(n):
                ws.write_number(first + i, 0, float(values[i]), fmt)
            if bounds is not None:  # bounds that follow the inputs, written as numbers
                ws.write_comment(first - 1, 0, f"Values, not formulas: {bounds}")
                self.not_live.append(f"{spec.name}.{spec.range.var}")
                self.freeze(ws, first, 0, n, 1, f"{spec.name}.{spec.range.var}")
            return
        lo, second, hi, points = bounds
        if spec.range.points is not None:  # log-spaced: FIRST*(LAST/FIRST)^(i/(n-1))
            inner = [f"=({lo})*(({hi})/({lo}))^({i}/{n - 1})" for i in range(1, n - 1)]
            count = rangeguard.log_count_formula(points, n)
        else:
            if second is not None:
                step = f"(({second})-({lo}))"
            else:
                step = "1" if values[-1] >= values[0] else "(-1)"
            inner = [f"=({lo})+{i}*{step}" for i in range(1, n - 1)]
            count = rangeguard.stepped_count_formula(lo, step, hi, n)
        ws.write_formula(first - 2, width, count, self.fmt["guard"], 0)
        guard = xl_rowcol_to_cell(first - 2, width, row_abs=True, col_abs=True)
        self.formula_cells += 1
        ws.write_formula(first, 0, f"=({lo})+{guard}", fmt, float(values[0]))
        for i, text in enumerate(inner, start=1):
            ws.write_formula(first + i, 0, f"{text}+{guard}", fmt, float(values[i]))
        if n > 1:
            ws.write_formula(first + n - 1, 0, f"=({hi})+{guard}", fmt, float(values[-1]))
        self.formula_cells += n
        ws.write_comment(
            first - 2,
            width,
            f"Live range {spec.range.text}: its bounds follow the inputs, but the number of "
            f"rows ({n}) was fixed when the workbook was written. This cell counts the range's "
            "values at the current inputs: while they are as many, it shows 'rows ok'; "
            "otherwise it is #N/A, and so is the table and every formula that reads it: "
            "regenerate (workbook run --inputs edited.xlsx).",
        )

    def _live_bounds(self, rng) -> tuple[str, str | None, str, str | None] | str | None:
        """Excel texts of a range's bounds in the variable's unit (and its points, for a
        log range); None when the bounds are
        constants (written as numbers); the reason when they follow the inputs but cannot be
        live formulas (the column is then written as numbers and marked frozen)."""
        nodes = (rng.first, rng.second, rng.last, rng.points)
        # a bound that names no input or definition names none through them either
        names = set().union(*(ex.names(x) for x in nodes if x))
        if not names & (set(self.sheet.spec.inputs) | set(self.sheet.spec.definitions)):
            return None
        typed = self.sheet.range_bounds(rng, f"range {rng.text}")
        if rng.points is not None:
            typed = [*typed, self.sheet.range_points(rng, f"range {rng.text}")]
        try:
            texts = [None if t is None else self.printer.formula(t, {})[1:] for t in typed]
        except NotLive as why:
            return str(why)
        return texts[0], texts[1], texts[2], texts[3] if len(texts) > 3 else None

    def _write_column(
        self, ws, table: str, first: int, j: int, col, var: str, var_ref: str, n, var_values
    ) -> bool:
        """Write one column, live formulas if it can be; True if it is live."""
        fmt = self.fmt["value"]
        steps = RowSteps(self, ws.name, first, n, var_ref, col.typed, {var: var_values})
        try:
            refused = self.refused.get((ws.name, first, j))
            if refused is not None:
                raise NotLive(refused.removeprefix("A value, not a formula: "))
            with self.printer.context(helpers=steps):  # a root's steps, one chain a row
                template = self.printer.formula(col.typed, {var: var_ref})
        except NotLive as why:
            for i in range(n):
                v = col.values[i]
                if i in col.failed:  # an error value, as Excel computes one
                    error = col.excel_error(i)
                    ws.write_formula(first + i, j, _ERROR_FORMULAS[error], fmt, error)
                else:
                    _write_value(
                        ws, first + i, j, v if isinstance(v, str) else cell_value(col.typed, v), fmt
                    )
            ws.write_comment(first - 1, j, f"Values, not formulas: {why}")
            self.not_live.append(f"{table}.{col.text}")
            self.freeze(ws, first, j, n, 1, f"{table}.{col.text}")
            _failed_comments(ws, first, j, col)
            return False
        steps.write()
        pieces = template.split(ROW_TOKEN)
        values = (
            [cell_value(col.typed, v) for v in col.values]
            if col.typed.complex
            else col.values.tolist()
        )
        for i in col.failed:  # the cached value of a failed row is Excel's error value
            values[i] = col.excel_error(i)
        _failed_comments(ws, first, j, col)
        label = f"table {table}: {col.title}"
        ws.write_formula_column(first, j, pieces, values, fmt, template.array, label)
        self.formula_cells += n
        return True

    def _count_table_cells(self, spec, rows: int, columns: int) -> None:
        """Refuse a table that would bring the cells of the workbook's tables past
        :data:`workbook.limits.MAX_TABLE_CELLS`, before it is written."""
        self.table_cells += rows * columns
        if self.table_cells > MAX_TABLE_CELLS:
            raise LimitError(
                f"table {spec.name} has {rows:,} rows x {columns} columns: the workbook's "
                f"tables would hold {self.table_cells:,} cells (limit {MAX_TABLE_CELLS:,}). "
                "Write it as CSV instead (workbook run --csv)",
                file=self.sheet.file,
                line=getattr(spec, "line", None),
                definition=f"table {spec.name}",
            )

    # -- block tables --------------------------------------------------------------------
    def write_computed_table(self, spec) -> None:
        ws = self.ws(spec.sheet)
        start = self.rows[spec.sheet]
        if spec.vary:  # its rows are its range's points: checked before it is computed
            n = len(self.sheet.range_values(spec.range, f"table {spec.name}"))
            if start + n + 3 > MAX_ROWS:
                raise LimitError(
                    f"table {spec.name} has {n:,} rows; an Excel sheet holds {MAX_ROWS:,}",
                    file=self.sheet.file,
                    line=spec.line,
                    definition=f"table {spec.name}",
                )
        df = self.computed.table(spec.name)
        n = len(df)
        if start + n + 3 > MAX_ROWS:
            raise LimitError(f"table {spec.name} has {n:,} rows; an Excel sheet holds {MAX_ROWS:,}")
        self._count_table_cells(spec, n, len(df.columns))
        ws.write_string(start, 0, spec.title, self.fmt["title"])
        write_labels(ws, start + 1, 0, [str(c) for c in df.columns], self.fmt["header"])
        how = (
            f"the solver block {spec.block}"
            if spec.block
            else "the engine at each value of "
            + "; ".join(f"{k} ({', '.join(v)})" for k, v in spec.vary.items())
            + ", the other inputs as on the Inputs sheet"
        )
        ws.write_comment(
            start + 1, 0, f"Values computed by {how}; not live formulas (rerun workbook to update)."
        )
        first = start + 2
        for j, name in enumerate(df.columns):
            col = df[name].tolist()
            for i, v in enumerate(col):
                self._write_value(ws, first + i, j, v)
            self.block_columns[(spec.name, str(name))] = ColumnCells(
                spec.sheet, j, first, first + n - 1, str(name)
            )
            if n:  # values of a solver block or of other inputs: they cannot follow an edit
                self.freeze(ws, first, j, n, 1, f"{spec.name}.{name}")
        ws.set_column(0, max(0, len(df.columns) - 1), 14)
        self.rows[spec.sheet] = first + n + 2

    def _write_value(self, ws, row, col, v):
        if v is None:
            return
        if isinstance(v, (bool, np.bool_)):
            ws.write_boolean(row, col, bool(v))
        elif isinstance(v, (int, float, np.integer, np.floating)):
            v = float(v)
            if math.isfinite(v):  # NaN/inf stay empty cells, so charts leave a gap
                ws.write_number(row, col, v, self.fmt["number"])
        else:
            ws.write_string(row, col, str(v))

    # -- charts ---------------------------------------------------------------------------
    def chart_series_cells(self, chart, index: int, s) -> tuple[ColumnCells, ColumnCells]:
        if s.table is not None:
            try:
                return (
                    self.block_columns[(s.table, s.x_column)],
                    self.block_columns[(s.table, s.y_column)],
                )
            except KeyError:
                raise WorkbookError(
                    f"chart {chart.name}: table '{s.table}' has no column "
                    f"'{s.x_column}' or '{s.y_column}'"
                ) from None
        rng = s.range or chart.range
        x = self.computed.x_columns[(chart.name, index)]
        wanted = [s.y] if x is None else [x, s.y]
        keys = [(rng.text, c.text, self._unit_key(c, rng, chart)) for c in wanted]
        # a table already written over the same range with these columns (same sheet, same rows)
        for sheet_name in dict.fromkeys(k[1] for k in self.columns):
            found = [self.columns.get((k[0], sheet_name, k[1], k[2])) for k in keys]
            if all(found):
                xcells = (
                    found[0]
                    if x is not None
                    else self.columns[(rng.text, sheet_name, rng.var, "var")]
                )
                return xcells, found[-1]
        # not in any table: write a chart data block
        from ..language.spec import TableSpec

        target = "Chart data"
        name = f"{chart.name}_{len(self.columns)}"
        spec = TableSpec(name, f"Data of {chart.title}: {s.name}", rng, wanted, target)
        series = self.computed.series[(chart.name, index)]
        if isinstance(series, BaseException):
            raise series
        self.write_range_table(spec, series.data)  # a table of the workbook, not of the Sheet
        found = [self.columns[(k[0], target, k[1], k[2])] for k in keys]
        xcells = found[0] if x is not None else self.columns[(rng.text, target, rng.var, "var")]
        return xcells, found[-1]

    def _unit_key(self, col, rng, chart) -> str:
        return str(self.sheet.typed_column(col, rng.var, f"chart {chart.name}").unit)

    def write_charts(self) -> None:
        if not self.sheet.spec.charts:
            return
        # Resolve (and if needed write) every series' data before the Charts sheet exists,
        # so the data sheets come before it in the workbook.
        cells = {
            (chart.name, i): self.chart_series_cells(chart, i, s)
            for chart in self.sheet.spec.charts
            for i, s in enumerate(chart.series)
        }
        ws = self.ws("Charts")
        row = 0
        for chart in self.sheet.spec.charts:
            c = style.scatter_chart(self.wb)
            for i, s in enumerate(chart.series):
                xcells, ycells = cells[(chart.name, i)]
                line = {"width": 2.0}
                if s.line == "dash":
                    line["dash_type"] = "dash"
                elif s.line == "dot":
                    line["dash_type"] = "round_dot"
                elif s.line == "none":
                    line = {"none": True}
                opts = {
                    "name": self._chart_text(ws, s.name),
                    "categories": _range_ref(xcells),
                    "values": _range_ref(ycells),
                    "line": line,
                    "marker": style.MARKER if s.marker else style.NO_MARKER,
                }
                if s.axis == "secondary":
                    opts["y2_axis"] = True
                c.add_series(opts)
            c.set_title({"name": self._chart_text(ws, chart.title)})
            xaxis = style.axis(
                self._chart_text(ws, chart.x_title or (chart.x.title if chart.x else "")),
                label_position="low",
            )
            yaxis = style.axis(self._chart_text(ws, chart.y_title))
            if chart.log_x:
                xaxis["log_base"] = 10
            if chart.log_y:
                yaxis["log_base"] = 10
            size = style.CHART_SIZE
            if chart.equal_axes:
                lo, hi = self._common_span(chart)
                for axis in (xaxis, yaxis):
                    axis.update({"min": lo, "max": hi})
                size = style.SQUARE_CHART_SIZE
                c.set_plotarea({"layout": {"x": 0.12, "y": 0.1, "width": 0.76, "height": 0.76}})
            c.set_x_axis(xaxis)
            c.set_y_axis(yaxis)
            if any(s.axis == "secondary" for s in chart.series):
                c.set_y2_axis({"name": self._chart_text(ws, chart.y2_title)})
            row = style.place_chart(ws, row, c, size)

    def _chart_text(self, ws, text: str):
        """A chart title, axis title or series name as literal text (:func:`chart_label`)."""
        label, self.rows["Charts"] = chart_label(
            ws, "Charts", text, self.rows["Charts"], self.fmt["header"]
        )
        return label

    def _common_span(self, chart) -> tuple[float, float]:
        values = []
        for i, _ in enumerate(chart.series):
            series = self.computed.series[(chart.name, i)]
            if isinstance(series, BaseException):
                raise series
            values += [series.x, series.y]
        if not values:
            return (0.0, 1.0)
        allv = np.concatenate([np.asarray(v, dtype=float) for v in values])
        lo, hi = float(np.nanmin(allv)), float(np.nanmax(allv))
        pad = 0.05 * (hi - lo or 1.0)
        return _nice(lo - pad, floor=True), _nice(hi + pad, floor=False)

    # -- checks and about (excelchecks) ----------------------------------------------------
    def write_checks(self, report) -> None:
        excelchecks.write_checks(self, report)

    def write_about(self) -> None:
        excelchecks.write_about(self)


#: Formulas that give an error value, for a failed row written as a value.
_ERROR_FORMULAS = {"#DIV/0!": "=1/0", "#NUM!": "=SQRT(-1)"}


def _failed_comments(ws, first: int, j: int, col) -> None:
    """A comment on each failed row of a table column naming why it has no value."""
    for i, why in col.failed.items():
        ws.write_comment(first + i, j, f"No value: {why}")


def _progress(text: str) -> None:
    import sys

    print(f"workbook: writing {text}", file=sys.stderr, flush=True)


def _nice(x: float, floor: bool) -> float:
    if x == 0:
        return 0.0
    mag = 10 ** math.floor(math.log10(abs(x)))
    step = mag / 2
    return (math.floor if floor else math.ceil)(x / step) * step


def needed_names(sheet) -> set[str]:
    """Inputs and definitions the workbook's tables, charts and checks depend on."""
    return names_used(sheet.spec, reads=sheet.reads)


def lay_out(computed, sheet, *, command: str | None = None, verify: bool = True) -> ExcelForm:
    """The Excel form of ``computed`` (the values of ``sheet``, whose typed trees the formulas
    are printed from). With ``verify`` every live formula is first computed by an independent
    evaluator (:mod:`workbook.compute.livecheck`); one that disagrees with the engine is laid out
    again as the engine's value with a comment, and listed in the form's ``refusals``."""
    report = computed.check_report()
    w = _lay_out(computed, sheet, command, report, {})
    if verify:
        from .livecheck import check

        outcome = check(w.log)
        if outcome.refusals:  # laid out again with the refused cells as values
            w = _lay_out(computed, sheet, command, report, outcome.refused())
            w.not_live.extend(_refused_what(outcome.refusals))
        w.wb.refusals = list(outcome.refusals)
        w.verified = outcome
    w.marked = frozen.mark(w)
    w.write_about()
    form = w.wb
    form.formula_cells, form.not_live, form.verified = w.formula_cells, w.not_live, w.verified
    return form


def _refused_what(refusals) -> list[str]:
    return [f"'{r.sheet}'!{xl_rowcol_to_cell(r.row, r.col)}" for r in refusals]


def _lay_out(computed, sheet, command: str | None, report, refused: dict) -> ExcelLayout:
    """Every Excel sheet but About, laid out."""
    w = ExcelLayout(computed, sheet, command, refused)
    needed = needed_names(sheet)
    w.plan_range_tables()
    w.write_inputs(needed)
    w.write_definitions(needed)
    for t in sheet.spec.tables:
        if t.computed:
            w.write_computed_table(t)
        else:
            w.write_range_table(t)
    w.write_charts()
    w.write_results()
    w.write_checks(report)
    return w


def _nested_text(value) -> str:
    """A nested array as text, in the language's literals: a column [a, b], a matrix by rows
    [[a, b], [c, d]], an array element in its place ([1, [0, 30]])."""

    def text(v) -> str:
        if isinstance(v, str):  # a text element
            return json.dumps(v, ensure_ascii=False)
        if not rt.is_array(v):
            return f"{float(v):.10g}"
        if v.shape[1] == 1:
            return "[" + ", ".join(text(e) for e in v[:, 0]) + "]"
        return "[" + ", ".join("[" + ", ".join(text(e) for e in row) + "]" for row in v) + "]"

    return text(value)
