"""Sums of temperatures by the rule table of docs/language.md (Temperatures), against
Mathcad's reading: every temperature is a number of kelvin (an absolute one from its zero, a
difference by its size), a sum is the sum of those kelvin, and the result is shown in the scale
of the absolute operand. The engine's numbers, the workbook's formulas recalculated by the
`formulas` package, and (slow) LibreOffice's recalculation are all compared with that model.
"""

from __future__ import annotations

import itertools
import math

import formulas
import openpyxl
import pytest

from workbook.errors import UnitError
from workbook.language import units as un
from workbook.language.unitrules import sum_kind

UNITS = ["K", "degC", "degF", "degR", "delta_degC", "delta_degF"]
LEFT, RIGHT = 300.0, 20.0
ETA = 0.88  # eta = "88 %"


def _name(prefix: str, unit: str) -> str:
    return f"{prefix}_{unit}"


# (formula, its kelvin under Mathcad's reading, its kind in a sum)
def _operand(prefix: str, magnitude: float, unit: str, scaled: bool = False):
    q = un.registry().Quantity(magnitude, unit)
    kind = un.temperature_kind(q.units)
    kelvin = float(q.to("K").magnitude)  # an absolute one from 0 K, a difference by its size
    if not scaled:
        return _name(prefix, unit), kelvin, kind
    # eta*B: an absolute temperature in a product is in kelvin; a difference stays one
    return (
        f"eta*{_name(prefix, unit)}",
        ETA * kelvin,
        ("difference" if kind == "difference" else "kelvin"),
    )


LEFTS = [_operand("A", LEFT, u) for u in UNITS] + [("P/G", 20.0, "kelvin")]
RIGHTS = (
    [_operand("B", RIGHT, u) for u in UNITS]
    + [_operand("B", RIGHT, u, scaled=True) for u in UNITS]
    + [("P/G", 20.0, "kelvin")]
)
CASES = [(op, a, b) for op, a, b in itertools.product("+-", LEFTS, RIGHTS)]


def expected_kind(op: str, left: str, right: str) -> str | None:
    """The rule table: None when refused, else "absolute" or "difference" (any value that is
    not on a scale with an offset: a difference, K, degR, a compound unit of kelvin)."""
    if (left, right) == ("absolute", "absolute"):
        return None if op == "+" else "difference"
    if left == "difference" and right == "absolute" and op == "-":
        return None
    if left == "absolute" or (right == "absolute" and op == "+"):
        return "absolute"
    return "difference"


INPUTS = (
    "".join(f'{_name("A", u)} = "{LEFT} {u}"\n' for u in UNITS)
    + "".join(f'{_name("B", u)} = "{RIGHT} {u}"\n' for u in UNITS)
    + 'eta = "88 %"\nP = "2 kW"\nG = "100 W/K"\n'
)


def _text(definitions: str) -> str:
    return f'[sheet]\ntitle = "sums"\n\n[inputs]\n{INPUTS}\n[definitions]\n{definitions}'


def _in_kelvin(q) -> float:
    return float(q.to("K").magnitude)


def test_the_kelvin_valued_operands_are_kelvin_or_differences():
    reg = un.registry()
    assert sum_kind(reg.Unit("kW*K/W")) == "kelvin"
    assert sum_kind(reg.Unit("percent*delta_degC")) == "difference"
    assert sum_kind(reg.Unit("degC")) == "absolute"
    assert sum_kind(reg.Unit("m")) is None


ACCEPTED = [
    (f"r{i}", f"{a[0]} {op} {b[0]}")
    for i, (op, a, b) in enumerate(CASES)
    if expected_kind(op, a[2], b[2]) is not None
]


@pytest.fixture(scope="module")
def every_sum(load_text):
    """One sheet with every sum the table accepts (r0, r1...: the index in CASES)."""
    return load_text(_text("".join(f'{n} = "{f}"\n' for n, f in ACCEPTED)), name="t")


@pytest.mark.slow
@pytest.mark.parametrize(
    "i,op,a,b",
    [(i, *c) for i, c in enumerate(CASES)],
    ids=[f"{a[0]}{op}{b[0]}".replace("*", "x") for op, a, b in CASES],
)
def test_a_sum_of_temperatures_is_mathcads(sheet_from, every_sum, i, op, a, b):
    (left, lk, lkind), (right, rk, rkind) = a, b
    kind = expected_kind(op, lkind, rkind)
    formula = f"{left} {op} {right}"
    if kind is None:
        with pytest.raises(UnitError, match="absolute temperature"):
            sheet_from(_text(f'r = "{formula}"\n'))
        return
    got = every_sum.evaluate(f"r{i}")
    want = lk + rk if op == "+" else lk - rk
    assert (sum_kind(got.units) == "absolute") == (kind == "absolute"), got
    if kind == "absolute":  # in the scale of the absolute operand
        scale = left if lkind == "absolute" else right
        assert str(got.units) == str(un.unit(scale.split("_", 1)[1]))
    assert math.isclose(_in_kelvin(got), want, rel_tol=1e-12, abs_tol=1e-9), (formula, got)


def _book(sheet_from, tmp, cases):
    sheet = sheet_from(_text("".join(f'{n} = "{f}"\n' for n, f in cases)), name="t")
    return sheet, sheet.write_xlsx(tmp / "sums.xlsx")


def _result_rows(path) -> dict[str, int]:
    results = openpyxl.load_workbook(path)["Results"]
    return {r[0].value: r[0].row for r in results.iter_rows(min_row=2) if r[0].value}


