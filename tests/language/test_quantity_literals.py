"""A number followed by a unit inside a formula (``F/(20 mm^2)``, ``9.81 m/s^2``) is a
quantity: parsed, typed, computed, printed in Excel and in the report, against pint."""

from __future__ import annotations

import math
import re

import formulas
import pytest
from helpers import report_parse as rp
from helpers.recalc import formula_values

from workbook.errors import WorkbookError
from workbook.language import expr as ex
from workbook.language import units as un
from workbook.outputs.report.mathml import MathML


@pytest.mark.parametrize(
    "text,value,unit",
    [
        ("20 mm", 20.0, "mm"),
        ("9.81 m/s^2", 9.81, "m/s^2"),
        ("1.5e3 N*m", 1500.0, "N*m"),
        ("360 deg", 360.0, "deg"),
        ("5 W/(m*K)", 5.0, "W/(m*K)"),
        ("2 s^-1", 2.0, "s^-1"),
        ("0.5 delta_degC", 0.5, "delta_degC"),
    ],
)
def test_a_number_then_a_unit_is_one_quantity(text, value, unit):
    assert ex.parse(text) == ex.Quantity(value, unit)


@pytest.mark.parametrize(
    "text,tree",
    [
        ("F/(20 mm^2)", ex.Binary("/", ex.Name("F"), ex.Quantity(20.0, "mm^2"))),
        ("2 m * x", ex.Binary("*", ex.Quantity(2.0, "m"), ex.Name("x"))),
        ("-20 mm + L", ex.Binary("+", ex.Unary("-", ex.Quantity(20.0, "mm")), ex.Name("L"))),
        ("f(2 mm, 3)", ex.Call("f", (ex.Quantity(2.0, "mm"), ex.Number(3.0)))),
        (
            "1 if x > 0 mm otherwise 0",
            ex.IfElse(
                ex.Number(1.0),
                ex.Compare((">",), (ex.Name("x"), ex.Quantity(0.0, "mm"))),
                ex.Number(0.0),
            ),
        ),
    ],
)
def test_a_space_ends_the_unit(text, tree):
    node = ex.parse(text)
    assert node == tree
    assert ex.parse(ex.to_text(node)) == node  # printed back, read again


@pytest.mark.parametrize(
    "text", ["F/(20 mm^2)", "9.81 m/s^2 * mass", "-20 mm + L", "5 W/(m*K) * A*(1.5 K)"]
)
def test_the_report_shows_the_literal_as_written(text):
    doc = rp.parse(f"<div><math>{MathML().box(ex.parse(text)).xml}</math></div>")
    back = rp.formula_text(doc.xpath("//math")[0])
    assert ex.to_text(ex.parse(back)) == ex.to_text(ex.parse(text)), back
    assert doc.xpath("//mrow[@class='literal']")


SHEET = """
[sheet]
title = "units inside formulas"

[inputs]
F = { value = "10 kN" }
L = { value = "2 m" }
m_1 = { value = "3 kg" }
theta = { value = "30 deg" }

[arguments]
x = { unit = "m" }

[definitions]
sigma = { expr = "F/(20 mm^2)", unit = "MPa" }
weight = { expr = "9.81 m/s^2 * m_1", unit = "N" }
longer = { expr = "L + 20 mm", unit = "m" }
rest = { expr = "360 deg - theta", unit = "deg" }
torque = { expr = "1.5e3 N*m", unit = "kN*m" }
"moment(x)" = { expr = "F*x + 2 kN*m", unit = "kN*m" }
at_half = { expr = "moment(500 mm)", unit = "kN*m" }
shorter = { expr = "-20 mm + L", unit = "mm" }
flux = { expr = "5 W/(m^2*K)*(3 m^2)*(T_2 - T_1)", unit = "W" }
T_1 = "20 degC"
T_2 = "T_1 + 15 delta_degC"
"""


