"""Norms, condition numbers, trace, diagonal and singular values of matrices (Mathcad's norm1,
norm2, normi, cond1, cond2, conde, condi, tr, diag, svds): the numerical side of their registry
entries in :mod:`workbook.functions.matrix`. Each takes one fixed matrix (no range axes)."""

from __future__ import annotations

import numpy as np

from ..errors import DomainError, InputError

#: numpy's order of each norm: 1 (largest column sum), 2 (largest singular value), Frobenius
#: (the square root of the sum of squares), infinity (largest row sum)
ORDERS = {"1": 1, "2": 2, "e": "fro", "i": np.inf}


def _fixed(m, what: str) -> np.ndarray:
    a = np.asarray(m, dtype=float)
    if a.ndim != 2:
        raise InputError(f"{what}: the matrix varies over a range; give a fixed matrix")
    return a


def matrix_norm(m, kind: str) -> float:
    """norm1, norm2, norme or normi of a matrix (``kind`` a key of ORDERS)."""
    return float(np.linalg.norm(_fixed(m, f"norm{kind}()"), ORDERS[kind]))


def condition(m, kind: str, singular_cond: float) -> float:
    """The condition number norm(M) norm(M^-1) in that norm; a singular matrix is an error."""
    a = _fixed(m, f"cond{kind}()")
    if a.shape[0] != a.shape[1]:
        raise InputError(f"cond{kind}() needs a square matrix, got {a.shape[0]}x{a.shape[1]}")
    with np.errstate(all="ignore"):
        two = np.linalg.cond(a)
    if not two < singular_cond:
        raise DomainError(f"cond{kind}(): the matrix is singular (condition number {two:.3g})")
    return float(np.linalg.cond(a, ORDERS[kind]))


def trace(m) -> float:
    a = _fixed(m, "tr()")
    if a.shape[0] != a.shape[1]:
        raise InputError(f"tr() needs a square matrix, got {a.shape[0]}x{a.shape[1]}")
    return float(np.trace(a))


def diag(m) -> np.ndarray:
    """The diagonal of a square matrix as a vector; of a vector, the diagonal matrix."""
    a = _fixed(m, "diag()")
    if a.shape[1] == 1:
        return np.diag(a[:, 0])
    if a.shape[0] != a.shape[1]:
        raise InputError(f"diag() needs a vector or a square matrix, got {a.shape[0]}x{a.shape[1]}")
    return np.diag(a).reshape(-1, 1).copy()


def singular_values(m) -> np.ndarray:
    """The singular values, largest first, as a vector."""
    return np.linalg.svd(_fixed(m, "svds()"), compute_uv=False).reshape(-1, 1)
