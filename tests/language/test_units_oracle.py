"""The engine against pint on random expressions of quantities in many units.

Each generated expression is written twice: as a worksheet formula for the engine, and as
Python on plain pint quantities (pint's own registry, not the engine's). Where both give a
value, the values must agree, except where a function or power is taken of an absolute
temperature (the language takes it in kelvin, as Mathcad does; pint in its own scale). Where
only one gives a value, that is one of the documented choices (an absolute temperature inside
a product is taken in kelvin, which pint refuses; a name joined to a unit is refused by the
engine); the engine then fails with a WorkbookError, never another exception.

Bare numbers are never added to or compared with another value here: next to an angle in
degrees the language reads a bare number as degrees (documented), where pint reads radians.
"""

from __future__ import annotations

import json
import math
import warnings
from dataclasses import dataclass

import numpy as np
import pint
import pytest
from helpers.sheets import fuzz_settings
from hypothesis import given
from hypothesis import strategies as st

from workbook.errors import WorkbookError

PINT = pint.UnitRegistry(autoconvert_offset_to_baseunit=False)

INPUTS = {
    "a": "20 mm", "b": "1.5 inch", "F": "3 kN", "Fl": "200 lbf", "P": "2 MPa", "Pp": "30 psi",
    "T1": "25 degC", "T2": "77 degF", "Tk": "300 K", "dT": "5 delta_degC", "dF": "9 delta_degF",
    "th": "30 deg", "r": "0.5 rad", "t": "2 s", "tm": "1.5 min", "w": "1200 rpm", "p": "15 %",
    "n": "2.5", "m": "3 kg", "v": "4 m/s", "E": "2 kJ", "pw": "1.2 kW", "L": "0.75 ft",
    "h": "2 h", "f": "50 Hz",
}  # fmt: skip
QUANTITIES = [
    "20 mm", "1 m", "3 kN", "10 degC", "4 delta_degC", "45 deg", "1 s", "2 kg", "90 %",
    "1 rad", "60 min", "5 psi", "100 K", "32 degF", "1 mile", "2 lb", "3 kN*cm", "0.5 hp",
]  # fmt: skip
NUMBERS = ["2", "0.5", "3.25"]
FUNCTIONS = ["sqrt", "abs", "sin", "cos", "tan", "exp", "ln", "atan"]
NUMPY = {
    "sqrt": np.sqrt, "abs": np.abs, "sin": np.sin, "cos": np.cos, "tan": np.tan,
    "exp": np.exp, "ln": np.log, "atan": np.arctan, "min": min, "max": max,
}  # fmt: skip


def quantity(text: str):
    number, _, unit = text.partition(" ")
    return PINT.Quantity(float(number), unit.replace("%", "percent") or "dimensionless")


ABSOLUTE = {"T1", "T2", "10 degC", "32 degF"}  # temperatures on a scale with an offset
DELTAS = {"dT", "dF", "4 delta_degC"}  # temperature differences


@dataclass(frozen=True)
class Case:
    text: str  # the worksheet formula
    python: str  # the same on pint quantities
    bare: bool = False  # a plain number written without a unit
    absolute: bool = False  # holds an absolute temperature
    kelvin: bool = False  # a function or power of one: kelvin by the language's rule


leaves = st.one_of(
    st.sampled_from(sorted(INPUTS)).map(lambda n: Case(n, n, absolute=n in ABSOLUTE)),
    st.sampled_from(QUANTITIES).map(lambda q: Case(q, f"Q({q!r})", absolute=q in ABSOLUTE)),
    st.sampled_from(NUMBERS).map(lambda x: Case(x, x, bare=True)),
)


