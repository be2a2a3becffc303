"""Given/Find: a system of equations in scalar unknowns (scipy.optimize.root)."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from ..functions.numerical import DEFAULT, NumericsError, Result, Tolerance, num
from ..language.given_find import METHODS as METHOD_NAMES

#: scipy's method of each method of a [[solve]] block
METHODS = dict(zip(METHOD_NAMES, ("hybr", "lm", "lm"), strict=True))

#: the distances from the guess (in units of the guess's size) of the starts ``nearest`` tries
_RADII = (0.0, 0.5, 1.0, 2.0, 4.0, 8.0)


def solve(
    residuals: Callable[[np.ndarray], np.ndarray],
    guess: Sequence[float],
    scales: Sequence[float],
    tol: Tolerance = DEFAULT,
    *,
    names: Sequence[str] = (),
    equations: Sequence[str] = (),
    method: str = "hybrid",
    violations: Callable[[np.ndarray], np.ndarray] | None = None,
) -> Result:
    """Unknowns x with ``residuals(x) == 0`` (one residual per equation, each divided by the
    size of its terms so that all are relative), starting from ``guess``.

    The unknowns are scaled by ``scales`` (the guess's size). Not converging, or a residual
    above the tolerance at the end, is an error that lists every equation's residual.
    The error estimate of each unknown is from the Jacobian: |J^-1 r|.

    ``levenberg-marquardt`` is MINPACK's (as Mathcad's Find): the residuals are padded with
    zeros to as many as unknowns (fewer equations than unknowns: the point it reaches), and
    ``violations(x)`` (how far x is outside each condition, 0 inside) are residuals too, so
    that the root meets the conditions (a guess outside one is first moved to meet them).
    ``nearest`` is the root meeting the conditions that is nearest the guess (in units of the
    guess's size), from Levenberg-Marquardt started at the guess and at points around it.
    """
    x0 = np.asarray(guess, dtype=float)
    s = np.where(np.asarray(scales, dtype=float) != 0, np.abs(scales), 1.0)
    square = method == "hybrid"
    if len(equations) != x0.size if square else not 0 < len(equations) <= x0.size:
        raise NumericsError(
            f"solve: {len(equations)} equation(s) for {x0.size} unknown(s) "
            f"({', '.join(names)}); give as many equations as unknowns"
            + ("" if square else " (or fewer)")
        )
    limit = max(tol.rtol * 100, 1e-12)
    if method == "hybrid":
        sol = _hybrid(residuals, x0, s, tol)
    elif method == "levenberg-marquardt":
        sol = _levenberg(residuals, violations, x0 / s, s, tol)
    else:
        sol = _nearest(residuals, violations, x0, s, tol, limit)
    x = sol.x * s
    r = np.asarray(residuals(x), dtype=float)
    if not (np.isfinite(r).all() and np.max(np.abs(r)) <= limit):
        lines = "; ".join(f"{e}: residual {num(v)}" for e, v in zip(equations, r))
        at = ", ".join(f"{n} = {num(v)}" for n, v in zip(names, x))
        why = " ".join(str(sol.message).split()).rstrip(".")
        raise NumericsError(
            f"solve did not converge ({why}): at {at} the relative residuals are {lines} "
            f"(limit {limit:g}); try other guesses"
        )
    err, cond = conditioned_error(residuals, x, s, r)
    return Result(x, err, evaluations=int(sol.nfev), notes={"condition": cond})


#: A relative residual is known to about this (its terms are rounded to doubles).
RESIDUAL_FLOOR = 4 * np.finfo(float).eps


def conditioned_error(residuals, x: np.ndarray, s: np.ndarray, r: np.ndarray):
    """(error estimate per unknown, condition number) at a solution x: the first-order effect
    of the residuals' uncertainty, |J^-1| (max(|r|, RESIDUAL_FLOOR)), with J the central-
    difference Jacobian of the relative residuals in the scaled unknowns x/s. An ill-
    conditioned system (p + q = 2, p + (1 + 1e-10) q = 2 + 1e-10: condition near 4e10) gets
    an estimate of its size, not the solver's last step."""
    z = x / s
    n, m = z.size, np.asarray(r).size
    if m != n:  # fewer equations than unknowns: a point reached, not a root to condition
        return np.full(n, np.nan), float("nan")
    jac = np.empty((m, n))
    with np.errstate(all="ignore"):
        for j in range(n):
            h = 1e-6 * max(1.0, abs(z[j]))
            up, down = z.copy(), z.copy()
            up[j] += h
            down[j] -= h
            jac[:, j] = (
                np.asarray(residuals(up * s), dtype=float)
                - np.asarray(residuals(down * s), dtype=float)
            ) / (2 * h)
    if not np.all(np.isfinite(jac)):
        return np.full(n, np.nan), float("nan")
    cond = float(np.linalg.cond(jac))
    try:
        inverse = np.linalg.inv(jac)
    except np.linalg.LinAlgError:
        return np.full(n, np.inf), float("inf")
    delta = np.maximum(np.abs(r), RESIDUAL_FLOOR)
    return (np.abs(inverse) @ delta) * s, cond


def _hybrid(residuals, x0, s, tol):
    from scipy.optimize import root

    def scaled(z):
        r = np.asarray(residuals(z * s), dtype=float)
        return np.where(np.isfinite(r), r, 1e300)

    with np.errstate(all="ignore"):
        return root(scaled, x0 / s, method="hybr", options={"xtol": max(tol.rtol, 1e-15)})


def _levenberg(residuals, violations, z0, s, tol):
    """MINPACK's Levenberg-Marquardt from ``z0`` (scaled unknowns): equations, then the
    conditions' violations, padded with zeros to as many residuals as unknowns; a start
    outside a condition is first moved to meet the conditions."""
    from types import SimpleNamespace

    from scipy.optimize import leastsq

    if violations is not None and np.asarray(violations(z0 * s)).any():
        # a guess outside a condition is first moved to meet it (the conditions alone)
        def outside(z):
            v = np.asarray(violations(z * s), dtype=float)
            v = np.concatenate([v, np.zeros(max(z.size - v.size, 0))])
            return np.where(np.isfinite(v), v, 1e300)

        with np.errstate(all="ignore"):
            z0 = leastsq(outside, z0, xtol=max(tol.rtol, 1e-15))[0]

    def scaled(z):
        r = np.asarray(residuals(z * s), dtype=float)
        if violations is not None:
            r = np.concatenate([r, np.asarray(violations(z * s), dtype=float)])
        if r.size < z.size:
            r = np.concatenate([r, np.zeros(z.size - r.size)])
        return np.where(np.isfinite(r), r, 1e300)

    with np.errstate(all="ignore"):
        x, _, info, message, _ = leastsq(
            scaled, z0, full_output=True, xtol=max(tol.rtol, 1e-15), ftol=max(tol.rtol, 1e-15)
        )
    return SimpleNamespace(x=x, message=message, nfev=info["nfev"])


def _nearest(residuals, violations, x0, s, tol, limit):
    """The root meeting the conditions nearest ``x0``, from Levenberg-Marquardt started at
    ``x0`` and at points on each axis and diagonal around it (distances ``_RADII``)."""
    n = x0.size
    directions = [np.eye(n)[i] * sign for i in range(n) for sign in (1, -1)]
    if n > 1:
        directions += [np.array(v) / np.sqrt(n) for v in _corners(n)]
    best, best_d, tried = None, np.inf, 0
    for radius in _RADII:
        for d in directions if radius else [np.zeros(n)]:
            sol = _levenberg(residuals, violations, x0 / s + radius * d, s, tol)
            tried += sol.nfev
            x = sol.x * s
            with np.errstate(all="ignore"):
                r = np.asarray(residuals(x), dtype=float)
                v = np.asarray(violations(x), dtype=float) if violations else np.zeros(1)
            if not (np.isfinite(r).all() and np.max(np.abs(r)) <= limit and not v.any()):
                continue
            dist = float(np.linalg.norm(sol.x - x0 / s))
            if dist < best_d:
                best, best_d = sol, dist
        if best is not None and best_d <= radius:  # a start farther out reaches farther roots
            break
    if best is None:
        best = _levenberg(residuals, violations, x0 / s, s, tol)
    best.nfev = tried
    return best


def _corners(n: int) -> list[list[float]]:
    """The 2^n sign patterns of a diagonal (at most 16: the first four unknowns)."""
    m = min(n, 4)
    return [[(1 if (k >> i) & 1 else -1) if i < m else 0 for i in range(n)] for k in range(2**m)]
