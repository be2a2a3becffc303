"""``workbook bench``'s reference of the linear-algebra built-ins: mpmath at 50 digits.

lsolve and inverse by ``mp.lu_solve`` (LU with partial pivoting, at 50 digits), det by
``mp.det``, eigenvalues and eigenvectors by ``mp.eig`` (Hessenberg QR at 50 digits), on the
matrix's elements as the doubles numpy computes with. Of a call over a range, at most
``ROWS`` range points spread over it are computed (the others are NaN: not compared).
The eigenvalues are given in the order of numpy's (each numpy eigenvalue takes the nearest
mpmath one not taken yet), the eigenvectors at the unit length and sign of numpy's columns:
the comparison is of the same eigenpair.
"""

from __future__ import annotations

import mpmath
import numpy as np

#: digits of the reference
DIGITS = 50
#: range points of one call computed at most (spread over it)
ROWS = 16


def _context():
    ctx = mpmath.MPContext()
    ctx.dps = DIGITS
    return ctx


def _points(batch: tuple[int, ...]) -> np.ndarray:
    n = int(np.prod(batch)) if batch else 1
    return np.arange(n) if n <= ROWS else np.unique(np.linspace(0, n - 1, ROWS).astype(np.intp))


def _matrix(ctx, a: np.ndarray):
    return ctx.matrix([[ctx.mpf(float(x)) for x in row] for row in a])


def _real(m) -> bool:
    return not np.iscomplexobj(m) and np.all(np.isfinite(m))


def solution(m: np.ndarray, v, shape: tuple[int, ...]) -> np.ndarray:
    """M^-1 v (``v`` None: M^-1) per range point, matrix axes last, in the engine's
    result ``shape``."""
    out = np.full(shape, np.nan)
    if not _real(m) or (v is not None and not _real(v)):
        return out
    ctx = _context()
    mb = np.broadcast_to(m, shape[:-2] + m.shape[-2:]).reshape(-1, *m.shape[-2:])
    flat = out.reshape(-1, *shape[-2:])
    vb = None
    if v is not None:
        vb = np.broadcast_to(v, shape).reshape(-1, *shape[-2:])
    for k in _points(shape[:-2]):
        a = _matrix(ctx, mb[k])
        if vb is None:
            x = ctx.inverse(a)
        else:
            x = ctx.matrix(shape[-2], shape[-1])
            for j in range(shape[-1]):
                col = ctx.lu_solve(a, ctx.matrix([ctx.mpf(float(e)) for e in vb[k][:, j]]))
                for i in range(shape[-2]):
                    x[i, j] = col[i]
        flat[k] = [[float(x[i, j]) for j in range(shape[-1])] for i in range(shape[-2])]
    return flat.reshape(shape)


def determinant(m: np.ndarray) -> np.ndarray:
    """det(M) per range point (matrix axes last)."""
    batch = m.shape[:-2]
    out = np.full(int(np.prod(batch)) if batch else 1, np.nan)
    if not _real(m):
        return out.reshape(batch)
    ctx = _context()
    mb = m.reshape(-1, *m.shape[-2:])
    for k in _points(batch):
        out[k] = float(ctx.det(_matrix(ctx, mb[k])))
    return out.reshape(batch)


def eigen(m: np.ndarray, lam: np.ndarray, vec: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(eigenvalues, eigenvectors) per range point in numpy's order (``lam``) and at the
    length and sign of numpy's columns (``vec``); NaN where a point is not computed or an
    eigenvalue is complex at 50 digits (the engine refuses those)."""
    values, vectors = np.full(lam.shape, np.nan), np.full(vec.shape, np.nan)
    if not _real(m):
        return values, vectors
    ctx = _context()
    n = m.shape[-1]
    mb, lb, vb = (a.reshape(-1, *a.shape[len(m.shape[:-2]) :]) for a in (m, lam, vec))
    fv, fw = values.reshape(lb.shape), vectors.reshape(vb.shape)
    for k in _points(m.shape[:-2]):
        e, er = ctx.eig(_matrix(ctx, mb[k]))
        exact = [complex(x) for x in e]
        taken: set[int] = set()
        for j in range(n):
            order = sorted(range(n), key=lambda i: abs(exact[i] - lb[k][j]))
            i = next(i for i in order if i not in taken)
            taken.add(i)
            if abs(exact[i].imag) > 1e-30 * max(1.0, abs(exact[i])):
                continue  # a complex pair at 50 digits: the engine's refusal, not compared
            fv[k][j] = exact[i].real
            col = np.array([complex(er[r, i]).real for r in range(n)])
            norm = float(np.linalg.norm(col))
            if norm == 0:
                continue
            want = vb[k][:, j]
            sign = 1.0 if float(np.dot(col, want)) >= 0 else -1.0
            fw[k][:, j] = sign * col / norm * float(np.linalg.norm(want))
    return values, vectors
