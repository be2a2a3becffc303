"""The unit in which a cell holds its number: one decision for every cell of a workbook.

A value has two units: the one its typed tree carries (``P1/P2`` with P1 in kW and P2 in W
is in kW/W, and every formula that uses it is typed against that unit), and the one in which
its cell holds it (a plain number, 0.75, since a leftover product of units reads badly).
:func:`stored_unit` decides the second; :func:`in_cell` gives the tree whose value the cell
holds (its formula and its cached value), and :func:`reading` the tree a formula uses to read
that cell (the cell's number back in the unit the formula was typed against). The engine's
shown values, the cached values, the cell formulas and every reference printed into a
formula all come from these three, so a cell and the formulas reading it cannot disagree.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import pint

from ..language import typed as ty
from ..language import units as un

#: ``convert(tree, unit, where)``: the typer's one conversion between units (a factor, or a
#: factor and an offset for degC and degF)
Convert = Callable[[ty.T, pint.Unit, str], ty.T]


def stored_unit(t: ty.T) -> pint.Unit:
    """The unit of the number in the cell that holds a value typed ``t`` (the value's own
    tree, or any node that reads the cell: a reference, a column's maximum).

    An input's cell holds the number the user typed, in the unit beside it. Any other value
    whose unit is a dimensionless product of units (kW/W, mm/m, sqrt(GPa/MPa)), declared or
    not, is held as a plain number; every other unit (percent, degrees, degC, "" and none
    declared) as it is."""
    if isinstance(t, ty.TRef) and t.kind in ("input", "choice", "builtin"):
        return t.unit
    if t.text:
        return t.unit
    return un.registry().dimensionless if un.is_compound_ratio(t.unit) else t.unit


def in_cell(convert: Convert, t: ty.T, where: str) -> ty.T:
    """``t`` in the unit its cell holds it (:func:`stored_unit`): the tree of the cell's
    formula and of its cached value."""
    return convert(t, stored_unit(t), where)


def reading(convert: Convert, t: ty.T) -> ty.T:
    """The tree a formula uses to read the cell of ``t`` (a reference to a definition, a
    column's maximum): the cell's number, in :func:`stored_unit`, converted back to the unit
    ``t`` is typed in; ``t`` itself when the two are one."""
    held = stored_unit(t)
    if held == t.unit:
        return t
    return convert(dataclasses.replace(t, unit=held), t.unit, "a cell read by a formula")


def read_factor(t: ty.T) -> float:
    """The factor from the number a cell holds to the value in ``t``'s unit (1 when it is
    held as typed); for the engine's reading of a column it holds in cells."""
    held = stored_unit(t)
    return 1.0 if held == t.unit else un.factor(held, t.unit)
