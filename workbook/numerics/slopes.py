"""diff()'s checks on the derivative's values: no derivative at a kink, and the rounding of
the derivative's formula in doubles as its error estimate.

The derivative is SymPy's formula, exact; its values are not. At a join of a piecewise
function or a kink of ``abs``, ``min``, ``max`` (the break points :mod:`workbook.numerics.kinks`
reads from the tree) the formula takes one side's slope: the slopes just left and right of
the point are compared, and where they differ there is no derivative (refused, naming both).
Elsewhere the formula is evaluated again in mpmath (:mod:`workbook.numerics.rounding`): the
difference is the estimate (``(exp(x) - 1 - x)/x^2`` differentiated and evaluated at 1e-3 is
3e-7 off in doubles, its formula a difference of nearly equal terms).
"""

from __future__ import annotations

import weakref

import numpy as np

from ..errors import WorkbookError
from ..functions.numerical import NumericsError, Result, live, num, reference

#: the two one-sided slopes are taken this far (relative) from the point
SIDE = 1e-9
#: rows of a call whose derivative is checked in mpmath (SymPy's formula of a second
#: derivative is large: its mpmath form costs ~0.1 s a row in reducer-profile)
CHECKED_ROWS = 2
#: a derivative's formula of more nodes than this is not checked in mpmath (its cost; the
#: second derivatives of reducer-profile are 820 nodes, the first ones 400)
MP_NODES = 600
#: one-sided slopes that differ by more than this (relative to the larger) are a kink
KINK = 1e-6


def derivative_values(of, order: int):
    """diff(EXPR, X, N) where it is: SymPy's formula compiled (its variable is the enclosing
    one's, in the environment), checked by :func:`check_derivative`."""
    from .derivative import compiled

    fn = compiled(of.evaluator, of.body, of.var_param, order)
    value = fn(of.env)
    if reference() and not live() and of.var in of.env:
        return _reference(of, order, value)
    check_derivative(of, fn, order, value)
    return value


def _reference(of, order: int, value):
    """Inside ``workbook bench``'s reference: mpmath's derivative at the points of the first
    call of this diff() (the engine keeps its estimate of the first call only), the formula's
    values at the others and in the rows not computed."""
    from ..functions.numerical import reference_values
    from . import mpref

    done = _CHECKED.setdefault(of.evaluator, set())
    key = ("reference", id(of.body), order)
    if key in done:
        return value
    done.add(key)
    x = np.asarray(of.env[of.var], dtype=float)
    exact = mpref.derivative(of, order, x)
    reference_values(of.body, exact)
    engine = np.broadcast_to(np.asarray(value, dtype=float), exact.shape)
    out = np.where(np.isnan(exact), engine, exact)
    return float(out) if out.ndim == 0 else out


def check_derivative(of, fn, order: int, value) -> None:
    """Refuse a derivative at a kink; record its rounding estimate. ``fn`` is the compiled
    derivative (env -> values), ``value`` its values where diff() is."""
    if live() or reference() or of.var not in of.env:
        return
    x = np.asarray(of.env[of.var], dtype=float)
    value = np.asarray(value, dtype=float)
    shape = np.broadcast_shapes(of.shape, x.shape, value.shape)
    xs = np.broadcast_to(x, shape).reshape(-1)
    _no_kink(of, fn, order, shape, xs)
    _record_rounding(of, order, shape, xs, np.broadcast_to(value, shape).reshape(-1))


def _no_kink(of, fn, order, shape, xs) -> None:
    try:
        breaks = [np.asarray(b, dtype=float).reshape(-1) for b in of.breaks(shape)]
    except (ArithmeticError, ValueError, WorkbookError):  # no value here: no break point
        return
    if not breaks:
        return
    at = np.zeros(xs.size, dtype=bool)
    for b in breaks:
        at |= np.abs(xs - b) <= 4 * np.spacing(np.maximum(np.abs(b), 1.0))
    if not at.any():
        return
    h = SIDE * np.maximum(np.abs(xs), 1.0)
    env = {k: np.broadcast_to(v, shape).reshape(-1) for k, v in of.arrays.items()}
    with np.errstate(all="ignore"):
        left = np.broadcast_to(np.asarray(fn({**of.env, **env, of.var: xs - h}), float), xs.shape)
        right = np.broadcast_to(np.asarray(fn({**of.env, **env, of.var: xs + h}), float), xs.shape)
    big = np.maximum(np.abs(left), np.abs(right))
    kink = at & (np.abs(left - right) > KINK * np.where(big > 0, big, 1.0))
    if kink.any():
        i = int(np.flatnonzero(kink)[0])
        what = "derivative" if order == 1 else f"derivative of order {order}"
        raise NumericsError(
            f"diff(): the expression has a kink at {of.var} = {num(xs[i])}{_unit(of)}: its "
            f"{what} is {num(left[i])} on the left and {num(right[i])} on the right, so there "
            "is none there"
        )


