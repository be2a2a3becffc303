"""How far a live Excel form of a numerical built-in is from the engine's value (a comment)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..functions.numerical import live_forms
from ..language import typed as ty


def _live_note(name: str) -> str:
    """How the approximate live Excel form of built-in ``name`` computes ("" when exact)."""
    from .registry import REGISTRY  # imported here: the registry imports numerics

    entry = REGISTRY.get(name)
    return entry.live_note if entry is not None else ""


def _approximate(sheet, t: ty.T) -> set[str]:
    found, stack, seen = set(), [t], set()
    while stack:
        n = stack.pop()
        if isinstance(n, ty.TFunc) and _live_note(n.func):
            found.add(n.func)
        if isinstance(n, ty.TCall) and n.name not in seen:
            seen.add(n.name)
            stack.append(sheet.defs.function(n.name).body)
        stack.extend(ty.children(n))
    return found


@dataclass(frozen=True)
class Difference:
    """How far the live form of a cell (or a column) is from the engine at the written inputs."""

    forms: tuple[str, ...]  # the approximate built-ins in it: integral, root, ...
    largest: float  # largest absolute difference
    relative: float
    value: float | None = None  # the live form's value, for one cell

    @property
    def note(self) -> str:
        """The cell comment: which form, and how far it is from the engine."""
        forms = "; ".join(f"{name}() is {_live_note(name)}" for name in self.forms)
        return (
            f"Live formula: {forms}. At the inputs written here it differs from the engine's "
            f"value by {self.largest:.2g} ({self.relative:.1g} relative); the engine's value "
            "has an error below the sheet's tolerance."
        )


def difference(sheet, t: ty.T, env: dict, values) -> Difference | None:
    """The live form's largest difference from the engine's ``values`` at the written inputs
    (None when the formula holds no approximate live form)."""
    found = _approximate(sheet, t)
    if not found:
        return None
    with live_forms():
        approx = np.asarray(sheet.evaluator.compile(t)(env), dtype=float)
    values = np.asarray(values, dtype=float)
    diff = float(np.max(np.abs(approx - values)))
    scale = float(np.max(np.abs(values))) or 1.0
    value = float(approx) if approx.ndim == 0 else None
    return Difference(tuple(sorted(found)), diff, diff / scale, value)
