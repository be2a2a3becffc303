"""Excel's information functions ISBLANK, ISNUMBER, ISTEXT, ISNONTEXT, ISLOGICAL, ISERROR and
ISERR, where the answer is certain (else the cell is listed, with the reason).

- ``ISBLANK(ref)`` of one cell is TRUE only for a cell with nothing in it: a formula cell is
  never blank (even where it gives ""), nor is a constant. The answer is known at import from
  what the cell is: a formula or a constant cell gives 1 == 0, an empty cell 1 == 1, where
  the empty cell stays empty in the worksheet: not an input (a value given to the input would
  make it not blank; ``book.py`` lists the formula then) and not a cell a VBA Sub writes.
- ``ISNUMBER``, ``ISTEXT``, ``ISNONTEXT`` and ``ISLOGICAL`` of a value whose kind ``kinds.py``
  knows (a formula that always gives a number, a constant text, a comparison): the value is
  still computed (``x == x``, or ``x != x`` for FALSE), so an error of x leaves the cell
  without a value (Excel's ISNUMBER of an error is FALSE: no value, never a wrong one). Of an
  empty cell the same rule as ISBLANK holds. Of a TRUE/FALSE constant cell (an input that may
  be given a number) or a value of unknown kind the cell is listed.

``ISBLANK`` of a value that is never a reference (a number or text written in the formula,
arithmetic, ``&``, a comparison, ``VLOOKUP``, ``HLOOKUP``, ``MATCH``: VLOOKUP of an empty cell
gives 0) is FALSE, as in Excel, whatever the value (an error value too). A range argument
(Excel's implicit intersection, or an array), a defined name that is a formula, a function
that may give a reference (``INDIRECT``, ``OFFSET``, ``INDEX``, ``CHOOSE``, ``IF``, a VBA
function) or any other argument is listed.

``ISERROR(x)`` and ``ISERR(x)`` of the arithmetic IFERROR takes (cells and numbers joined by
+ - * /, ^ by a number, SQRT, LN, LOG10, ABS) are the conditions under which x is an error
value (a divisor 0, a root of a negative number...), or x != x, x computed. ISNA, and either
of any other x (a lookup, a VBA function), are listed.
"""

from __future__ import annotations

from .formula_terms import FormulaProblem, row_relative

INFORMATION = {"ISBLANK", "ISNUMBER", "ISTEXT", "ISNONTEXT", "ISLOGICAL", "ISERROR", "ISERR"}

#: for each function, the kinds of value for which it is TRUE
_TRUE_FOR = {
    "ISNUMBER": {"number"},
    "ISTEXT": {"text"},
    "ISNONTEXT": {"number", "empty", "bool"},
    "ISLOGICAL": {"bool"},
}


def information(ft, upper: str, args) -> str:
    """The condition (``1 == 1``, ``x == x``...) Excel's IS-function gives."""
    if len(args) != 1:
        raise FormulaProblem(f"{upper} with {len(args)} arguments")
    (node,) = args
    if upper == "ISBLANK":
        return _blank(ft, node)
    if upper in ("ISERROR", "ISERR"):
        return _error(ft, upper, node)
    if _one_cell(ft, node) is not None:
        cell_kinds = _cell_kinds(ft, node)
        if cell_kinds == {"empty"}:
            truth = "1 == 1" if "empty" in _TRUE_FOR[upper] else "1 == 0"
            return _assume_empty(ft, upper, node, truth)
        if "empty" in cell_kinds:
            raise FormulaProblem(
                f"{upper} of a cell that is empty in some rows of the filled-down column and "
                "not in others"
            )
        _not_written(ft, node, f"{upper} of a cell that the macro Sub {{sub}} writes")
        cell = ft.book.cell(*_one_cell(ft, node))
        if cell is not None and cell.formula is None and isinstance(cell.value, bool):
            raise FormulaProblem(
                f"{upper} of a TRUE/FALSE cell (an input of the worksheet, which may be given a "
                "number)"
            )
    found = _sure_kind(ft, node, 0)
    if found is None or found == "empty":
        raise FormulaProblem(f"{upper} of a value whose kind (number, text...) is not known")
    x = ft.value(node, 3)
    return f"{x} == {x}" if found in _TRUE_FOR[upper] else f"{x} != {x}"


def _error(ft, upper: str, node) -> str:
    """``ISERROR(x)`` (``ISERR``: the errors of arithmetic are never #N/A) of the arithmetic
    IFERROR takes: the conditions under which x is an error value, then x itself, so that a
    cell of x that has no value leaves the formula without one (never FALSE in its place)."""
    errors: list[str] = []
    if upper == "ISERR" and _calls_lookup(node):
        raise FormulaProblem("ISERR of a lookup (its #N/A is no error to ISERR)")
    try:
        ft.arithmetic_only(node, errors)
    except FormulaProblem:
        raise FormulaProblem(
            f"{upper} of other than + - * /, ^ by a number, the functions IFERROR takes and exact "
            "lookups of numbers and cells (where else Excel's value is an error is not known here)"
        ) from None
    x = ft.value(node, 3)
    return " or ".join([f"({e})" for e in dict.fromkeys(errors)] + [f"{x} != {x}"])


def _calls_lookup(node) -> bool:
    kind, name, payload = node
    if kind == "fn" and name.upper() in ("VLOOKUP", "HLOOKUP", "MATCH"):
        return True
    return kind in ("fn", "op") and any(_calls_lookup(a) for a in payload)


