"""An edited workbook recalculated by LibreOffice gives the engine's numbers at the edited
inputs in every live cell; a cell that does not is marked frozen (grey) or as reading a
frozen value (orange). Slow: each starts LibreOffice."""

from __future__ import annotations

from pathlib import Path

import pytest
from helpers.edited import check_edited, numeric_inputs
from helpers.paths import DATA
from helpers.recalc import soffice
from helpers.sheets import FROZEN, RATIOS

import workbook

pytestmark = [
    pytest.mark.skipif(soffice() is None, reason="LibreOffice is not installed"),
    pytest.mark.slow,
]


@pytest.mark.parametrize("text", [RATIOS, FROZEN], ids=["ratios", "frozen"])
def test_each_input_edited_by_ten_percent(tmp_path, text, sheet_from):
    sheet = sheet_from(text)
    for name in numeric_inputs(sheet):
        bad = check_edited(sheet, tmp_path / name, [name])
        assert not bad, f"{name} +10 %: {len(bad)} cells differ, e.g. {bad[:5]}"


SHEETS = [*workbook.list_templates(), *sorted(str(p) for p in DATA.glob("*.toml"))]


@pytest.mark.parametrize("name", SHEETS, ids=[Path(n).stem for n in SHEETS])
def test_every_sheet_with_its_inputs_edited(tmp_path, name):
    sheet = workbook.load(name)
    bad = check_edited(sheet, tmp_path, numeric_inputs(sheet))
    assert not bad, f"every input +10 %: {len(bad)} cells differ, e.g. {bad[:5]}"
