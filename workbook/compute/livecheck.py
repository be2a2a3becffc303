"""Every live formula of a workbook checked against the engine before the workbook is written.

The writer records each cell it writes (:class:`CellLog`, through :class:`RecordingSheet`):
formulas with their cached values (the engine's), numbers, texts and defined names. Each
formula that is not :func:`plain` is then computed by an evaluator independent of the engine,
the ``formulas`` package (its own parser and its own implementation of Excel's functions and
array rules), from the cached values of the cells and names it reads; a formula whose value
differs from its cached value beyond :data:`RELATIVE` is refused (a live approximate form too:
an integral's 20-point Gauss-Legendre sum of an integrand with an end-point singularity), and
the writer writes that cell as a number with a comment saying why. Checked cell by cell from
cached inputs, a chain of formulas agrees with the engine wherever each link does.

A table column (or a column of helper cells) is one formula with the row number filled in: it
is compiled once and computed at :data:`ROWS_CHECKED` rows spread over the column, first and
last included; when one row disagrees, the whole column is refused.
"""

from __future__ import annotations

import functools
import math
import re
from dataclasses import dataclass, field

import numpy as np

from ..functions.complexes import parse_text
from . import xleval

#: the evaluator of most formulas (the formulas package computes the others)
XLEVAL = "the check's own reader of Excel formulas, workbook.compute.xleval"
#: largest relative difference between a live formula and the engine's value
RELATIVE = 1e-9
#: rows of a table column computed by the check (spread evenly, first and last included)
ROWS_CHECKED = 9
#: a row number no written cell has (a table ends 3 rows above Excel's last row, which the
#: evaluator would read as a whole column): it stands for a column's row
SENTINEL = 1_048_575

_REF = re.compile(
    r"^(?:'?(?P<sheet>.+?)'?!)?\$?(?P<c0>[A-Z]{1,3})\$?(?P<r0>\d+)"
    r"(?::\$?(?P<c1>[A-Z]{1,3})\$?(?P<r1>\d+))?$"
)
_NAME_REF = re.compile(r"^=?(?:'?(?P<sheet>.+?)'?!)(?P<cells>.+)$")


def _col_index(letters: str) -> int:
    n = 0
    for ch in letters:
        n = n * 26 + ord(ch) - 64
    return n - 1


@dataclass
class Formula:
    """One formula written into a block of cells (one cell unless an array formula)."""

    sheet: str
    row: int
    col: int
    text: str
    last_row: int
    last_col: int


@dataclass
class Column:
    """One formula written down a column: ``pieces`` joined by a row number (1-based)."""

    sheet: str
    col: int
    first: int
    n: int
    pieces: list[str]


@dataclass
class Refusal:
    """A live formula that disagrees with the engine: where, and the two values."""

    sheet: str
    row: int
    col: int
    formula: str
    independent: object
    engine: object
    rows: int = 1  # a column: the rows refused from ``row`` down
    by: str = "the formulas package"  # the evaluator that computed it

    @property
    def where(self) -> str:
        """The cell (or the column's cells) in Excel's notation."""
        from xlsxwriter.utility import xl_rowcol_to_cell

        cells = xl_rowcol_to_cell(self.row, self.col)
        if self.rows > 1:
            cells += ":" + xl_rowcol_to_cell(self.row + self.rows - 1, self.col)
        return f"'{self.sheet}'!{cells}"

    @property
    def disagreement(self) -> str:
        """One line: the two values."""
        return (
            f"its live formula computes {_shown(self.independent)} ({self.by}), "
            f"the engine {_shown(self.engine)}"
        )

    @property
    def why(self) -> str:
        """The cell comment of the value written instead of the formula."""
        return (
            f"A value, not a formula: the live formula {_short(self.formula)} computes "
            f"{_shown(self.independent)} in an independent evaluation of its Excel formula "
            f"({self.by}), the engine {_shown(self.engine)}; the engine's value is "
            "written."
        )


def _short(formula: str, limit: int = 160) -> str:
    formula = re.sub(r"\{[^{}]*\}", "{...}", formula)  # array constants: a node row
    return formula if len(formula) <= limit else formula[: limit - 3] + "..."


def _shown(value) -> str:
    if isinstance(value, float):
        return f"{value:.10g}"
    return str(value)


