"""Differences of nearly equal numbers: a cell's value carries the rounding error of the
numbers it is computed from, not of its own size (``=ABS(M602-V602)`` of two azimuths near
236 that agree to 1e-11; ``=F140+F141*B136`` that Excel shows as 0). First-order error
propagation through the formula (+, -, *, /, ^, SUM, MAX, MIN, ABS, SQRT, the elements of
MINVERSE), from Excel's
cached values of the cells it reads, gives that size; where it is more than CANCELS times the
value, the cached value is compared with an absolute tolerance of the printed values' relative
tolerance times that size (each of the numbers it is made of is compared so); every other
cell with the relative tolerance of its own value."""

from __future__ import annotations

import math

#: cells of a range read at most, and references followed in depth
MAX_CELLS, MAX_DEPTH = 2_000, 4
#: a value this many times smaller than the numbers it is made of is a cancellation
CANCELS = 1e3


def scale(book, cell, depth: int = 0, seen: dict | None = None) -> float:
    """The size of the rounding error a cell's value carries, in units of the relative
    tolerance: its own magnitude, or what first-order error propagation through its formula
    gives from the cells it reads (Excel's cached values), whichever is larger."""
    seen = {} if seen is None else seen
    key = (cell.sheet, cell.row, cell.col)
    if key in seen:
        return seen[key]
    own = abs(cell.value) if _number(cell.value) else 0.0
    seen[key] = own
    if cell.formula is None or depth >= MAX_DEPTH:
        return own
    from .cells import parse_formula
    from .formula_terms import FormulaProblem

    try:
        tree = parse_formula(cell.formula).tree
        if cell.array is not None and cell.array_master is not None:
            err = _inverse_element(book, cell, tree, depth, seen)
        else:
            _, err = _propagate(book, cell.sheet, tree, depth, seen)
    except (FormulaProblem, _Unknown, ArithmeticError, ValueError, OverflowError):
        return own
    seen[key] = max(own, err) if math.isfinite(err) else own
    return seen[key]


class _Unknown(Exception):
    """A part of a formula whose error is not propagated here."""


def _number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _propagate(book, sheet: str, node, depth: int, seen: dict) -> tuple[float, float]:
    """(value, error size) of a formula node from Excel's cached values."""
    kind, name, payload = node
    if kind == "leaf":
        if name == "Number":
            return float(payload.name), 0.0
        if name != "Range" or "r1" not in payload.attr:
            raise _Unknown()
        attr = payload.attr
        target = sheet
        if attr.get("sheet_id"):
            target = book.sheet_named(str(attr.get("sheet") or attr["sheet_id"]))
            if target is None:
                raise _Unknown()
        from openpyxl.utils import column_index_from_string

        r, c = int(attr["r1"]), column_index_from_string(str(attr["c1"]))
        if (attr["r1"], attr["c1"]) != (attr["r2"], attr["c2"]):
            raise _Unknown()  # a range: only within SUM, MAX, MIN (below)
        other = book.cell(target, r, c)
        if other is None or not _number(other.value):
            raise _Unknown()
        return float(other.value), scale(book, other, depth + 1, seen)
    args = [_propagate(book, sheet, a, depth, seen) for a in payload] if kind == "op" else None
    if kind == "op":
        if name in ("u-", "u+"):
            return (-args[0][0] if name == "u-" else args[0][0]), args[0][1]
        (a, ea), (b, eb) = args
        if name in ("+", "-"):
            return (a + b if name == "+" else a - b), ea + eb
        if name == "*":
            return a * b, abs(a) * eb + abs(b) * ea
        if name == "/":
            return a / b, ea / abs(b) + abs(a) * eb / (b * b)
        if name == "^" and eb == 0:
            return a**b, abs(b) * abs(a) ** (b - 1) * ea if a else 0.0
        raise _Unknown()
    upper = name.upper()
    if upper in ("SUM", "MAX", "MIN", "ABS"):
        items = []
        for a in payload:
            items += _cells_of(book, sheet, a, depth, seen)
        values = [v for v, _ in items]
        err = sum(e for _, e in items)
        if upper == "ABS" and len(items) == 1:
            return abs(values[0]), err
        if not values:
            raise _Unknown()
        pick = {"SUM": sum, "MAX": max, "MIN": min}.get(upper)
        if pick is None:
            raise _Unknown()
        return pick(values), err if upper == "SUM" else max(e for _, e in items)
    if upper == "POWER" and len(payload) == 2:
        return _propagate(book, sheet, ("op", "^", payload), depth, seen)
    if upper == "SQRT" and len(payload) == 1:
        a, ea = _propagate(book, sheet, payload[0], depth, seen)
        return math.sqrt(a), ea / (2 * math.sqrt(a)) if a > 0 else math.inf
    raise _Unknown()


