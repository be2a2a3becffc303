"""An edited workbook recalculated by LibreOffice gives the engine's numbers at the edited
inputs in every live cell; a cell that does not is marked frozen (grey) or as reading a
frozen value (orange). Slow: each starts LibreOffice."""

from __future__ import annotations

import math
from pathlib import Path

import openpyxl
import pytest
from recalc import agree, cell_values, formula_values, recalculate, soffice
from test_cell_units import RATIOS
from test_live_everywhere import FROZEN

import workbook

pytestmark = [
    pytest.mark.skipif(soffice() is None, reason="LibreOffice is not installed"),
    pytest.mark.slow,
]

DATA = Path(__file__).parent / "data"
RELATIVE = 1e-9
MARKED = ("FFD9D9D9", "FFFCE4D6")  # frozen, reads a frozen value
# sheets of helper cells (a root's steps): which columns are live, and so where their steps
# go, can differ at the edited inputs (a root met in only some rows of a table is written as
# numbers); the cells of the other sheets are where a person reads, and keep their place
HELPERS = ("Solver rows", "Solver steps")


def _numeric_inputs(sheet) -> list[str]:
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


def _edited(sheet, out: Path, names: list[str], tmp: Path) -> tuple[Path, dict]:
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


def _check(sheet, tmp: Path, names: list[str]) -> list:
    tmp.mkdir(parents=True, exist_ok=True)
    out = sheet.write_xlsx(tmp / "sheet.xlsx", force=True)
    edited, changes = _edited(sheet, out, names, tmp)
    engine = sheet.with_inputs(**changes).write_xlsx(tmp / "engine.xlsx", force=True)
    return unmarked_differences(out, recalculate(edited, tmp / "lo"), engine)


@pytest.mark.parametrize("text", [RATIOS, FROZEN], ids=["ratios", "frozen"])
def test_each_input_edited_by_ten_percent(tmp_path, text, sheet_from):
    sheet = sheet_from(text)
    for name in _numeric_inputs(sheet):
        bad = _check(sheet, tmp_path / name, [name])
        assert not bad, f"{name} +10 %: {len(bad)} cells differ, e.g. {bad[:5]}"


SHEETS = [*workbook.list_templates(), *sorted(str(p) for p in DATA.glob("*.toml"))]


@pytest.mark.parametrize("name", SHEETS, ids=[Path(n).stem for n in SHEETS])
def test_every_sheet_with_its_inputs_edited(tmp_path, name):
    sheet = workbook.load(name)
    bad = _check(sheet, tmp_path, _numeric_inputs(sheet))
    assert not bad, f"every input +10 %: {len(bad)} cells differ, e.g. {bad[:5]}"
