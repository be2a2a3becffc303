"""Fixed Gauss-Legendre rules: the live Excel form of an integral (a sum over nodes).

Excel computes with arrays of at most two axes, and an array operation between two arrays of
the same shape is element by element. The nodes of an integral are therefore a row, and the
nodes of an integral inside its integrand (a beam's double integration) a column: the inner
integrand is then a matrix (inner nodes down, outer nodes across), which ``MMULT`` with the
weights sums down each column into a row of the outer integrand's values. A third integral
inside has no axis left and is not live.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..errors import NotLive


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


def _literal(values: np.ndarray, separator: str) -> str:
    return "{" + separator.join(repr(float(v)).upper() for v in values) + "}"


@lru_cache(maxsize=8)
def literals(n: int) -> tuple[str, str, str, str]:
    """Excel array constants of the ``n``-point rule: nodes as a row, weights as a row,
    nodes as a column, weights as a column."""
    t, w = rule(n)
    return _literal(t, ","), _literal(w, ","), _literal(t, ";"), _literal(w, ";")


def axes_in(text: str, n: int) -> int:
    """How many node arrays of the ``n``-point rule (enclosing integrals) a printed formula
    holds: 0, 1 (a row) or 2 (a row and a column)."""
    row, _, column, _ = literals(n)
    return (row in text) + (column in text)


def excel_form(body, a: str, b: str, n: int, scope: tuple[str, ...]) -> str:
    """The live formula of the integral of ``body`` (prints EXPR at a node array) for the
    variable from ``a`` to ``b`` by the ``n``-point rule; ``scope`` holds the printed values
    of the variables around it (an enclosing integral's nodes make this one a column)."""
    row, weights, column, _ = literals(n)
    outer = max((axes_in(text, n) for text in (a, b, *scope)), default=0)
    width = f"(({b})-({a}))"
    if outer == 0:
        return f"{width}*SUMPRODUCT({weights}*({body(f'(({a})+{width}*{row})')}))"
    if outer == 1:
        x = f"(({a})+{width}*{column})"
        # +0*column makes EXPR a matrix (or a column) even where it does not depend on x
        return f"{width}*MMULT({weights},({body(x)})+0*{column})"
    raise NotLive(
        "an integral inside two enclosing integrals: Excel's arrays have two axes, one for "
        "each of the two outer integrals' nodes; its values are written as numbers"
    )


def refuse_in_integral(name: str, texts, n: int) -> None:
    """NotLive when a built-in computed in helper cells (one value per cell: a root's
    bisection, an extremum's samples) would depend on an enclosing integral's nodes."""
    if any(axes_in(text, n) for text in texts):
        raise NotLive(
            f"{name}() inside an integral's integrand depends on the integral's variable: "
            "its helper cells hold one value each, not one per node; its values are "
            "written as numbers"
        )
