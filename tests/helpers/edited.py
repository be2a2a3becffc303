"""Workbooks edited as a person edits them (inputs raised on the Inputs sheet), recalculated
by LibreOffice, and compared with the engine at the edited inputs."""

from __future__ import annotations

import math
from pathlib import Path

import openpyxl

import workbook
from helpers.recalc import agree, cell_values, formula_values, recalculate

RELATIVE = 1e-9
MARKED = ("FFD9D9D9", "FFFCE4D6")  # frozen, reads a frozen value
# sheets of helper cells (a root's steps): which columns are live, and so where their steps
# go, can differ at the edited inputs (a root met in only some rows of a table is written as
# numbers); the cells of the other sheets are where a person reads, and keep their place
HELPERS = ("Solver rows", "Solver steps")


def numeric_inputs(sheet) -> list[str]:
    """The inputs that are numbers and may be raised by 10 % (within their limits); a count
    or an order (a whole plain number: n = 4) is not raised, since 4.4 teeth is no edit."""
    out = []
    for n, spec in sheet.spec.inputs.items():
        q = sheet.values[n]
        if spec.options or (not q.dimensionality and float(q.magnitude).is_integer()):
            continue
        try:
            sheet.with_inputs(**{n: sheet.values[n] * 1.1})
        except workbook.WorkbookError:
            continue
        out.append(n)
    return out


def edited_book(sheet, out: Path, names: list[str], tmp: Path) -> tuple[Path, dict]:
    """The workbook with each input of ``names`` raised by 10 % on its Inputs sheet (as a
    person edits it), and the same inputs as the engine's changes."""
    book = openpyxl.load_workbook(out)
    ws = book["Inputs"]
    changes = {}
    for r in range(2, ws.max_row + 1):
        name = ws.cell(r, 1).value
        if name in names:
            value = ws.cell(r, 2).value * 1.1
            ws.cell(r, 2).value = value
            changes[name] = sheet.values[name] * 1.1
    edited = tmp / "edited.xlsx"
    book.save(edited)
    return edited, changes


def unmarked_differences(original: Path, recalculated: Path, engine: Path) -> list:
    """Formula cells of ``original`` whose value recalculated by LibreOffice differs from the
    engine's at the edited inputs (``engine``: the engine's workbook at those inputs) and
    that are not marked frozen or reading a frozen value."""
    formulas, theirs = formula_values(original), formula_values(engine)
    got, want = cell_values(recalculated), cell_values(engine)
    book = openpyxl.load_workbook(original)
    moved = {
        h
        for h in HELPERS
        if {k: f for k, (f, _) in formulas.items() if k[0] == h}
        != {k: f for k, (f, _) in theirs.items() if k[0] == h}
    }
    bad = []
    for (sheet, cell), (formula, _) in formulas.items():
        if sheet in ("About", "Checks"):  # Checks: printed values at the sheet's own inputs
            continue
        if sheet in moved:
            continue  # another layout of the helper cells: their readers are compared
        a, b = got.get((sheet, cell)), want.get((sheet, cell))
        numbers = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in (a, b))
        if numbers:
            if not (math.isfinite(a) and math.isfinite(b)):
                continue
            same = abs(a - b) <= RELATIVE * max(abs(a), abs(b), 1e-300) + 1e-12
        else:
            same = agree(a, b, RELATIVE)
        if same:
            continue
        c = book[sheet][cell]
        if c.fill.fill_type and c.fill.fgColor.rgb in MARKED:
            continue
        bad.append((sheet, cell, formula[:80], a, b))
    return bad


def check_edited(sheet, tmp: Path, names: list[str]) -> list:
    tmp.mkdir(parents=True, exist_ok=True)
    out = sheet.write_xlsx(tmp / "sheet.xlsx", force=True)
    edited, changes = edited_book(sheet, out, names, tmp)
    engine = sheet.with_inputs(**changes).write_xlsx(tmp / "engine.xlsx", force=True)
    return unmarked_differences(out, recalculate(edited, tmp / "lo"), engine)