@dataclass
class CellLog:
    """What a writer wrote: values by (sheet, row, col), formulas, columns, defined names."""

    values: dict[tuple[str, int, int], object] = field(default_factory=dict)
    formulas: dict[tuple[str, int, int], Formula] = field(default_factory=dict)
    columns: list[Column] = field(default_factory=list)
    names: dict[str, str] = field(default_factory=dict)  # NAME (upper) -> "=Sheet!$B$3"
    in_columns: set[tuple[str, int, int]] = field(default_factory=set)
    sheets: dict[str, str] = field(default_factory=dict)  # NAME (upper) -> Name

    def column(self, sheet: str, col: int, first: int, n: int, pieces: list[str]) -> Column:
        """Register a formula written down a column (its cells are checked as one)."""
        c = Column(sheet, col, first, n, pieces)
        self.columns.append(c)
        self.in_columns.update((sheet, first + i, col) for i in range(n))
        return c


class RecordingSheet:
    """An Excel sheet being laid out (:class:`workbook.compute.excelsheets.FormSheet`) that records
    what is written into a :class:`CellLog`, and writes a refused formula as its cached value
    with a comment."""

    def __init__(self, ws, log: CellLog, refused: dict[tuple[str, int, int], str]):
        self._ws, self._log, self._refused = ws, log, refused
        self.name = ws.name
        log.sheets.setdefault(ws.name.upper(), ws.name)

    def __getattr__(self, name):
        return getattr(self._ws, name)

    def _value(self, row: int, col: int, value) -> None:
        self._log.values[(self.name, row, col)] = value

    def write_number(self, row, col, number, fmt=None):
        self._value(row, col, float(number))
        return self._ws.write_number(row, col, number, fmt)

    def write_string(self, row, col, text, fmt=None):
        self._value(row, col, text)
        return self._ws.write_string(row, col, text, fmt)

    def write_boolean(self, row, col, value, fmt=None):
        self._value(row, col, bool(value))
        return self._ws.write_boolean(row, col, value, fmt)

    def write_formula(self, row, col, formula, fmt=None, value=0):
        why = self._refused.get((self.name, row, col))
        if why is not None:
            self._write_cached(row, col, value, fmt)
            self._ws.write_comment(row, col, why)
            return 0
        self._value(row, col, value)
        self._log.formulas[(self.name, row, col)] = Formula(self.name, row, col, formula, row, col)
        return self._ws.write_formula(row, col, formula, fmt, value)

    def write_array_formula(
        self, first_row, first_col, last_row, last_col, formula, fmt=None, value=0
    ):
        why = self._refused.get((self.name, first_row, first_col))
        if why is not None:
            self._write_cached(first_row, first_col, value, fmt)
            self._ws.write_comment(first_row, first_col, why)
            return 0
        self._value(first_row, first_col, value)
        self._log.formulas[(self.name, first_row, first_col)] = Formula(
            self.name, first_row, first_col, formula, last_row, last_col
        )
        return self._ws.write_array_formula(
            first_row, first_col, last_row, last_col, formula, fmt, value
        )

    def write_formula_column(self, first, col, pieces, values, fmt=None, array=False, label=""):
        """A formula down a column (``pieces`` joined by each row's number), checked as one
        (:meth:`CellLog.column`); the caller lays a refused column out as values."""
        self._log.column(self.name, col, first, len(values), pieces)
        name = self.name
        self._log.values.update(((name, first + i, col), v) for i, v in enumerate(values))
        return self._ws.write_formula_column(first, col, pieces, values, fmt, array, label)

    def _write_cached(self, row, col, value, fmt) -> None:
        if isinstance(value, str):
            self.write_string(row, col, value, fmt)
        elif isinstance(value, (bool, np.bool_)):
            self.write_boolean(row, col, value, fmt)
        else:
            self.write_number(row, col, float(value), fmt)


@dataclass
class Outcome:
    """What the check found: refused formulas, and how many formulas it computed."""

    refusals: list[Refusal]
    checked: int  # formula cells computed
    unchecked: dict[str, int]  # why not computed (a function the evaluator lacks) -> cells
    plain: int = 0  # formula cells of scalar arithmetic only, left out (see plain())

    def refused(self) -> dict[tuple[str, int, int], str]:
        """(sheet, row, col) -> comment, for the writer's second pass."""
        out = {}
        for r in self.refusals:
            for i in range(r.rows):
                out[(r.sheet, r.row + i, r.col)] = r.why
        return out


