"""The typed sheet: the typed trees of a loaded sheet besides its definitions (which the
:class:`workbook.language.typecheck.Typer` keeps), typed at load and read by the compute stage.

Table columns and chart series (in the unit they are shown in), range bounds and a log
range's number of points, declared checks (value, condition, every placeholder) and the
formulas of printed values are typed once, when the sheet loads (``Sheet.check_units``), and
kept here by the item of the spec they belong to. Typing does not depend on input values, so
the Sheets of other inputs or parts (``with_inputs``, ``with_parts``) share one typed sheet.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable
from typing import Any

from .typed import T


class TypedSheet:
    """Typed trees by the spec item they belong to and a key (see the module's docstring)."""

    def __init__(self) -> None:
        # (id of the item, key) -> (the item, kept alive so that its id is not reused; the tree)
        self._trees: dict[tuple[int, Hashable], tuple[Any, Any]] = {}

    def tree(self, item: object, key: Hashable, make: Callable[[], T]) -> Any:
        """The typed tree of ``item`` under ``key``: ``make()`` types it the first time (an
        error is raised and nothing kept, so it is raised again where it was)."""
        k = (id(item), key)
        found = self._trees.get(k)
        if found is None:
            found = self._trees[k] = (item, make())
        return found[1]

    def __len__(self) -> int:
        return len(self._trees)
