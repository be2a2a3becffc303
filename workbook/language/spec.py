"""The specification a worksheet is read into (:class:`SheetSpec` and its parts) and the keys
each of its TOML tables may hold; :mod:`workbook.language.template` reads the text into it."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pint

from ..errors import UnitError
from . import expr as ex
from . import units as un
from .fields import find_line
from .ranges import RangeSpec

SECTIONS = {
    "sheet",
    "inputs",
    "arguments",
    "definitions",
    "blocks",
    "tables",
    "charts",
    "printed",
    "relations",
    "findings",
    "checks",
    "sweep",
    "parts",
    "data",
    "solve",
    "ode",
}

ALL_PARTS = "all"

MAX_VARY = 50  # curves of one family table

# The keys each table of a template may hold (anything else is a misspelling: refused).
SHEET_KEYS = (
    "name",
    "title",
    "source",
    "description",
    "bench",
    "export",
    "about",
    "hand_checks",
    "samples",
    "tolerance",
    "origin",
    "complex",
    "time_limit",
)  # every key the engine reads from [sheet] (SheetSpec.meta); checked by
# tests/hardening/test_harden.py

INPUT_KEYS = ("value", "unit", "note", "options", "min", "max", "positive", "label")

ARGUMENT_KEYS = ("unit", "note", "plain")

DEFINITION_KEYS = ("expr", "pieces", "program", "unit", "note", "positive", "min", "max")

PART_KEYS = ("title", "note")

TABLE_KEYS = ("name", "title", "range", "columns", "sheet", "block", "part", "vary")

COLUMN_KEYS = ("expr", "unit", "title")

CHART_KEYS = (
    "name",
    "title",
    "range",
    "x",
    "x_title",
    "y_title",
    "y2_title",
    "series",
    "log_x",
    "log_y",
    "equal_axes",
    "part",
)

AXIS_KEYS = ("expr", "title", "unit")

SERIES_KEYS = ("y", "unit", "name", "line", "axis", "marker", "x", "x_unit", "range", "table")

PRINTED_KEYS = (
    "file",
    "title",
    "argument",
    "tolerance",
    "rel_tolerance",
    "role",
    "misprints",
    "note",
    "part",
)

MISPRINT_KEYS = ("name", "at", "note", "corrected")

RELATION_KEYS = ("relation", "range", "unit", "part")

FINDING_KEYS = ("block", "title", "part")

SWEEP_KEYS = ("outputs", "units")


@dataclass
class InputSpec:
    name: str
    value: pint.Quantity | str
    unit: pint.Unit | None  # None for a choice input
    note: str = ""
    options: tuple[str, ...] = ()
    minimum: pint.Quantity | None = None
    maximum: pint.Quantity | None = None
    positive: bool = False
    line: int | None = None
    label: str = ""  # unit shown beside a plain number (e.g. "deg" for Mathcad's Theta = 52)


@dataclass
class ArgumentSpec:
    name: str
    unit: pint.Unit
    note: str = ""
    line: int | None = None
    plain: bool = False  # inside formulas the argument is a plain number in `unit` (Mathcad style)

    @property
    def binding_unit(self) -> pint.Unit:
        return un.registry().dimensionless if self.plain else self.unit


@dataclass
class Branch:
    value: ex.Node
    condition: ex.Node | None  # None: 'otherwise'
    text: str


@dataclass(frozen=True)
class Limits:
    """What a definition's values must meet, declared like an input's bounds: a value outside
    is an error naming the definition and its limit, never a number."""

    positive: bool = False
    minimum: pint.Quantity | None = None  # a plain number is in the definition's unit
    maximum: pint.Quantity | None = None

    def magnitudes(self, unit, display=None, what: str = "") -> tuple[float, float, bool]:
        """(lowest, highest, positive) as magnitudes in ``unit``; a plain-number bound is in
        ``display`` (the unit the definition is shown in), else in ``unit``."""
        out = []
        for bound, default in ((self.minimum, -math.inf), (self.maximum, math.inf)):
            if bound is None:
                out.append(default)
                continue
            q = bound
            if q.unitless and not un.registry().Quantity(1, unit).unitless:
                q = un.registry().Quantity(q.magnitude, display or unit)
            try:
                out.append(float(q.to(unit).magnitude))
            except pint.DimensionalityError:
                raise UnitError(
                    f"{what}: the limit {bound:~} is {un.dims(bound.units)}, the value "
                    f"{un.dims(unit)} ({un.pretty(unit)})"
                ) from None
        return out[0], out[1], self.positive

    def text(self, display: str = "") -> str:
        """The limits as the template says them: "positive", "at least 0 mm"."""
        parts = ["positive"] if self.positive else []
        for bound, word in ((self.minimum, "at least"), (self.maximum, "at most")):
            if bound is not None:
                unit = "" if not bound.unitless else display
                parts.append(f"{word} {bound:~}{(' ' + unit) if unit else ''}".rstrip())
        return " and ".join(parts)


@dataclass
class Definition:
    name: str
    params: tuple[str, ...]
    body: ex.Node | None
    branches: list[Branch] | None = None
    text: str = ""
    note: str = ""
    unit: pint.Unit | None = None  # display unit, optional
    line: int | None = None
    program: Any = None  # workbook.program.statements.Program: a body of statements
    ode: tuple[str, int] | None = None  # a state of an [[ode]]: (ode name, state index)
    limits: Limits | None = None  # what its values must meet (positive = true, min, max)

    @property
    def is_function(self) -> bool:
        return bool(self.params)

    def expressions(self) -> list[ex.Node]:
        """Every expression the definition's value is made of (for dependencies)."""
        if self.body is not None:
            return [self.body]
        if self.branches is not None:
            return [x for b in self.branches for x in (b.value, b.condition) if x is not None]
        if self.program is not None:
            from ..program.statements import expressions

            return list(expressions(self.program.body))
        return []  # an ODE state: its section's expressions are listed by the sheet


