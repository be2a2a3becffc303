"""Built-in constants: ``pi``, ``e`` (Euler's number) and ``g`` (standard gravity).

A constant is one :class:`Constant` entry: its value and unit, its Excel text, its SymPy form,
and how the report writes it. Every consumer (the typer, the numpy evaluator, the Excel and
SymPy printers, the report) reads :data:`CONSTANTS` from here (the typer as
:data:`workbook.numerics.registry.BUILTINS` gives them); nothing else lists them. A worksheet
may define a name of its own that is also a constant (``e``, an eccentricity, is common):
then the name is the sheet's everywhere, and the About sheet of the workbook says so
(:func:`shadowed`)."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Constant:
    """One built-in constant."""

    name: str
    value: float
    unit: str  # pint unit text, "" for a plain number
    excel: str  # the Excel formula text of the value
    sympy: Callable[[], Any]  # its exact SymPy form
    doc: str
    symbol: str = ""  # the letter the report shows (a name's own rendering when empty)


def _sympy_pi():
    import sympy

    return sympy.pi


def _sympy_e():
    import sympy

    return sympy.E


def _sympy_g():
    import sympy

    return sympy.Rational(980665, 100000)


CONSTANTS: dict[str, Constant] = {
    c.name: c
    for c in (
        Constant("pi", math.pi, "", "PI()", _sympy_pi, "3.14159..., the ratio of a circle"),
        Constant("e", math.e, "", "EXP(1)", _sympy_e, "2.71828..., Euler's number"),
        Constant(
            "g",
            9.80665,
            "m/s^2",
            "9.80665",
            _sympy_g,
            "9.80665 m/s^2, standard gravity (as Mathcad's g)",
        ),
    )
}


def shadowed(spec) -> list[str]:
    """The constants a worksheet defines names of its own for (inputs or definitions)."""
    own = {*spec.inputs, *spec.definitions}
    return [name for name in CONSTANTS if name in own]
