"""A written workbook against its recalculation (LibreOffice, the formulas package or the
live check's own evaluator): Excel's error values, the cells that differ."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import openpyxl
from openpyxl.utils import get_column_letter

from helpers.recalc import cell_values, formula_values

#: The relative difference allowed between a cell's cached value and its recalculation.
RELATIVE = 1e-9

#: Excel's error values. LibreOffice saves some errors under another code (SQRT(-1) is #NUM!
#: in Excel, #VALUE! in LibreOffice): an error must stay an error, never become a number.
ERRORS = frozenset({"#NULL!", "#DIV/0!", "#VALUE!", "#REF!", "#NAME?", "#NUM!", "#N/A"})


def assert_same(original, recalculated, rel=1e-9):
    cached = formula_values(original)
    new = cell_values(recalculated)
    assert cached, "the workbook has no formulas"
    bad = []
    for key, (formula, value) in cached.items():
        got = new.get(key)
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            if not isinstance(got, (int, float)) or abs(got - value) > rel * max(1.0, abs(value)):
                bad.append((key, formula[:80], value, got))
        elif value in ERRORS:
            if got not in ERRORS:
                bad.append((key, formula[:80], value, got))
        elif value != got:
            bad.append((key, formula[:80], value, got))
    assert not bad, f"{len(bad)} of {len(cached)} formula cells differ, e.g. {bad[:5]}"
    return len(cached)


def differences(original: Path, recalculated: Path) -> list:
    """Formula cells whose LibreOffice value differs from the engine's (cached) beyond
    RELATIVE of the largest of: the two values, the largest value in its column, and the
    values of the cells of its sheet it reads (a value near zero is then a difference of
    near terms, |computed - printed| on the Checks sheet: its rounding is not an error)."""
    cached = formula_values(original)
    written = cell_values(original)
    new = cell_values(recalculated)

    def number(v) -> float:
        return abs(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else 0.0

    column: dict[tuple[str, str], float] = {}
    for (sheet, cell), (_, value) in cached.items():
        key = (sheet, cell.rstrip("0123456789"))
        column[key] = max(column.get(key, 0.0), number(value))
    bad = []
    for key, (formula, value) in cached.items():
        got = new.get(key)
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            if isinstance(value, float) and not math.isfinite(value):
                continue  # an error cell in the engine too (#NUM!)
            read = [
                number(written.get((quoted or bare or key[0], f"{c}{r}")))
                for quoted, bare, c, r in re.findall(
                    r"(?:'([^']+)'!|(?<![\w$'])([A-Za-z_]\w*)!)?(?<![\w$])\$?([A-Z]{1,3})\$?(\d+)(?![\w(])",
                    formula,
                )
            ]
            scale = max(
                [abs(value), number(got), column[(key[0], key[1].rstrip("0123456789"))]] + read
            )
            ok = isinstance(got, (int, float)) and abs(got - value) <= RELATIVE * scale
            if not ok:
                bad.append((key, formula[:100], value, got))
        elif value in ERRORS and got in ERRORS:
            continue  # an error stays an error (SQRT(-1): Excel's #NUM!, LibreOffice's #VALUE!)
        elif value != got:
            bad.append((key, formula[:100], value, got))
    return bad


def formulas_recalculated(xlsx: Path) -> dict[tuple[str, str], object]:
    """{(sheet, cell): value} of every cell of ``xlsx`` recalculated by the formulas package
    (its own parser and its own Excel functions, not the writer's)."""
    import formulas

    solution = formulas.ExcelModel().loads(str(xlsx)).finish().calculate()
    out = {}
    for key, value in solution.items():
        if "!" not in key or ":" in key.split("!")[1]:
            continue
        book_sheet, cell = key.split("!")
        sheet = book_sheet.split("]", 1)[1].strip("'")
        v = getattr(value, "value", value)
        try:
            v = v[0][0]
        except (TypeError, IndexError):
            pass
        out[(sheet.upper(), cell.upper())] = v
    return out


def xleval_recalculated(xlsx: Path) -> dict[tuple[str, str], object]:
    """{(sheet, cell): value} of every formula cell of ``xlsx`` recalculated from its inputs
    (not from cached values) by workbook.compute.xleval, each formula reading the
    recalculated values of the cells and defined names it refers to."""
    from openpyxl.utils import range_boundaries

    from workbook.compute import xleval

    book = openpyxl.load_workbook(xlsx)
    sheets = {ws.title.upper(): ws for ws in book.worksheets}
    names = {n.upper(): d.attr_text for n, d in book.defined_names.items()}
    done: dict[tuple[str, str], object] = {}

    def cell(sheet: str, coord: str):
        key = (sheet, coord)
        if key not in done:
            v = sheets[sheet][coord].value
            if isinstance(v, str) and v.startswith("="):
                done[key] = None  # a cycle reads as empty
                fn = xleval.compile_formula(v)
                v = fn(lambda ref, here=sheet: read(ref, here))
                if isinstance(v, np.ndarray):
                    v = v.flat[0]
            done[key] = float(v) if isinstance(v, int) and not isinstance(v, bool) else v
        return done[key]

    def read(ref: str, here: str):
        if ref.upper() in names:
            return read(names[ref.upper()], here)
        sheet, _, cells = ref.rpartition("!")
        sheet = sheet.strip("'").upper() or here
        cells = cells.replace("$", "")
        if ":" not in cells:
            return cell(sheet, cells)
        c0, r0, c1, r1 = range_boundaries(cells)
        out = np.empty((r1 - r0 + 1, c1 - c0 + 1), dtype=object)
        for i in range(r1 - r0 + 1):
            for j in range(c1 - c0 + 1):
                out[i, j] = cell(sheet, f"{get_column_letter(c0 + j)}{r0 + i}")
        return out

    return {
        (title, c.coordinate): cell(title, c.coordinate)
        for title, ws in sheets.items()
        for row in ws.iter_rows()
        for c in row
        if isinstance(c.value, str) and c.value.startswith("=")
    }


def mismatches(xlsx: Path, recalculated: dict | None = None) -> list:
    """Formula cells whose recalculated value differs from the one the writer cached (the
    engine's) beyond RELATIVE (an absolute 1e-12 floor for zeros), with the formula."""
    cached = formula_values(xlsx)
    recalculated = formulas_recalculated(xlsx) if recalculated is None else recalculated
    bad = []
    for (sheet, cell), (formula, value) in cached.items():
        got = recalculated.get((sheet.upper(), cell.upper()))
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            if str(got) != str(value) and got != value:
                bad.append((sheet, cell, formula, value, got))
            continue
        if isinstance(got, bool) or not isinstance(got, (int, float)):
            bad.append((sheet, cell, formula, value, got))
        elif abs(got - value) > RELATIVE * max(abs(value), abs(got)) + 1e-12:
            bad.append((sheet, cell, formula, value, got))
    return bad
