"""The unit a cell holds its number in, and the formulas that read it: written workbooks
recalculated by an evaluator independent of the writer (the `formulas` package) give the
engine's numbers in every formula cell, for ratios of prefixed units (kW/W, mm/m,
sqrt(GPa/MPa)), percentages, degrees, offset temperatures, `unit = ""` and no declared unit,
in scalars, table columns and a column's maximum."""

from __future__ import annotations

import math
from pathlib import Path

import openpyxl
import pytest
from helpers.recalc import formula_values
from helpers.recalculated import formulas_recalculated, mismatches
from helpers.sheets import RATIOS

from workbook.language import cellunit
from workbook.language import units as un

RELATIVE = 1e-9


# the engine's numbers, worked out by hand: P1/P2 = 0.75, d/D = 1/60, E/Sy = 800
EXPECTED = {
    "r": 0.75,
    "y": 1.5,
    "s": 1 / 60,
    "s1": 1 + 1 / 60,
    "lam": math.sqrt(800),
    "Pcr": 750 / 800,
    "q": 0.75 * 85,
    "q1": 0.75,
    "ang": 22.5,
    "c": math.cos(math.pi / 6) / 60,
    "T2": 27.5,
    "T3": 300.65,
    "n": 2.25,
    "m": 0.75,
    "m2": 1.5,
}


def results(xlsx: Path) -> dict[str, tuple[object, object]]:
    """{name: (formula, cached value)} of the Results sheet."""
    ws = openpyxl.load_workbook(xlsx)["Results"]
    values = openpyxl.load_workbook(xlsx, data_only=True)["Results"]
    return {
        ws.cell(r, 1).value: (ws.cell(r, 2).value, values.cell(r, 2).value)
        for r in range(2, ws.max_row + 1)
        if ws.cell(r, 1).value
    }


@pytest.fixture
def ratios(tmp_path, sheet_from):
    sheet = sheet_from(RATIOS)
    refusals: list = []
    out = sheet.write_xlsx(tmp_path / "ratios.xlsx", refusals=refusals)
    return sheet, out, refusals


def test_the_engine_and_the_cached_values_are_the_hand_worked_numbers(ratios):
    sheet, out, _ = ratios
    cells = results(out)
    for name, exact in EXPECTED.items():
        q = sheet.evaluate(name)
        assert math.isclose(float(q.magnitude), exact, rel_tol=1e-12), (name, q, exact)
        formula, cached = cells[name]
        assert math.isclose(cached, exact, rel_tol=1e-12), (name, cached, exact)
        assert str(formula).startswith("="), (name, formula)
    assert cells["mode"][1] == "Euler"


@pytest.mark.slow
def test_every_formula_cell_recalculates_to_the_engine(ratios):
    _, out, refusals = ratios
    assert refusals == []  # no formula had to be written as a number
    recalculated = formulas_recalculated(out)
    bad = mismatches(out, recalculated)
    assert not bad, bad
    row = next(r for r, name in enumerate(results(out), start=2) if name == "y")
    assert math.isclose(recalculated[("RESULTS", f"B{row}")], 1.5, rel_tol=1e-12)  # 2*r
    listing = {k: v for k, v in formula_values(out).items() if k[0] == "Listing"}
    assert len(listing) >= 15  # the table's columns are formulas, checked above


def test_the_cell_unit_is_one_decision():
    ureg = un.registry()
    from workbook.language import typed as ty

    def ref(unit: str, kind: str = "definition") -> ty.TRef:
        return ty.TRef(un.unit(unit), name="r", kind=kind)

    assert cellunit.stored_unit(ref("kW/W")) == ureg.dimensionless
    assert cellunit.stored_unit(ref("mm/m")) == ureg.dimensionless
    assert cellunit.stored_unit(ref("kW/W", "input")) == un.unit("kW/W")  # typed by the user
    for kept in ("percent", "deg", "degC", "", "mm"):
        assert cellunit.stored_unit(ref(kept)) == un.unit(kept)
    assert cellunit.read_factor(ref("kW/W")) == pytest.approx(1e-3, rel=1e-15)
    assert cellunit.read_factor(ref("percent")) == 1.0
