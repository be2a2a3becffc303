"""The rounding of EXPR itself: EXPR spot-checked at a few points in extended precision.

The method's estimate (a quadrature rule's, a bracket's width, n eps sum |term|) says
nothing of what numpy's doubles lose inside EXPR (``cos(1e-4*x) - 1`` is 5e-9 computed as
the difference of two numbers near 1, with an absolute error near 1e-16 whatever the rule).
:func:`discrepancy` evaluates EXPR at given points both ways, numpy and its mpmath form
(:mod:`workbook.numerics.mpform`, the same tree and the same double constants), and gives
per row the difference; the built-ins add what it costs them to their estimate: an
integral the width times it, a root it over the slope (:func:`root_rounding`), an extremum
twice it, and its place through the curvature (:func:`extremum_rounding`).

Only some rows spread over a call are checked (an mpmath evaluation is ~1e4 times a numpy
one): the others take the difference of the nearest checked rows.
Where EXPR has no mpmath form, or a point has no value in mpmath, nothing is added; nor
where EXPR's own integrals cost more than INNER_EVALUATIONS evaluations of their integrands
in one check (an integral nested twice).
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
#: evaluations of the integrands of EXPR's own integrals in one spot check at most (one inner
#: integral at every point checked fits; an integral nested twice does not, and is not
#: checked: its inner integrals' estimates hold their rounding)
INNER_EVALUATIONS = 20_000


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
    from ..functions.numerical import live, reference
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
    of, shape, xs: np.ndarray, fs: np.ndarray, prepared=None, most: int = 0, only=None
) -> np.ndarray | None:
    """[row, k] per flat row of ``shape``: |numpy's EXPR - mpmath's EXPR| at the points
    ``xs[row, k]`` where numpy's values are ``fs[row, k]`` (None: no mpmath form; 0 where
    a point has no value; ``prepared``: :func:`form_of`'s; ``most``: rows checked,
    by default ROWS, or more where BUDGET mpmath evaluations allow; ``only``: the rows
    checked, the others NaN). Rows not checked take the largest difference of the nearest
    checked rows (interpolated along the call)."""
    from .mpform import NoValue, TooCostly, evaluations

    prepared = prepared or form_of(of)
    if prepared is None:
        return None
    ctx, form = prepared
    n = math.prod(shape)
    xs = np.broadcast_to(xs, (n, xs.shape[-1]))
    fs = np.broadcast_to(fs, xs.shape)
    row_env = _row_env(of, shape)
    if row_env is None:
        return None
    most = most or max(ROWS, BUDGET // max(xs.shape[-1], 1))
    rows = np.arange(n) if n <= most else np.unique(np.linspace(0, n - 1, most).astype(np.intp))
    if only is not None:
        rows = np.asarray(only, dtype=np.intp)
    out = np.full(xs.shape, np.nan)
    with evaluations(INNER_EVALUATIONS):
        for i in rows:
            env = row_env(i)
            for j, (x, f) in enumerate(zip(xs[i], fs[i])):
                out[i, j] = 0.0
                if not np.isfinite(f):
                    continue
                try:
                    exact = form({**env, of.var: ctx.mpf(float(x))})
                except (NoValue, ZeroDivisionError, ValueError, TypeError):
                    continue
                except TooCostly:
                    return None
                if isinstance(exact, str):
                    return None
                out[i, j] = abs(float(ctx.mpf(float(f)) - exact))
    if n > rows.size and only is None:
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


#: rows of a root's or an extremum's call checked (the others take the nearest checked
#: rows' addition)
POINT_ROWS = 4
#: a root's rounding is checked at the root and these relative offsets from it
ROOT_OFFSETS = np.array([0.0, -1e-9, 1e-9])
#: an extremum's rounding is checked at its place and this far (relative to the interval)
#: to each side (the search compares values around it)
EXTREMUM_OFFSETS = (0.0, -1e-6, 1e-6, -1e-3, 1e-3)


def _row_env(of, shape):
    """``env(row)``: the environment of EXPR's mpmath form at a flat row (None: an input
    that is not a number)."""

    arrays = {k: np.broadcast_to(a, shape).reshape(-1) for k, a in of.arrays.items()}
    used = of.names_read
    fixed = {}
    for k, v in of.env.items():
        if k in used and k not in arrays:
            try:
                fixed[k] = float(np.asarray(v))
            except (TypeError, ValueError):
                return None
    return lambda i: {**fixed, **{k: float(a[i]) for k, a in arrays.items()}}


def _derivative(of, prepared, env, x: float, h: float, order: int) -> float | None:
    """EXPR's first or second derivative at x by a central difference of step h on its
    mpmath form (at DIGITS, so the difference loses none of what doubles would)."""
    from .mpform import NoValue

    ctx, form = prepared
    steps = (-1, 1) if order == 1 else (-1, 0, 1)
    try:
        g = [form({**env, of.var: ctx.mpf(x) + k * ctx.mpf(h)}) for k in steps]
    except (NoValue, ZeroDivisionError, ValueError, TypeError, KeyError):
        return None
    if any(isinstance(v, str) for v in g):
        return None
    d = (g[-1] - g[0]) / (2 * h) if order == 1 else (g[2] - 2 * g[1] + g[0]) / h**2
    return abs(float(d))


def _checked_rows(n: int, most: int = POINT_ROWS) -> np.ndarray:
    return np.unique(np.linspace(0, n - 1, min(n, most)).astype(np.intp))


def _spread(n: int, rows: np.ndarray, add: np.ndarray) -> np.ndarray:
    """The additions at the checked rows, the nearest checked rows' for the others."""
    keep = np.isfinite(add)
    if not keep.any():
        return np.zeros(n)
    return np.interp(np.arange(n), rows[keep], add[keep])


