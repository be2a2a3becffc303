"""Mathcad's spline pair: ``lspline``/``pspline``/``cspline(vx, vy)`` give the second derivatives
of a cubic spline through the points at the points (its coefficients), ``interp(vs, vx, vy, x)``
the spline's value at x. The ends: linear (``lspline``, the natural spline: no curvature at the
ends), parabolic (``pspline``: the end intervals are parabolas) or cubic (``cspline``: the
third derivative is continuous at the second and the last but one point, SciPy's not-a-knot;
with three points or fewer, the natural spline, as ``cspline(X, Y, x)`` does)."""

from __future__ import annotations

import numpy as np

from ..functions.numerical import NumericsError, num
from .interpolate import check_data


def second_derivatives(xs: np.ndarray, ys: np.ndarray, ends: str) -> np.ndarray:
    """The spline's second derivative at each point (a tridiagonal system, banded solve)."""
    from scipy.linalg import solve_banded

    n = xs.size
    if n < 2:
        raise NumericsError("a spline needs at least 2 points")
    if n == 2 or (ends == "cubic" and n <= 3):
        ends = "linear"
    h = np.diff(xs)
    slope = np.diff(ys) / h
    rhs = np.zeros(n)
    rhs[1:-1] = 6 * np.diff(slope)
    # the banded matrix: rows of ab are the diagonals +2, +1, 0, -1, -2
    ab = np.zeros((5, n))
    ab[2, 1:-1] = 2 * (h[:-1] + h[1:])  # M_i
    ab[1, 2:] = h[1:]  # M_(i+1) of row i
    ab[3, :-2] = h[:-1]  # M_(i-1) of row i
    if ends == "linear":  # M_0 = 0, M_(n-1) = 0
        ab[2, 0] = ab[2, -1] = 1.0
    elif ends == "parabolic":  # M_0 = M_1, M_(n-1) = M_(n-2)
        ab[2, 0], ab[1, 1] = 1.0, -1.0
        ab[2, -1], ab[3, -2] = 1.0, -1.0
    else:  # continuous third derivative: h1 (M1 - M0) = h0 (M2 - M1), and at the other end
        ab[2, 0], ab[1, 1], ab[0, 2] = -h[1], h[0] + h[1], -h[0]
        ab[2, -1], ab[3, -2], ab[4, -3] = -h[-2], h[-1] + h[-2], -h[-1]
    with np.errstate(over="ignore", invalid="ignore"):
        out = solve_banded((2, 2), ab, rhs)
    if not np.isfinite(out).all():
        raise NumericsError(
            "the spline's second derivatives overflow (values pass the largest double); give "
            "the data in a larger unit"
        )
    return out


def evaluate(ms: np.ndarray, xs: np.ndarray, ys: np.ndarray, x, what: str) -> np.ndarray:
    """The spline of second derivatives ``ms`` through the points, at x (inside the data)."""
    x = np.asarray(x, dtype=float)
    slack = 1e-12 * max(float(np.max(np.abs(xs))), float(xs[-1] - xs[0]))
    out = (x < xs[0] - slack) | (x > xs[-1] + slack)
    if out.any():
        v = x[out].flat[0] if x.ndim else float(x)
        raise NumericsError(
            f"{what}: x = {num(v)} is outside the data [{num(xs[0])}, {num(xs[-1])}]"
        )
    x = np.clip(x, xs[0], xs[-1])
    i = np.clip(np.searchsorted(xs, x, side="right") - 1, 0, xs.size - 2)
    h = xs[i + 1] - xs[i]
    a = (xs[i + 1] - x) / h
    b = 1 - a
    with np.errstate(over="ignore", invalid="ignore"):
        y = a * ys[i] + b * ys[i + 1] + ((a**3 - a) * ms[i] + (b**3 - b) * ms[i + 1]) * h * h / 6
    if not np.isfinite(y).all():
        raise NumericsError(f"{what}: the spline overflows; give the data in a larger unit")
    return y


def checked(xs, ys, what: str) -> tuple[np.ndarray, np.ndarray]:
    """The points as two vectors of numbers, x strictly increasing."""
    xs, ys = _vector(xs, what), _vector(ys, what)
    check_data(xs, ys, what)
    return xs, ys


def _vector(v, what: str) -> np.ndarray:
    v = np.asarray(v)
    if v.ndim == 2 and v.shape[1] == 1 and v.dtype != object:
        v = v[:, 0]
    if v.ndim != 1 or v.dtype == object:
        raise NumericsError(f"{what}: the points must be vectors of numbers (not over a range)")
    return v.astype(float)
