"""Unit text as engineers write it: repeated factors joined by an operator, fractional
powers, and the names of Mathcad's unit list, against the exact definitions of the units
(NIST SP 811: the foot, the pound and the gallon are exact), not against pint."""

from __future__ import annotations

import math

import pytest

from workbook.errors import InputError, LimitError
from workbook.language import units as un

FOOT = 0.3048  # m
POUND = 0.45359237  # kg
LBF = POUND * 9.80665  # N
GALLON = 231 * 0.0254**3  # m^3

# (unit text, its value in SI base units)
EXACT = [
    ("psf", LBF / FOOT**2),
    ("pcf", POUND / FOOT**3),
    ("gpm", GALLON / 60),
    ("cfs", FOOT**3),
    ("var", 1.0),
    ("kvar", 1000.0),
    ("Mvar", 1e6),
    ("VA", 1.0),
    ("kVA", 1000.0),
    ("gm", 1e-3),
    ("lbm", POUND),
    ("tonf", 2000 * LBF),
    ("rev", 2 * math.pi),
    ("gph", GALLON / 3600),
    ("ppb", 1e-9),
    ("Torr", 101325 / 760),
    ("N*m/m", 1.0),
    ("kN*m/m", 1000.0),
    ("m*m", 1.0),
    ("m^(1/2)/s", 1.0),
    ("ft^(1/2)", math.sqrt(FOOT)),
    ("ft^(-3/2)", FOOT**-1.5),
    ("(ft/s)^(3/2)", FOOT**1.5),
]


@pytest.mark.parametrize("text,si", EXACT, ids=[t for t, _ in EXACT])
def test_the_unit_is_read_with_its_exact_size(text, si):
    u = un.unit(text)
    got = float(un.registry().Quantity(1.0, u).to_base_units().magnitude)
    assert math.isclose(got, si, rel_tol=1e-14)


@pytest.mark.parametrize(
    "text,same",
    [("m^(1/2)/s", "m^0.5/s"), ("kN*m/m", "kN"), ("s^(-3/2)", "s^-1.5"), ("kvar", "kV*A")],
)
def test_the_two_spellings_are_one_unit(text, same):
    assert un.unit(text).dimensionality == un.unit(same).dimensionality
    assert un.factor(un.unit(text), un.unit(same)) == pytest.approx(1.0, rel=1e-15)


@pytest.mark.parametrize(
    "text,error,message",
    [
        ("700 MPa MPa", InputError, "a space between two units multiplies them"),
        ("1 m^(1/0)", InputError, "a power divides by zero"),
        ("1 m^(1/2)^2", LimitError, "raises a power to a power"),
        ("1 kg^(9)^(9)^(9)", LimitError, "raises a power to a power"),
        ("1 m^(26/2)", LimitError, "power 13"),
        ("1 m^(1/2/3)", InputError, "a number where a unit should be"),
    ],
)
def test_a_refusal_says_what_is_wrong(text, error, message):
    with pytest.raises(error, match=message.replace("(", r"\(").replace("^", r"\^")):
        un.quantity(text, what="x")


def test_the_refusal_of_a_repeated_name_no_longer_advises_a_power_for_a_ratio():
    with pytest.raises(InputError) as err:
        un.quantity("3 kN m m", what="x")
    assert "written twice" in str(err.value)
    assert un.quantity("3 kN*m/m").to("kN").magnitude == pytest.approx(3.0, rel=1e-15)


def test_units_in_formulas(sheet_from):
    text = """
[inputs]
w = "1.2 m"

[definitions]
M = { expr = "3 kN*m/m * w", unit = "kN*m" }
Q = { expr = "5 kvar + 200 var", unit = "kvar" }
k = { expr = "2 m^(1/2)/s * sqrt(w)", unit = "m/s" }
v = "var([1, 2, 3, 4]*w)"
"""
    sheet = sheet_from(text)
    assert sheet.evaluate("M").to("kN*m").magnitude == pytest.approx(3.6, rel=1e-14)
    assert sheet.evaluate("Q").to("kvar").magnitude == pytest.approx(5.2, rel=1e-14)
    assert sheet.evaluate("k").to("m/s").magnitude == pytest.approx(2 * math.sqrt(1.2), rel=1e-14)
    assert sheet.evaluate("v").to("m^2").magnitude == pytest.approx(1.25 * 1.44, rel=1e-14)
