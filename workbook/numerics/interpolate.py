"""Interpolation in measured data (Mathcad's linterp, and interp over cspline)."""

from __future__ import annotations

import numpy as np

from ..functions.numerical import NumericsError, num
from ..functions.numerical import unit_suffix as _u


def check_data(xs: np.ndarray, ys: np.ndarray, what: str) -> None:
    """Data points must be finite, as many x as y, at least 2, x strictly increasing."""
    if xs.shape != ys.shape or xs.ndim != 1:
        raise NumericsError(f"{what}: x and y need the same number of values")
    if xs.size < 2:
        raise NumericsError(f"{what}: at least 2 points are needed, got {xs.size}")
    if not (np.isfinite(xs).all() and np.isfinite(ys).all()):
        raise NumericsError(f"{what}: the data hold a value that is not a finite number")
    with np.errstate(over="ignore", invalid="ignore"):
        dx, dy = np.diff(xs), np.diff(ys)
        slopes = dy / dx
    if not (np.isfinite(dx).all() and np.isfinite(dy).all() and np.isfinite(slopes).all()):
        raise NumericsError(
            f"{what}: the data are too large for an interpolation in doubles (a difference or "
            "slope between neighbouring points overflows); give them in a larger unit"
        )
    step = np.flatnonzero(dx <= 0)
    if step.size:
        i = step[0]
        raise NumericsError(
            f"{what}: x must be strictly increasing; x[{i + 1}] = {num(xs[i])} is followed by "
            f"{num(xs[i + 1])}"
        )


def interpolate(xs, ys, x, *, kind: str = "linear", what: str = "linterp()", unit: str = ""):
    """y at x by linear interpolation (``linear``) or a not-a-knot cubic spline (``cubic``,
    Mathcad's cspline with cubic ends). x outside the data is an error, not an extrapolation."""
    x = np.asarray(x, dtype=float)
    # unit conversions round: an end point a few ulps outside is the end point
    slack = 1e-12 * max(float(np.max(np.abs(xs))), float(xs[-1] - xs[0]))
    out = (x < xs[0] - slack) | (x > xs[-1] + slack)
    if out.any():
        v = x[out].flat[0] if x.ndim else float(x)
        raise NumericsError(
            f"{what}: x = {num(v)}{_u(unit)} is outside the data "
            f"[{num(xs[0])}, {num(xs[-1])}]{_u(unit)}"
        )
    x = np.clip(x, xs[0], xs[-1])
    if kind == "linear":
        return np.interp(x, xs, ys)
    from scipy.interpolate import CubicSpline

    bc = "not-a-knot" if xs.size > 3 else "natural"
    with np.errstate(over="ignore", invalid="ignore"):
        try:
            y = CubicSpline(xs, ys, bc_type=bc)(x)
        except ValueError as exc:
            raise NumericsError(f"{what}: the data cannot be interpolated ({exc})") from None
    if not np.isfinite(y).all():
        raise NumericsError(
            f"{what}: the spline through the data overflows (its values pass the largest "
            "double); give the data in a larger unit"
        )
    return y
