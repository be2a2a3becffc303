"""Matrix factorizations as Mathcad computes them: ``lu`` (Crout's method with implicit row
scaling), ``rref`` (reduced row echelon form) and ``geninv`` (the generalized inverse).

Each takes one matrix (rows, columns; no range axes: a matrix that varies over a range is an
error) and gives one matrix. Where the result depends on a choice the mathematics leaves open
(which row becomes the pivot), the choice is Mathcad's, so that the stored results of
Mathcad's worksheets are reproduced, not only a valid factorization.
"""

from __future__ import annotations

import numpy as np

from ..errors import DomainError, InputError

#: A pivot smaller than this times the largest element of the matrix is taken as 0 by rref.
RREF_TOLERANCE = 1e-12


def _fixed(m, what: str) -> np.ndarray:
    a = np.array(m, dtype=float)
    if a.ndim != 2:
        raise InputError(f"{what}: the matrix varies over a range; factor a fixed matrix")
    return a


def lu(m) -> np.ndarray:
    """Mathcad's lu(M): the n x 3n matrix augment(P, L, U) with P M = L U, P a permutation,
    L lower triangular with ones on its diagonal, U upper triangular.

    Crout's method with implicit pivoting (each row scaled by its largest element when the
    pivot is chosen; of equal candidates, the last row), which is the pivot order of
    Mathcad's stored results. A zero pivot (a singular matrix) is an error."""
    a = _fixed(m, "lu()")
    n, c = a.shape
    if n != c:
        raise InputError(f"lu() needs a square matrix, got {n}x{c}")
    largest = np.abs(a).max(axis=1)
    if np.any(largest == 0):
        raise DomainError("lu(): the matrix is singular (a row of zeros)")
    scale = 1.0 / largest
    perm = np.arange(n)
    for j in range(n):
        for i in range(j):
            a[i, j] -= a[i, :i] @ a[:i, j]
        best, pivot = 0.0, j
        for i in range(j, n):
            a[i, j] -= a[i, :j] @ a[:j, j]
            if scale[i] * abs(a[i, j]) >= best:
                best, pivot = scale[i] * abs(a[i, j]), i
        if pivot != j:
            a[[j, pivot]] = a[[pivot, j]]
            scale[pivot] = scale[j]
            perm[[j, pivot]] = perm[[pivot, j]]
        if a[j, j] == 0:
            raise DomainError(f"lu(): the matrix is singular (pivot {j + 1} is 0)")
        a[j + 1 :, j] /= a[j, j]
    lower = np.tril(a, -1) + np.eye(n)
    upper = np.triu(a)
    return np.hstack([np.eye(n)[perm], lower, upper])


def rref(m) -> np.ndarray:
    """The reduced row echelon form: Gauss-Jordan elimination with partial pivoting (the
    largest element of the column); a pivot below RREF_TOLERANCE times the largest element
    of the matrix is 0."""
    a = _fixed(m, "rref()")
    rows, cols = a.shape
    tiny = RREF_TOLERANCE * max(float(np.abs(a).max()), np.finfo(float).tiny)
    row = 0
    for j in range(cols):
        if row >= rows:
            break
        p = row + int(np.argmax(np.abs(a[row:, j])))
        if abs(a[p, j]) <= tiny:
            a[row:, j] = 0.0
            continue
        a[[row, p]] = a[[p, row]]
        a[row] /= a[row, j]
        others = np.arange(rows) != row
        a[others] -= np.outer(a[others, j], a[row])
        a[others, j] = 0.0
        row += 1
    return a


def geninv(m, singular_cond: float) -> np.ndarray:
    """Mathcad's geninv(M): the left inverse L of an m x n matrix (m >= n) of full column
    rank, L M = I: the pseudo-inverse (M^T M)^-1 M^T. A matrix of fewer rows than columns, or
    of dependent columns (condition number above ``singular_cond``), is an error."""
    a = _fixed(m, "geninv()")
    r, c = a.shape
    if r < c:
        raise InputError(f"geninv() needs at least as many rows as columns, got {r}x{c}")
    with np.errstate(all="ignore"):
        cond = np.linalg.cond(a)
    if not cond < singular_cond:
        raise DomainError(
            f"geninv(): the columns of the matrix are dependent (condition number {cond:.3g})"
        )
    return np.linalg.pinv(a)
