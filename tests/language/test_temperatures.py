"""Absolute temperatures and temperature differences, against pint's own arithmetic.

Every sum, difference, product and quotient of two temperatures in K, degC, degF, degR,
delta_degC and delta_degF, and every conversion between them, is computed by the engine
(numpy), printed as an Excel formula and recalculated by the `formulas` package (an
independent Excel evaluator), and compared with pint (the registry the engine uses, with
its offset units converted to kelvin in products, as the engine does).
"""

from __future__ import annotations

import itertools
import math
import operator

import formulas
import numpy as np
import pint
import pytest
from helpers.recalc import formula_values

import workbook
from workbook.errors import UnitError
from workbook.language import units as un

UNITS = ["K", "degC", "degF", "degR", "delta_degC", "delta_degF"]
LEFT, RIGHT = 300.0, 20.0  # magnitudes of the two operands


def _pint(op: str, a: str, b: str):
    """pint's answer (None when pint refuses), with degC and degF in kelvin in products."""
    q = un.registry().Quantity
    left, right = q(LEFT, a), q(RIGHT, b)
    if op in "*/":  # pint keeps 2*T in degC; products with a temperature use kelvin here
        left, right = (
            x.to("kelvin") if un.temperature_kind(x.units) == "absolute" else x
            for x in (left, right)
        )
    try:
        return {"+": operator.add, "-": operator.sub, "*": operator.mul, "/": operator.truediv}[op](
            left, right
        )
    except (pint.errors.OffsetUnitCalculusError, pint.DimensionalityError):
        return None


def _text(a: str, b: str, definitions: str) -> str:
    return f"""
[sheet]
title = "temperatures"

[inputs]
A = {{ value = "{LEFT} {a}" }}
B = {{ value = "{RIGHT} {b}" }}

[definitions]
{definitions}
"""


def _mathcad_sum(op: str, a: str, b: str) -> bool:
    """K or degR added to or subtracted from degC or degF: a difference by Mathcad's rule."""
    kinds = {un.temperature_kind(un.unit(a)), un.temperature_kind(un.unit(b))}
    return op in "+-" and kinds == {"absolute", "kelvin"}


COMBINATIONS = [c for c in itertools.product("+-*/", UNITS, UNITS) if not _mathcad_sum(*c)]


@pytest.mark.slow
@pytest.mark.parametrize("op,a,b", COMBINATIONS, ids=[f"{a}{o}{b}" for o, a, b in COMBINATIONS])
def test_arithmetic_of_two_temperatures_is_pints(sheet_from, op, a, b):
    """Where the language follows pint; kelvin in a sum with an absolute temperature is a
    difference (Mathcad's rule, where pint differs) and is tested against Mathcad's reading
    in test_temperatures_mathcad.py."""
    expected = _pint(op, a, b)
    kinds = (un.temperature_kind(un.unit(a)), un.temperature_kind(un.unit(b)))
    refused_here = op == "-" and kinds == ("difference", "absolute")  # pint: meaningless
    if expected is None or refused_here:
        with pytest.raises(UnitError, match="temperature"):
            sheet_from(_text(a, b, f'r = "A {op} B"'))
        return
    got = sheet_from(_text(a, b, f'r = "A {op} B"')).evaluate("r")
    if op in "+-":  # an absolute temperature or a difference, as pint says
        assert un.temperature_kind(got.units) == un.temperature_kind(expected.units)
    assert math.isclose(got.magnitude, expected.to(got.units).magnitude, rel_tol=1e-13)


@pytest.mark.parametrize("a,b", list(itertools.product(UNITS, UNITS)))
def test_a_temperature_shown_in_another_unit_is_pints_conversion(sheet_from, a, b):
    q = un.registry().Quantity(LEFT, a)
    try:
        expected = q.to(b).magnitude
    except pint.DimensionalityError:
        with pytest.raises(UnitError, match="temperature"):
            sheet_from(_text(a, a, f'r = {{ expr = "A", unit = "{b}" }}'))
        return
    got = sheet_from(_text(a, a, f'r = {{ expr = "A", unit = "{b}" }}')).evaluate("r")
    assert str(got.units) == str(un.unit(b))
    assert math.isclose(got.magnitude, expected, rel_tol=1e-13)


