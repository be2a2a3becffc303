"""Sheets written as a new user would, in fields the templates do not cover (a heat
exchanger in degC and K, an AC circuit with complex impedances, a tank drained while a sum
over inputs fills it, a bolted joint with percentages and MPa/GPa ratios): each workbook
recalculated by LibreOffice gives the engine's numbers in every formula cell, before and
after its inputs are edited by +10 % (against the engine at the edited inputs). Slow: each
starts LibreOffice."""

from __future__ import annotations

import openpyxl
import pytest
from helpers.edited import MARKED, check_edited, numeric_inputs
from helpers.paths import DATA
from helpers.recalc import agree, cell_values, formula_values, recalculate, soffice

import workbook

pytestmark = [
    pytest.mark.skipif(soffice() is None, reason="LibreOffice is not installed"),
    pytest.mark.slow,
]

NEWCOMER = sorted((DATA / "newcomer").glob("*.toml"))
RELATIVE = 1e-9


def _same(a, b) -> bool:
    return agree(a, b, RELATIVE)


def test_there_are_four_sheets():
    assert len(NEWCOMER) == 4


@pytest.mark.parametrize("path", NEWCOMER, ids=[p.stem for p in NEWCOMER])
def test_recalculated_as_written(tmp_path, path):
    """Every formula cell recalculates to the value the engine cached in it; none is frozen
    (these sheets need no solver block, ODE or data file)."""
    out = workbook.load(path).write_xlsx(tmp_path / "sheet.xlsx", force=True)
    formulas = formula_values(out)
    got = cell_values(recalculate(out, tmp_path / "lo"))
    book = openpyxl.load_workbook(out)
    marked = [
        (ws.title, c.coordinate)
        for ws in book.worksheets
        for row in ws.iter_rows()
        for c in row
        if c.fill.fill_type and c.fill.fgColor.rgb in MARKED
    ]
    assert not marked
    bad = [
        (cell, f[:80], cached, got.get(cell))
        for cell, (f, cached) in formulas.items()
        if cell[0] != "About" and not _same(got.get(cell), cached)
    ]
    assert len(formulas) > 20 and not bad, bad[:5]


@pytest.mark.parametrize("path", NEWCOMER, ids=[p.stem for p in NEWCOMER])
def test_recalculated_after_every_input_is_edited(tmp_path, path):
    sheet = workbook.load(path)
    names = numeric_inputs(sheet)
    assert names
    bad = check_edited(sheet, tmp_path, names)
    assert not bad, f"every input +10 %: {len(bad)} cells differ, e.g. {bad[:5]}"


def test_the_comparison_sees_a_wrong_cell(tmp_path):
    """The comparison is not blind: a difference beyond 1e-9 is one, in a number or in a part
    of a complex text; the 15th digit of a complex text's part is not."""
    assert _same(1.0, 1.0 + 1e-12) and not _same(1.0, 1.0 + 1e-8) and not _same("ok", "yield")
    assert _same("1.48584034476054+1.95627180420648i", "1.48584034476075+1.95627180420658i")
    assert not _same("1.48584034476054+1.95627180420648i", "1.48584034476054+1.95627182i")
    assert not _same("2i", "2")
