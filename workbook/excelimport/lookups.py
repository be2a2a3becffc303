"""Excel's MATCH, INDEX and HLOOKUP as chains of conditions over the cells they read.

``MATCH(x, keys, 0)`` is the position of the first key equal to x, ``MATCH(x, keys[, 1])`` of
the last key at most x and ``MATCH(x, keys, -1)`` of the last key at least x — Excel's answers
where the keys ascend (descend), so those chains are guarded by the keys ascending (descending)
strictly: elsewhere, and where nothing matches (#N/A), the value is an error. Keys are constant
cells; texts are compared by Excel's rule (without case) only where x is a text written in the
formula or a constant text cell (whose case and patterns, ``*`` ``?`` ``~``, are then known);
an empty key cell never matches, nor does a text key an exact match of a number written in the
formula or held by a constant cell. ``INDEX(range, i[, j])`` is the cell at (i, j), a chain over
i and j: an index outside the range is an error (#REF!). ``HLOOKUP`` is VLOOKUP by rows.
``OFFSET(cell, MATCH(...) + k, m)`` (or the MATCH in the columns) is the same chain over the
cells the offset reaches at each position."""

from __future__ import annotations

import re

from .formula_terms import FormulaProblem, Ref, written_number

#: cells that one lookup reads at most (a chain of as many conditions)
MAX_LOOKUP_CELLS = 200


def _range(ft, node, what: str) -> Ref:
    if node[0] != "leaf" or node[1] != "Range" or ft.is_name_formula(node[2]):
        raise FormulaProblem(f"{what} of other than a range")
    ref = ft.ref_of(node[2])
    if (ref.r2 - ref.r1 + 1) * (ref.c2 - ref.c1 + 1) > MAX_LOOKUP_CELLS:
        raise FormulaProblem(f"{what} over more than {MAX_LOOKUP_CELLS} cells")
    return ref


def _cells(ref: Ref) -> list[tuple[int, int]]:
    return [(r, c) for r in range(ref.r1, ref.r2 + 1) for c in range(ref.c1, ref.c2 + 1)]


def _match_keys(ft, args) -> tuple[float, list[tuple[int, str | None]]]:
    """(type, keys) of ``MATCH(x, keys[, type])``'s arguments (of 2 or 3)."""
    kind = 1.0 if len(args) == 2 else written_number(args[2])
    if kind not in (-1.0, 0.0, 1.0):
        raise FormulaProblem("MATCH whose type is not written as -1, 0 or 1")
    ref = _range(ft, args[1], "MATCH")
    if ref.r1 != ref.r2 and ref.c1 != ref.c2:
        raise FormulaProblem("MATCH in a block of rows and columns (#N/A in Excel)")
    return kind, _keys(ft, ref, args[0], exact=kind == 0)


def match(ft, args) -> str:
    """``MATCH(x, keys[, type])`` as a chain giving the position (from 1)."""
    if len(args) not in (2, 3):
        raise FormulaProblem(f"MATCH with {len(args)} arguments")
    kind, keys = _match_keys(ft, args)
    return _chain(ft, args[0], keys, kind, [str(k) for k in range(1, len(keys) + 1)])


def _keys(ft, ref: Ref, x_node, exact: bool) -> list[tuple[int, str | None]]:
    """(position, the key's name or None for an empty cell) of the cells of ``ref``; texts
    only for an exact match of a known text x."""
    seen = _known_text(ft, x_node)
    out: list[tuple[int, str | None]] = []
    folded: dict[str, str] = {}
    for k, (r, c) in enumerate(_cells(ref), start=1):
        cell = ft.book.cell(ref.sheet, r, c)
        if cell is None or cell.value is None:
            out.append((k, None))
            continue
        if cell.formula is not None:
            raise FormulaProblem("a lookup whose keys are formula cells")
        value = cell.value
        if isinstance(value, bool):
            raise FormulaProblem("a lookup whose keys hold TRUE/FALSE")
        if isinstance(value, str) and seen is None and exact and known_number(ft, x_node):
            out.append((k, None))  # a text never equals a number: as an empty cell
            continue
        if isinstance(value, str):
            if not exact or seen is None:
                raise FormulaProblem(
                    "a lookup of texts other than an exact one of a text the formula shows"
                )
            low = value.casefold()
            if low in folded and folded[low] != value:
                raise FormulaProblem("a lookup whose texts differ only by case")
            folded[low] = value
            # Excel's rule applied here: the key whose text equals x's without case
            out.append((k, '"1"' if low == seen.casefold() else '"0"'))
            continue
        if seen is not None:
            out.append((k, '"0"'))  # a text never equals a number
            continue
        ft.out.refs.append(Ref(ref.sheet, r, c, r, c))
        out.append((k, ft.name_of(ref.sheet, r, c)))
    return out