SHEET = """
[sheet]
title = "a heated rod"

[inputs]
T1 = { value = "20 degC", note = "before" }
T2 = { value = "85 degC", note = "after" }
T3 = { value = "358.15 K" }
Tf = { value = "98.6 degF" }
alpha = { value = "1.2e-5 1/K", note = "expansion coefficient" }
L = { value = "2 m" }

[definitions]
dT = { expr = "T2 - T1", unit = "K" }
dT_plain = "T2 - T1"
dT_F = { expr = "T2 - T1", unit = "delta_degF" }
T2_K = { expr = "T2", unit = "K" }
T3_C = { expr = "T3", unit = "degC" }
Tf_C = { expr = "Tf", unit = "degC" }
T1_F = { expr = "T1", unit = "degF" }
dL = { expr = "alpha*L*(T2 - T1)", unit = "mm" }
T_mid = "T1 + (T2 - T1)/2"
T_mid_F = { expr = "T1 + (T2 - T1)/2", unit = "degF" }
ratio = "T2/T1"
hot = "max(T1, T2)"
warm = "1 if T2 > T3 otherwise 0"
"""

# (name, pint's value in the definition's unit)
_Q = None


def _expected():
    q = un.registry().Quantity
    t1, t2, t3, tf = q(20, "degC"), q(85, "degC"), q(358.15, "K"), q(98.6, "degF")
    alpha, length = q(1.2e-5, "1/K"), q(2, "m")
    return {
        "dT": (t2 - t1).to("K"),
        "dT_plain": (t2 - t1).to("delta_degC"),
        "dT_F": (t2 - t1).to("delta_degF"),
        "T2_K": t2.to("K"),
        "T3_C": t3.to("degC"),
        "Tf_C": tf.to("degC"),
        "T1_F": t1.to("degF"),
        "dL": (alpha * length * (t2 - t1)).to("mm"),
        "T_mid": (t1 + (t2 - t1) / 2).to("degC"),
        "T_mid_F": (t1 + (t2 - t1) / 2).to("degF"),
        "ratio": (t2.to("K") / t1.to("K")).to(""),
        "hot": max(t1.to("K"), t2.to("K")),
        "warm": q(1 if t2.to("K") > t3 else 0, ""),
    }


