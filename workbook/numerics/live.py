"""How far a live Excel form of a numerical built-in is from the engine's value (a comment)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..language import typed as ty
from ._common import live_forms

#: built-ins whose Excel form is live but approximate
APPROXIMATE = {
    "integral": "a 20-point Gauss-Legendre sum (SUMPRODUCT over constant nodes)",
    "root": "60 bisection steps on the sheet 'Solver steps' (in a table, a chain per table "
    "row on 'Solver rows'; #N/A when f(A) and f(B) have the same sign; with more than one "
    "root in [A, B] it may find another one than the engine)",
    **{
        name: "samples at 4 x samples + 1 points and 60 golden-section steps around the best "
        "one, on the sheet 'Solver steps' or, in a table, 'Solver rows' (with two peaks "
        "nearly as high it may find another one than the engine)"
        + (
            "; where the extremum is, the workbook finds to about 1e-6 relative (values of "
            "EXPR within 1e-12 count as equal in its steps, so that another spreadsheet's "
            "rounding takes the same steps; the function is flat there), the engine to "
            "about 1e-8"
            if name.startswith("arg")
            else ""
        )
        for name in ("maximum", "minimum", "argmax", "argmin")
    },
}


def _approximate(sheet, t: ty.T) -> set[str]:
    found, stack, seen = set(), [t], set()
    while stack:
        n = stack.pop()
        if isinstance(n, ty.TFunc) and n.func in APPROXIMATE:
            found.add(n.func)
        if isinstance(n, ty.TCall) and n.name not in seen:
            seen.add(n.name)
            stack.append(sheet.typer.function(n.name).body)
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
        forms = "; ".join(f"{name}() is {APPROXIMATE[name]}" for name in self.forms)
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