def known_number(ft, node) -> bool:
    """x is a number whatever the inputs: written in the formula, or a constant number cell
    (an input of the translation, which stays a number)."""
    if written_number(node) is not None:
        return True
    if node[0] == "leaf" and node[1] == "Range" and not ft.is_name_formula(node[2]):
        ref = ft.ref_of(node[2])
        cell = ft.book.cell(ref.sheet, ref.r1, ref.c1) if ref.single else None
        return (
            cell is not None
            and cell.formula is None
            and isinstance(cell.value, (int, float))
            and not isinstance(cell.value, bool)
        )
    return False


def _known_text(ft, node) -> str | None:
    """The text x is, when the formula writes it or it is a constant text cell (None if x is
    not a known text); a pattern is refused."""
    text = None
    if node[0] == "leaf" and node[1] == "String":
        text = node[2].name
    elif node[0] == "leaf" and node[1] == "Range" and not ft.is_name_formula(node[2]):
        ref = ft.ref_of(node[2])
        cell = ft.book.cell(ref.sheet, ref.r1, ref.c1) if ref.single else None
        if cell is not None and cell.formula is None and isinstance(cell.value, str):
            text = cell.value
    if text is not None and re.search(r"[*?~]", text):
        raise FormulaProblem("a lookup of a text with a pattern (* ? ~)")
    return text


def _chain(ft, x_node, keys, kind: float, results: list[str], none: str = "1/0") -> str:
    """The chain of conditions: ``results[k - 1]`` where key k is the match (``none``, an
    error value of the results' kind, where there is no such result, as Excel's #REF!)."""
    pick = [results[k - 1] if k <= len(results) else none for k in range(1, len(keys) + 1)]
    present = [(k, name) for k, name in keys if name is not None]
    if _known_text(ft, x_node) is not None:  # a constant text: the match is known here
        if kind != 0:
            raise FormulaProblem("an approximate lookup of a text")
        return next((pick[k - 1] for k, name in present if name == '"1"'), none)
    x = ft.value(x_node, 3)
    if kind == 0:
        text = none
        for k, name in reversed(present):
            text = f"({pick[k - 1]} if {x} == {name} otherwise {text})"
        return text
    if len(present) != len(keys):
        raise FormulaProblem("an approximate lookup over empty cells")
    op, order = (">=", "<") if kind == 1 else ("<=", ">")
    text = none
    for k, name in present:
        text = f"({pick[k - 1]} if {x} {op} {name} otherwise {text})"
    names = [name for _, name in present]
    guard = " and ".join(f"{a} {order} {b}" for a, b in zip(names, names[1:])) or "1 == 1"
    return f"({text} if {guard} otherwise {none})"


def _no_value(ft, ref: Ref) -> str:
    """An error value of the kind of the cells of ``ref``: ``num2str(1/0)`` (a text that has
    no value) where every cell holds a text, else ``1/0``."""
    values = [getattr(ft.book.cell(ref.sheet, r, c), "value", None) for r, c in _cells(ref)]
    return "num2str(1/0)" if all(isinstance(v, str) for v in values) else "1/0"


