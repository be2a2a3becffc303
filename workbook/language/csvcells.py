"""Texts in CSV cells that a spreadsheet opens: the one escape rule, for writing printed
values and tables, and its reverse, for reading printed values back."""

from __future__ import annotations

# The characters that make a spreadsheet read a cell as a formula (with the full-width forms
# some spreadsheets also accept), and the ones that may come before them unnoticed.
FORMULA_STARTS = frozenset("=+-@\uff1d\uff0b\uff0d\uff20")
CONTROL_STARTS = frozenset("\t\r\n")


def csv_text(text: str) -> str:
    """``text`` safe for a CSV cell that a spreadsheet opens: a text whose first character
    that is not a space is = + - @ (or their full-width forms), or that starts with a tab, CR
    or LF, gets a leading apostrophe."""
    first = text.lstrip(" \t\r\n\u00a0\u3000")[:1]
    if text[:1] in CONTROL_STARTS or first in FORMULA_STARTS:
        return "'" + text
    return text


def unescaped(cell: str) -> str:
    """A cell's text without the apostrophe :func:`csv_text` put before it (other texts as
    they are)."""
    if cell.startswith("'") and csv_text(cell[1:]) == cell:
        return cell[1:]
    return cell
