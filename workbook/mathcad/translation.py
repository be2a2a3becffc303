"""The translation of a Mathcad worksheet as data: its entries in Mathcad's order, the results
Mathcad stored, the regions not translated and why."""

from __future__ import annotations

from dataclasses import dataclass, field

from ..language import expr as ex
from .symbols import Sym


@dataclass
class Item:
    """One entry of the worksheet in Mathcad's order."""

    kind: str  # note | input | definition | function | range
    region: str = ""
    sym: Sym | None = None
    params: list[Sym] = field(default_factory=list)
    body: ex.Node | None = None
    pieces: list[tuple[ex.Node, ex.Node | None]] | None = None
    value: str = ""  # input: quantity text; note: the text
    unit: str = ""  # display unit (pint text)
    range: tuple[ex.Node, ex.Node | None, ex.Node] | None = None
    range_values: list[float] | None = None
    program: list | None = None  # lines of a program: (indent, [text or tree, ...])
    solve: tuple | None = None  # a solve block: ([(unknown, guess text)], equations, regions)
    chart: list | None = None  # a plot: its traces, [(x, y, range item, points?, number)]


@dataclass
class Result:
    """A result Mathcad stored for one evaluation."""

    region: str
    sym: Sym | None  # what the worksheet evaluates (None: nothing could be)
    name: str  # the Mathcad expression, for messages
    unit: str
    rows: list[tuple[float | None, float | str]]
    argument: Sym | None = None
    # where Mathcad's value is round-off of a larger size (a difference whose terms cancel, a
    # stored 0 among large elements): the absolute tolerance, and why
    round_off: tuple[float, str] | None = None
    #: why the stored values do not fit what the translation computes (a unit of another
    #: dimension): each stays a value, listed as not computable with this reason
    misfit: str = ""


@dataclass
class Skipped:
    region: str
    what: str
    why: str


@dataclass
class Translation:
    items: list[Item] = field(default_factory=list)
    results: list[Result] = field(default_factory=list)
    skipped: list[Skipped] = field(default_factory=list)
    syms: list[Sym] = field(default_factory=list)
    title: str = ""
    ignored: list[str] = field(default_factory=list)  # regions that show and define nothing
    origin: int = 0
    generator: str = ""  # "Mathcad Prime" for a .mcdx
    solve_tolerance: float = 1e-3  # Mathcad's TOL (its default, or the largest the sheet sets)


def uses(sym: Sym) -> str:
    """Why a use of an untranslated name is untranslated: the name and the first reason."""
    root = sym.broken.split(", which is not translated: ", 1)[-1]
    return f"uses {sym.mathcad}, which is not translated: {root}"
