"""Reading an Excel workbook safely: its cells (formula, cached value, number format), its
defined names and its array formulas; never a macro run, never an external link followed."""

from __future__ import annotations

import re
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import InputError, LimitError
from ..limits import MAX_XLSX_MEMBER_BYTES, MAX_XLSX_MEMBERS, regular_file

#: Largest workbook read (compressed), and cells of all sheets together.
MAX_BOOK_BYTES = 200_000_000
MAX_CELLS = 2_000_000


@dataclass
class Cell:
    sheet: str
    row: int
    col: int
    formula: str | None  # the text after "=", or None for a constant
    value: object  # Excel's cached value (a constant's own value); None when empty
    number_format: str = "General"
    array: str | None = None  # "B10:E10" for every cell of a multi-cell array formula
    array_master: tuple[int, int] | None = None
    in_array: bool = False  # a cell of an array formula, of one cell or more

    @property
    def address(self) -> str:
        from openpyxl.utils import get_column_letter

        return f"{get_column_letter(self.col)}{self.row}"

    @property
    def ref(self) -> str:
        return f"{self.sheet}!{self.address}"


@dataclass
class Book:
    path: Path
    sheets: dict[str, dict[tuple[int, int], Cell]] = field(default_factory=dict)
    names: dict[str, tuple[str, str]] = field(default_factory=dict)  # name -> (sheet, A1 ref)
    #: defined names that are not one range: a constant (``0.5``) or a formula, as text
    name_formulas: dict[str, str] = field(default_factory=dict)
    skipped: list[tuple[str, str]] = field(default_factory=list)  # (what, why)
    stale: bool = False  # saved before Excel finished calculating: cached values may be old
    #: {cell ref: why} of formulas whose structured references (tables) are not read
    formula_problems: dict[str, str] = field(default_factory=dict)
    #: {(sheet, row, col): the parsed formula} of the formulas translated
    trees: dict = field(default_factory=dict)
    #: {(sheet, row, col): the Sub} of the cells the VBA Subs write (set by the translation:
    #: an IS-function of such a cell is not certain)
    sub_written: dict = field(default_factory=dict)

    def cell(self, sheet: str, row: int, col: int) -> Cell | None:
        return self.sheets.get(sheet, {}).get((row, col))

    def sheet_named(self, name: str) -> str | None:
        """The sheet's own name for a name written in a formula (case-insensitive)."""
        low = name.strip("'").lower()
        return next((s for s in self.sheets if s.lower() == low), None)


def check_archive(path: Path) -> None:
    """Refuse a workbook whose zip members would inflate beyond the limits of ``--inputs``,
    before any parser decompresses one."""
    try:
        with zipfile.ZipFile(path) as z:
            infos = z.infolist()
    except (zipfile.BadZipFile, OSError, ValueError, EOFError) as exc:
        raise InputError(f"{path}: cannot read it as an Excel workbook ({exc})") from None
    if len(infos) > MAX_XLSX_MEMBERS:
        raise LimitError(f"{path} has {len(infos):,} members (limit {MAX_XLSX_MEMBERS:,})")
    for info in infos:
        if info.file_size > MAX_XLSX_MEMBER_BYTES:
            raise LimitError(
                f"{path}: member {info.filename} inflates to {info.file_size:,} bytes "
                f"(limit {MAX_XLSX_MEMBER_BYTES:,})"
            )


def read_book(path: Path) -> Book:
    """The cells of every worksheet of an .xlsx/.xlsm/.xlam (formulas and cached values)."""
    regular_file(path, what="workbook", max_bytes=MAX_BOOK_BYTES)
    book = Book(path)
    if path.suffix.lower() == ".xls":
        return _read_xls(book, path)
    return _read_xlsx(book, path)


def _read_xls(book: Book, path: Path) -> Book:
    """An Excel 97-2003 workbook: its formulas from LibreOffice's conversion to .xlsx, the
    values Excel cached from the file's own records."""
    import tempfile

    from . import xls

    xls.soffice()  # exit 2 at once when LibreOffice is missing
    cached = xls.cached_values(path)
    with tempfile.TemporaryDirectory(prefix="workbook-xls-") as tmp:
        converted = xls.convert(path, Path(tmp))
        _read_xlsx(book, converted)
    by_name = {name: values for name, values in cached}
    for k, (sheet, cells) in enumerate(book.sheets.items()):
        values = by_name.get(sheet, cached[k][1] if k < len(cached) else {})
        for key, cell in cells.items():
            if cell.formula is not None:
                cell.value = values.get(key)
    return book