@dataclass
class PartSpec:
    """An optional part of a worksheet (hand checks, studies): left out unless asked for."""

    name: str
    title: str
    note: str = ""
    line: int | None = None


@dataclass
class ColumnSpec:
    text: str
    node: ex.Node
    unit: pint.Unit | None
    title: str


@dataclass
class TableSpec:
    name: str
    title: str
    range: RangeSpec | None
    columns: list[ColumnSpec]
    sheet: str = "Listing"
    block: str | None = None
    line: int | None = None
    part: str | None = None
    # a family of curves: input name -> the values (texts) the columns are computed at
    vary: dict[str, tuple[str, ...]] = field(default_factory=dict)

    @property
    def computed(self) -> bool:
        """Values computed by the engine and written as numbers (a solver block's table, or
        a family over input values), not a live formula per cell."""
        return bool(self.block or self.vary)


@dataclass
class SeriesSpec:
    y: ColumnSpec
    name: str
    line: str = "solid"  # solid | dash | dot | none
    axis: str = "primary"
    marker: bool = False
    x: ColumnSpec | None = None
    range: RangeSpec | None = None
    table: str | None = None  # series read from a block table: column names
    x_column: str | None = None
    y_column: str | None = None


@dataclass
class ChartSpec:
    name: str
    title: str
    range: RangeSpec | None
    x: ColumnSpec | None
    x_title: str
    y_title: str
    y2_title: str = ""
    series: list[SeriesSpec] = field(default_factory=list)
    log_x: bool = False
    log_y: bool = False
    equal_axes: bool = False
    line: int | None = None
    part: str | None = None


@dataclass
class Misprint:
    name: str
    at: float
    note: str
    corrected: float | None = None


@dataclass
class PrintedSpec:
    file: Path
    title: str
    argument: str
    tolerance: float | None = None  # absolute, in the printed unit
    rel_tolerance: float | None = None
    role: str = "check"  # check | information
    misprints: list[Misprint] = field(default_factory=list)
    note: str = ""
    part: str | None = None
    folder: Path | None = None  # the template's folder: the file must resolve inside it
    # the rows of the file once read, or the error reading it (typedsheet.printed_rows)
    read: Any = field(default=None, init=False, repr=False, compare=False)


@dataclass
class RelationSpec:
    """A declared derivative relation: child == factor * d(parent)/d(var)."""

    text: str
    child: str
    factor: ex.Node
    parent: str
    var: str
    var_unit: str
    range: RangeSpec | None
    line: int | None = None
    part: str | None = None


@dataclass
class SheetSpec:
    name: str
    title: str
    path: Path
    source: str
    description: str
    inputs: dict[str, InputSpec]
    arguments: dict[str, ArgumentSpec]
    definitions: dict[str, Definition]
    blocks: dict[str, str]
    tables: list[TableSpec]
    charts: list[ChartSpec]
    printed: list[PrintedSpec]
    relations: list[RelationSpec]
    findings: list[dict]
    meta: dict[str, Any]
    text: str
    parts: dict[str, PartSpec] = field(default_factory=dict)
    data: dict[str, Any] = field(default_factory=dict)  # column name -> measured.DataColumn
    solves: list[Any] = field(default_factory=list)  # given_find.SolveSpec, [[solve]] blocks
    odes: dict[str, Any] = field(default_factory=dict)  # name -> workbook.language.odes.OdeSpec
    checks: list[Any] = field(default_factory=list)  # checkspec.CheckSpec, [[checks]]
    # the names that may not be a built-in function's (functions, blocks, columns, unknowns,
    # ODE states) -> their line: the typer, which knows the built-ins, refuses them
    function_names: dict[str, int | None] = field(default_factory=dict)

    def solve_of(self, name: str):
        """The [[solve]] block that finds ``name``, or None."""
        return next((s for s in self.solves if name in s.unknowns), None)

    @property
    def origin(self) -> int:
        """The first index of vectors and matrices (Mathcad's ORIGIN; [sheet] origin)."""
        return int(self.meta.get("origin", 0))

    @property
    def polar(self) -> bool:
        """Complex results shown as r∠phi (``[sheet] complex = "polar"``), else as a + bi."""
        return self.meta.get("complex", "rectangular") == "polar"

    def line_of(self, key: str, section: str | None = None) -> int | None:
        return find_line(self.text, key, section)
