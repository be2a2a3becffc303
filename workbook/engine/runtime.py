"""Run-time arrays: values whose shape is known only when a program runs, as in Mathcad.

A vector grown element by element (``l[rows(l) + 1] := x``), an array whose elements are
arrays (``[num, vt, vx]`` with vectors inside) or a local that is a number and later a
vector has no shape at load: the typer gives it the shape :data:`workbook.language.typed.RUNTIME`
and still checks its unit (one unit for all its elements, as every matrix). Its shape is
checked here, when it runs, by Mathcad's rules; every mistake is an error naming the
expression, never a guess.

A run-time value is a number (a float), a text (a str: an element of an array that holds
text) or a matrix: a 2-D numpy array (rows, columns) of floats, or of objects when an element
is itself an array (a nested array) or a text (a table of load kinds beside their values, as
Mathcad's arrays and Excel's ranges hold). A text element is compared with text (``==``,
``!=``); arithmetic on it, ordering it or comparing it with a number is an error naming it,
never a number. Run-time values never carry the range axes of a table
(:mod:`workbook.functions.matrix`): a program runs once per point.
"""

from __future__ import annotations

import operator

import numpy as np

from ..errors import InputError, LimitError
from ..functions.matrix import power
from ..language.expr import COMPARE
from ..limits import ELEMENT_WORK, MAX_ARRAY_ELEMENTS, charge_matrix_work, check_elements

#: Arrays inside arrays at most this deep: a deeper one (``T := [T, 1]`` in a loop) would
#: exhaust the C stack when it is freed or printed.
MAX_NESTING = 100
#: Elements of one run-time array (80 MB of numbers; its spare room for growing doubles that
#: at most): the limit of every array a program builds, checked before it is made.
MAX_RUNTIME_ELEMENTS = MAX_ARRAY_ELEMENTS


def value(v):
    """``v`` as a run-time value: a float, or a 2-D array (a vector is a column)."""
    if isinstance(v, np.ndarray):
        if v.ndim == 0:
            return v.item() if v.dtype == object else float(v)
        if v.ndim == 1:
            return v.reshape(-1, 1)
        return v
    if isinstance(v, (bool, np.bool_)):
        return float(v)
    if isinstance(v, (int, float, np.number)):
        return float(v)
    return v


def is_array(v) -> bool:
    return isinstance(v, np.ndarray) and v.ndim == 2


def shape_of(v) -> tuple[int, int] | None:
    """(rows, columns) of a run-time array, None for a number."""
    return v.shape if is_array(v) else None


def all_finite(v) -> bool:
    """Every number of ``v`` (of its elements' elements, for a nested array) is finite."""
    if isinstance(v, str):
        return True
    if isinstance(v, np.ndarray) and v.dtype == object:
        return all(all_finite(value(e)) for e in v.ravel())
    return bool(np.all(np.isfinite(v)))


def holds_text(v) -> bool:
    """``v`` is a text, or an array with a text element (at any depth)."""
    if isinstance(v, str):
        return True
    return is_array(v) and v.dtype == object and any(holds_text(e) for e in v.ravel())


def no_text(v, what: str):
    """``v``, which must hold no text here (an argument of a function of numbers)."""
    if holds_text(v):
        raise InputError(f"{what}: {_text_shown(v)} where a number is wanted")
    return v


def _text_shown(v) -> str:
    if isinstance(v, str):
        return f"the text {v!r}"
    first = next(e for e in v.ravel() if holds_text(e))
    return f"{describe(v)} holding text ({_text_shown(first)})"


def scale(v, factor: float):
    """``v`` times a unit's factor: the numbers of an array that holds text, its texts kept."""
    if isinstance(v, str):
        return v
    if is_array(v) and v.dtype == object:
        out = np.empty(v.shape, dtype=object)
        for at, e in np.ndenumerate(v):
            out[at] = scale(value(e), factor)
        return out
    return v * factor


def negate(v, what: str):
    """``-v`` of a run-time value (an error on text)."""
    v = value(v)
    if holds_text(v):
        raise InputError(f"{what}: arithmetic on {_text_shown(v)}")
    if is_array(v) and v.dtype == object:
        raise InputError(f"{what}: arithmetic on a nested array; use its elements")
    return -v


def describe(v) -> str:
    if is_array(v):
        r, c = v.shape
        nested = " (nested)" if v.dtype == object and any(is_array(e) for e in v.ravel()) else ""
        return (f"a vector of {r}" if c == 1 else f"a {r}x{c} matrix") + nested
    if isinstance(v, str):
        return f"the text {v!r}"
    return "a number"


