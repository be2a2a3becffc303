"""Given/Find: a system of equations in scalar unknowns (scipy.optimize.root)."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from ._common import DEFAULT, NumericsError, Result, Tolerance, num

#: the methods of a [[solve]] block: Powell's hybrid method (the default), or Levenberg-Marquardt
#: (Mathcad's Find); from the same guess they may reach different roots of a system with several
METHODS = {"hybrid": "hybr", "levenberg-marquardt": "lm"}


def solve(
    residuals: Callable[[np.ndarray], np.ndarray],
    guess: Sequence[float],
    scales: Sequence[float],
    tol: Tolerance = DEFAULT,
    *,
    names: Sequence[str] = (),
    equations: Sequence[str] = (),
    method: str = "hybrid",
) -> Result:
    """Unknowns x with ``residuals(x) == 0`` (one residual per equation, each divided by the
    size of its terms so that all are relative), starting from ``guess``.

    The unknowns are scaled by ``scales`` (the guess's size). Not converging, or a residual
    above the tolerance at the end, is an error that lists every equation's residual.
    The error estimate of each unknown is from the Jacobian: |J^-1 r|.
    """
    from scipy.optimize import root

    x0 = np.asarray(guess, dtype=float)
    s = np.where(np.asarray(scales, dtype=float) != 0, np.abs(scales), 1.0)
    if len(equations) != x0.size:
        raise NumericsError(
            f"solve: {len(equations)} equation(s) for {x0.size} unknown(s) "
            f"({', '.join(names)}); give as many equations as unknowns"
        )

    def scaled(z):
        r = np.asarray(residuals(z * s), dtype=float)
        return np.where(np.isfinite(r), r, 1e300)

    with np.errstate(all="ignore"):
        scipy_method = METHODS[method]
        sol = root(scaled, x0 / s, method=scipy_method, options={"xtol": max(tol.rtol, 1e-15)})
    x = sol.x * s
    r = np.asarray(residuals(x), dtype=float)
    limit = max(tol.rtol * 100, 1e-12)
    if not (np.isfinite(r).all() and np.max(np.abs(r)) <= limit):
        lines = "; ".join(f"{e}: residual {num(v)}" for e, v in zip(equations, r))
        at = ", ".join(f"{n} = {num(v)}" for n, v in zip(names, x))
        why = " ".join(str(sol.message).split()).rstrip(".")
        raise NumericsError(
            f"solve did not converge ({why}): at {at} the relative residuals are {lines} "
            f"(limit {limit:g}); try other guesses"
        )
    try:
        jac = np.asarray(sol.fjac).T @ np.triu(_unpack_r(sol.r, x0.size))
        err = np.abs(np.linalg.solve(jac, r)) * s
    except (AttributeError, np.linalg.LinAlgError, ValueError):
        err = np.full(x.size, np.nan)
    return Result(x, err, evaluations=int(sol.nfev))


def _unpack_r(packed: np.ndarray, n: int) -> np.ndarray:
    out = np.zeros((n, n))
    out[np.triu_indices(n)] = packed
    return out