def index(ft, args) -> str:
    """``INDEX(range, i[, j])``: the cell at row i and column j of the range (of a row or a
    column, i counts along it), a chain over the indices."""
    if len(args) not in (2, 3):
        raise FormulaProblem(f"INDEX with {len(args)} arguments")
    ref = _range(ft, args[0], "INDEX")
    rows, cols = ref.r2 - ref.r1 + 1, ref.c2 - ref.c1 + 1
    if len(args) == 2 and rows > 1 and cols > 1:
        raise FormulaProblem("INDEX of a block by one index (a whole row in Excel)")
    if any(a[0] == "leaf" and a[1] == "Empty" for a in args[1:]):
        raise FormulaProblem("INDEX of a whole row or column")
    cells = []
    for r, c in _cells(ref):
        ft.out.refs.append(Ref(ref.sheet, r, c, r, c))
        cells.append(ft.name_of(ref.sheet, r, c))
    pos = args[1]
    if len(args) == 2 and pos[0] == "fn" and pos[1].upper() == "MATCH" and len(pos[2]) in (2, 3):
        m = pos[2]  # INDEX(range, MATCH(x, keys, type)): one chain over the keys
        kind, keys = _match_keys(ft, m)
        return _chain(ft, m[0], keys, kind, cells, _no_value(ft, ref))
    fixed = [written_number(a) for a in args[1:]]
    if None not in fixed:  # INDEX(range, 3, 2): the cell itself
        at = (fixed + [1.0])[:2] if cols == 1 or len(fixed) == 2 else [1.0, fixed[0]]
        if any(v != int(v) or v < 1 for v in at) or at[0] > rows or at[1] > cols:
            raise FormulaProblem("INDEX outside its range (#REF! in Excel)")
        return cells[(int(at[0]) - 1) * cols + int(at[1]) - 1]
    i = ft.value(args[1], 3)
    j = ft.value(args[2], 3) if len(args) == 3 else None
    text = _no_value(ft, ref)
    for (r, c), name in reversed(list(zip(_cells(ref), cells))):
        dr, dc = r - ref.r1 + 1, c - ref.c1 + 1
        cond = f"{i} == {dr if cols == 1 or j is not None else dc}"
        if j is not None:
            cond += f" and {j} == {dc}"
        text = f"({name} if {cond} otherwise {text})"
    return text


def _match_plus(node) -> tuple[tuple, float] | None:
    """``MATCH(...)``, ``MATCH(...) + k`` or ``MATCH(...) - k`` (k written): (the MATCH's
    arguments, k); None for another offset."""
    if node[0] == "fn" and node[1].upper() == "MATCH":
        return node[2], 0.0
    if node[0] == "op" and node[1] in ("+", "-") and len(node[2]) == 2:
        a, b = node[2]
        k = written_number(b)
        if k is not None and a[0] == "fn" and a[1].upper() == "MATCH":
            return a[2], k if node[1] == "+" else -k
        k = written_number(a)
        if k is not None and node[1] == "+" and b[0] == "fn" and b[1].upper() == "MATCH":
            return b[2], k
    return None


def offset_by_match(ft, base: Ref, rows, cols) -> str | None:
    """``OFFSET(base, rows, cols)`` where one offset is ``MATCH(x, keys, type) + k`` and the
    other a written number: a chain over the keys whose results are the cells reached at each
    position (outside the sheet an error, #REF!); None where the offsets are otherwise."""
    found = [(i, _match_plus(a)) for i, a in enumerate((rows, cols))]
    moving = [(i, m) for i, m in found if m is not None]
    fixed = [written_number(a) for i, a in enumerate((rows, cols)) if found[i][1] is None]
    if len(moving) != 1 or len(fixed) != 1 or fixed[0] is None or fixed[0] != int(fixed[0]):
        return None
    along, (m, k) = moving[0]
    if k != int(k) or len(m) not in (2, 3):
        return None
    kind, keys = _match_keys(ft, m)
    results, kinds = [], set()
    for p in range(1, len(keys) + 1):
        step = (p + int(k), int(fixed[0]))
        row, col = base.r1 + step[along], base.c1 + step[1 - along]
        if row < 1 or col < 1:
            results.append("1/0")
            continue
        cell = ft.book.cell(base.sheet, row, col)
        kinds.add(isinstance(getattr(cell, "value", None), str))
        ft.out.refs.append(Ref(base.sheet, row, col, row, col))
        results.append(ft.name_of(base.sheet, row, col))
    if kinds == {True, False}:
        raise FormulaProblem("OFFSET by a MATCH to cells of texts and numbers")
    return _chain(ft, m[0], keys, kind, results, "num2str(1/0)" if kinds == {True} else "1/0")


