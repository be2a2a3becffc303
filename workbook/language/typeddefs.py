"""The typed definitions of a loaded sheet, read without the typer.

The :class:`workbook.language.typecheck.Typer` keeps every tree it types in the plain dicts of
a :class:`TypedDefinitions` (``Typer.defs``): a scalar's body, a function and each of its
specializations, the function that stands for one typed only by its calls with vectors or
matrices, an [[ode]] section. The sheet types its definitions at load, so what computes and
writes it (the evaluator, the Excel printer, the numerics of bounds, kinks, derivatives and
references, the renderers' computed sheet) reads them here: no typer code runs after the load.
A tree not typed yet is a miss, and a miss asks the typer (so it types it, and the count of
``scripts/compute_calls.py`` shows it).

The reader also answers what the readers of a typed tree ask besides the trees: the sheet's
spec, the functions that call themselves (``recursive``) and the diff() calls recorded at load
(``derivatives``); :class:`workbook.numerics.symbolic.SympyConverter` converts the trees it
holds (``SympyConverter(SimpleNamespace(typer=defs, values={}))``).
"""

from __future__ import annotations

from typing import Any

from . import units as un
from .spec import SheetSpec
from .typed import T, TypedFunction


class TypedDefinitions:
    """The typed trees of one sheet's definitions (filled by its typer; see the module)."""

    def __init__(self, typer: Any, spec: SheetSpec) -> None:
        self.typer = typer  # asked on a miss
        self.spec = spec
        self.dimensionless = un.registry().dimensionless
        self.scalars: dict[str, T] = {}
        # functions and their specializations, by specialization key
        self.functions: dict[str, TypedFunction] = {}
        # a function with no typing at numbers -> the key of the specialization standing for it
        self.stand_ins: dict[str, str] = {}
        self.odes: dict[str, Any] = {}
        self.recursive: set[str] = set()  # specialization keys of functions that call themselves
        # diff() calls typed, by id of EXPR's typed tree (workbook.numerics.derivative)
        self.derivatives: dict[int, object] = {}

    def scalar(self, name: str) -> T:
        """The typed body of scalar definition ``name``."""
        found = self.scalars.get(name)
        return found if found is not None else self.typer.scalar(name)

    def function(self, name: str) -> TypedFunction:
        """Typed function ``name`` or one of its specializations by its key (as
        ``Typer.function``: a function typed only by its calls, the specialization that
        stands for it)."""
        found = self.functions.get(name)
        if found is None and name in self.stand_ins:
            found = self.functions.get(self.stand_ins[name])
        return found if found is not None else self.typer.function(name)

    def ode(self, name: str) -> Any:
        """The typed section ``[[ode]] name``."""
        found = self.odes.get(name)
        return found if found is not None else self.typer.ode(name)
