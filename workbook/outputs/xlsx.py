"""Write a computed sheet's Excel form as an xlsx file: live formulas with cached values,
native charts.

The form (:class:`workbook.compute.excelsheets.ExcelForm`, made by
:func:`workbook.compute.computed.compute`) holds every cell, chart and defined name; this module
only writes them with xlsxwriter. It neither types nor evaluates: what a cell holds was decided, and
checked, before."""

from __future__ import annotations

import re
import sys
from pathlib import Path

from ..compute import style
from ..errors import InputError
from ..functions.excel_functions import CLASSIC
from .atomic import check_target, replacing

#: a workbook with more formula cells than this says so on stderr while it is saved
PROGRESS_CELLS = 200_000


_CALLED = re.compile(r"([A-Za-z_][A-Za-z0-9._]*)\(")


def classic_formulas_as_they_are(ws) -> None:
    """Skip xlsxwriter's ~30 regex substitutions per formula when they cannot change it.

    xlsxwriter rewrites every formula to prefix Excel 365 functions (FILTER, XLOOKUP...) with
    "_xlfn."; that costs ~70 % of the time of writing a table of formulas. A formula that
    calls only classic functions (:data:`workbook.functions.excel_functions.CLASSIC`) is written as
    it is; any other goes through xlsxwriter's own rewriting, as before.
    tests/outputs/test_formula_shortcut.py proves every template's worksheets identical with and
    without this; pyproject.toml bounds xlsxwriter to the versions checked."""
    original = getattr(ws, "_prepare_formula", None)
    if original is None or getattr(ws, "use_future_functions", False):
        return

    def prepare(formula, expand_future_functions=False):
        if expand_future_functions or not all(
            name.upper() in CLASSIC for name in _CALLED.findall(formula)
        ):
            return original(formula, expand_future_functions)
        if formula.startswith("{"):
            formula = formula[1:]
        if formula.startswith("="):
            formula = formula[1:]
        if formula.endswith("}"):
            formula = formula[:-1]
        return formula

    ws._prepare_formula = prepare


def write_workbook(computed, path: Path, *, force: bool = False) -> Path:
    """Write the Excel form of ``computed`` (a :class:`workbook.compute.computed.ComputedSheet`
    computed with ``excel=True``) to ``path`` atomically: the old file survives any failure."""
    form = computed.excel
    if form is None:
        raise ValueError("the sheet was computed without its Excel form (compute(excel=True))")
    path = Path(path)
    check_target(path, force=force)
    with replacing(path) as tmp:
        render(form, tmp)
    return path


def render(form, path: Path) -> None:
    """Write ``form`` to ``path`` (not atomically: see :func:`write_workbook`). xlsxwriter's
    own temporary files go to a folder beside ``path`` that is removed whatever happens (in
    the system's temporary folder, a Ctrl-C while saving left them there)."""
    import tempfile

    with tempfile.TemporaryDirectory(
        prefix=f".{Path(path).name[:100]}.", suffix=".partial", dir=Path(path).parent
    ) as scratch:
        _render(form, path, scratch)


def _render(form, path: Path, scratch: str) -> None:
    import xlsxwriter

    options = {"nan_inf_to_errors": True, "strings_to_formulas": False, "strings_to_urls": False}
    wb = xlsxwriter.Workbook(str(path), {**options, "tmpdir": scratch})
    wb.set_properties(form.properties)
    formats = style.add_formats(wb)
    sheets = []
    for sheet in form.sheets:
        ws = wb.add_worksheet(sheet.name)
        classic_formulas_as_they_are(ws)
        sheets.append(ws)
    for name, ref in form.names:
        wb.define_name(name, ref)
    replay(wb, sheets, form.ops, formats)
    if form.formula_cells > PROGRESS_CELLS:
        _progress(f"{Path(path).name}: saving {form.formula_cells:,} formula cells")
    try:
        wb.close()
    except Exception as exc:  # xlsxwriter wraps the OSError (disk full, read-only)
        cause = exc.__context__ if isinstance(exc.__context__, OSError) else exc
        if isinstance(cause, OSError):
            from .atomic import os_error

            raise os_error(Path(path), cause) from None
        if type(exc).__name__ == "FileCreateError":
            raise InputError(f"cannot write {path}: {getattr(cause, 'strerror', cause)}") from None
        raise


def replay(wb, sheets: list, ops, formats: dict) -> None:
    """Write the recorded operations, in the order they were laid out: (sheet index, method,
    arguments, index of the format role among the arguments or -1)."""
    for index, method, args, at in ops:
        ws = sheets[index]
        if at >= 0:
            args = (*args[:at], formats[args[at]], *args[at + 1 :])
        if method == "formula_column":
            _formula_column(ws, *args)
        elif method == "insert_chart":
            row, col, chart = args
            ws.insert_chart(row, col, _chart(wb, chart))
        else:
            getattr(ws, method)(*args)


def _formula_column(ws, first: int, col: int, pieces, values, fmt, array: bool, label: str):
    """One formula down a column: ``pieces`` joined by each row's number (1-based)."""
    n = len(values)
    write = ws.write_formula
    if array:  # computes with vectors or matrices: one-cell array formulas
        write = lambda r, c, f, fm, v: ws.write_array_formula(r, c, r, c, f, fm, v)  # noqa: E731
    for lo in range(0, n, PROGRESS_CELLS):
        if lo:  # a long column says how far it is
            _progress(f"{label}, row {lo:,} of {n:,}")
        for i in range(lo, min(n, lo + PROGRESS_CELLS)):
            row = first + i
            write(row, col, str(row + 1).join(pieces), fmt, values[i])


def _chart(wb, chart):
    """An xlsxwriter chart from its recorded calls."""
    out = wb.add_chart(chart.options)
    for method, args, kwargs in chart.calls:
        getattr(out, method)(*args, **kwargs)
    return out


def _progress(text: str) -> None:
    print(f"workbook: writing {text}", file=sys.stderr, flush=True)
