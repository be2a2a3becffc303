"""Roots, one per row: in a bracket where the function changes sign, or near a guess."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..errors import WorkbookError
from ._common import DEFAULT, Fn, NumericsError, Result, Tolerance, _u, call, num, row_text, rows


def _tolerances(tol: Tolerance) -> dict:
    return {"xatol": tol.atol, "xrtol": max(tol.rtol, 4 * np.finfo(float).eps)}


def root_in(
    f: Fn,
    a,
    b,
    args=(),
    tol: Tolerance = DEFAULT,
    *,
    var: str = "x",
    unit: str = "",
    label: Callable[[int], str] | None = None,
) -> Result:
    """The root of ``f(x, *args) = 0`` in [a, b] for every row (Mathcad's ``root(f, x, a, b)``).

    [a, b] is sampled at ``tol.samples`` intervals: no sign change is an error that lists the
    samples and their signs, more than one sign change (more than one root) is an error too;
    the one interval with the sign change is refined by ``find_root``. The error estimate is
    the width of the final bracket.
    """
    from scipy.optimize.elementwise import find_root

    shape, (a, b, *args) = rows(a, b, *args)
    n, k = a.size, max(int(tol.samples), 1)
    if n == 0:
        return Result(np.empty(shape), np.empty(shape))
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    xs = lo[:, None] + (hi - lo)[:, None] * np.linspace(0.0, 1.0, k + 1)
    fs = call(f, xs, [g[:, None] for g in args])
    if not np.isfinite(fs).all():
        i, j = np.argwhere(~np.isfinite(fs))[0]
        raise NumericsError(
            f"root(): the function is not a finite number at {var} = {num(xs[i, j])}{_u(unit)}"
            f"{row_text(label, i, n)}, inside the bracket [{num(lo[i])}, {num(hi[i])}]{_u(unit)}"
        )
    # signs as booleans (a byte each, not a float): the sampling is a fair share of the time
    positive = fs > 0
    zero = fs == 0
    change = positive[:, :-1] != positive[:, 1:]
    if zero.any():  # a sampled exact zero counts once, even where it touches two intervals
        change &= ~(zero[:, :-1] | zero[:, 1:])
        count = change.sum(axis=1) + zero.sum(axis=1)
    else:
        count = change.sum(axis=1)
    none = np.flatnonzero(count == 0)
    if none.size:
        i = none[0]
        raise NumericsError(
            f"root(): no sign change of the function in [{num(lo[i])}, {num(hi[i])}]{_u(unit)}"
            f"{row_text(label, i, n)}: sampled at {var} = "
            + ", ".join(num(x) for x in xs[i])
            + f" with signs {''.join('+' if v > 0 else '-' for v in fs[i])}"
            + (f" ({none.size} of {n} rows)" if n > 1 else "")
            + "; choose bounds on either side of the root"
        )
    many = np.flatnonzero(count > 1)
    if many.size:
        i = many[0]
        where = [f"[{num(xs[i, j])}, {num(xs[i, j + 1])}]" for j in np.flatnonzero(change[i])] + [
            f"{var} = {num(xs[i, j])}" for j in np.flatnonzero(zero[i])
        ]
        raise NumericsError(
            f"root(): more than one root in [{num(lo[i])}, {num(hi[i])}]{_u(unit)}"
            f"{row_text(label, i, n)}: the function changes sign in {', '.join(where)}; "
            "narrow the bracket to one of them"
        )
    value = np.empty(n)
    error = np.zeros(n)
    evaluations = k + 1
    if zero.any():
        at_zero = zero.any(axis=1)
        value[at_zero] = xs[at_zero][zero[at_zero]]
        todo = np.flatnonzero(~at_zero)
        todo_args = tuple(g[todo] for g in args)
    else:  # every row is refined (no copy of the arguments)
        todo, todo_args = np.arange(n), tuple(args)
    if todo.size:
        j = np.argmax(change[todo], axis=1)
        xl, xr = xs[todo, j], xs[todo, j + 1]
        res = find_root(f, (xl, xr), args=todo_args, tolerances=_tolerances(tol))
        _check_status(res, todo, lo, hi, label, n, unit)
        value[todo] = res.x
        error[todo] = _error(res, tol)
        evaluations += int(np.max(res.nfev))
    return Result(value.reshape(shape), error.reshape(shape), evaluations=evaluations)


def root_near(
    f: Fn,
    guess,
    args=(),
    tol: Tolerance = DEFAULT,
    *,
    var: str = "x",
    unit: str = "",
    label: Callable[[int], str] | None = None,
) -> Result:
    """A root of ``f(x, *args) = 0`` near ``guess`` for every row (``root(f, x, guess)``).

    The function is sampled on both sides of the guess at distances growing by 2 (from a
    quarter of the secant step, so that a root nearer than the secant says is not stepped
    over); the first interval where it changes sign, the nearest the guess, is refined by
    ``find_root`` (both sides at once: the nearer root). A side where the function leaves its
    domain (an error, or not a finite number) is not searched further.
    """
    from scipy.optimize.elementwise import find_root

    shape, (x0, *args) = rows(guess, *args)
    n = x0.size
    if n == 0:
        return Result(np.empty(shape), np.empty(shape))
    h = np.where(x0 != 0, 1e-4 * np.abs(x0), 1e-4)
    try:
        f0 = call(f, x0, args)
        f1 = call(f, x0 + h, args)
    except WorkbookError as err:
        raise NumericsError(
            f"root(): at the guess {var} = {num(x0[0])}{_u(unit)}"
            f"{' (and others)' if n > 1 else ''} the expression has no value ({err.message})"
        ) from None
    with np.errstate(all="ignore"):
        slope = (f1 - f0) / h
        secant = np.where(slope != 0, -f0 / slope, np.inf)
    step = np.where(np.isfinite(secant), np.maximum(0.25 * np.abs(secant), h), 100 * h)
    brackets, evaluations = _brackets_both_sides(f, x0, f0, step, args)
    found = np.isfinite(brackets[..., 0]).any(axis=0)
    failed = np.flatnonzero(~found & (f0 != 0))
    if failed.size:
        i = failed[0]
        raise NumericsError(
            f"root(): no sign change found searching from the guess {var} = {num(x0[i])}"
            f"{_u(unit)}{row_text(label, i, n)} on either side (up to "
            f"{num(step[i] * (2.0**_DOUBLINGS - 1))}{_u(unit)} away, or where the expression "
            f"has a value); give a bracket: root(EXPR, {var}, A, B)"
        )
    value, error = np.where(f0 == 0, x0, np.nan), np.zeros(n)
    for side in (0, 1):  # the sign change on each side, then the nearer root of the two
        idx = np.flatnonzero((f0 != 0) & np.isfinite(brackets[side, :, 0]))
        if not idx.size:
            continue
        lo, hi = brackets[side, idx, 0], brackets[side, idx, 1]
        res = find_root(f, (lo, hi), args=tuple(a[idx] for a in args), tolerances=_tolerances(tol))
        _check_status(res, idx, brackets[side, :, 0], brackets[side, :, 1], label, n, unit)
        evaluations += int(np.max(res.nfev))
        distance = np.abs(value[idx] - x0[idx])
        take = ~(np.abs(res.x - x0[idx]) >= distance)  # nearer, or the first found (NaN)
        value[idx[take]] = res.x[take]
        error[idx[take]] = _error(res, tol)[take]
    return Result(value.reshape(shape), error.reshape(shape), evaluations=evaluations)


#: how many times the distance from the guess doubles (from the first step) in root_near
_DOUBLINGS = 60


def _brackets_both_sides(f, x0, f0, step, args) -> tuple[np.ndarray, int]:
    """[side, row, (lo, hi)]: the interval nearest ``x0`` where ``f`` changes sign, on the
    right (side 0) and on the left (side 1), NaN where none was found; both sides are
    searched to the same distance, which stops at the first distance with a sign change."""
    n = x0.size
    out = np.full((2, n, 2), np.nan)
    prev_x = np.stack([x0, x0])
    prev_f = np.stack([f0, f0])
    alive = np.stack([f0 != 0, f0 != 0]) & np.isfinite(np.stack([f0, f0]))
    evaluations = 2
    for k in range(1, _DOUBLINGS + 1):
        active = alive.any(axis=0) & ~np.isfinite(out[..., 0]).any(axis=0)
        if not active.any():
            break
        for side, sign in ((0, 1.0), (1, -1.0)):
            idx = np.flatnonzero(active & alive[side])
            if not idx.size:
                continue
            x = x0[idx] + sign * step[idx] * (2.0**k - 1)
            fx = _values(f, x, [a[idx] for a in args])
            evaluations += 1
            ok = np.isfinite(fx)
            alive[side, idx[~ok]] = False
            change = ok & (np.sign(fx) * np.sign(prev_f[side, idx]) <= 0)
            rows_ = idx[change]
            a, b = prev_x[side, rows_], x[change]
            out[side, rows_, 0], out[side, rows_, 1] = np.minimum(a, b), np.maximum(a, b)
            prev_x[side, idx], prev_f[side, idx] = x, fx
    return out, evaluations


def _values(f, x, args) -> np.ndarray:
    """f at every row, NaN where the expression has no value (the row is evaluated alone)."""
    try:
        with np.errstate(all="ignore"):
            return np.asarray(call(f, x, args), dtype=float)
    except WorkbookError:
        out = np.full(x.size, np.nan)
        for i in range(x.size):
            try:
                with np.errstate(all="ignore"):
                    out[i] = float(
                        np.asarray(call(f, x[i : i + 1], [a[i : i + 1] for a in args]))[0]
                    )
            except WorkbookError:
                pass
        return out


def _error(res, tol: Tolerance) -> np.ndarray:
    """The final bracket's width; where the function is exactly 0 (the search stops there,
    with a bracket that may still be wide), the tolerance asked for: the computed function's
    own rounding moves its zero by a few units in the last place."""
    width = np.abs(res.bracket[1] - res.bracket[0])
    x = np.abs(res.x)
    asked = np.maximum(tol.rtol * x + tol.atol, 4 * np.spacing(x))
    return np.where(np.asarray(res.f_x) == 0, np.minimum(asked, width), width)


def _check_status(res, idx, lo, hi, label, n, unit) -> None:
    bad = np.flatnonzero(~np.asarray(res.success))
    if bad.size:
        i = bad[0]
        row = idx[i]
        why = {-2: "did not converge", -3: "met a value that is not a finite number"}.get(
            int(res.status[i]), f"failed (status {int(res.status[i])})"
        )
        raise NumericsError(
            f"root(): the root search in [{num(lo[row])}, {num(hi[row])}]{_u(unit)}"
            f"{row_text(label, row, n)} {why}; last bracket [{num(res.bracket[0][i])}, "
            f"{num(res.bracket[1][i])}] with f = {num(res.f_bracket[0][i])}, "
            f"{num(res.f_bracket[1][i])}"
        )
