"""The unit a cell holds its number in, and the formulas that read it: written workbooks
recalculated by an evaluator independent of the writer (the `formulas` package) give the
engine's numbers in every formula cell, for ratios of prefixed units (kW/W, mm/m,
sqrt(GPa/MPa)), percentages, degrees, offset temperatures, `unit = ""` and no declared unit,
in scalars, table columns and a column's maximum."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import openpyxl
import pytest
from openpyxl.utils import get_column_letter
from recalc import formula_values

from workbook.compute import cellunit
from workbook.language import units as un

RELATIVE = 1e-9

RATIOS = """
[sheet]
title = "Ratios of prefixed units"

[inputs]
P1 = "1.5 kW"
P2 = "2000 W"
d = "10 mm"
D = "0.6 m"
E = "200 GPa"
Sy = "250 MPa"
eta = "85 %"
theta = "30 deg"
T1 = "20 degC"
k = "3"
dT = "10 delta_degC"

[arguments]
x = { unit = "" }

[definitions]
r = "P1/P2"
y = "2*r"
s = "d/D"
s1 = "s + 1"
lam = "sqrt(E/Sy)"
mode = "\\"Euler\\" if lam > 20 otherwise \\"Johnson\\""
Pcr = "1000*r/lam^2 if lam > 20 otherwise 1000*r*(1 - lam/60)"
q = { expr = "r*eta", unit = "%" }
q1 = { expr = "P1/P2", unit = "" }
ang = { expr = "theta*r", unit = "deg" }
c = "cos(theta)*s"
T2 = { expr = "T1 + dT*q1", unit = "degC" }
T3 = { expr = "T2", unit = "K" }
n = "k*r"
"f(x)" = "x*r"
"g(x)" = "x*P1/P2"
"h(x)" = "x*d/D + r"
m = "max_over(T, g)"
m2 = "m*2"

[[tables]]
name = "T"
range = "x := 0, 0.25 .. 1"
columns = ["x", "f(x)", "g", "h"]
"""

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