class _Inputs:
    """Values of the references a compiled formula reads, from the log."""

    def __init__(self, log: CellLog, raw: bool = False):
        self.log, self.raw = log, raw
        self.sheets = log.sheets

    def value(self, key: str, here: str, depth: int = 0):
        m = _REF.match(key)
        if m is None:
            ref = self.log.names.get(key.upper())
            if ref is None or depth > 4:
                raise KeyError(key)
            n = _NAME_REF.match(ref)
            if n is None:
                raise KeyError(key)
            return self.value(f"{n['sheet']}!{n['cells'].replace('$', '')}", here, depth + 1)
        sheet = self.sheets.get((m["sheet"] or here).upper().strip("'"), m["sheet"] or here)
        r0, c0 = int(m["r0"]) - 1, _col_index(m["c0"])
        if m["c1"] is None:
            return self._cell(sheet, r0, c0)
        r1, c1 = int(m["r1"]) - 1, _col_index(m["c1"])
        out = np.empty((r1 - r0 + 1, c1 - c0 + 1), dtype=object)
        for i in range(r1 - r0 + 1):
            for j in range(c1 - c0 + 1):
                out[i, j] = self._cell(sheet, r0 + i, c0 + j)
        return out

    def _cell(self, sheet: str, row: int, col: int):
        if self.raw:  # as the fast evaluator reads them (xleval): None for an empty cell
            return self.log.values.get((sheet, row, col))
        import schedula
        from formulas.tokens.operand import NUM

        v = self.log.values.get((sheet, row, col), schedula.EMPTY)
        if isinstance(v, float) and not math.isfinite(v):
            return NUM
        return v


#: a cell or range reference, optionally on another sheet (not inside a name such as R1_)
_CELLS = re.compile(
    r"(?<![\w.$'])((?:'[^']+'|[A-Za-z_][\w.]*)!)?(\$?[A-Z]{1,3}\$?\d+(?::\$?[A-Z]{1,3}\$?\d+)?)"
    r"(?![\w.(!])"
)


_NUMBER = re.compile(r"(?<![\w.$])\d+(?:\.\d*)?(?:E[+-]?\d+)?(?![\w.(])")
_CONSTANTS = re.compile(r'(\{[^{}]*\}|"(?:[^"]|"")*")')  # array constants and texts


@functools.lru_cache(maxsize=2048)
def generic(text: str) -> tuple[str, tuple[str, ...]]:
    """The formula with its cell references and numbers (outside array constants and texts)
    replaced by names _REF_0_, _REF_1_, ...; and what they stand for: formulas that differ
    only in the cells they read or in a constant (a sample's position) share one
    compilation."""
    refs: list[str] = []

    def one(m: re.Match) -> str:
        if m[1] is not None:  # an array constant or a text, kept as it is
            return m[1]
        refs.append((m[2] or "") + m[3].replace("$", "") if m[3] is not None else m[0])
        return f"_REF_{len(refs) - 1}_"

    return _GENERIC.sub(one, text), tuple(refs)


#: one pass over a formula: a constant (group 1), a reference (groups 2 and 3) or a number
_GENERIC = re.compile(
    f"({_CONSTANTS.pattern[1:-1]})|{_CELLS.pattern}|{_NUMBER.pattern}".replace("\n", "")
)


@functools.lru_cache(maxsize=4096)
def compiled(text: str):
    """A generic formula (:func:`generic`) compiled, by the check's own reader of Excel
    formulas or else the formulas package; kept for the process: the formulas of a sheet
    written again (``workbook serve`` at each edit) are not read again."""
    try:
        return xleval.compile_formula(text)
    except xleval.Unsupported:  # the formulas package computes the rest
        import formulas

        return formulas.Parser().ast(text)[1].compile()


def plain(text: str, sheet: str, arrays: frozenset[str] = frozenset()) -> bool:
    """A formula the default check leaves out: scalar arithmetic only (no array constant, no
    range, no defined name of a vector or matrix (``arrays``, upper case), no function but
    :data:`SCALAR`), which the engine and the printer compute by the same operations in the
    same order (tests/outputs/test_excel_golden.py checks the printer's scalar forms against
    the same evaluator); and a helper cell of a root's bisection or an extremum's golden-section
    steps, whose cached value is the engine's own step of the same form (the cell that reads
    the last step is checked)."""
    if sheet in HELPER_SHEETS:
        return True
    if "{" in text or ":" in text:
        return False
    for name, call in re.findall(r"([A-Za-z_][\w.]*)\s*(\(?)", _CONSTANTS.sub("", text)):
        if call and name.upper() not in SCALAR:
            return False
        if not call and name.upper() in arrays:
            return False
    return True