def _read_xlsx(book: Book, path: Path) -> Book:
    check_archive(path)
    import warnings

    import openpyxl

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            wb = openpyxl.load_workbook(path, data_only=False, keep_links=False)
            cached = openpyxl.load_workbook(path, data_only=True, keep_links=False)
    except Exception as exc:  # noqa: BLE001 - zip, XML: the file is not a readable workbook
        raise InputError(f"{path}: cannot read it as an Excel workbook ({exc})") from None
    calc = getattr(wb, "calculation", None)
    book.stale = calc is not None and calc.calcCompleted is False
    total = 0
    for ws in wb.worksheets:
        cells: dict[tuple[int, int], Cell] = {}
        values = cached[ws.title]
        arrays: dict[tuple[int, int], tuple[str, tuple[int, int]]] = {}
        for row in ws.iter_rows():
            for c in row:
                if c.value is None:
                    continue
                total += 1
                if total > MAX_CELLS:
                    raise LimitError(f"{path} has more than {MAX_CELLS:,} cells")
                formula = None
                v = c.value
                in_array = False
                if hasattr(v, "text") and hasattr(v, "ref"):  # an ArrayFormula
                    formula = str(v.text or "").lstrip("=")
                    ref = str(v.ref)
                    in_array = True
                    if ":" in ref:
                        for cells_row in ws[ref]:
                            for part in cells_row:
                                arrays[(part.row, part.column)] = (ref, (c.row, c.column))
                elif isinstance(v, str) and v.startswith("="):
                    formula = v[1:]
                value = values.cell(c.row, c.column).value if formula is not None else v
                cells[(c.row, c.column)] = Cell(
                    ws.title,
                    c.row,
                    c.column,
                    formula,
                    value,
                    c.number_format or "General",
                    in_array=in_array,
                )
        for (r, col), (ref, master) in arrays.items():
            cell = cells.get((r, col))
            value = values.cell(r, col).value
            if cell is None:
                cell = cells[(r, col)] = Cell(ws.title, r, col, None, value)
            cell.array, cell.array_master, cell.in_array = ref, master, True
            if (r, col) != master:
                cell.formula = cells[master].formula
                cell.value = value
        book.sheets[ws.title] = cells
    read_names(book, _defined_names(wb))
    _structured_references(book, wb)
    return book


def _structured_references(book: Book, wb) -> None:
    """Formulas that read tables by their columns, written with A1 references; a table's
    bare name is its data (a defined name of that range, unless a defined name has it)."""
    from openpyxl.utils import get_column_letter

    from .tables import StructuredProblem, read_tables, rewrite

    tables = read_tables(wb)
    for key, t in tables.items():
        d1, d2 = t.data
        if d1 <= d2 and not any(k.casefold() == key for k in book.names):
            if not any(k.casefold() == key for k in book.name_formulas):
                corner = f"{get_column_letter(t.c1)}{d1}:{get_column_letter(t.c2)}{d2}"
                book.names[t.name] = (t.sheet, corner)
    if not tables:
        return
    for cells in book.sheets.values():
        for cell in cells.values():
            if cell.formula is None or "[" not in cell.formula:
                continue
            row = cell.row if cell.array_master is None else cell.array_master[0]
            try:
                cell.formula = rewrite(cell.formula, cell.sheet, row, tables)
            except StructuredProblem as exc:
                book.formula_problems[cell.ref] = str(exc)


#: a defined name that is one reference: Sheet1!$A$1, 'Load table'!$B$2:$C$9
_NAME_REF = re.compile(
    r"^(?:'(?:[^']|'')+'|[^'!*/+\-^&=<>(),\"]+)!\$?[A-Za-z]{1,3}\$?\d+"
    r"(?::\$?[A-Za-z]{1,3}\$?\d+)?$"
)


def read_names(book: Book, items) -> None:
    """Defined names: one range (``book.names``), else a constant or a formula
    (``book.name_formulas``); a name whose text reads another workbook or a DDE link (``cmd|``)
    is listed, never followed."""
    for name, dn in items:
        text = str(getattr(dn, "attr_text", None) or getattr(dn, "value", "") or "").strip()
        text = text.removeprefix("=")
        if not text:
            continue
        if "|" in text or "[" in text:
            book.skipped.append(
                (f"the defined name {name}", "a DDE or external link (never followed)")
            )
            continue
        if _NAME_REF.match(text):
            try:
                dests = list(getattr(dn, "destinations", []) or [])
            except Exception:  # noqa: BLE001 - openpyxl's tokenizer refuses the text
                dests = []
            if len(dests) == 1 and book.sheet_named(dests[0][0]):
                book.names[name] = (book.sheet_named(dests[0][0]), dests[0][1].replace("$", ""))
                continue
        if "#REF!" in text.upper():
            book.skipped.append((f"the defined name {name}", f"a broken reference ({text[:60]})"))
            continue
        book.name_formulas[name] = text


def _defined_names(wb):
    names = getattr(wb, "defined_names", {})
    items = list(names.items()) if hasattr(names, "items") else []
    for ws in wb.worksheets:  # names local to a sheet
        local = getattr(ws, "defined_names", {})
        items += list(local.items()) if hasattr(local, "items") else []
    return items