# -- indexing and setting elements ------------------------------------------------------------
def _position(i, origin: int, n: int | None, word: str, what: str) -> int:
    x = float(np.asarray(i, dtype=float)) if np.ndim(i) == 0 else None
    if x is None:
        raise InputError(f"{what}: the {word} index is an array; an index is a number")
    if not np.isfinite(x) or abs(x - round(x)) > 1e-9:
        raise InputError(f"{what}: {word} index {x:g} is not an integer")
    k = round(x)
    if abs(k) > 2**53:  # beyond any array (and any exact integer)
        if n is None:
            check_elements(abs(float(k)), f"{what}: {word} index {x:g}")
        raise InputError(f"{what}: {word} index {x:g} is out of range")
    k -= origin
    if k < 0 or (n is not None and k >= n):
        shown = f"{n} {word}s: {origin} .. {origin + n - 1}" if n else f"no {word}s"
        raise InputError(
            f"{what}: {word} index {k + origin} is out of range ({shown} with origin {origin})"
        )
    return k


def index(target, indices: list, *, origin: int, what: str):
    """``v[i]`` or ``M[i, j]`` of a run-time value (an element may be an array)."""
    target = value(target)
    if not is_array(target):
        raise InputError(f"{what}: the value is {describe(target)}; it cannot be indexed")
    r, c = target.shape
    if len(indices) == 1:
        if c != 1:
            raise InputError(
                f"{what}: the value is {describe(target)}; write M[i, j] (one index is for "
                "a vector)"
            )
        at = (_position(indices[0], origin, r, "element", what), 0)
    else:
        at = (
            _position(indices[0], origin, r, "row", what),
            _position(indices[1], origin, c, "column", what),
        )
    return value(target[at])


def set_item(target, indices: list, x, *, origin: int, what: str):
    """``target`` with element ``[i]`` or ``[i, j]`` set to ``x``: a number or a missing local
    becomes a vector, and an array grows with zeros to reach the index (as Mathcad); an array
    element makes the array nested (it is stored as a copy: the array set stays a value).
    Returns the new array. ``target`` must be the caller's own (it is changed in place); an
    array that grows by rows keeps spare rows, so appending one element at a time costs
    amortised constant time, not a copy of the whole array each time."""
    x = _element(value(x), what)
    target = value(target) if target is not None else None
    if len(indices) == 1:
        if is_array(target) and target.shape[1] != 1:
            raise InputError(
                f"{what}: the value is {describe(target)}; set M[i, j] (one index is for a vector)"
            )
        at = (_position(indices[0], origin, None, "element", what), 0)
    else:
        at = (
            _position(indices[0], origin, None, "row", what),
            _position(indices[1], origin, None, "column", what),
        )
    if not is_array(target):
        target = np.zeros((0, 1 if len(indices) == 1 else 0))
    r, c = target.shape
    nested = target.dtype == object or is_array(x)
    if at[0] >= r or at[1] >= c or nested != (target.dtype == object):
        target = _grown(target, max(r, at[0] + 1), max(c, at[1] + 1), nested, what)
    target[at] = x
    return target


