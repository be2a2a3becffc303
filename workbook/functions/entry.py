"""One built-in function: the :class:`Builtin` record, the registry it is kept in, and
:func:`register` (the fields are described in :mod:`workbook.functions.builtins`; the complete
registry, every module's entries registered, is :data:`workbook.numerics.registry.REGISTRY`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
import pint

from ..errors import TemplateError
from ..language import typed as ty

Arity = int | tuple[int, int | None] | None


class UnitContext(Protocol):
    """What a unit rule may ask of the typer: the unit rules of typed trees
    (:class:`workbook.language.unitrules.UnitRules`, a base of the typer), and for ``diff`` whether
    a typed body has a symbolic form."""

    dimensionless: pint.Unit

    def convert(self, t: ty.T, target: pint.Unit, where: str) -> ty.T: ...

    def plain(self, t: ty.T, where: str) -> ty.T: ...

    def meeting(self, values) -> list[ty.T]: ...


@dataclass(frozen=True)
class Domain:
    """A restricted domain of argument ``arg``: ``bad(values)`` marks values outside it."""

    kind: str  # "sqrt of a negative number"
    bad: Callable[[np.ndarray], np.ndarray]
    shown: str  # "sqrt({})", filled with the argument's text
    arg: int = 0


@dataclass(frozen=True)
class Builtin:
    """One built-in function (see the module docstring for the meaning of each field)."""

    name: str
    arity: Arity
    unit_rule: Callable[..., ty.T]
    numpy: Callable[..., Any]
    excel: Callable[..., tuple[str, int]]
    sympy: Callable[..., Any]
    domain: tuple[Domain, ...] = ()
    doc: str = ""
    binds: tuple[int, int] | None = None
    data_args: tuple[int, ...] = ()  # arguments that name columns of [data] tables
    mathml: str = ""
    mathml_powered: bool = False
    arrays: bool = (
        False  # takes vectors/matrices: the hooks get ``shapes=`` (workbook.functions.matrix)
    )
    # the unit rule when an argument is a run-time array (workbook.engine.runtime); None: refused
    runtime: Callable[..., ty.T] | None = None
    texts: bool = False  # takes text arguments (the unit rule checks each; else numbers only)
    sizes: bool = False  # reads only an array's size: the array may hold texts
    # complex arguments: "" refused at load; "complex": taken, the value complex when an
    # argument is; "real": taken, the value real (abs, Re, arg)
    complex: str = ""
    # the Excel formula when an argument is complex (Excel's IM* functions); None: not live
    complex_excel: Callable[..., tuple[str, int]] | None = None
    # the name of the mpmath function of one argument with numpy's meaning ("" if none)
    mpmath: str = ""
    # where the value is singular, for an integrand's singular points (numerics.singular): the
    # typed trees, given the typed call, that are 0 there (sqrt: its argument; tan: the cosine)
    singular: Callable[[ty.TFunc], tuple[ty.T, ...]] | None = None
    # where a step function jumps (numerics.switches): a smooth tree, given the typed call,
    # that is 0 at every jump (floor(u): sin(pi u)); None from it: no such tree for this call
    jumps: Callable[[ty.TFunc], ty.T | None] | None = None
    # where the value has a kink (numerics.switches): pairs (x, y), given the typed call, whose
    # difference x - y (x itself when y is None) is 0 there (abs: its argument; max: x - y)
    kinks: Callable[[ty.TFunc], tuple[tuple[ty.T, ty.T | None], ...]] | None = None
    angle: bool = False  # takes an angle (sin): the angle warnings read its argument
    # how its value's error is estimated (numerics.bench): "iterative", a method with an error
    # estimate (root, integral); "condition", from the values' condition number (lsolve)
    estimate: str = ""
    # how an approximate live Excel form computes, said beside its cell ("" when exact)
    live_note: str = ""
    # the interval enclosures of a one-argument built-in and of its derivative (functions.
    # interval_arith): root counts, certified extrema and integrands' features read them
    interval: tuple[Callable, Callable] | None = None
    # Mathcad's names of this built-in (Mathcad 15 and Prime: log10 is Mathcad's ``log``), the
    # operator element Mathcad writes it as (``absval``, ``summation``), and Mathcad's argument
    # positions in the order the language takes them (None: the same): the Mathcad importer
    # reads them
    mathcad: tuple[str, ...] = ()
    mathcad_operator: str = ""
    mathcad_order: tuple[int, ...] | None = None
    # Excel's worksheet functions and VBA's own functions that are this built-in, their
    # arguments in the same order (Excel's LOG of one argument is log10, VBA's Log is ln): the
    # Excel importer reads them
    excel_import: tuple[str, ...] = ()
    vba: tuple[str, ...] = ()

    @property
    def of_numbers(self) -> bool:
        """A function of plain numbers (no arrays, texts, sizes, bound variables, [data] columns
        or run-time hook): called with one vector or matrix, it applies to each element."""
        return not (
            self.arrays or self.texts or self.sizes or self.binds or self.runtime or self.data_args
        )

    def check_arity(self, n: int) -> None:
        """Raise a TemplateError if ``n`` arguments do not fit."""
        a = self.arity
        if a is None:
            if n < 1:
                raise TemplateError(f"{self.name}() needs at least one argument")
            return
        if isinstance(a, int):
            if n != a:
                raise TemplateError(f"{self.name}() takes {a} argument(s), got {n}")
            return
        lo, hi = a
        if n < lo or (hi is not None and n > hi):
            span = f"{lo} or more" if hi is None else f"{lo} to {hi}"
            raise TemplateError(f"{self.name}() takes {span} arguments, got {n}")


# Every built-in function by name, filled as the modules that define entries are imported.
# Read it as workbook.numerics.registry.REGISTRY, which imports all of them first (a module
# reading it from here could see only some).
ENTRIES: dict[str, Builtin] = {}


def register(entry: Builtin) -> Builtin:
    """Add a built-in; a name can be registered once."""
    if entry.name in ENTRIES:
        raise ValueError(f"built-in {entry.name}() is registered twice")
    ENTRIES[entry.name] = entry
    return entry


@dataclass(frozen=True)
class Builtins:
    """The built-in functions and constants a typer resolves names against (the complete
    registry is :data:`workbook.numerics.registry.BUILTINS`; the typer imports no registry)."""

    functions: dict[str, Builtin]
    constants: dict[str, Any]  # name -> workbook.functions.constants.Constant
    home: str = ""  # "module:name" of the one instance, by which it pickles (a typer does)

    def refuse_functions_named(self, names: dict[str, int | None], file: str) -> None:
        """A sheet's function, block, column, unknown or ODE state (``names``: name -> line
        in ``file``) may not have a built-in function's name."""
        for name, line in names.items():
            if name in self.functions:
                raise TemplateError(
                    f"'{name}' shadows the built-in function {name}(); choose another name",
                    file=file,
                    line=line,
                    definition=name,
                )

    def __reduce__(self):
        if not self.home:
            return super().__reduce__()
        return (_named, (self.home,))


def _named(home: str) -> Any:
    """The object ``home`` (``"module:name"``) names: the registry's instance, unpickled."""
    import importlib

    module, name = home.split(":")
    return getattr(importlib.import_module(module), name)
