"""Fixed Gauss-Legendre rules: the live Excel form of an integral (SUMPRODUCT over nodes)."""

from __future__ import annotations

from functools import lru_cache

import numpy as np


@lru_cache(maxsize=32)
def rule(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes on [0, 1] and weights (summing to 1) of the ``n``-point Gauss-Legendre rule."""
    x, w = np.polynomial.legendre.leggauss(n)
    return (x + 1.0) / 2.0, w / 2.0


def pieces_value(f, points: np.ndarray, n: int, args=()) -> np.ndarray:
    """The n-point rule on every piece between consecutive ``points`` (axis 0), summed."""
    t, w = rule(n)
    left, right = points[:-1], points[1:]
    x = left[..., None] + (right - left)[..., None] * t
    fx = np.asarray(f(x, *[np.asarray(g)[..., None] for g in args]), dtype=float)
    return (((right - left)[..., None] * w * fx).sum(axis=-1)).sum(axis=0)


def smallest_rule(
    f, points, target, tolerance: float, args=(), most: int = 64
) -> tuple[int, float]:
    """The fewest nodes per piece (doubling from 4) whose value is within ``tolerance`` of
    ``target`` (the engine's value); returns (n, largest difference). Beyond ``most`` nodes
    the best found is returned with its difference."""
    n, best = 4, (4, np.inf)
    while n <= most:
        diff = float(np.max(np.abs(pieces_value(f, points, n, args) - target)))
        if diff < best[1]:
            best = (n, diff)
        if diff <= tolerance:
            return n, diff
        n *= 2
    return best