def _grown(target: np.ndarray, rows: int, cols: int, nested: bool, what: str) -> np.ndarray:
    """``target`` grown to ``rows`` x ``cols`` with zeros: a view into spare rows of the array
    it is a view of when they suffice, else a new array with twice the rows it needs."""
    r, c = target.shape
    check_elements(float(rows) * cols, f"{what}: growing it to {rows:,} x {cols:,}")
    dtype = object if nested else float
    base = target.base
    if (
        cols == c
        and target.dtype == dtype
        and isinstance(base, np.ndarray)
        and base.ndim == 2
        and base.dtype == dtype
        and base.shape[1] == c
        and base.shape[0] >= rows
        and target.flags.c_contiguous
        and base.flags.c_contiguous
        and target.__array_interface__["data"][0] == base.__array_interface__["data"][0]
    ):
        view = base[:rows]
        view[r:] = 0.0
        return view
    spare = min(max(rows, 2 * r), max(rows, MAX_RUNTIME_ELEMENTS // max(cols, 1)))
    grown = np.zeros((spare if cols == c else rows, cols), dtype=dtype)
    if nested:
        grown.fill(0.0)
    grown[:r, :c] = target
    return grown[:rows] if grown.shape[0] != rows else grown


def _element(x, what: str):
    """An array stored as an element of another: a copy (a later change to the local it came
    from does not reach it), nested at most :data:`MAX_NESTING` deep, and of at most the
    element limit counted whole (an array given itself twice, ``v := [v, v]``, doubles)."""
    if not is_array(x):
        return x
    if x.dtype == object:
        depth, count = _measure(x, {})
        if depth >= MAX_NESTING:
            raise LimitError(f"{what}: arrays nested more than {MAX_NESTING} deep")
        check_elements(count, f"{what}: an array holding arrays (their elements counted whole)")
    return x.copy()


def _measure(v, seen: dict) -> tuple[int, float]:
    """(how deep, how many numbers counted whole) of a nested array; an array met again (the
    same one held twice) is measured once."""
    key = id(v)
    if key not in seen:
        depth, count = 0, 0.0
        for e in v.ravel():
            if is_array(e):
                d, c = _measure(e, seen) if e.dtype == object else (1, float(e.size))
                depth, count = max(depth, d), count + c
            else:
                count += 1
        seen[key] = (depth + 1, count)
    return seen[key]


def nesting(v) -> int:
    """How deep arrays are nested in ``v``: 0 for a number, 1 for an array of numbers."""
    if not is_array(v):
        return 0
    if v.dtype != object:
        return 1
    return _measure(v, {})[0]


def build(rows: list[list], what: str = "array"):
    """A matrix literal with run-time elements: nested when an element is an array (stored
    as a copy)."""
    values = [[value(e) for e in row] for row in rows]
    if not any(is_array(e) or isinstance(e, str) for row in values for e in row):
        return np.array(values, dtype=float)
    out = np.empty((len(values), len(values[0])), dtype=object)
    for i, row in enumerate(values):
        for j, e in enumerate(row):
            out[i, j] = _element(e, what)
    return out


# -- operators --------------------------------------------------------------------------------
_ARITH = {"+": operator.add, "-": operator.sub, "*": operator.mul, "/": operator.truediv}


def binary(op: str, a, b, what: str):
    """``a op b`` by Mathcad's rules on the shapes the values have when they run: ``+ -``
    element by element (same shape, or an array and a number); ``*`` a number times an
    array, the dot product of two vectors of one length, else the matrix product; ``/`` by a
    number; ``^`` a power of a number, or a matrix power (``M^-1`` the inverse)."""
    a, b = value(a), value(b)
    for v in (a, b):
        if holds_text(v):
            raise InputError(f"{what}: arithmetic on {_text_shown(v)}")
    sa, sb = shape_of(a), shape_of(b)
    if sa is None and sb is None:
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            # x/0 is inf or nan, as in the rest of the engine (then refused as not finite)
            if op == "^":
                return float(np.power(a, b))
            return float(_ARITH[op](np.float64(a), np.float64(b)))
    for v in (a, b):
        if is_array(v) and v.dtype == object:
            raise InputError(f"{what}: arithmetic on a nested array; use its elements")
    elements = max(a.size if sa else 1, b.size if sb else 1)
    if op in "+-":
        if sa is not None and sb is not None and sa != sb:
            raise InputError(f"{what}: cannot add or subtract {describe(a)} and {describe(b)}")
        charge_matrix_work(ELEMENT_WORK * float(elements), what)
        return _ARITH[op](a, b)
    if op == "*":
        if sa is None or sb is None:
            charge_matrix_work(ELEMENT_WORK * float(elements), what)
            return a * b
        if sa[1] == 1 and sb[1] == 1 and sa[0] == sb[0]:
            return float(np.sum(a * b))  # Mathcad's v*w of two vectors
        if sa[1] != sb[0]:
            raise InputError(f"{what}: cannot multiply {describe(a)} by {describe(b)}")
        product = f"{what}: a product of {describe(a)} by {describe(b)}"
        charge_matrix_work(float(sa[0]) * sa[1] * sb[1], product)
        check_elements(float(sa[0]) * sb[1], product)
        return a @ b
    if op == "/":
        if sb is not None:
            raise InputError(f"{what}: cannot divide by {describe(b)}")
        charge_matrix_work(ELEMENT_WORK * float(elements), what)
        return a / b
    if sb is not None:
        raise InputError(f"{what}: an exponent must be a number, got {describe(b)}")
    n = float(b)
    if sa[0] != sa[1] or n != int(n):
        raise InputError(f"{what}: a power of {describe(a)} needs a square matrix and an integer")
    return power(a, int(n))


def compare(op: str, a, b, what: str) -> bool:
    """``a op b`` of numbers; ``==`` and ``!=`` of arrays compare whole values (same shape
    and elements), as Mathcad's; ``<`` of an array is an error."""
    a, b = value(a), value(b)
    if isinstance(a, str) or isinstance(b, str):
        if not (isinstance(a, str) and isinstance(b, str)):
            raise InputError(f"{what}: cannot compare {describe(a)} with {describe(b)}")
        if op not in ("==", "!="):
            raise InputError(f"{what}: text is compared with == or != only")
        return bool(COMPARE[op](a, b))
    if is_array(a) or is_array(b):
        if op not in ("==", "!="):
            raise InputError(f"{what}: cannot order {describe(a)} and {describe(b)}")
        same = _same(a, b)
        return same if op == "==" else not same
    return bool(COMPARE[op](a, b))


def _same(a, b) -> bool:
    if not (is_array(a) and is_array(b)) or a.shape != b.shape:
        return False
    return all(
        _same(x, y) if is_array(x) or is_array(y) else bool(x == y)
        for x, y in zip(a.ravel(), b.ravel())
    )


def shapes(values) -> tuple:
    """The shapes a matrix built-in's hook gets (``shapes=``) for run-time values."""
    return tuple(shape_of(value(v)) for v in values)


def number(v, what: str) -> float:
    """A run-time value that must be a number here (a loop bound, a table cell)."""
    v = value(v)
    if is_array(v) or isinstance(v, str):
        raise InputError(f"{what}: {describe(v)} where a number is wanted")
    return v
