"""Vectors and matrices on numpy arrays: the numerical side of the matrix built-ins.

Layout: a matrix value is an array whose **first two axes are (rows, columns)**; any further
axes are those of a table's range variable (a matrix that depends on phi, evaluated over
phi's values). A scalar of shape S then broadcasts against a matrix of shape (r, c) + S by
numpy's own rules once the matrix has as many trailing axes (:func:`pad`). A vector is a
column, shape (n, 1), as in Mathcad.

Errors say what is wrong with the value (singular, not square, index out of range); the
back end adds the definition's name and location.
"""

from __future__ import annotations

import math

import numpy as np

from .errors import DomainError, InputError

#: A matrix whose condition number exceeds this is singular for inverse and lsolve.
SINGULAR_COND = 1e14


def pad(m, extra: int):
    """Matrix ``m`` with ``extra`` more trailing unit axes (to meet a scalar's range axes)."""
    m = np.asarray(m)
    return m.reshape(m.shape + (1,) * extra) if extra > 0 else m


def elementwise(op, a, b, a_matrix: bool, b_matrix: bool):
    """``op(a, b)`` element by element, a matrix against a matrix or a scalar."""
    a, b = np.asarray(a), np.asarray(b)
    ra = a.ndim - 2 if a_matrix else a.ndim  # range axes of each
    rb = b.ndim - 2 if b_matrix else b.ndim
    if a_matrix:
        a = pad(a, rb - ra)
    if b_matrix:
        b = pad(b, ra - rb)
    if a_matrix and not b_matrix:
        b = b.reshape((1, 1) + b.shape) if b.ndim else b
    if b_matrix and not a_matrix:
        a = a.reshape((1, 1) + a.shape) if a.ndim else a
    return op(a, b)


def _last(m):
    """Matrix axes last (numpy.linalg's layout)."""
    m = np.asarray(m, dtype=float)
    return np.moveaxis(m, (0, 1), (-2, -1))


def _first(m):
    return np.moveaxis(m, (-2, -1), (0, 1))


def build(rows: list[list]) -> np.ndarray:
    """A matrix from its elements (each a scalar or an array over the range)."""
    flat = np.broadcast_arrays(*[np.asarray(v, dtype=float) for row in rows for v in row])
    r, c = len(rows), len(rows[0])
    return np.stack(flat).reshape((r, c) + flat[0].shape)