def _inverse_element(book, cell, tree, depth: int, seen: dict) -> float:
    """The error size of an element of ``MINVERSE(range)`` (a cell of the array formula):
    first order, d(A^-1) = -A^-1 dA A^-1, so element (i, j) carries
    sum over k, l of |A^-1[i, k]| size(A[k, l]) |A^-1[l, j]|, from Excel's cached values."""
    import numpy as np

    kind, name, payload = tree
    if kind != "fn" or name.upper() != "MINVERSE" or len(payload) != 1:
        raise _Unknown()
    arg = payload[0]
    if arg[0] != "leaf" or arg[1] != "Range" or "r1" not in arg[2].attr:
        raise _Unknown()
    attr = arg[2].attr
    if attr.get("sheet_id"):
        raise _Unknown()
    from openpyxl.utils import column_index_from_string

    r1, r2 = int(attr["r1"]), int(attr["r2"])
    c1, c2 = (column_index_from_string(str(attr[k])) for k in ("c1", "c2"))
    n = r2 - r1 + 1
    if n != c2 - c1 + 1 or n * n > MAX_CELLS:
        raise _Unknown()
    key = ("MINVERSE", cell.sheet, *cell.array_master)
    if key not in seen:
        values, sizes = np.zeros((n, n)), np.zeros((n, n))
        for i in range(n):
            for j in range(n):
                other = book.cell(cell.sheet, r1 + i, c1 + j)
                if other is None or not _number(other.value):
                    raise _Unknown()
                values[i, j] = float(other.value)
                sizes[i, j] = scale(book, other, depth + 1, seen)
        inverse = np.abs(np.linalg.inv(values))
        seen[key] = inverse @ sizes @ inverse
    i, j = cell.row - cell.array_master[0], cell.col - cell.array_master[1]
    if not (0 <= i < n and 0 <= j < n):
        raise _Unknown()
    return float(seen[key][i, j])


def _cells_of(book, sheet: str, node, depth: int, seen: dict) -> list[tuple[float, float]]:
    """(value, error) of each number of a SUM/MAX/MIN argument (a range's cells one by one)."""
    kind, name, payload = node
    if kind == "leaf" and name == "Range" and "r1" in payload.attr:
        attr = payload.attr
        if (attr["r1"], attr["c1"]) != (attr["r2"], attr["c2"]):
            from openpyxl.utils import column_index_from_string

            target = sheet
            if attr.get("sheet_id"):
                target = book.sheet_named(str(attr.get("sheet") or attr["sheet_id"]))
                if target is None:
                    raise _Unknown()
            c1, c2 = (column_index_from_string(str(attr[k])) for k in ("c1", "c2"))
            r1, r2 = int(attr["r1"]), int(attr["r2"])
            if (r2 - r1 + 1) * (c2 - c1 + 1) > MAX_CELLS:
                raise _Unknown()
            out = []
            for r in range(r1, r2 + 1):
                for c in range(c1, c2 + 1):
                    other = book.cell(target, r, c)
                    if other is not None and _number(other.value):
                        out.append((float(other.value), scale(book, other, depth + 1, seen)))
            return out
    return [_propagate(book, sheet, node, depth, seen)]


def decade(book, ref: str, value: float, memo: dict | None = None) -> int | None:
    """The power of ten of the numbers a cancelling cell is made of (None: no cancellation)."""
    sheet, _, address = ref.rpartition("!")
    from openpyxl.utils.cell import column_index_from_string, coordinate_from_string

    letters, row = coordinate_from_string(address)
    cell = book.cell(sheet, row, column_index_from_string(letters))
    if cell is None or cell.formula is None:
        return None
    size = scale(book, cell, 0, memo)
    if size == 0 or not math.isfinite(size) or size <= CANCELS * abs(value):
        return None
    return math.ceil(math.log10(size))
