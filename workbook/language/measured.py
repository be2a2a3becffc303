"""``[data]`` tables: measured points read from a CSV file beside the template (READPRN).

::

    [data.pump]
    file = "pump.csv"                       # a header row of column names, then numbers
    columns = { Q = "m^3/h", H = "m" }      # the unit of each column used

Each column becomes a name that ``linterp(X, Y, x)`` and ``cspline(X, Y, x)`` read, and,
anywhere else, a vector of its values in its unit (Mathcad's READPRN columns); the file is read
when the sheet is loaded, so a missing file, a missing column or a value that
is not a number is an error naming the file and line.
"""

from __future__ import annotations

import csv
import functools
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pint

from ..errors import LimitError, TemplateError, WorkbookError
from . import units as un
from .typed import TConst, TMatrix

#: most points of one data file
MAX_POINTS = 1_000_000


@dataclass(frozen=True, eq=False)
class DataColumn:
    """One column of a [data] table: its values in ``unit``."""

    name: str
    table: str
    unit: pint.Unit
    values: np.ndarray
    file: Path
    line: int | None

    @functools.cached_property
    def vector(self) -> TMatrix:
        """The typed vector of the values (built once, however often the column is used)."""
        rows = tuple((TConst(self.unit, value=float(v)),) for v in self.values)
        return TMatrix(self.unit, rows=rows, shape=(len(rows), 1))


def column_vector(col: DataColumn) -> TMatrix:
    """The column as a vector written out (its values in its unit): every vector built-in
    takes it, and the workbook writes it as an array of numbers."""
    return col.vector


def read_data(raw: dict, path: Path, lines: dict[str, int | None]) -> list[DataColumn]:
    """Every column of every [data] table, in the order written; ``lines`` gives the line of
    each table (the reader of the template claims the column names)."""
    out: list[DataColumn] = []
    for table, spec in raw.items():
        line = lines.get(table)
        try:
            out.extend(_table(table, spec, path, line))
        except WorkbookError as err:
            raise err.located(line=line, definition=f"data.{table}") from None
    return out


def _table(table: str, spec, path: Path, line) -> list[DataColumn]:
    if not isinstance(spec, dict) or "file" not in spec or "columns" not in spec:
        raise TemplateError(
            f'[data.{table}] needs file = "name.csv" and columns = {{ X = "unit", ... }}'
        )
    columns = spec["columns"]
    if not isinstance(columns, dict) or not columns:
        raise TemplateError(
            f'[data.{table}] columns = {{ X = "unit", ... }} names the columns used'
        )
    from ..limits import MAX_CSV_BYTES, file_beside, read_text

    what = f"[data.{table}] file"  # inside the template's folder once symlinks are resolved
    file = file_beside(path.parent, str(spec["file"]), what=what, max_bytes=MAX_CSV_BYTES)
    text = read_text(file, what=what, max_bytes=MAX_CSV_BYTES)
    try:
        rows = [r for r in csv.reader(text.splitlines()) if r and not r[0].lstrip().startswith("#")]
    except csv.Error as err:
        raise TemplateError(f"[data.{table}]: cannot read {file.name} as CSV ({err})") from None
    if not rows:
        raise TemplateError(f"[data.{table}]: {file.name} is empty")
    header = [h.strip() for h in rows[0]]
    if len(rows) - 1 > MAX_POINTS:
        raise LimitError(
            f"[data.{table}]: {file.name} has {len(rows) - 1} rows (limit {MAX_POINTS})"
        )
    out = []
    for name, unit_text in columns.items():
        if name not in header:
            raise TemplateError(
                f"[data.{table}]: {file.name} has no column '{name}' (columns: {', '.join(header)})"
            )
        j = header.index(name)
        values = []
        for k, row in enumerate(rows[1:], start=2):
            try:
                v = float(row[j])
            except (IndexError, ValueError):
                cell = row[j] if j < len(row) else ""
                raise TemplateError(
                    f"[data.{table}]: {file.name}, data row {k}, column {name}: {cell!r} is not "
                    "a number"
                ) from None
            if not math.isfinite(v):
                raise TemplateError(f"[data.{table}]: {file.name}, data row {k}: {v} is not finite")
            values.append(v)
        unit = un.unit(str(unit_text), what=f"data.{table}.{name}")
        out.append(DataColumn(name, table, unit, np.asarray(values), file, line))
    return out