@pytest.fixture(scope="module")
def rod(load_text, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("rod")
    sheet = load_text(SHEET, name="t")
    path = sheet.write_xlsx(tmp / "rod.xlsx")
    return sheet, path


@pytest.mark.parametrize("name", list(_expected()))
def test_the_engine_agrees_with_pint(rod, name):
    sheet, _ = rod
    expected = _expected()[name]
    got = sheet.evaluate(name)
    assert str(got.units) == str(expected.units)
    assert math.isclose(got.magnitude, expected.magnitude, rel_tol=1e-13, abs_tol=1e-12)


def test_excel_formulas_are_affine_and_recalculate_to_pint(rod):
    """The workbook's formulas add the offset (never a scale factor of 274.15), and the
    `formulas` package recalculates them to pint's values."""
    import openpyxl

    sheet, path = rod
    cells = formula_values(path)
    results = openpyxl.load_workbook(path)["Results"]
    rows = {r[0].value: r[0].row for r in results.iter_rows(min_row=2) if r[0].value}
    text = {name: cells[("Results", f"B{rows[name]}")][0] for name in ("T2_K", "T3_C", "dT")}
    assert text == {"T2_K": "=T2_+273.15", "T3_C": "=T3_-273.15", "dT": "=T2_-T1_"}
    solution = formulas.ExcelModel().loads(str(path)).finish().calculate()
    values = {}
    for key, ranges in solution.items():
        book_sheet, _, cell = key.rpartition("!")
        if book_sheet.split("]", 1)[-1].strip("'").upper() == "RESULTS" and ":" not in cell:
            values[cell.upper()] = ranges.value[0, 0]
    for name, expected in _expected().items():
        got = values[f"B{rows[name]}"]
        assert math.isclose(float(got), expected.magnitude, rel_tol=1e-12, abs_tol=1e-12), name


@pytest.mark.parametrize(
    "expr,message",
    [
        ('"T1 + T2"', "two absolute temperatures cannot be added"),
        ('{ expr = "T2 - T1", unit = "degC" }', "difference .* cannot be shown as an absolute"),
        ('{ expr = "T1", unit = "delta_degC" }', "cannot be shown as a\\s+difference"),
        ('"(T2 - T1) - T1"', "difference minus an absolute"),
        ('"1 if T1 > T2 - T1 otherwise 0"', "difference"),
    ],
)
def test_temperature_mistakes_are_refused_with_what_to_write(sheet_from, expr, message):
    text = SHEET.split("[definitions]")[0] + f"[definitions]\nbad = {expr}\n"
    with pytest.raises(UnitError, match=message) as err:
        sheet_from(text)
    assert "bad" in str(err.value)


def test_set_and_a_table_column_shown_in_degf(sheet_from):
    text = (
        SHEET
        + """
[arguments]
x = { unit = "" }

[[tables]]
name = "heating"
range = "x := 0, 0.25 .. 1"
columns = { "T1 + x*(T2 - T1)" = "degF" }
"""
    )
    sheet = sheet_from(text).with_inputs(T1="293.15 K")
    table = sheet.table("heating")
    q = un.registry().Quantity
    t1, t2 = q(20, "degC"), q(85, "degC")
    for x, got in zip((0, 0.25, 0.5, 0.75, 1), table.iloc[:, 1]):
        assert math.isclose(got, (t1 + x * (t2 - t1)).to("degF").magnitude, rel_tol=1e-13)
    assert math.isclose(sheet.evaluate("dT").magnitude, 65.0, rel_tol=1e-13)


@pytest.mark.slow
def test_libreoffice_recalculates_the_temperature_sheet(rod, tmp_path):
    import openpyxl
    from helpers.recalc import cell_values, recalculate, soffice

    if soffice() is None:
        pytest.skip("LibreOffice is not installed")
    _, path = rod
    rows = {
        r[0].value: r[0].row
        for r in openpyxl.load_workbook(path)["Results"].iter_rows(min_row=2)
        if r[0].value
    }
    values = cell_values(recalculate(path, tmp_path))
    for name, expected in _expected().items():
        got = values[("Results", f"B{rows[name]}")]
        assert math.isclose(float(got), expected.magnitude, rel_tol=1e-12, abs_tol=1e-12), name


def test_a_data_column_in_degc_read_at_a_temperature_in_k(sheet_from, tmp_path):
    """linterp over a column in degC at an input in K converts the input affinely (not by a
    factor 1/274.15), and a column of differences in delta_degC gives a difference."""
    (tmp_path / "oil.csv").write_text("T_col,nu,rise\n0,180,0\n40,46,5\n100,10,12\n", "utf-8")
    text = """
[inputs]
T = { value = "333.15 K" }

[data.oil]
file = "oil.csv"
columns = { T_col = "degC", nu = "mm^2/s", rise = "delta_degC" }

[definitions]
viscosity = { expr = "linterp(T_col, nu, T)", unit = "mm^2/s" }
heated = { expr = "T + linterp(T_col, rise, T)", unit = "degC" }
"""
    sheet = sheet_from(text)
    t = 333.15 - 273.15  # 60 degC
    nu = 46 + (t - 40) / 60 * (10 - 46)
    assert sheet.evaluate("viscosity").to("mm^2/s").magnitude == pytest.approx(nu, rel=1e-13)
    rise = 5 + (t - 40) / 60 * (12 - 5)
    assert sheet.evaluate("heated").to("degC").magnitude == pytest.approx(t + rise, rel=1e-13)


def test_set_refuses_a_difference_for_an_absolute_temperature(sheet_from):
    sheet = sheet_from(SHEET)
    with pytest.raises(workbook.WorkbookError, match="is a temperature difference, but T1 is an"):
        sheet.with_inputs(T1="5 delta_degC")
    assert sheet.with_inputs(T1="68 degF").evaluate("dT").to("K").magnitude == pytest.approx(65)


def test_a_sweep_output_shown_in_degf_adds_the_offset(sheet_from):
    """A sweep output in degF of a temperature in degC is pint's conversion (it was refused
    as 'cannot show'; a scale factor would have been wrong), in both sweep modes."""
    from workbook import sweep as sw

    sheet = sheet_from(SHEET)
    q = un.registry().Quantity
    for mode in ("vector", "serial"):
        res = sw.sweep(
            sheet,
            {"T2": "60degC..100degC:5"},
            [sw.parse_output_option("mid[degF]=T_mid")],
            mode=mode,
        )
        got = res.table["mid [degF]"].to_numpy()
        t2 = [60, 70, 80, 90, 100]
        want = [(q(20, "degC") + (q(t, "degC") - q(20, "degC")) / 2).to("degF").m for t in t2]
        np.testing.assert_allclose(got, want, rtol=1e-13)


OVER_A_TEMPERATURE = """
[inputs]
c = "2 J/K"
T1 = "20 degC"

[arguments]
T = { unit = "degC" }

[definitions]
"cp(T)" = { expr = "c*(1 + 0.001*(T - T1)/(1 K))", unit = "J/K" }
"dcp(T)" = { expr = "diff(cp(T), T)", unit = "J/K^2" }
Q = { expr = "integral(cp(T), T, 20 degC, 80 degC)", unit = "J" }
Qf = { expr = "integral(cp(T), T, 68 degF, 176 degF)", unit = "J" }
Tr = { expr = "root(cp(T) - 2.05 J/K, T, 0 degC, 100 degC)", unit = "degF" }
d = { expr = "dcp(40 degC)", unit = "J/K^2" }
"""


def test_builtins_over_a_temperature_variable_step_by_differences(sheet_from):
    """integral over T in degC has the unit of cp times delta_degC, diff is per delta_degC
    (both were internal errors: 'offset units in higher order'); against closed forms."""
    sheet = sheet_from(OVER_A_TEMPERATURE)
    heat = 2 * (60 + 0.001 * 60**2 / 2)  # J, the integral of cp from 20 to 80 degC
    assert sheet.evaluate("Q").to("J").magnitude == pytest.approx(heat, rel=1e-13)
    assert sheet.evaluate("Qf").to("J").magnitude == pytest.approx(heat, rel=1e-12)
    assert sheet.evaluate("Tr").to("degC").magnitude == pytest.approx(45, rel=1e-12)
    assert sheet.evaluate("d").to("J/K^2").magnitude == pytest.approx(0.002, rel=1e-13)


def test_a_compound_unit_with_an_offset_temperature_is_a_unit_error():
    """pint refuses degC inside a compound unit ('offset units in higher order'); the one
    conversion of the engine says so as a UnitError (exit 2), not pint's error (exit 3)."""
    r = un.registry()
    src = r.Unit("joule") / r.Unit("kelvin") / r.Unit("degree_Celsius")
    with pytest.raises(UnitError, match="inside a compound unit a temperature is a difference"):
        un.factor(src, r.Unit("joule") / r.Unit("kelvin") ** 2)


def test_a_written_negative_temperature_is_below_zero_and_a_negated_one_is_refused(sheet_from):
    # -T1 was -25 degC (248.15 K) while -1*T1 was -298.15 K: the same formula, two numbers
    from workbook.errors import UnitError

    head = '[inputs]\nT1 = "25 degC"\n\n[definitions]\n'
    sheet = sheet_from(
        head + 'low = { expr = "max(T1 - 40 delta_degC, -10 degC)", unit = "degC" }\n'
        'd = "-(T1 - 0 degC)"\nk = { expr = "-1*T1", unit = "K" }\n'
    )
    assert math.isclose(sheet.evaluate("low").magnitude, -10.0, rel_tol=1e-12)
    assert sheet.evaluate("d").to("delta_degC").magnitude == pytest.approx(-25.0, rel=1e-12)
    assert sheet.evaluate("k").magnitude == pytest.approx(-298.15, rel=1e-12)
    for text in ("-T1", "2*(-T1)", "-(T1 + 5 delta_degC)"):
        with pytest.raises(UnitError, match="negative of an absolute temperature"):
            sheet_from(head + f'x = "{text}"\n')
