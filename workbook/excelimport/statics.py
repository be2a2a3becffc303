"""What is fixed when the workbook is imported: an exact ``VLOOKUP`` or
``HLOOKUP`` of a text that never changes (a text written in the formula or held by a constant
cell) over keys that are constants, and a column (row) given by ``MATCH(name, headers, 0)``.

Excel compares texts without case; the first key equal to the text is the row (the column), a
number or an empty key never equals a text, and no key equal to it is ``#N/A`` (an error
value). The cell found is read by its name, so its value stays live; which cell it is never
changes, since the texts never do. A ``MATCH`` whose text a formula computes is the position
Excel found, guarded: where the text computes to another one the value is an error. And the
pieces of a text that never changes, cut by ``TEXTSPLIT`` into a column.
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


def text_split(ft, args) -> str:
    """``TEXTSPLIT(text, , row_delimiter)`` (a column) of a text that never changes, at a
    delimiter written in the formula, in an array formula of as many cells as pieces: the pieces
    as Excel cuts them (at every occurrence, left to right, with case; empty pieces kept), texts
    that never change either. Into a row (``TEXTSPLIT(text, col_delimiter)``) it is refused."""
    from .formula_terms import text_problem
    from .kinds import static_text

    if len(args) not in (2, 3):
        raise FormulaProblem(f"TEXTSPLIT with {len(args)} arguments")
    seps = [a[2].name if a[:2] == ("leaf", "String") else None for a in args[1:]]
    given = [a[:2] != ("leaf", "Empty") for a in args[1:]]
    if given.count(True) != 1 or None in [s for s, g in zip(seps, given) if g]:
        raise FormulaProblem("TEXTSPLIT other than at one delimiter written in the formula")
    by_rows = given[-1] and len(args) == 3
    sep = seps[-1] if by_rows else seps[0]
    text = static_text(ft, args[0])
    if text is None:
        raise FormulaProblem("TEXTSPLIT of a text a formula computes")
    if not sep:
        raise FormulaProblem("TEXTSPLIT at an empty delimiter (#VALUE! in Excel)")
    pieces = text.split(sep)
    for piece in pieces:
        problem = text_problem(piece)
        if problem:
            raise FormulaProblem(problem)
    shape = (len(pieces), 1) if by_rows else (1, len(pieces))
    if shape[0] == 1:  # a row's cells read the array by a condition, whose value is a number
        raise FormulaProblem("TEXTSPLIT into a row (texts in a row of an array formula)")
    if ft.block != shape:
        raise FormulaProblem(
            f"TEXTSPLIT whose {shape[0]}x{shape[1]} pieces are not shown in as many cells"
        )
    quoted = [f'"{p}"' for p in pieces]
    rows = [[q] for q in quoted] if by_rows else [quoted]
    return "[" + ", ".join("[" + ", ".join(r) + "]" for r in rows) + "]"