def matmul(a, b):
    """Matrix product; two vectors of one length give their dot product (Mathcad's v*w)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    ra, rb = a.ndim - 2, b.ndim - 2
    a, b = pad(a, rb - ra), pad(b, ra - rb)
    return np.einsum("ik...,kj...->ij...", a, b)


def dot(a, b):
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    ra, rb = a.ndim - 2, b.ndim - 2
    a, b = pad(a, rb - ra), pad(b, ra - rb)
    return _scalar(np.sum(a * b, axis=(0, 1)))


def _scalar(x):
    return float(x) if np.ndim(x) == 0 else x


def transpose(m):
    return np.swapaxes(np.asarray(m, dtype=float), 0, 1)


def det(m):
    return _scalar(np.linalg.det(_last(m)))


def _check_regular(m, what: str):
    mm = _last(m)
    with np.errstate(all="ignore"):
        cond = np.linalg.cond(mm)
    worst = float(np.max(np.where(np.isfinite(cond), cond, np.inf)))
    if not worst < SINGULAR_COND:
        shown = "infinite" if not math.isfinite(worst) else f"{worst:.3g}"
        raise DomainError(
            f"{what}: the matrix is singular (condition number {shown}, limit {SINGULAR_COND:g})"
        )
    return mm


def inverse(m):
    return _first(np.linalg.inv(_check_regular(m, "inverse()")))


def power(m, n: int):
    """Matrix power M^n (n an integer; M^-1 is the inverse)."""
    if n < 0:
        m = inverse(m)
        n = -n
    return _first(np.linalg.matrix_power(_last(m), n))


def lsolve(m, v):
    mm = _check_regular(m, "lsolve()")
    vv = _last(v)
    extra = mm.ndim - vv.ndim
    if extra > 0:
        vv = vv.reshape((1,) * extra + vv.shape)
    elif extra < 0:
        mm = mm.reshape((1,) * -extra + mm.shape)
    return _first(np.linalg.solve(mm, vv))


def _real(values, what: str):
    if np.any(np.abs(values.imag) > 1e-9 * np.maximum(1.0, np.abs(values.real))):
        raise DomainError(f"{what}: the matrix has complex eigenvalues (not supported)")
    return values.real


def eigenvals(m):
    """Eigenvalues, ascending, as a column vector."""
    lam = _real(np.linalg.eigvals(_last(m)), "eigenvals()")
    lam = np.sort(lam, axis=-1)
    return np.moveaxis(lam[..., None], (-2, -1), (0, 1))


def eigenvecs(m):
    """Unit eigenvectors as columns, in the order of eigenvals (ascending); each column's
    largest component is positive (a fixed sign)."""
    lam, vec = np.linalg.eig(_last(m))
    lam = _real(lam, "eigenvecs()")
    vec = _real(vec, "eigenvecs()")
    order = np.argsort(lam, axis=-1)
    vec = np.take_along_axis(vec, order[..., None, :], axis=-1)
    big = np.take_along_axis(vec, np.argmax(np.abs(vec), axis=-2)[..., None, :], axis=-2)
    vec = vec * np.where(big < 0, -1.0, 1.0)
    return _first(vec)


def cross(a, b):
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    ra, rb = a.ndim - 2, b.ndim - 2
    a, b = pad(a, rb - ra), pad(b, ra - rb)
    return np.cross(a, b, axis=0)


def norm(v):
    return _scalar(np.sqrt(np.sum(np.square(np.asarray(v, dtype=float)), axis=(0, 1))))


def augment(*ms):
    ms = _same_range(ms)
    return np.concatenate(ms, axis=1)


def stack(*ms):
    ms = _same_range(ms)
    return np.concatenate(ms, axis=0)


def _same_range(ms):
    ms = [np.asarray(m, dtype=float) for m in ms]
    extra = max(m.ndim - 2 for m in ms)
    ms = [pad(m, extra - (m.ndim - 2)) for m in ms]
    shape = np.broadcast_shapes(*[m.shape[2:] for m in ms])
    return [np.broadcast_to(m, m.shape[:2] + shape) for m in ms]


def reduce(kind: str, *values, matrix: tuple[bool, ...]):
    """max/min/mean/sum over every element of the matrices (and the scalars) given."""
    parts = []
    for v, is_m in zip(values, matrix):
        v = np.asarray(v, dtype=float)
        if is_m:
            parts.append(v.reshape((-1,) + v.shape[2:]))
        else:
            parts.append(v[None, ...])
    shape = np.broadcast_shapes(*[p.shape[1:] for p in parts])
    flat = np.concatenate([np.broadcast_to(p, p.shape[:1] + shape) for p in parts], axis=0)
    fn = {"max": np.max, "min": np.min, "mean": np.mean, "sum": np.sum}[kind]
    return _scalar(fn(flat, axis=0))


def index(m, i, j=None, *, origin: int, shape: tuple[int, int], what: str):
    """Element [i] of a vector or [i, j] of a matrix, with the sheet's origin; an index out of
    range or not an integer is an error naming it."""
    m = np.asarray(m, dtype=float)
    ii = _index_values(i, origin, shape[0], "row" if j is not None else "element", what)
    jj = _index_values(j, origin, shape[1], "column", what) if j is not None else 0
    if m.ndim > 2 and (np.ndim(ii) or np.ndim(jj)):
        raise InputError(
            f"{what}: an index that varies over a range into a matrix that also varies is not "
            "supported; index a matrix that does not depend on the range variable"
        )
    return _scalar(m[ii, jj])


def _index_values(i, origin: int, n: int, word: str, what: str):
    arr = np.asarray(i, dtype=float)
    k = np.rint(arr)
    if not np.all(np.isfinite(arr)) or np.any(np.abs(arr - k) > 1e-9):
        bad = np.atleast_1d(arr)[~np.atleast_1d(np.isfinite(arr) & (np.abs(arr - k) <= 1e-9))]
        raise InputError(f"{what}: {word} index {bad[0]:g} is not an integer")
    k = k.astype(int) - origin
    out = (k < 0) | (k >= n)
    if np.any(out):
        first = int(np.atleast_1d(k)[np.atleast_1d(out)][0]) + origin
        raise InputError(
            f"{what}: {word} index {first} is out of range ({n} {word}s: "
            f"{origin} .. {origin + n - 1} with origin {origin})"
        )
    return k if k.ndim else int(k)


def submatrix(m, ir: int, jr: int, ic: int, jc: int):
    return np.asarray(m, dtype=float)[ir : jr + 1, ic : jc + 1]