def _grow(children):
    def joined(text: str, python: str, *parts: Case, bare=False, kelvin=False) -> Case:
        absolute = any(c.absolute for c in parts)
        kelvin = kelvin and absolute or any(c.kelvin for c in parts)
        return Case(text, python, bare, absolute, kelvin)

    def binary(op):
        def make(pair):
            a, b = pair
            if op in "+-" and (a.bare or b.bare):  # a bare number next to an angle is degrees
                return None
            bare = a.bare and b.bare
            # kelvin in a sum with an absolute temperature is a difference (Mathcad's rule,
            # where pint reads K as absolute): compared in test_temperatures_mathcad.py
            mathcad = op in "+-" and a.absolute != b.absolute and not {a.text, b.text} & DELTAS
            return joined(
                f"({a.text} {op} {b.text})",
                f"({a.python} {op} {b.python})",
                a,
                b,
                bare=bare,
                kelvin=mathcad,
            )

        return st.tuples(children, children).map(make)

    def power(pair):
        a, e = pair
        return joined(f"({a.text})^{e}", f"({a.python})**({e})", a, bare=a.bare, kelvin=True)

    def call(pair):
        f, a = pair
        return joined(f"{f}({a.text})", f"{f}({a.python})", a, bare=a.bare, kelvin=True)

    def extremum(triple):
        f, a, b = triple
        if a.bare or b.bare:
            return None
        return joined(f"{f}({a.text}, {b.text})", f"{f}({a.python}, {b.python})", a, b, kelvin=True)

    def negative(a):
        return joined(f"-{a.text}", f"-{a.python}", a, bare=a.bare)

    return st.one_of(
        *(binary(op) for op in "+-*/"),
        st.tuples(children, st.sampled_from(["2", "3", "0.5", "-1"])).map(power),
        st.tuples(st.sampled_from(FUNCTIONS), children).map(call),
        st.tuples(st.sampled_from(["min", "max"]), children, children).map(extremum),
        children.map(negative),
    ).filter(lambda x: x is not None)


expressions = st.recursive(leaves, _grow, max_leaves=6)


def by_pint(text: str):
    env = {name: quantity(value) for name, value in INPUTS.items()}
    env.update(NUMPY, Q=quantity)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        value = eval(text, {"__builtins__": {}}, env)  # noqa: S307 - generated by this test
    value = value if isinstance(value, PINT.Quantity) else PINT.Quantity(value)
    magnitude = value.to_base_units().magnitude
    if isinstance(magnitude, complex) or not math.isfinite(magnitude):
        return None  # a negative number to the power 0.5: Python gives a complex number
    return value


def by_engine(load_text, text: str):
    body = "[inputs]\n" + "".join(f"{k} = {json.dumps(v)}\n" for k, v in INPUTS.items())
    sheet = load_text(f"{body}\n[definitions]\nk = {json.dumps(text)}\n", name="oracle")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return sheet.evaluate("k")


def check(load_text, case: Case) -> None:
    text, python = case.text, case.python
    try:
        expected = by_pint(python)
    except (pint.errors.PintError, ValueError, ZeroDivisionError, OverflowError):
        expected = None
    try:
        got = by_engine(load_text, text)
    except WorkbookError as err:
        assert str(err)
        return
    if expected is None or case.kelvin:  # pint takes the scale's number: 2*T1, abs(T1)
        return
    engine = float(got.magnitude)
    if not math.isfinite(engine):
        return
    reference = float(expected.to(str(got.units).replace("%", "percent")).magnitude)
    assert math.isclose(engine, reference, rel_tol=1e-9, abs_tol=1e-9), (
        f"{text}: engine {got}, pint {expected} ({reference} {got.units})"
    )


@pytest.mark.slow
@fuzz_settings(300)
@given(case=expressions)
def test_the_engine_agrees_with_pint(load_text, case):
    check(load_text, case)


@pytest.mark.slow
@fuzz_settings(5000)
@given(case=expressions)
def test_the_engine_agrees_with_pint_many(load_text, case):
    check(load_text, case)


@pytest.mark.parametrize(
    "text,python",
    [
        ("(20 mm / 10 mm) + th", "(Q('20 mm') / Q('10 mm')) + th"),
        ("10 degC/100 K - (a/(5 mm) - th)", "Q('10 degC').to('K')/Q('100 K') - (a/Q('5 mm') - th)"),
        ("T1 - T2", "T1 - T2.to('degC')"),
        ("w*t", "w*t"),
        ("sin(th)*F", "np.sin(th)*F"),
    ],
)  # fmt: skip
def test_known_cases(load_text, text, python):
    got = by_engine(load_text, text)
    env = {name: quantity(value) for name, value in INPUTS.items()}
    expected = eval(python, {"__builtins__": {}}, {**env, "Q": quantity, "np": np})  # noqa: S307
    assert math.isclose(
        float(got.magnitude), float(expected.to(str(got.units)).magnitude), abs_tol=1e-12
    ), (got, expected)
