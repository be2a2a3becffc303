"""Lookups whose answer is fixed when the workbook is imported: an exact ``VLOOKUP`` or
``HLOOKUP`` of a text that never changes (a text written in the formula or held by a constant
cell) over keys that are constants, and a column (row) given by ``MATCH(name, headers, 0)``.

Excel compares texts without case; the first key equal to the text is the row (the column), a
number or an empty key never equals a text, and no key equal to it is ``#N/A`` (an error
value). The cell found is read by its name, so its value stays live; which cell it is never
changes, since the texts never do. A ``MATCH`` whose text a formula computes is the position
Excel found, guarded: where the text computes to another one the value is an error.
"""

from __future__ import annotations

from .formula_terms import FormulaProblem

#: keys read at most to find a text (one comparison each, when imported)
MAX_STATIC_KEYS = 100_000


def position(ft, node) -> tuple[int, str | None]:
    """(k, guard): a column or row number written in the formula (guard None), or
    ``MATCH(x, headers, 0)`` over constant texts, as Excel found it (a guard where x is not a
    text that never changes)."""
    from .formula_terms import written_number
    from .kinds import static_text

    written = written_number(node)
    if written is not None:
        if written != int(written):
            raise FormulaProblem("a lookup of a column that is not a whole number")
        return int(written), None
    if node[0] == "fn" and node[1].upper() == "MATCH":
        k = int(ft.match(node[2]))
        lookup = node[2][0]
        return k, None if static_text(ft, lookup) is not None else ft.guard(node, k)
    raise FormulaProblem("a lookup of a column not written as a number or an exact MATCH")


def found(ft, x_node, keys: list[tuple[str, int, int]]) -> int | None:
    """The index of the first key equal to x without case (-1: none, Excel's #N/A), where x is
    a text that never changes; None where it is not one (the lookup is translated otherwise)."""
    from .kinds import static_text

    x = static_text(ft, x_node)
    if x is None:
        return None
    if len(keys) > MAX_STATIC_KEYS:
        raise FormulaProblem(f"a lookup over more than {MAX_STATIC_KEYS:,} keys")
    if any(ch in x for ch in "*?~"):
        raise FormulaProblem("a lookup of a text with a pattern (* ? ~)")
    want = x.casefold()
    for i, (sheet, r, c) in enumerate(keys):
        cell = ft.book.cell(sheet, r, c)
        if cell is None or cell.value is None:
            continue
        if cell.formula is not None:
            raise FormulaProblem("a lookup of a text over keys that formulas compute")
        if isinstance(cell.value, str) and cell.value.casefold() == want:
            return i
    return -1


def guarded(text: str, guard: str | None) -> str:
    return text if guard is None else f"({text} if {guard} otherwise 1/0)"
