"""Limits on the files the engine reads and writes: regular files of bounded size only.

A path given by a user may name a device (``/dev/zero``), a FIFO (a read or a write blocks
forever), a sparse file of gigabytes, or an xlsx whose members inflate to gigabytes (a zip
bomb). Each is refused here, before any parser sees it, with an error of kind
``limit exceeded`` or ``input error`` (exit status 2).

The memory of a computation is bounded here too: the matrix work of one evaluation, and the
elements of every array made while computing (:func:`check_elements`, before it is made). The
time of a command is in :mod:`workbook.limits_time`.
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import stat
import zipfile
from pathlib import Path

from .errors import InputError, LimitError, OutOfBudget

MAX_CSV_BYTES = 20_000_000  # a printed-values CSV
MAX_INPUTS_XLSX_BYTES = 200_000_000  # an edited workbook given to --inputs (compressed)
MAX_XLSX_MEMBER_BYTES = 64_000_000  # one member of it that is read, decompressed
MAX_XLSX_MEMBERS = 10_000
# Parts openpyxl parses whole before a cell is read, bounded by what they hold: a 60 MB
# styles.xml took 57 s and 1.55 GB, 3.5 million tiny shared strings 59 s.
MAX_STYLES_BYTES = 2_000_000
MAX_SHARED_STRINGS = 300_000
#: Cells of the tables of one written workbook (range, block and family tables, charts' data),
#: checked before each table is written: a table of 399,999 rows and 2 columns took 7.0 s of
#: CPU to compute and write (19.3 s of wall time at a load average of 5.7 on 2 cores); one of
#: 1,000,001 rows 16.0 s. A longer table is written as CSV (``--csv``).
MAX_TABLE_CELLS = 800_000
#: Matrix work of one evaluation, in multiply-adds of a matrix product: a product of
#: (n x k) by (k x m) is n*k*m, a decomposition a multiple of n^3 (below), an element-wise
#: operation ELEMENT_WORK per element. 40e9 is five products of 2000 x 2000 matrices, about
#: 3 s of one core (numpy's BLAS, 12.7e9 multiply-adds a second, measured unloaded).
MAX_MATRIX_WORK = 40_000_000_000
#: What an element-wise operation on a large array costs per element, in multiply-adds of a
#: product (adding two 2000 x 2000 arrays took 7.9 ms, their product 0.63 s: about 20).
ELEMENT_WORK = 20
#: Elements of one array built while a program runs or a built-in joins arrays (stack,
#: augment, a vector grown by its elements: 80 MB of numbers), and characters of one text
#: (concat), checked before the memory is taken.
MAX_ARRAY_ELEMENTS = 10_000_000
MAX_TEXT_CHARS = 10_000_000
_STYLES_TYPE = "application/vnd.openxmlformats-officedocument.spreadsheetml.styles+xml"
_STRINGS_TYPE = "application/vnd.openxmlformats-officedocument.spreadsheetml.sharedStrings+xml"


def regular_file(path: Path, *, what: str, max_bytes: int) -> int:
    """Refuse a path that is missing, not a regular file, or larger than ``max_bytes``.

    Returns the size. ``stat`` does not open the file, so a FIFO or a device never blocks.
    """
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise InputError(f"{what} {path}: no such file") from None
    except OSError as exc:
        raise InputError(f"{what} {path}: cannot read it ({exc.strerror})") from None
    if not stat.S_ISREG(st.st_mode):
        raise InputError(f"{what} {path} is not a regular file ({_kind(st.st_mode)})")
    if st.st_size > max_bytes:
        raise LimitError(f"{what} {path} is {st.st_size:,} bytes (limit {max_bytes:,})")
    return st.st_size


def file_beside(folder: Path, name: str, *, what: str, max_bytes: int) -> Path:
    """The regular file ``name`` inside ``folder`` (a worksheet's own folder), after every
    symlink is resolved; refused when ``name`` is absolute, climbs out with ``..``, or
    resolves (through a symlink, itself or a folder on the way) to a file outside ``folder``,
    or is not a regular file of at most ``max_bytes``. Returns the resolved path.

    A worksheet folder from an archive or a clone may hold a symlink to any file of the
    machine; the error names only the name given, never what it points to.
    """
    rel = Path(str(name))
    if rel.is_absolute() or ".." in rel.parts or not str(name).strip():
        raise InputError(f"{what} {str(name)!r} must be a file name beside the template")
    base = Path(folder).resolve()
    try:
        target = (base / rel).resolve(strict=True)
    except FileNotFoundError:
        raise InputError(f"{what} {str(name)!r}: no such file beside the template") from None
    except (OSError, RuntimeError) as exc:  # a symlink loop, a name too long
        raise InputError(f"{what} {str(name)!r}: cannot read it ({exc})") from None
    if not target.is_relative_to(base):
        raise InputError(
            f"{what} {str(name)!r} is a link to a file outside the template's folder; a "
            "worksheet reads only files in its own folder"
        )
    regular_file(target, what=what, max_bytes=max_bytes)
    return target


def read_text(path: Path, *, what: str, max_bytes: int) -> str:
    """The UTF-8 text of a regular file of at most ``max_bytes`` (a UTF-8 BOM is dropped).

    Errors name the path; one about bad UTF-8 carries the file and line as its location.
    """
    regular_file(path, what=what, max_bytes=max_bytes)
    try:
        with open(path, "rb") as f:
            data = f.read(max_bytes + 1)
    except OSError as exc:
        raise InputError(f"{what} {path}: cannot read it ({exc.strerror})") from None
    if len(data) > max_bytes:  # the file grew after the check
        raise LimitError(f"{what} {path} is more than {max_bytes:,} bytes")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise InputError(
            f"{what} is not UTF-8 text (byte {exc.start}); save it as UTF-8",
            file=str(path),
            line=line,
        ) from None


def _kind(mode: int) -> str:
    for test, name in (
        (stat.S_ISDIR, "a folder"),
        (stat.S_ISFIFO, "a named pipe"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
    ):
        if test(mode):
            return name
    return "not a plain file"


def check_xlsx_archive(path: Path, *, what: str, sheet: str) -> None:
    """Refuse an xlsx whose members would inflate beyond :data:`MAX_XLSX_MEMBER_BYTES` each,
    before openpyxl decompresses anything. Of the worksheets only ``sheet`` is checked (the
    others are not read; a workbook with a long table stays readable).

    zipfile stops reading a member at the size its header declares, so checking the declared
    sizes bounds what is decompressed.
    """
    regular_file(path, what=what, max_bytes=MAX_INPUTS_XLSX_BYTES)
    try:
        with zipfile.ZipFile(path) as z:
            infos = z.infolist()
    except (zipfile.BadZipFile, OSError, ValueError, EOFError) as exc:
        raise InputError(f"{what} {path}: cannot read it as an xlsx workbook ({exc})") from None
    if len(infos) > MAX_XLSX_MEMBERS:
        raise LimitError(f"{what} {path} has {len(infos):,} members (limit {MAX_XLSX_MEMBERS:,})")
    wanted = _sheet_member(path, sheet, {i.filename: i.file_size for i in infos}, what)
    for info in infos:
        name = info.filename
        if name.startswith("xl/worksheets/") and name.endswith(".xml") and name != wanted:
            continue
        if info.file_size > MAX_XLSX_MEMBER_BYTES:
            raise LimitError(
                f"{what} {path}: member {info.filename} inflates to {info.file_size:,} bytes "
                f"(limit {MAX_XLSX_MEMBER_BYTES:,})"
            )
    _check_parsed_parts(path, infos, what)


def _check_parsed_parts(path: Path, infos: list, what: str) -> None:
    """Bound the parts openpyxl parses whole: the styles by their size, the shared strings by
    how many they are (counted in a stream, stopping at the limit). The parts are found by
    their content types, as openpyxl finds them, and by their usual names."""
    import re

    types = _content_types(path, infos)
    by_name = {i.filename: i for i in infos}
    styles = {n for n, t in types.items() if t == _STYLES_TYPE} | {"xl/styles.xml"}
    strings = {n for n, t in types.items() if t == _STRINGS_TYPE} | {"xl/sharedStrings.xml"}
    for name in sorted(styles):
        info = by_name.get(name)
        if info is not None and info.file_size > MAX_STYLES_BYTES:
            raise LimitError(
                f"{what} {path}: its styles part {name} is {info.file_size:,} bytes "
                f"(limit {MAX_STYLES_BYTES:,})"
            )
    item = re.compile(rb"<(?:[A-Za-z_][\w.-]*:)?si[\s/>]")
    for name in sorted(strings):
        if name not in by_name:
            continue
        count, tail = 0, b""
        with zipfile.ZipFile(path) as z, z.open(name) as f:
            while chunk := f.read(1 << 20):
                data = tail + chunk
                count += len(item.findall(data))
                tail = data[-32:]
                count -= len(item.findall(tail))  # counted again with the next chunk
                if count > MAX_SHARED_STRINGS:
                    raise LimitError(
                        f"{what} {path}: more than {MAX_SHARED_STRINGS:,} shared strings"
                    )


def _content_types(path: Path, infos: list) -> dict[str, str]:
    """Part name -> content type, from [Content_Types].xml (empty when it is unreadable)."""
    from defusedxml import ElementTree

    info = next((i for i in infos if i.filename == "[Content_Types].xml"), None)
    if info is None or info.file_size > MAX_XLSX_MEMBER_BYTES:
        return {}
    try:
        with zipfile.ZipFile(path) as z:
            root = ElementTree.fromstring(z.read(info))
    except Exception:  # noqa: BLE001 - openpyxl will name the fault
        return {}
    return {
        el.get("PartName", "").lstrip("/"): el.get("ContentType", "")
        for el in root.iter()
        if el.tag.endswith("}Override")
    }


def writable_target(path: Path) -> None:
    """Refuse an output path that exists and is not a regular file (a FIFO, a device, a
    socket): writing to it would block or go elsewhere, with or without ``--force``."""
    try:
        st = os.stat(path)
    except FileNotFoundError:
        return
    except OSError as exc:
        raise InputError(f"output path {path}: {exc.strerror}") from None
    if stat.S_ISDIR(st.st_mode):
        return  # the caller names the folder
    if not stat.S_ISREG(st.st_mode):
        raise InputError(
            f"output path {path} is {_kind(st.st_mode)}; only regular files are written "
            "(--force does not change that)"
        )


def _sheet_member(path: Path, sheet: str, sizes: dict[str, int], what: str) -> str | None:
    """The archive member of worksheet ``sheet`` (from xl/workbook.xml and its rels)."""
    from defusedxml import ElementTree

    names = ("xl/workbook.xml", "xl/_rels/workbook.xml.rels")
    if any(sizes.get(n, 0) > MAX_XLSX_MEMBER_BYTES for n in names):
        raise LimitError(f"{what} {path}: its workbook part is too large")
    try:
        with zipfile.ZipFile(path) as z:
            book = ElementTree.fromstring(z.read(names[0]))
            rels = ElementTree.fromstring(z.read(names[1]))
    except Exception:  # noqa: BLE001 - missing or malformed: openpyxl will name the fault
        return None
    rid = next(
        (
            value
            for el in book.iter()
            if el.tag.endswith("}sheet") and el.get("name") == sheet
            for key, value in el.attrib.items()
            if key.endswith("}id")
        ),
        None,
    )
    for el in rels.iter():
        if el.get("Id") == rid and rid is not None:
            target = el.get("Target", "")
            return target.lstrip("/") if target.startswith("/") else "xl/" + target
    return None


def exhausted(exc: BaseException) -> LimitError:
    """A RecursionError or MemoryError met while computing, as the limit error it is (the
    caller gives it the file, line and definition)."""
    if isinstance(exc, RecursionError):
        return LimitError("nested too deeply for the engine (Python's recursion limit)")
    return LimitError("too large for memory (an array or a computation could not be allocated)")


_matrix_work: contextvars.ContextVar[list[float] | None] = contextvars.ContextVar(
    "workbook_matrix_work", default=None
)


@contextlib.contextmanager
def matrix_work():
    """One evaluation's budget of matrix work (:data:`MAX_MATRIX_WORK`): the outermost block
    opens it, blocks inside share it."""
    if _matrix_work.get() is not None:
        yield
        return
    token = _matrix_work.set([0.0])
    try:
        yield
    finally:
        _matrix_work.reset(token)


def charge_matrix_work(work: float, what: str) -> None:
    """Count ``work`` (multiply-adds, see :data:`MAX_MATRIX_WORK`) against the evaluation's
    budget before it is done; past the budget a LimitError says what was asked (the caller
    adds the definition). Outside an evaluation one operation is checked alone."""
    spent = _matrix_work.get()
    total = work + (spent[0] if spent is not None else 0.0)
    if total > MAX_MATRIX_WORK:
        raise LimitError(
            f"{what} would bring the matrix work of this evaluation to {total:,.0f} "
            f"multiply-adds (limit {MAX_MATRIX_WORK:,})"
        )
    if spent is not None:
        spent[0] = total


def count_text(count: float) -> str:
    """A count for a message: ``12,345,678``, or ``1e+300`` when it is beyond any array."""
    return f"{count:,.0f}" if count < 1e15 else f"{count:.3g}"


def check_elements(count: float, what: str) -> None:
    """Refuse an array of ``count`` elements before it is made (:data:`MAX_ARRAY_ELEMENTS`):
    the memory budget of the command is spent, and it stops (:class:`OutOfBudget`)."""
    if count > MAX_ARRAY_ELEMENTS:
        raise OutOfBudget(
            LimitError(
                f"{what} would make an array of {count_text(count)} elements (limit "
                f"{MAX_ARRAY_ELEMENTS:,} elements); build a smaller one"
            )
        )


def check_text_length(count: float, what: str) -> None:
    """Refuse a text of ``count`` characters before it is made (:data:`MAX_TEXT_CHARS`)."""
    if count > MAX_TEXT_CHARS:
        raise OutOfBudget(
            LimitError(
                f"{what} would make a text of {count_text(count)} characters "
                f"(limit {MAX_TEXT_CHARS:,} characters)"
            )
        )