#: Excel functions of numbers that return a number (any other function is checked)
SCALAR = frozenset(
    "ABS ACOS AND ASIN ATAN ATAN2 COS COSH EXP IF INT LN LOG10 MAX MIN MOD NA NOT OR PI "
    "POWER ROUND SIGN SIN SINH SQRT TAN TANH TRUNC".split()
)
#: Excel sheets of helper cells (a root's bisection, an extremum's samples)
HELPER_SHEETS = ("Solver steps", "Solver rows")


def _first(result):
    a = np.asarray(result, dtype=object)
    return a.ravel()[0] if a.size else None


def agrees(got, cached, scale: float) -> bool:
    """The independent evaluator's value ``got`` agrees with the engine's ``cached`` one
    (numbers within the check's relative tolerance of ``scale``; texts and booleans equal)."""
    if isinstance(cached, str) and _complex_agree(got, cached):
        return True
    if isinstance(cached, (str, bool, np.bool_)):
        return not isinstance(got, (float, int)) and str(got) == str(cached) or got == cached
    cached = float(cached)
    if isinstance(got, (bool, np.bool_)) and cached in (0.0, 1.0):
        return float(got) == cached  # a condition's TRUE written as its number, 1
    if isinstance(got, (bool, np.bool_)) or not isinstance(got, (int, float, np.number)):
        return not math.isfinite(cached)  # an Excel error where the engine has none is wrong
    got = float(got)
    if not math.isfinite(got):  # an error element of an array
        return not math.isfinite(cached)
    if not math.isfinite(cached):
        return False
    return abs(got - cached) <= RELATIVE * max(abs(cached), abs(got), scale)


#: why a complex formula is not computed by the check: the `formulas` package has an error
#: value where Excel has a number (its IMARGUMENT of a pure imaginary value is #DIV/0!)
COMPLEX_ERROR = "an IM* function the formulas package does not compute here"
_IM_CALL = re.compile(r"(?<![\w.])(?:_xlfn\.)?(?:IM[A-Z0-9]+|COMPLEX)\(")


def complex_error(text: str, got) -> bool:
    """An Excel error value computed for a formula of complex numbers: not checkable."""
    from formulas.tokens.operand import XlError

    if not _IM_CALL.search(text):
        return False
    return got is None or isinstance(got, XlError)


def _complex_agree(got, cached: str) -> bool:
    """A complex text (Excel's ``3+4i``) and a complex text or a number (a real branch of a
    complex value) of the same number to :data:`RELATIVE` (the evaluator may write more
    digits, or ``j``)."""
    from formulas.tokens.operand import XlError

    if isinstance(got, (bool, np.bool_, XlError)) or not isinstance(got, (str, int, float)):
        return False
    a, b = parse_text(str(got)), parse_text(cached)
    if a is None or b is None:
        return False
    return abs(a - b) <= RELATIVE * max(abs(a), abs(b))


def _magnitude(value) -> float:
    """The largest finite number of a value read by a formula (0 for text)."""
    if isinstance(value, np.ndarray):
        return max((_magnitude(v) for v in value.flat), default=0.0)
    if isinstance(value, (float, int)) and not isinstance(value, bool) and math.isfinite(value):
        return abs(float(value))
    return 0.0


def _resolver(inputs: _Inputs, refs: list[str], here: str, row_of, read: list[float], memo: dict):
    """The values a formula compiled by :mod:`workbook.compute.xleval` reads: its generic
    names (``_REF_k_``: a cell, a range or a number) and the defined names."""

    def resolve(key: str):
        if key.startswith("_REF_"):
            key = refs[int(key[5:-1])]
            if key[0].isdigit():
                return float(key)
        if row_of is not None:
            key = key.replace(str(SENTINEL), str(row_of))
        found = memo.get((key, here))
        if found is None:  # the cells do not change while they are checked
            value = inputs.value(key, here)
            found = memo[(key, here)] = (value, _magnitude(value))
        read.append(found[1])
        return found[0]

    return resolve


