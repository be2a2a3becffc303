"""Defined names of one workbook, assigned under Excel's rules.

Excel reads a defined name case-insensitively (``d`` and ``D`` are one name: after the first
recalculation ``=D/d`` is 1), allows at most 255 characters, and reads names like ``A1``,
``XFD1``, ``R1C1``, ``R``, ``C`` as cell references, and a name spelt as a function
(``rate``) or as one of its built-in names (``Print_Area``) as that one. :class:`ExcelNames`
gives every worksheet name a defined name that is valid and unique among all of them; a
name that had to change is listed in :attr:`ExcelNames.renamed` so that the writer can say so
(a comment on the cell, and a list on the About sheet).
"""

from __future__ import annotations

import re
from collections.abc import Iterable

from .excel_functions import FUNCTIONS

MAX_NAME = 255  # Excel's limit on the length of a defined name

_CELL = re.compile(r"^[A-Za-z]{1,3}[0-9]+$")  # A1 .. XFD1048576 (and beyond: refused too)
_R1C1 = re.compile(r"^([Rr][0-9]*)?([Cc][0-9]*)?$")  # R, C, R1, C1, R1C1, RC
# Excel's built-in names (a workbook's print area, autostart macros, filters...): a defined
# name spelt so would be read as the built-in one.
BUILTIN_NAMES = frozenset(
    "Auto_Open Auto_Close Auto_Activate Auto_Deactivate Consolidate_Area Criteria Data_Form "
    "Database Extract Print_Area Print_Titles Recorder Sheet_Title _FilterDatabase".split()
)
# Names a defined name must not take (case-insensitively): every Excel function (LibreOffice
# reads some of them without brackets; TRUE and FALSE are among them) and the built-in names.
RESERVED = frozenset(
    [name.lower() for name in FUNCTIONS] + [name.lower() for name in BUILTIN_NAMES]
)


def needs_change(name: str) -> bool:
    """True when Excel would not read ``name`` as a defined name of its own."""
    return (
        bool(_CELL.match(name) or _R1C1.match(name))
        or name.lower() in RESERVED
        or len(name) == 1
        or len(name) > MAX_NAME
    )


def single(name: str) -> str:
    """The defined name for ``name`` alone (no other names to avoid): ``R1`` -> ``R1_``."""
    if len(name) > MAX_NAME:
        return name[: MAX_NAME - 1] + "_"
    return name + "_" if needs_change(name) else name


class ExcelNames:
    """Defined names for all the worksheet names of one workbook.

    Names that Excel reads as they are keep their spelling; the first of names equal but for
    case keeps it too. Every other name gets ``NAME_`` or, if that is taken (case-insensitively),
    ``NAME_2``, ``NAME_3``, ...; a name over 255 characters is shortened first.
    """

    def __init__(self, names: Iterable[str]):
        self.mapping: dict[str, str] = {}
        self._taken: set[str] = set()
        self._next: dict[str, int] = {}  # base -> the first suffix not tried yet
        self._alike: dict[str, list[str]] | None = None
        names = list(dict.fromkeys(names))
        for name in names:  # first pass: names that are fine as they are
            if not needs_change(name) and name.lower() not in self._taken:
                self._claim(name, name)
        for name in names:
            if name not in self.mapping:
                self._claim(name, self._free(name))

    def _claim(self, name: str, xname: str) -> None:
        self.mapping[name] = xname
        self._taken.add(xname.lower())

    def _free(self, name: str) -> str:
        base = name[: MAX_NAME - 8]
        # a suffix tried once stays taken or unfit, whatever the case of the base (both are
        # read ignoring case): the next name of this base starts after it (5,000 names spelt
        # alike but for case tried 12 million suffixes)
        key = base.lower()
        for n in range(self._next.get(key, 1), 10_000_000):
            candidate = f"{base}_" if n == 1 else f"{base}_{n}"
            if candidate.lower() not in self._taken and not needs_change(candidate):
                self._next[key] = n + 1
                return candidate
        raise RuntimeError("no free defined name")  # pragma: no cover - 10^7 names

    def __getitem__(self, name: str) -> str:
        return self.mapping[name]

    def get(self, name: str, default: str | None = None) -> str | None:
        return self.mapping.get(name, default)

    @property
    def renamed(self) -> dict[str, str]:
        """Worksheet name -> defined name, for the names that had to change."""
        return {k: v for k, v in self.mapping.items() if k != v}

    def why(self, name: str) -> str:
        """Why ``name`` was renamed, for a cell comment."""
        xname = self.mapping[name]
        if len(name) > MAX_NAME:
            reason = f"Excel's names have at most {MAX_NAME} characters"
        elif needs_change(name):
            reason = f"Excel reads '{name}' as a cell reference, a function or a built-in name"
        else:
            reason = "Excel's names ignore case, and another name of this sheet is spelt alike"
        if self._alike is None:  # names by their lower case, in order (built once)
            self._alike = {}
            for k in self.mapping:
                self._alike.setdefault(k.lower(), []).append(k)
        clash = [k for k in self._alike.get(name.lower(), ()) if k != name]
        if clash:
            reason = f"Excel's names ignore case: '{name}' and '{clash[0]}' would be one name"
        return f"Defined name {xname} ({reason})"
