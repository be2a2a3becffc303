"""LibreOffice recalculates the matrix blocks (array formulas: MMULT, MINVERSE, TRANSPOSE,
MDETERM, INDEX, CHOOSE), the text IFs and the program IFs to the engine's values."""

from __future__ import annotations

import math

import pytest
from helpers.paths import DATA
from helpers.recalc import cell_values, recalculate, soffice

from workbook.facade import Sheet
from workbook.language.template import load_spec

pytestmark = [
    pytest.mark.skipif(soffice() is None, reason="LibreOffice is not installed"),
    pytest.mark.slow,
]
DATA = DATA / "arrays.toml"


def test_libreoffice_recalculates_matrices_texts_and_programs(tmp_path):
    sheet = Sheet(load_spec(DATA))
    path = sheet.write_xlsx(tmp_path / "arrays.xlsx")
    written = cell_values(path)
    again = cell_values(recalculate(path, tmp_path / "out"))
    import openpyxl

    wb = openpyxl.load_workbook(path)
    arrays = [
        c
        for ws in wb.worksheets
        for row in ws.iter_rows()
        for c in row
        if type(c.value).__name__ == "ArrayFormula"
    ]
    assert len(arrays) >= 10  # matrix blocks and one-cell array formulas
    compared = 0
    for key, value in written.items():
        if key[0] not in ("Matrices", "Definitions", "Listing") or value in ("", None):
            continue
        got = again.get(key)
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            assert isinstance(got, (int, float)), (key, value, got)
            assert math.isclose(got, value, rel_tol=1e-9, abs_tol=1e-12), (key, value, got)
            compared += 1
        else:
            assert got == value, (key, value, got)
    assert compared >= 60