def _first_disagreement(log: CellLog, f: Formula, got: np.ndarray, scale: float):
    """(computed, cached) of the first cell of ``f``'s block whose value ``got`` (a value or
    an array) disagrees with the cached one; None when all agree."""
    if got.ndim < 2:
        got = got.reshape(1, -1) if got.ndim == 1 else got.reshape(1, 1)
    for i in range(f.last_row - f.row + 1):
        for j in range(f.last_col - f.col + 1):
            cached = log.values.get((f.sheet, f.row + i, f.col + j))
            try:
                value = got[min(i, got.shape[0] - 1), min(j, got.shape[1] - 1)]
            except IndexError:
                value = None
            if cached is not None and not agrees(value, cached, scale):
                return value, cached
    return None


def check(log: CellLog, everything: bool = True) -> Outcome:
    """Compute the formulas of ``log`` independently (every one with ``everything``, else
    all but the :func:`plain` ones); the ones that disagree with the engine's (cached)
    values."""
    inputs, raw = _Inputs(log), _Inputs(log, raw=True)
    refusals: list[Refusal] = []
    unchecked: dict[str, int] = {}
    checked = 0
    # the magnitudes of the values the formula being computed reads: a result near zero (a
    # difference of near terms) is compared at their scale, its rounding is not an error
    read: list[float] = []
    by = ["the formulas package"]
    memo: dict = {}  # (reference, sheet) -> (value, magnitude)

    def run(text: str, here: str, row_of=None):
        text_g, refs = generic(text)
        fn = compiled(text_g)
        if not hasattr(fn, "inputs"):
            by[0] = XLEVAL
            return fn(_resolver(raw, refs, here, row_of, read, memo))
        by[0] = "the formulas package"
        args = []
        for key in fn.inputs:
            if key.startswith("_REF_"):
                key = refs[int(key[5:-1])]
                if key[0].isdigit():
                    args.append(float(key))
                    continue
            if row_of is not None:
                key = key.replace(str(SENTINEL), str(row_of))
            args.append(inputs.value(key, here))
            read.append(_magnitude(args[-1]))
        return fn(*args)

    def skipped(err: Exception, cells: int) -> None:
        why = f"{type(err).__name__}: {err}".splitlines()[0][:120]
        unchecked[why] = unchecked.get(why, 0) + cells

    plain_cells = 0
    arrays = frozenset(name for name, ref in log.names.items() if ":" in ref)
    for key, f in log.formulas.items():
        if key in log.in_columns:
            continue
        if not everything and plain(f.text, f.sheet, arrays):
            plain_cells += 1
            continue
        try:
            read.clear()
            got = np.asarray(run(f.text, f.sheet), dtype=object)
        except Exception as err:  # noqa: BLE001 - a formula the evaluator cannot compute
            skipped(err, 1)
            continue
        checked += 1
        wrong = _first_disagreement(log, f, got, max(read, default=0.0))
        if wrong is None:
            continue
        if complex_error(f.text, wrong[0]):
            skipped(ValueError(COMPLEX_ERROR), 1)
        else:
            refusals.append(Refusal(f.sheet, f.row, f.col, f.text, *wrong, by=by[0]))

    for c in log.columns:
        template = str(SENTINEL).join(c.pieces)
        if not everything and plain(template, c.sheet, arrays):
            plain_cells += c.n
            continue
        cached_all = [log.values.get((c.sheet, c.first + i, c.col)) for i in range(c.n)]
        # a value near zero in a column (a difference of near terms) is compared at the
        # column's scale: its rounding is not the formula's error
        numbers = [abs(v) for v in cached_all if isinstance(v, float) and math.isfinite(v)]
        scale = max(numbers, default=0.0)
        rows = sorted({round(k * (c.n - 1) / (ROWS_CHECKED - 1)) for k in range(ROWS_CHECKED)})
        for i in rows if c.n > 1 else [0]:
            row = c.first + i
            try:
                read.clear()
                got = _first(run(template, c.sheet, row + 1))
            except Exception as err:  # noqa: BLE001 - a formula the evaluator cannot compute
                skipped(err, c.n)
                break
            checked += 1
            if not agrees(got, cached_all[i], max([scale, *read])):
                if complex_error(template, got):
                    skipped(ValueError(COMPLEX_ERROR), c.n)
                    break
                text = str(row + 1).join(c.pieces)
                refusals.append(
                    Refusal(c.sheet, c.first, c.col, text, got, cached_all[i], c.n, by[0])
                )
                break
    return Outcome(refusals, checked, unchecked, plain_cells)
