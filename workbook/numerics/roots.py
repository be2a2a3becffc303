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
    bad = ~np.isfinite(fs)
    if bad.any():
        i, j = np.argwhere(bad)[0]
        raise NumericsError(
            f"root(): the function is not a finite number at {var} = {num(xs[i, j])}{_u(unit)}"
            f"{row_text(label, i, n)}, inside the bracket [{num(lo[i])}, {num(hi[i])}]{_u(unit)}"
        )
    s = np.sign(fs)
    change = s[:, :-1] * s[:, 1:] < 0
    zero = s == 0
    # a sampled exact zero counts once, even where it touches two intervals
    count = change.sum(axis=1) + zero.sum(axis=1)
    none = np.flatnonzero(count == 0)
    if none.size:
        i = none[0]
        raise NumericsError(
            f"root(): no sign change of the function in [{num(lo[i])}, {num(hi[i])}]{_u(unit)}"
            f"{row_text(label, i, n)}: sampled at {var} = "
            + ", ".join(num(x) for x in xs[i])
            + f" with signs {''.join('+' if v > 0 else '-' for v in s[i])}"
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
    at_zero = zero.any(axis=1)
    value[at_zero] = xs[at_zero][zero[at_zero]]
    todo = np.flatnonzero(~at_zero)
    evaluations = k + 1
    if todo.size:
        j = np.argmax(change[todo], axis=1)
        xl, xr = xs[todo, j], xs[todo, j + 1]
        res = find_root(f, (xl, xr), args=tuple(g[todo] for g in args), tolerances=_tolerances(tol))
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

    A secant step from the guess says on which side the root is; a bracket is searched on
    that side only (``bracket_root``, steps growing by 2 from 1.5 secant steps, so that the
    search does not leave the function's domain on the other side), then refined by
    ``find_root``.
    """
    from scipy.optimize.elementwise import bracket_root, find_root

    shape, (x0, *args) = rows(guess, *args)
    n = x0.size
    if n == 0:
        return Result(np.empty(shape), np.empty(shape))
    h = np.where(x0 != 0, 1e-4 * np.abs(x0), 1e-4)
    try:
        f0 = call(f, x0, args)
        f1 = call(f, x0 + h, args)
        with np.errstate(all="ignore"):
            slope = (f1 - f0) / h
            secant = np.where(slope != 0, -f0 / slope, np.inf)
        right = np.where(np.isfinite(secant), secant > 0, True)
        step = np.where(np.isfinite(secant), np.maximum(1.5 * np.abs(secant), h), 100 * h)
        xl0 = np.where(right, x0, x0 - step)
        xr0 = np.where(right, x0 + step, x0)
        xmin = np.where(right, x0, -np.inf)
        xmax = np.where(right, np.inf, x0)
        with np.errstate(all="ignore"):
            br = bracket_root(f, xl0, xr0, xmin=xmin, xmax=xmax, args=tuple(args), maxiter=200)
    except WorkbookError as err:
        raise NumericsError(
            f"root(): searching for a sign change from the guess {var} = {num(x0[0])}"
            f"{_u(unit)}{' (and others)' if n > 1 else ''}, the expression left its domain "
            f"({err.message}); give a bracket: root(EXPR, {var}, A, B)"
        ) from None
    failed = np.flatnonzero(~br.success & (f0 != 0))
    if failed.size:
        i = failed[0]
        raise NumericsError(
            f"root(): no sign change found searching from the guess {var} = {num(x0[i])}"
            f"{_u(unit)}{row_text(label, i, n)} (searched [{num(br.bracket[0][i])}, "
            f"{num(br.bracket[1][i])}]{_u(unit)}, f = {num(br.f_bracket[0][i])} and "
            f"{num(br.f_bracket[1][i])}); give a bracket: root(EXPR, {var}, A, B)"
        )
    xl, xr = br.bracket
    xl, xr = np.where(f0 == 0, x0, xl), np.where(f0 == 0, x0, xr)
    res = find_root(f, (xl, xr), args=tuple(args), tolerances=_tolerances(tol))
    _check_status(res, np.arange(n), np.minimum(xl, xr), np.maximum(xl, xr), label, n, unit)
    error = _error(res, tol)
    evaluations = 2 + int(np.max(br.nfev)) + int(np.max(res.nfev))
    return Result(res.x.reshape(shape), error.reshape(shape), evaluations=evaluations)


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