def _sure_kind(ft, node, depth: int) -> str | None:
    """The kind of value ``node`` always gives, from its form (never from a cached value: a
    formula such as ``VLOOKUP`` may give a text where it gave a number): a number or text
    written, arithmetic (a number), ``&`` (a text), a comparison (TRUE/FALSE), a function that
    gives one kind; of a cell, a constant's own kind, a formula cell's by its formula's form
    (in every row of a filled-down column); None where it is not sure."""
    from .kinds import NUMBER_FUNCTIONS, TEXT_FUNCTIONS, cell_kind, kind

    what, name, payload = node
    if depth > 12:
        return None
    if what == "leaf" and name == "Range":
        if _one_cell(ft, node) is None:
            return None
        kinds = set()
        for key in _rows(ft, node):
            cell = ft.book.cell(*key)
            if cell is None or cell.formula is None:
                kinds.add(cell_kind(cell))
                continue
            tree = getattr(ft.book, "trees", {}).get(key)
            if tree is None or cell.array is not None:
                return None
            kinds.add(_sure_kind(_reader_of(ft, key[0]), tree, depth + 1))
        return kinds.pop() if len(kinds) == 1 else None
    if what == "leaf" or what == "op":
        return kind(ft, node)
    upper = name.upper()
    if upper in NUMBER_FUNCTIONS:
        return "number"
    if upper in TEXT_FUNCTIONS:
        return "text"
    if upper in INFORMATION:
        return "bool"
    return None


def _reader_of(ft, sheet: str):
    """A translator of another cell's formula on ``sheet``, to read its form."""
    from .kinds import cell_reader

    return cell_reader(ft, sheet)


def _one_cell(ft, node) -> tuple[str, int, int] | None:
    """The cell a reference to one cell names (the first row's, of a filled-down column)."""
    if node[0] == "leaf" and node[1] == "Range" and not ft.is_name_formula(node[2]):
        ref = ft.ref_of(node[2])
        if ref.single:
            return (ref.sheet, ref.r1, ref.c1)
    return None


def _rows(ft, node) -> list[tuple[str, int, int]]:
    key = _one_cell(ft, node)
    assert key is not None
    if key in ft.moving and row_relative(node[2]):
        return [(key[0], key[1] + k, key[2]) for k in range(ft.rows)]
    return [key]


#: Excel's functions whose result is a value, never a reference (VLOOKUP gives the cell's
#: value, 0 for an empty one): INDEX, OFFSET, INDIRECT, CHOOSE, IF, XLOOKUP and a VBA function
#: may give a reference, so they are not here
_VALUE_FUNCTIONS = {"VLOOKUP", "HLOOKUP", "MATCH", "CONCATENATE", "LEN", "ROUND", "ABS", "SUM"}
_VALUE_OPS = {"+", "-", "*", "/", "^", "u-", "u+", "%", "&", "=", "<>", "<", ">", "<=", ">="}


def _a_value(node) -> bool:
    """Whether ``node`` gives a value, never a reference (so ISBLANK of it is FALSE, even where
    it is an error value: an IS-function gives TRUE or FALSE of any value)."""
    what, name, _ = node
    if what == "leaf":
        return name in ("Number", "String")
    if what == "op":
        return name in _VALUE_OPS
    return name.upper() in _VALUE_FUNCTIONS


def _what(cell) -> str:
    if cell is None or (cell.value is None and cell.formula is None):
        return "empty"
    return "formula" if cell.formula is not None else "constant"


def _cell_kinds(ft, node) -> set[str]:
    from .kinds import cell_kind

    out = set()
    for key in _rows(ft, node):
        what = _what(ft.book.cell(*key))
        out.add("empty" if what == "empty" else cell_kind(ft.book.cell(*key)) or "unknown")
    return out


def _blank(ft, node) -> str:
    if _one_cell(ft, node) is None:
        if _a_value(node):
            return "1 == 0"  # a value, never a reference: never blank, nor an error here
        if node[0] == "leaf" and node[1] == "Range":
            raise FormulaProblem("ISBLANK of a range or a defined name that is no one cell")
        raise FormulaProblem(
            "ISBLANK of other than a reference to one cell (a value, or a cell that a function "
            "such as INDIRECT or OFFSET names)"
        )
    found = {_what(ft.book.cell(*key)) for key in _rows(ft, node)}
    if found == {"empty"}:
        return _assume_empty(ft, "ISBLANK", node, "1 == 1")
    if "empty" in found:
        raise FormulaProblem(
            "ISBLANK of a cell that is empty in some rows of the filled-down column and not in "
            "others"
        )
    _not_written(
        ft, node, "ISBLANK of a cell that the macro Sub {sub} writes (it may leave it empty)"
    )
    return "1 == 0"  # a formula cell, or a constant: never blank


def _not_written(ft, node, message: str) -> None:
    """Refuse (``message``, its ``{sub}`` the Sub) where a VBA Sub writes a cell of ``node``."""
    for key in _rows(ft, node):
        sub = ft.book.sub_written.get(key)
        if sub is not None:
            raise FormulaProblem(message.format(sub=sub))


def _assume_empty(ft, upper: str, node, truth: str) -> str:
    """An answer that holds while the empty cell stays empty: not a cell a Sub writes, and
    (checked by book.py over the whole worksheet) not an input."""
    _not_written(ft, node, f"{upper} of an empty cell that the macro Sub {{sub}} writes")
    ft.out.empty_cells.extend(_rows(ft, node))
    return truth
