"""Sums and products over the integers i = a..b, for every row at once."""

from __future__ import annotations

import numpy as np

from ..errors import LimitError
from ..functions.numerical import Fn, NumericsError, Result, call, num, rows

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


#: terms of a sum or product whose rounding in EXPR is checked in mpmath (log-spaced)
SPOT_TERMS = 24


def record_series(of, lo, hi, value, absolute, count=None, kind: str = "sum") -> None:
    """Keep the estimate of ``sum``/``product`` over i = lo..hi (per row): the rounding of
    the additions (n eps sum |term|; a product's n eps |value|) plus EXPR's own rounding,
    checked in mpmath at SPOT_TERMS log-spaced terms (numerics.rounding), each standing for
    the terms around it (a sum's absolute differences add; a product's relative ones)."""
    from ..functions.numerical import live, reference
    from .rounding import discrepancy, form_of

    if reference():  # workbook bench: the reference's values of this call, in mpmath
        from ..functions.numerical import reference_values
        from . import mpref

        ref = mpref.series(of, lo, hi, kind)
        if ref is not None:
            reference_values(of.body, ref)
        return
    if live():  # a live form's call repeats the engine's
        return
    eps = np.finfo(float).eps
    if count is None:  # the terms of every row's own bounds
        count = np.maximum(np.asarray(hi, dtype=float) - np.asarray(lo, dtype=float) + 1, 0)
    value = np.asarray(value, dtype=float)
    shape = np.broadcast_shapes(of.shape, value.shape, np.shape(count), np.shape(absolute))
    value = np.broadcast_to(value, shape).reshape(-1)
    count = np.broadcast_to(np.asarray(count, dtype=float), shape).reshape(-1)
    absolute = np.broadcast_to(np.asarray(absolute, dtype=float), shape).reshape(-1)
    error = count * eps * (absolute if kind == "sum" else np.abs(value))
    first, last = int(np.min(lo)), int(np.max(hi))
    n = last - first + 1
    prepared = form_of(of) if n > 0 else None
    if prepared is not None:
        offsets = np.unique(np.round(np.geomspace(1, n, min(SPOT_TERMS, n))).astype(int)) - 1
        bounds = np.r_[0.0, (offsets[:-1] + offsets[1:]) / 2 + 0.5, float(n)]
        weights = np.diff(bounds)
        i = (first + offsets).astype(float)
        with np.errstate(all="ignore"):
            fs = np.stack(
                [np.broadcast_to(np.asarray(of(x), dtype=float), shape).reshape(-1) for x in i],
                axis=1,
            )
        d = discrepancy(of, shape, np.broadcast_to(i, fs.shape), fs, prepared)
        if d is not None:
            if kind == "sum":
                error = error + d @ weights
            else:
                with np.errstate(all="ignore"):
                    rel = np.where(fs != 0, d / np.abs(fs), 0.0)
                error = error + (rel @ weights) * np.abs(value)
    # measured against the terms' size, not against 1: a sum of small terms (1e-9/i^2) is
    # as uncertain as its cancellation makes it, whatever its unit
    scale = float(np.max(absolute, initial=0.0)) if kind == "sum" else 0.0
    notes = {"relative": True, "scale": scale}
    of.record(kind, Result(value.reshape(shape), error.reshape(shape), notes=notes))
