"""An evaluated table as the Sheet fills it: its columns' values in their units, and the rows
that failed (read by the compute stage's ComputedSheet and the Excel form)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np
    import pint

    from ..language.typed import T


@dataclass
class Column:
    """One evaluated table column: values in ``unit``."""

    title: str
    unit: pint.Unit
    values: np.ndarray
    typed: T | None  # None for the range variable itself
    text: str
    failed: dict[int, str] = field(default_factory=dict)  # row -> why it has no value (NaN)

    def excel_error(self, row: int) -> str:
        """The Excel error value of a failed row: #DIV/0! for a division by zero, else #NUM!."""
        return "#DIV/0!" if "division by zero" in self.failed[row] else "#NUM!"


@dataclass
class TableData:
    name: str
    title: str
    var: str
    var_unit: pint.Unit
    columns: list[Column]  # the first is the range variable
