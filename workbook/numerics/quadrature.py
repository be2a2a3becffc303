"""Definite integrals, one per row, by tanh-sinh quadrature split at the function's kinks."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from ._common import DEFAULT, Fn, NumericsError, Result, Tolerance, _u, num, row_text, rows

_WHY = {
    -1: "the error estimate did not fall below the tolerance (a singular or divergent integral?)",
    -2: "the refinement limit was reached (a singular or divergent integral?)",
    -3: "the function is not a finite number somewhere in the interval (a singularity?)",
}


def integrate(
    f: Fn,
    a,
    b,
    args=(),
    tol: Tolerance = DEFAULT,
    *,
    breaks: Sequence = (),
    var: str = "x",
    unit: str = "",
    label: Callable[[int], str] | None = None,
) -> Result:
    """The integral of ``f(x, *args)`` from a to b for every row (``tanhsinh``).

    ``breaks`` are points (one array each, per row) where f has a kink or a jump (piecewise
    joins, abs, min/max): the interval is split there, so that every piece is smooth. Pieces
    of all rows go to one ``tanhsinh`` call; the error estimate is the sum of the pieces'.
    """
    from scipy.integrate import tanhsinh

    shape, (a, b, *rest) = rows(a, b, *args, *breaks)
    args, brk = rest[: len(args)], rest[len(args) :]
    n = a.size
    if n == 0:
        return Result(np.empty(shape), np.empty(shape))
    sign = np.where(b < a, -1.0, 1.0)
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    if brk:
        inner = np.clip(np.vstack(brk), lo, hi)
        pts = np.sort(np.vstack([lo, inner, hi]), axis=0)
    else:
        pts = np.vstack([lo, hi])
    left, right = pts[:-1], pts[1:]  # (pieces, rows)
    with np.errstate(all="ignore"):
        res = tanhsinh(
            f,
            left,
            right,
            args=tuple(g[None, :] for g in args),
            rtol=max(tol.rtol, 1e-15),
            atol=tol.atol or None,
        )
    status = np.asarray(res.status)
    if (status != 0).any():
        p, i = np.argwhere(status != 0)[0]
        raise NumericsError(
            f"integral(): {_WHY.get(int(status[p, i]), f'status {int(status[p, i])}')}: "
            f"on [{num(left[p, i])}, {num(right[p, i])}]{_u(unit)}{row_text(label, i, n)} "
            f"the estimate is {num(res.integral[p, i])} +- {num(res.error[p, i])}"
        )
    value = sign * res.integral.sum(axis=0)
    error = res.error.sum(axis=0)
    return Result(
        value.reshape(shape), error.reshape(shape), evaluations=int(res.nfev.sum(axis=0).max())
    )