def root_rounding(of, shape, result, span: float | np.ndarray) -> None:
    """Add EXPR's rounding at the root over the slope there to a root's estimate (in place),
    for the rows the mpmath polish did not certify (``result.notes["certified"]``): the
    residual numpy computes at the root is off by d, which moves the sign change by about
    d/|f'|. ``span``: the bracket's width per row (the slope's step is a millionth of the
    root's size, or of it at 0)."""
    prepared = form_of(of)
    if prepared is None:
        return
    value = np.ravel(np.asarray(result.value, dtype=float))
    n = value.size
    certified = result.notes.pop("certified", np.zeros(n, dtype=bool))
    if certified.all():
        return
    env = _row_env(of, shape)
    if env is None:
        return
    todo = np.flatnonzero(~certified & np.isfinite(value))
    if not todo.size:
        return
    # (2 rows of a table over 2,000 rows: the engine's own cost per row is what it is held to)
    rows = todo[_checked_rows(todo.size, 2 if n > 2_000 else POINT_ROWS)]
    # the residual's rounding at the root and beside it (it varies from double to double;
    # the sign change is wherever the noise crosses)
    near = value[rows, None] * (1 + ROOT_OFFSETS[None, :])
    f = of.over(shape)
    with np.errstate(all="ignore"):
        fs = np.asarray(f(near.ravel(), np.repeat(rows, ROOT_OFFSETS.size).astype(float)), float)
    xs = np.zeros((n, ROOT_OFFSETS.size))
    xs[rows] = near
    full = np.zeros(xs.shape)
    full[rows] = np.broadcast_to(fs, (near.size,)).reshape(near.shape)
    d = discrepancy(of, shape, xs, full, prepared, only=rows)
    if d is None:
        return
    widths = np.broadcast_to(np.abs(np.asarray(span, dtype=float)), shape).reshape(-1)
    add = np.full(rows.size, np.nan)
    for j, i in enumerate(rows):
        x = float(value[i])
        h = 1e-6 * (abs(x) if x != 0 else max(float(widths[i]), 1e-300))
        slope = _derivative(of, prepared, env(i), x, h, 1)
        if slope:
            add[j] = np.nanmax(d[i]) / slope
    spread = _spread(todo.size, np.searchsorted(todo, rows), add)
    error = np.ravel(np.asarray(result.error, dtype=float)).copy()
    error[todo] += spread
    result.error = error.reshape(np.shape(result.error))


def extremum_rounding(of, shape, a, b, result, where: bool) -> None:
    """Add EXPR's rounding near an extremum to its estimate (in place): d, the largest
    difference between numpy's and mpmath's EXPR at the place and beside it, moves the
    value by up to 2 d (the search keeps the largest of values each off by d); the place
    by sqrt(2 (2 d)/|f''|) (how far a parabola of that curvature moves within 2 d), at most
    the interval. ``result.where`` is the place."""
    prepared = form_of(of)
    if prepared is None or result.where is None:
        return
    at = np.ravel(np.asarray(result.where, dtype=float))
    n = at.size
    env = _row_env(of, shape)
    if env is None:
        return
    a, b = (np.broadcast_to(np.asarray(v, dtype=float), shape).reshape(-1) for v in (a, b))
    width = np.abs(b - a)
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    rows = _checked_rows(n)
    offsets = np.asarray(EXTREMUM_OFFSETS)
    xs = np.clip(at[:, None] + width[:, None] * offsets[None, :], lo[:, None], hi[:, None])
    f = of.over(shape)
    full = np.zeros(xs.shape)
    k = offsets.size
    with np.errstate(all="ignore"):
        fs = np.asarray(f(xs[rows].ravel(), np.repeat(rows, k).astype(float)), dtype=float)
    full[rows] = np.broadcast_to(fs, (rows.size * k,)).reshape(rows.size, k)
    d = discrepancy(of, shape, np.nan_to_num(xs), np.nan_to_num(full), prepared, only=rows)
    if d is None:
        return
    dmax = np.nan_to_num(d[rows], nan=0.0).max(axis=1)
    error = np.ravel(np.asarray(result.error, dtype=float)).copy()
    if not where:
        result.error = (error + _spread(n, rows, 2 * dmax)).reshape(np.shape(result.error))
        return
    add = np.full(rows.size, np.nan)
    for j, i in enumerate(rows):
        if not np.isfinite(at[i]) or dmax[j] == 0:
            add[j] = 0.0
            continue
        h = 1e-8 * max(float(width[i]), abs(float(at[i])), 1e-300)
        curve = _derivative(of, prepared, env(i), float(at[i]), h, 2)
        add[j] = width[i] if not curve else min(np.sqrt(4 * dmax[j] / curve), width[i])
    error = error + _spread(n, rows, add)
    result.error = error.reshape(np.shape(result.error))
    # a place known less well than the square root of rounding: measured against the interval
    result.notes["span"] = float(np.max(width, initial=0.0))
