"""The workbook's Excel form as data: its sheets (:class:`FormSheet`, each a list of the
xlsxwriter calls made into it), charts and defined names (:class:`ExcelForm`), and the cell
notation the layout and the helper cells share. :mod:`workbook.compute.excelform` lays it
out; :mod:`workbook.outputs.xlsx` replays it into a file."""

from __future__ import annotations

from dataclasses import dataclass, field

MAX_COLS = 16_384  # columns of an Excel sheet
#: stands for a table row's number in a column's formula (one formula, a row each)
ROW_TOKEN = "\x00"


class FormSheet:
    """One Excel sheet of the form: what is written into it goes to the form's list of
    xlsxwriter calls (sheet index, method, arguments, index of the format among the arguments
    or -1), in the order written; a format is its role in :data:`workbook.compute.style.FORMATS`."""

    def __init__(self, name: str, index: int, ops: list):
        self.name, self.index, self._ops = name, index, ops

    def _op(self, method: str, args: tuple, at: int = -1) -> int:
        at = at if at >= 0 and args[at] is not None else -1
        self._ops.append((self.index, method, args, at))
        return 0

    def write_string(self, row, col, text, fmt=None):
        return self._op("write_string", (row, col, text, fmt), 3)

    def write_number(self, row, col, number, fmt=None):
        return self._op("write_number", (row, col, number, fmt), 3)

    def write_boolean(self, row, col, value, fmt=None):
        return self._op("write_boolean", (row, col, value, fmt), 3)

    def write_formula(self, row, col, formula, fmt=None, value=0):
        return self._op("write_formula", (row, col, str(formula), fmt, value), 3)

    def write_array_formula(
        self, first_row, first_col, last_row, last_col, formula, fmt=None, value=0
    ):
        args = (first_row, first_col, last_row, last_col, str(formula), fmt, value)
        return self._op("write_array_formula", args, 5)

    def write_formula_column(self, first, col, pieces, values, fmt=None, array=False, label=""):
        """A formula down a column: ``pieces`` joined by each row's number (1-based), the
        cached ``values`` a row."""
        return self._op("formula_column", (first, col, pieces, values, fmt, array, label), 4)

    def write_comment(self, row, col, text):
        return self._op("write_comment", (row, col, text))

    def set_column(self, first, last, width):
        return self._op("set_column", (first, last, width))

    def data_validation(self, first_row, first_col, last_row, last_col, options):
        return self._op("data_validation", (first_row, first_col, last_row, last_col, options))

    def freeze_panes(self, row, col):
        return self._op("freeze_panes", (row, col))

    def insert_chart(self, row, col, chart):
        return self._op("insert_chart", (row, col, chart))


class ChartForm:
    """A chart of the form: its options and the calls that style it, in order."""

    def __init__(self, options: dict):
        self.options = options
        self.calls: list[tuple[str, tuple, dict]] = []

    def __getattr__(self, method: str):
        if method.startswith("_"):
            raise AttributeError(method)

        def call(*args, **kwargs):
            self.calls.append((method, args, kwargs))

        return call


@dataclass
class ExcelForm:
    """A workbook before it is written: its Excel sheets in order, defined names, document
    properties; what the live-cell check found, and counts for the About sheet."""

    properties: dict = field(default_factory=dict)
    sheets: list[FormSheet] = field(default_factory=list)
    ops: list[tuple[int, str, tuple, int]] = field(default_factory=list)  # see FormSheet
    names: list[tuple[str, str]] = field(default_factory=list)
    formula_cells: int = 0
    not_live: list[str] = field(default_factory=list)
    refusals: list = field(default_factory=list)  # livecheck.Refusal: written as values
    verified: object = None  # livecheck.Outcome, when checked

    # the calls of xlsxwriter's Workbook the layout makes
    def set_properties(self, properties: dict) -> None:
        self.properties = dict(properties)

    def add_worksheet(self, name: str) -> FormSheet:
        sheet = FormSheet(name, len(self.sheets), self.ops)
        self.sheets.append(sheet)
        return sheet

    def define_name(self, name: str, ref: str) -> None:
        self.names.append((name, ref))

    def add_chart(self, options: dict) -> ChartForm:
        return ChartForm(options)


@dataclass
class ColumnCells:
    sheet: str
    col: int
    first_row: int  # 0-based
    last_row: int
    title: str


def col_letter(col: int) -> str:
    """Excel's letters of a 0-based column: 0 is A, 26 is AA."""
    letters = ""
    col += 1
    while col:
        col, rem = divmod(col - 1, 26)
        letters = chr(65 + rem) + letters
    return letters


def cells_text(c: ColumnCells) -> str:
    """``'Design'!$E$3:$E$103``: the absolute range of a column, for a formula."""
    col = col_letter(c.col)
    return f"'{c.sheet}'!${col}${c.first_row + 1}:${col}${c.last_row + 1}"


def write_labels(ws, row: int, col: int, texts, fmt=None) -> None:
    """Write texts as text cells: a title like "=1+1" or "http://..." stays text, never a
    formula or a link (xlsxwriter's ``write``/``write_row`` would convert them)."""
    for j, text in enumerate(texts):
        ws.write_string(row, col + j, str(text), fmt)


CHART_LABEL_COLUMN = 15  # column P of a charts sheet holds the labels that need a cell


def chart_label(ws, sheet_name: str, text: str, row: int, header_fmt=None):
    """A chart title, axis title or series name as xlsxwriter takes it, and the next free row
    of the label column. xlsxwriter reads a text that starts with '=' or looks like a
    reference (``Sheet!A1``, a path to another workbook before ``!A1``, ``cmd|' /C calc'!A0``)
    as a formula: a link to another workbook, a DDE call or another cell. Such a text is
    written into a text cell of ``ws`` (column P, below a header) and the chart refers to that
    cell, so it shows exactly as written; any other text is given as it is."""
    if not (text.startswith("=") or "!" in text):
        return text, row
    if row == 0:
        ws.write_string(0, CHART_LABEL_COLUMN, "Chart labels", header_fmt)
        row = 1
    ws.write_string(row, CHART_LABEL_COLUMN, text)
    return [sheet_name, row, CHART_LABEL_COLUMN], row + 1
