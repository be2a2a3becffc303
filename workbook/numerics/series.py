"""Sums and products over the integers i = a..b, for every row at once."""

from __future__ import annotations

import numpy as np

from ..errors import LimitError
from ._common import Fn, NumericsError, Result, call, num, rows

#: most terms of one sum or product (per row times rows)
MAX_TERMS = 10_000_000


def reduce(f: Fn, a, b, args=(), *, kind: str = "sum", var: str = "i") -> Result:
    """``sum`` or ``product`` of ``f(i, *args)`` for integer i from a to b (both included).

    The bounds must be whole numbers; b < a gives the empty sum 0 (product 1), as Mathcad.
    The error estimate is the rounding of the terms (n * eps * sum |term|).
    """
    shape, (a, b, *args) = rows(a, b, *args)
    for name, v in (("first", a), ("last", b)):
        frac = np.flatnonzero(v != np.round(v))
        if frac.size:
            raise NumericsError(
                f"{kind}(): the {name} value of {var} must be a whole number, got {num(v[frac[0]])}"
            )
    if a.size == 0:
        return Result(np.empty(shape), np.empty(shape))
    start, stop = int(a.min()), int(b.max())
    width = max(stop - start + 1, 0)
    if width * a.size > MAX_TERMS:
        raise LimitError(
            f"{kind}() over {var} = {start}..{stop} has {width * a.size} terms "
            f"(limit {MAX_TERMS}: workbook.numerics.series.MAX_TERMS)"
        )
    i = np.arange(start, start + width, dtype=float)[None, :]
    inside = (i >= a[:, None]) & (i <= b[:, None])
    terms = call(f, np.broadcast_to(i, inside.shape), [g[:, None] for g in args])
    bad = inside & ~np.isfinite(terms)
    if bad.any():
        r, j = np.argwhere(bad)[0]
        raise NumericsError(f"{kind}(): the term for {var} = {int(i[0, j])} is not a finite number")
    eps = np.finfo(float).eps
    if kind == "sum":
        value = np.where(inside, terms, 0.0).sum(axis=1)
        error = inside.sum(axis=1) * eps * np.where(inside, np.abs(terms), 0.0).sum(axis=1)
    else:
        value = np.where(inside, terms, 1.0).prod(axis=1)
        error = inside.sum(axis=1) * eps * np.abs(value)
    return Result(value.reshape(shape), error.reshape(shape), evaluations=width)