def _unit(of) -> str:
    return f" {of.unit_text}" if of.unit_text else ""


#: per evaluator, the (EXPR, order) whose rounding was checked: once each (a diff() inside
#: a root's or an extremum's EXPR is called at every step of the search, a sheet function's
#: by every definition that calls it; the first call's rows stand for the others)
_CHECKED: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
#: EXPR's mpmath form is taken to be numpy's where they agree to this (relative) at the rows
#: checked (else a sweep's varied inputs, which the form cannot read, are in EXPR)
SAME_FUNCTION = 1e-6


def _record_rounding(of, order, shape, xs, values) -> None:
    """The derivative's formula evaluated in mpmath at the rows spot-checked: the difference
    from the doubles is the estimate, where EXPR's own mpmath form agrees with numpy's."""
    from .derivative import formula, inlined_size
    from .mpform import NoMpForm, mp_form
    from .rounding import discrepancy, form_of

    done = _CHECKED.setdefault(of.evaluator, set())
    key = (id(of.body), order)
    if key in done:
        return
    done.add(key)
    prepared = form_of(of)  # None: no mpmath form of EXPR, or inside the reference
    if prepared is None:
        return
    ctx = prepared[0]
    tree = formula(of.evaluator.defs, of.body, of.var_param, order)
    if inlined_size(of.evaluator.defs, tree) > MP_NODES:
        return
    try:
        form = mp_form(of.evaluator, ctx, tree)
    except (NoMpForm, RecursionError):
        return
    with np.errstate(all="ignore"):
        body = np.broadcast_to(np.asarray(of(of.env[of.var]), dtype=float), shape).reshape(-1)
    if not _same_function(of, shape, xs, body, prepared):
        return
    d = discrepancy(of, shape, xs[:, None], values[:, None], (ctx, form), most=CHECKED_ROWS)
    if d is None or (order <= 2 and not _form_agrees(of, prepared, form, shape, xs, order)):
        return
    # plus the rounding of the double the value is returned as
    error = d[:, 0] + 4 * np.spacing(np.abs(values))
    of.record("diff", Result(values.reshape(shape), error.reshape(shape)))


def _same_function(of, shape, xs, body, prepared) -> bool:
    """EXPR's mpmath form computes numpy's EXPR (to SAME_FUNCTION) at the rows checked, or,
    where it does not at the point, beside it (0.37 of the point's size away): there the
    difference is numpy's rounding at the point ((1 - cos x)/x^2 is 0 in doubles at 1e-8,
    0.5 in mpmath), not values the form cannot read (a sweep's cases)."""
    from .rounding import discrepancy

    same = discrepancy(of, shape, xs[:, None], body[:, None], prepared, most=CHECKED_ROWS)
    if same is None:
        return False
    if not np.any(same[:, 0] > SAME_FUNCTION * np.maximum(np.abs(body), 1e-300)):
        return True
    away = xs + 0.37 * np.maximum(np.abs(xs), 1.0)
    with np.errstate(all="ignore"):
        there = np.broadcast_to(np.asarray(of(away.reshape(shape)), dtype=float), shape)
    there = there.reshape(-1)
    same = discrepancy(of, shape, away[:, None], there[:, None], prepared, most=CHECKED_ROWS)
    if same is None:
        return False
    return not np.any(same[:, 0] > SAME_FUNCTION * np.maximum(np.abs(there), 1e-300))


def _form_agrees(of, prepared, form, shape, xs, order: int) -> bool:
    """The derivative's mpmath form agrees with a central difference of EXPR's mpmath form
    (at 80 digits, steps of 1e-12 and 1e-10 relative) at the first row: the form computes
    the derivative the doubles are compared with."""

    ctx, body = prepared
    used = of.names_read
    env = {}
    for k, v in of.env.items():
        if k in used:
            env[k] = float(np.broadcast_to(np.asarray(v, dtype=float), shape).reshape(-1)[0])
    # at twice the digits: EXPR's own cancellation (1 - cos x at 1e-8 loses 16 digits) and
    # the difference's (10 more) are what the check must see through
    with ctx.workdps(2 * ctx.dps):
        x = ctx.mpf(float(xs[0]))
        h = ctx.mpf("1e-12" if order == 1 else "1e-10") * (abs(x) if x != 0 else 1)
        try:
            g = [body({**env, of.var: x + k * h}) for k in (-1, 0, 1)]
            exact = form({**env, of.var: x})
        except (ArithmeticError, ValueError, TypeError, KeyError):  # no check: no estimate
            return False
        if order == 1:
            fd = (g[2] - g[0]) / (2 * h)
        else:
            fd = (g[2] - 2 * g[1] + g[0]) / h**2
        return abs(fd - exact) <= ctx.mpf("1e-8") * max(abs(exact), abs(fd), ctx.mpf("1e-300"))