def hlookup(ft, args) -> str:
    """``HLOOKUP(x, table, k[, exact])``: the k-th row's cell below the matching key of the
    first row (an exact match, or the approximate one guarded by the keys ascending)."""
    if len(args) not in (3, 4):
        raise FormulaProblem(f"HLOOKUP with {len(args)} arguments")
    from .statics import found, guarded, position

    if args[1][0] != "leaf" or args[1][1] != "Range" or ft.is_name_formula(args[1][2]):
        raise FormulaProblem("HLOOKUP of other than a range")
    whole = ft.ref_of(args[1][2])
    k, guard = position(ft, args[2])
    if not 1 <= k <= whole.r2 - whole.r1 + 1:
        raise FormulaProblem("HLOOKUP of a row outside its table (#REF! in Excel)")
    exact = len(args) == 4 and written_number(args[3]) == 0
    if len(args) == 4 and not exact and written_number(args[3]) is None:
        raise FormulaProblem("HLOOKUP whose match type is not written in the formula")
    if exact:
        keys = [(whole.sheet, whole.r1, c) for c in range(whole.c1, whole.c2 + 1)]
        i = found(ft, args[0], keys)
        if i is not None:
            if i < 0:
                return "(1/0)"
            row, col = whole.r1 + int(k) - 1, whole.c1 + i
            ft.out.refs.append(Ref(whole.sheet, row, col, row, col))
            return guarded(ft.name_of(whole.sheet, row, col), guard)
    if guard is not None:
        raise FormulaProblem("HLOOKUP of a number whose row a MATCH computes")
    ref = _range(ft, args[1], "HLOOKUP")
    keys_ref = Ref(ref.sheet, ref.r1, ref.c1, ref.r1, ref.c2)
    keys = _keys(ft, keys_ref, args[0], exact=exact)
    row = ref.r1 + int(k) - 1
    results = []
    for c in range(ref.c1, ref.c2 + 1):
        ft.out.refs.append(Ref(ref.sheet, row, c, row, c))
        results.append(ft.name_of(ref.sheet, row, c))
    none = _no_value(ft, Ref(ref.sheet, row, ref.c1, row, ref.c2))
    return _chain(ft, args[0], keys, 0.0 if exact else 1.0, results, none)


def lookup_misses(ft, upper: str, args) -> str | None:
    """Where an exact ``VLOOKUP(x, table, k, FALSE)``, ``HLOOKUP(x, table, k, FALSE)`` or
    ``MATCH(x, keys, 0)`` finds no key (Excel's #N/A), as a condition (``"1 == 1"``: never
    found; None: always found), for IFERROR and ISERROR around it: x a text that never changes
    (found here) or a number, over the keys a lookup takes (:func:`_keys`). Else
    FormulaProblem."""
    from .statics import found

    exact = len(args) == (3 if upper == "MATCH" else 4) and written_number(args[-1]) == 0
    if not exact:
        raise FormulaProblem(f"IFERROR of a {upper} other than an exact one")
    if upper == "MATCH":
        keys_ref = _range(ft, args[1], "MATCH")
        if keys_ref.r1 != keys_ref.r2 and keys_ref.c1 != keys_ref.c2:
            raise FormulaProblem("MATCH in a block of rows and columns (#N/A in Excel)")
    else:  # the first column (row) of the table
        t = _range(ft, args[1], upper)
        last = (t.r2, t.c1) if upper == "VLOOKUP" else (t.r1, t.c2)
        keys_ref = Ref(t.sheet, t.r1, t.c1, *last)
    at = found(ft, args[0], [(keys_ref.sheet, r, c) for r, c in _cells(keys_ref)])
    if at is not None:
        return "1 == 1" if at < 0 else None
    x = ft.value(args[0], 3)
    equal = [f"{x} == {name}" for _, name in _keys(ft, keys_ref, args[0], exact=True) if name]
    return "not (" + " or ".join(equal) + ")" if equal else "1 == 1"
