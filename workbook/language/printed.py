"""Printed values: the CSV files of values a source document printed, read once."""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

from ..errors import TemplateError, WorkbookError
from ..limits import MAX_CSV_BYTES, file_beside, read_text
from . import units as un
from .csvcells import unescaped
from .spec import PrintedSpec


@dataclass
class PrintedRow:
    name: str
    at: float
    value: float | str  # a text (Mathcad's "OK") is compared as text
    unit: str
    line: int


def read_commented_csv(path, what: str):
    """Read a CSV whose '#' lines and blank lines are comments.

    Returns (header cells or None, [(line number, cells, line text), ...]).
    """
    return commented_csv(read_text(Path(path), what=what, max_bytes=MAX_CSV_BYTES), str(path))


def commented_csv(text: str, file: str):
    """:func:`read_commented_csv` of a CSV's text (``file`` names it in messages)."""
    header, rows = None, []
    for number, line in enumerate(text.splitlines(), start=1):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        try:
            cells = next(csv.reader([line]))
        except csv.Error as exc:
            raise TemplateError(
                f"cannot read the line as CSV ({exc})", file=file, line=number
            ) from None
        if header is None:
            header = cells
        else:
            rows.append((number, cells, line))
    return header, rows


def _number_or_text(cell: str) -> float | str:
    """A printed value: a number, else a text (compared as text with what the sheet gives);
    a text that a writer escaped for spreadsheets (a leading apostrophe before = + - @) is
    read without its apostrophe."""
    try:
        return float(cell)
    except ValueError:
        if not cell.strip():
            raise
        return unescaped(cell)


def read_printed(spec: PrintedSpec) -> list[PrintedRow]:
    """Read a printed-values CSV: name, argument value, value, unit ('#' lines are comments)."""
    file = spec.file
    if spec.folder is not None:  # resolved, and inside the template's folder
        file = file_beside(
            spec.folder,
            str(spec.file.relative_to(spec.folder)),
            what="[[printed]] file",
            max_bytes=MAX_CSV_BYTES,
        )
    return printed_from_lines(spec, read_commented_csv(file, "printed values")[1])


def printed_from_text(spec: PrintedSpec, text: str) -> list[PrintedRow]:
    """The rows of a printed-values CSV given as text (a file written in memory, not read)."""
    return printed_from_lines(spec, commented_csv(text, str(spec.file))[1])


def printed_from_lines(spec: PrintedSpec, lines) -> list[PrintedRow]:
    """The rows of a printed-values CSV's lines (:func:`commented_csv`), each checked."""
    rows = []
    for number, cells, line in lines:
        if len(cells) != 4:
            raise TemplateError(f"{spec.file}:{number}: expected name, argument, value, unit")
        try:
            at = float(cells[1]) if cells[1].strip() else math.nan
            value = _number_or_text(cells[2])
        except ValueError:
            raise TemplateError(f"{spec.file}:{number}: not a number in {line!r}") from None
        if math.isinf(at) or (isinstance(value, float) and not math.isfinite(value)):
            raise TemplateError(f"{spec.file}:{number}: not a finite number in {line!r}")
        try:  # the unit is read now: a misspelt one is an error naming the line
            un.unit(cells[3], what=f"{spec.file}:{number}: unit")
        except WorkbookError as err:
            raise TemplateError(err.message) from None
        rows.append(PrintedRow(cells[0].strip(), at, value, cells[3].strip(), number))
    return rows
