"""The rounding of EXPR itself: EXPR spot-checked at a few points in extended precision.

The method's estimate (a quadrature rule's, a bracket's width, n eps sum |term|) says
nothing of what numpy's doubles lose inside EXPR (``cos(1e-4*x) - 1`` is 5e-9 computed as
the difference of two numbers near 1, with an absolute error near 1e-16 whatever the rule).
:func:`discrepancy` evaluates EXPR at given points both ways, numpy and its mpmath form
(:mod:`workbook.numerics.mpform`, the same tree and the same double constants), and gives
per row the difference; the built-ins add what it costs them to their estimate.

Only some rows spread over a call are checked (an mpmath evaluation is ~1e4 times a numpy
one): the others take the difference of the nearest checked rows.
Where EXPR has no mpmath form, or a point has no value in mpmath, nothing is added.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np

#: digits of the spot check (doubles lose at most ~16 digits in EXPR worth reporting)
DIGITS = 40
#: rows of one call checked at least (all where there are fewer), and mpmath evaluations
#: of one call at most beyond them (a table of few points a row checks more rows)
ROWS = 8
BUDGET = 256


_CONTEXT: list = []


def _context():
    """One private mpmath context at DIGITS (making one costs ~3 ms: a sum of products makes
    one a term otherwise); its precision is never changed."""
    if not _CONTEXT:
        ctx = mpmath.MPContext()
        ctx.dps = DIGITS
        _CONTEXT.append(ctx)
    return _CONTEXT[0]


def form_of(of):
    """(ctx, EXPR's mpmath form) or None where EXPR has none (or inside bench's reference)."""
    from ._common import live, reference
    from .mpform import NoMpForm, mp_form

    if live() or reference():
        return None
    ctx = _context()
    try:
        return ctx, mp_form(of.evaluator, ctx, of.body)
    except NoMpForm:
        return None
    except RecursionError:
        return None


def discrepancy(
    of, shape, xs: np.ndarray, fs: np.ndarray, prepared=None, most: int = 0
) -> np.ndarray | None:
    """[row, k] per flat row of ``shape``: |numpy's EXPR - mpmath's EXPR| at the points
    ``xs[row, k]`` where numpy's values are ``fs[row, k]`` (None: no mpmath form; 0 where
    a point has no value; ``prepared``: :func:`form_of`'s; ``most``: rows checked,
    by default ROWS, or more where BUDGET mpmath evaluations allow). Rows not checked take
    the largest difference of the nearest checked rows (interpolated along the call)."""
    from ..language import typed as ty
    from .mpform import NoValue

    prepared = prepared or form_of(of)
    if prepared is None:
        return None
    ctx, form = prepared
    n = math.prod(shape)
    xs = np.broadcast_to(xs, (n, xs.shape[-1]))
    fs = np.broadcast_to(fs, xs.shape)
    arrays = {k: np.broadcast_to(a, shape).reshape(-1) for k, a in of.arrays.items()}
    used = ty.parameters(of.body) - {of.var}
    fixed = {}
    for k, v in of.env.items():
        if k in used and k not in arrays:
            try:
                fixed[k] = float(np.asarray(v))
            except (TypeError, ValueError):
                return None
    most = most or max(ROWS, BUDGET // max(xs.shape[-1], 1))
    rows = np.arange(n) if n <= most else np.unique(np.linspace(0, n - 1, most).astype(np.intp))
    out = np.full(xs.shape, np.nan)
    for i in rows:
        env = {**fixed, **{k: float(a[i]) for k, a in arrays.items()}}
        for j, (x, f) in enumerate(zip(xs[i], fs[i])):
            out[i, j] = 0.0
            if not np.isfinite(f):
                continue
            try:
                exact = form({**env, of.var: ctx.mpf(float(x))})
            except (NoValue, ZeroDivisionError, ValueError, TypeError):
                continue
            if isinstance(exact, str):
                return None
            out[i, j] = abs(float(ctx.mpf(float(f)) - exact))
    if n > rows.size:
        # the nearest checked rows' difference (rounding varies along a table: a step size;
        # relative to a row's own value it would blow up beside a zero of EXPR)
        fill = np.interp(np.arange(n), rows, out[rows].max(axis=1))
        out = np.where(np.isnan(out), fill[:, None], out)
    return out


#: nodes of an integral's spot check a row, and rows checked
INTEGRAL_NODES = 8
INTEGRAL_ROWS = 2


def integral_rounding(of, shape, a, b, result) -> None:
    """Add EXPR's own rounding to an integral's estimate (in place): width times the largest
    difference between numpy's and mpmath's EXPR at INTEGRAL_NODES interior points of
    INTEGRAL_ROWS rows (the others interpolated)."""
    prepared = form_of(of)
    if prepared is None:
        return
    n = math.prod(shape)
    a, b = (np.broadcast_to(np.asarray(v, dtype=float), shape).reshape(-1) for v in (a, b))
    t = (np.arange(INTEGRAL_NODES) + 0.5) / INTEGRAL_NODES
    xs = a[:, None] + (b - a)[:, None] * t[None, :]
    rows = np.unique(np.linspace(0, n - 1, min(n, INTEGRAL_ROWS)).astype(np.intp))
    f = of.over(shape)
    with np.errstate(all="ignore"):
        fs = np.asarray(
            f(xs[rows].ravel(), np.repeat(rows, INTEGRAL_NODES).astype(float)), dtype=float
        )
    full = np.full(xs.shape, np.nan)
    full[rows] = np.broadcast_to(fs, (rows.size * INTEGRAL_NODES,)).reshape(rows.size, -1)
    d = discrepancy(of, shape, xs, np.nan_to_num(full, nan=0.0), prepared, most=rows.size)
    if d is None:
        return
    add = (np.abs(b - a) * np.nanmax(d, axis=1)).reshape(np.shape(result.error))
    error = np.asarray(result.error, dtype=float)
    if np.any(add > error):
        # EXPR's rounding is what the estimate is: measured against the integrand's size
        # (width x largest |EXPR| seen), not against 1 in its unit (numerics.estimates)
        size = np.abs(b - a)[rows] * np.nanmax(np.abs(full[rows]), axis=1)
        result.notes["scale"] = max(result.notes.get("scale", 0.0), float(np.max(size)))
        result.notes["relative"] = True
    result.error = error + add
