"""The typed sheet: the typed trees of a loaded sheet besides its definitions (which the
typer keeps in :class:`workbook.language.typeddefs.TypedDefinitions`), typed at load and read
by the compute stage.

Table columns and chart series (in the unit they are shown in), range bounds and a log
range's number of points, declared checks (value, condition, every placeholder) and the
formulas of printed values are typed once, when the sheet loads (``Sheet.check_units``), and
kept here by the item of the spec they belong to. The Sheet and the declared checks ask
(:meth:`TypedSheet.get`) and type and keep what is not there: no callback, so the walk of a
load does not climb back up through here. Typing does not depend on input values, so the
Sheets of other inputs or parts (``with_inputs``, ``with_parts``) share one typed sheet; the
rows of a printed-values file are read once (:func:`printed_rows`).
"""

from __future__ import annotations

from collections.abc import Hashable
from typing import Any

from ..errors import WorkbookError
from .printed import PrintedRow, read_printed
from .spec import PrintedSpec


class TypedSheet:
    """Typed trees by the spec item they belong to and a key (see the module's docstring)."""

    def __init__(self) -> None:
        # (id of the item, key) -> (the item, kept alive so that its id is not reused; the tree)
        self._trees: dict[tuple[int, Hashable], tuple[Any, Any]] = {}

    def get(self, item: object, key: Hashable) -> Any:
        """The tree kept for ``item`` under ``key``, or None when none is."""
        found = self._trees.get((id(item), key))
        return None if found is None else found[1]

    def keep(self, item: object, key: Hashable, tree: Any) -> Any:
        """Keep ``tree`` for ``item`` under ``key``; returns it."""
        self._trees[(id(item), key)] = (item, tree)
        return tree

    def __len__(self) -> int:
        return len(self._trees)


def printed_rows(spec: PrintedSpec) -> list[PrintedRow]:
    """The rows of a printed-values file, read once (``PrintedSpec.read``); a file that cannot
    be read raises its error each time it is asked."""
    if spec.read is None:
        try:
            spec.read = read_printed(spec)
        except WorkbookError as err:
            spec.read = err
    if isinstance(spec.read, WorkbookError):
        raise spec.read.reworded(spec.read.message)
    return spec.read