def _expected():
    q = un.registry().Quantity
    force, length, mass, theta = q(10, "kN"), q(2, "m"), q(3, "kg"), q(30, "deg")
    return {
        "sigma": (force / q(20, "mm^2")).to("MPa"),
        "weight": (q(9.81, "m/s^2") * mass).to("N"),
        "longer": (length + q(20, "mm")).to("m"),
        "rest": (q(360, "deg") - theta).to("deg"),
        "torque": q(1.5e3, "N*m").to("kN*m"),
        "at_half": (force * q(500, "mm") + q(2, "kN*m")).to("kN*m"),
        "shorter": (-q(20, "mm") + length).to("mm"),
        "flux": (q(5, "W/(m^2*K)") * q(3, "m^2") * q(15, "delta_degC")).to("W"),
        "T_2": q(35, "degC"),
    }


@pytest.fixture(scope="module")
def written(load_text, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("literals")
    sheet = load_text(SHEET, name="t")
    return sheet, sheet.write_xlsx(tmp / "literals.xlsx")


@pytest.mark.parametrize("name", list(_expected()))
def test_values_are_pints(written, name):
    sheet, _ = written
    expected = _expected()[name]
    got = sheet.evaluate(name)
    assert str(got.units) == str(expected.units)
    assert math.isclose(got.magnitude, expected.magnitude, rel_tol=1e-13)


def test_excel_writes_the_number_in_the_unit_the_cell_needs(written):
    """``L + 20 mm`` in m is ``=L_+0.02``; the `formulas` package recalculates every cell."""
    import openpyxl

    sheet, path = written
    cells = formula_values(path)
    results = openpyxl.load_workbook(path)["Results"]
    rows = {r[0].value: r[0].row for r in results.iter_rows(min_row=2) if r[0].value}
    assert cells[("Results", f"B{rows['longer']}")][0] == "=L_+0.02"
    assert cells[("Results", f"B{rows['at_half']}")][0] == "=F_*0.5+2"
    solution = formulas.ExcelModel().loads(str(path)).finish().calculate()
    values = {}
    for key, ranges in solution.items():
        book_sheet, _, cell = key.rpartition("!")
        if book_sheet.split("]", 1)[-1].strip("'").upper() == "RESULTS" and ":" not in cell:
            values[cell.upper()] = ranges.value[0, 0]
    for name, expected in _expected().items():
        got = float(values[f"B{rows[name]}"])
        assert math.isclose(got, expected.magnitude, rel_tol=1e-12), name


@pytest.mark.parametrize(
    "expr,message",
    [
        ("2 m*L", "to multiply by 'L', put spaces around '*': '2 m * L'"),
        ("2 m*zz", "a space ends the unit of a number"),
        ("L + mm", "a unit is written after a number: 1 mm"),
        ("F/(20 kg)", "cannot be converted"),
        ("1" + "0" * 309 + " MPa", "too large"),  # an int past the largest double
        ("1e999 MPa", "too large"),
    ],
)
def test_mistakes_say_what_to_write(sheet_from, expr, message):
    text = (
        SHEET.split("[definitions]")[0]
        + f'[definitions]\nbad = {{ expr = "{expr}", unit = "MPa" }}\n'
    )
    with pytest.raises(WorkbookError, match=re.escape(message)):
        sheet_from(text)


@pytest.mark.parametrize(
    "text,tree",
    [
        ("85 %", ex.Quantity(85.0, "%")),
        ("100% - p", ex.Binary("-", ex.Quantity(100.0, "%"), ex.Name("p"))),
        ("15%/t", ex.Binary("/", ex.Quantity(15.0, "%"), ex.Name("t"))),
        ("1 - 15 %", ex.Binary("-", ex.Number(1.0), ex.Quantity(15.0, "%"))),
        ("7 % - 2", ex.Binary("-", ex.Quantity(7.0, "%"), ex.Number(2.0))),
    ],
)  # fmt: skip
def test_a_number_then_percent_is_a_percentage(text, tree):
    assert ex.parse(text) == tree
    assert ex.parse(ex.to_text(tree)) == tree


@pytest.mark.parametrize("text", ["7 % 2", "7 % (2)", "a % b", "7 % -2", "7 % +x"])
def test_percent_between_two_values_is_refused_not_read_as_a_remainder(text):
    with pytest.raises(WorkbookError, match=r"mod\(x, y\) is the remainder"):
        ex.parse(text)


def test_a_percentage_in_a_formula_is_live_in_excel(sheet_from, tmp_path):
    text = (
        '[inputs]\nP_in = "12 kW"\nloss = "4 %"\n\n[definitions]\n'
        'P_out = { expr = "P_in*(100% - loss - 2.5 %)", unit = "kW" }\n'
    )
    sheet = sheet_from(text)
    assert math.isclose(sheet.evaluate("P_out").to("kW").magnitude, 12 * 0.935, rel_tol=1e-14)
    path = sheet.write_xlsx(tmp_path / "p.xlsx")
    solution = formulas.ExcelModel().loads(str(path)).finish().calculate()
    values = [
        float(r.value[0, 0])
        for key, r in solution.items()
        if key.upper().endswith("RESULTS'!B2") or key.upper().endswith("RESULTS!B2")
    ]
    assert values and math.isclose(values[0], 11.22, rel_tol=1e-12), values


@pytest.mark.slow
def test_libreoffice_recalculates_literals_constants_and_a_log_range(sheet_from, tmp_path):
    """The quantities, g, e and pi, and a logspace table, recalculated by LibreOffice."""
    import numpy as np
    from helpers.recalc import cell_values, recalculate, soffice

    if soffice() is None:
        pytest.skip("LibreOffice is not installed")
    text = SHEET.replace('x = { unit = "m" }\n', 'x = { unit = "m" }\nf = { unit = "Hz" }\n')
    text += """weight_g = { expr = "m_1*g", unit = "N" }
growth = "e^2 + pi"

[[tables]]
name = "bode"
range = "f := logspace(10 Hz, 10 kHz, 4)"
columns = { "1/(1 + f/(1 kHz))" = "" }
"""
    sheet = sheet_from(text, name="lo")
    path = sheet.write_xlsx(tmp_path / "lo.xlsx")
    import openpyxl

    results = openpyxl.load_workbook(path)["Results"]
    rows = {r[0].value: r[0].row for r in results.iter_rows(min_row=2) if r[0].value}
    values = cell_values(recalculate(path, tmp_path / "out"))
    for name in [*_expected(), "weight_g", "growth"]:
        engine = sheet.evaluate(name)
        if sheet.spec.definitions[name].unit is not None:
            engine = engine.to(sheet.spec.definitions[name].unit)
        got = float(values[("Results", f"B{rows[name]}")])
        assert got == pytest.approx(float(engine.magnitude), rel=1e-12), name
    table = sheet.table("bode")
    listing = {k[1]: v for k, v in values.items() if k[0] == "Listing"}
    got = [float(listing[f"B{3 + i}"]) for i in range(4)]
    np.testing.assert_allclose(got, table.iloc[:, 1], rtol=1e-12)


def test_a_bound_with_a_unit_is_converted_in_an_ode_time_range(sheet_from):
    """t := 0 .. 2 min with t in s runs to 120 s (the unit of the bound was dropped before:
    the run ended at 2 s)."""
    text = """
[inputs]
k = "0.1 1/s"
tq = "100 s"

[arguments]
t = { unit = "s" }

[[ode]]
name = "decay"
time = "t := 0 .. 2 min"
states = [{ name = "y", unit = "", initial = "1", derivative = "-k*y" }]

[definitions]
y_q = "y(tq)"
y_end = "y(2 min)"
"""
    sheet = sheet_from(text)
    assert sheet.evaluate("y_q").magnitude == pytest.approx(math.exp(-10), rel=1e-4)
    assert sheet.evaluate("y_end").magnitude == pytest.approx(math.exp(-12), rel=1e-4)


def test_python_syntax_warnings_do_not_reach_the_user():
    # '1if' made Python print "<unknown>:1: SyntaxWarning: invalid decimal literal" on stderr
    import warnings

    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        assert ex.parse("1if a > 0 else 2") == ex.parse("1 if a > 0 else 2")
    assert not [w for w in seen if issubclass(w.category, SyntaxWarning)], seen


def test_a_units_name_gets_both_hints_when_the_sheet_has_a_name_like_it(sheet_from):
    """``P1 + kW`` beside an input ``k``: the sheet's name like it, and how a unit is written
    (the second hint was lost when the first was found)."""
    text = '[inputs]\nk = "2"\nP1 = "3 kW"\n[definitions]\nP = "P1 + kW"\n'
    with pytest.raises(WorkbookError) as err:
        sheet_from(text)
    assert "unknown name 'kW' (did you mean k?; a unit is written after a number: 1 kW)" in str(
        err.value
    )