def _recalculated_by_formulas(path) -> dict[str, object]:
    solution = formulas.ExcelModel().loads(str(path)).finish().calculate()
    values = {}
    for key, ranges in solution.items():
        book_sheet, _, cell = key.rpartition("!")
        if book_sheet.split("]", 1)[-1].strip("'").upper() == "RESULTS" and ":" not in cell:
            values[cell.upper()] = ranges.value[0, 0]
    return values


def _check_recalculation(sheet_from, tmp, cases):
    sheet, path = _book(sheet_from, tmp, cases)
    rows = _result_rows(path)
    values = _recalculated_by_formulas(path)
    for name, formula in cases:
        want = float(sheet.evaluate(name).magnitude)
        got = float(values[f"B{rows[name]}"])
        assert math.isclose(got, want, rel_tol=1e-12, abs_tol=1e-9), (name, formula, got, want)


@pytest.mark.slow
def test_the_workbook_recalculates_to_the_engine(sheet_from, tmp_path):
    """The `formulas` package (an independent Excel evaluator) recalculates sums of the
    workbook (one in twelve of the table's) to the engine's number."""
    _check_recalculation(sheet_from, tmp_path, ACCEPTED[::12])


@pytest.mark.slow
def test_the_workbook_recalculates_every_sum_to_the_engine(sheet_from, tmp_path):
    _check_recalculation(sheet_from, tmp_path, ACCEPTED)


@pytest.mark.slow
def test_libreoffice_recalculates_the_sums(sheet_from, tmp_path):
    from helpers.recalc import cell_values, recalculate, soffice

    if soffice() is None:
        pytest.skip("LibreOffice is not installed")
    sheet, path = _book(sheet_from, tmp_path, ACCEPTED)
    rows = _result_rows(path)
    values = cell_values(recalculate(path, tmp_path / "lo"))
    for name, formula in ACCEPTED:
        want = float(sheet.evaluate(name).magnitude)
        got = float(values[("Results", f"B{rows[name]}")])
        assert math.isclose(got, want, rel_tol=1e-12, abs_tol=1e-9), (name, formula, got, want)


def test_a_wall_and_a_heater_in_degc_with_kelvin_rises(sheet_from):
    """Heat transfer as a course writes it: surface temperatures from a heat flux over a film
    coefficient (K), an outlet temperature from a power over m*cp (W/(kg/s*J/(kg*K)) = K),
    88 % of a rise; each against the same arithmetic on plain numbers in kelvin."""
    text = """
[inputs]
T_in = "22 degC"
T_out = "-8 degC"
h_i = "8 W/(m^2*K)"
h_o = "23 W/(m^2*K)"
L = "0.2 m"
k = "0.8 W/(m*K)"
P = "3 kW"
m_dot = "0.05 kg/s"
cp = "4.18 kJ/(kg*K)"
eta = "88 %"

[definitions]
R = "1/h_i + L/k + 1/h_o"
q = { expr = "(T_in - T_out)/R", unit = "W/m^2" }
T_si = "T_in - q/h_i"
T_so = { expr = "T_out + q/h_o", unit = "degF" }
T_2 = "T_in + P/(m_dot*cp)"
T_3 = "T_in + eta*(T_2 - T_in)"
"""
    sheet = sheet_from(text)
    t_in, t_out = 22 + 273.15, -8 + 273.15
    r = 1 / 8 + 0.2 / 0.8 + 1 / 23
    q = (t_in - t_out) / r
    want = {
        "T_si": (t_in - q / 8, "degC"),
        "T_so": (t_out + q / 23, "degF"),
        "T_2": (t_in + 3000 / (0.05 * 4180), "degC"),
        "T_3": (t_in + 0.88 * 3000 / (0.05 * 4180), "degC"),
    }
    for name, (kelvin, unit) in want.items():
        got = sheet.evaluate(name)
        assert str(got.units) == str(un.unit(unit)), (name, got)
        assert _in_kelvin(got) == pytest.approx(kelvin, rel=1e-13), name


@pytest.mark.parametrize("unit", ["degC", "degF"])
def test_an_indexed_sum_of_absolute_temperatures_adds_their_kelvin(sheet_from, unit):
    """sum(T1 + i*dT, i, 1, n) with T1 absolute: each term is a number of kelvin, as in
    sum(v) of a vector of temperatures and in Mathcad (not the sum of the scale's numbers)."""
    sheet = sheet_from(
        f"""
[inputs]
T1 = "27 {unit}"
dT = "15 K"
n = "12"
[definitions]
S = {{ expr = "sum(T1 + i*dT, i, 1, n)", unit = "K" }}
v = {{ expr = "[T1, T1 + dT]", unit = "{unit}" }}
Sv = {{ expr = "sum(v)", unit = "K" }}
Sk = {{ expr = "sum(T1 + i*dT, i, 1, 2)", unit = "K" }}
"""
    )
    t1 = float(un.registry().Quantity(27, unit).to("K").magnitude)
    assert sheet.evaluate("S").to("K").magnitude == pytest.approx(12 * t1 + 15 * 78, rel=1e-12)
    assert sheet.evaluate("Sv").to("K").magnitude == pytest.approx(2 * t1 + 15, rel=1e-12)
    assert sheet.evaluate("Sk").to("K").magnitude == pytest.approx(2 * t1 + 45, rel=1e-12)
