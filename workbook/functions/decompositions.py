"""Matrix decompositions that the mathematics fixes up to signs, with the signs chosen here:
``cholesky`` (unique), ``qr`` (R's diagonal not negative) and ``svd`` (each pair of singular
vectors turned so that the largest component of U's column is positive), and their registry
entries.

Each takes one fixed matrix of plain numbers or, for cholesky, of any unit (L is in its square
root). Mathcad's qr and svd give the same decompositions with the signs of its own solver, which
no stored result measured here shows; the importer does not translate them (docs/mathcad.md).
"""

from __future__ import annotations

import numpy as np

from ..errors import DomainError, InputError, TemplateError, UnitError
from ..language.typed import shape_text
from ..language.units import pretty
from .matrix_entries import entry, func, need, not_live, square

#: How far from symmetric (relative to the largest element) a matrix cholesky takes may be.
SYMMETRY_TOLERANCE = 1e-12


def _fixed(m, what: str) -> np.ndarray:
    a = np.array(m, dtype=float)
    if a.ndim != 2:
        raise InputError(f"{what}: the matrix varies over a range; decompose a fixed matrix")
    return a


def cholesky(m) -> np.ndarray:
    """The lower triangular L with L L^T = M, M symmetric and positive definite (Mathcad's
    cholesky); a matrix that is not is an error."""
    a = _fixed(m, "cholesky()")
    scale = max(float(np.abs(a).max()), np.finfo(float).tiny)
    if np.abs(a - a.T).max() > SYMMETRY_TOLERANCE * scale:
        raise DomainError("cholesky(): the matrix is not symmetric")
    try:
        return np.linalg.cholesky(a)
    except np.linalg.LinAlgError:
        raise DomainError("cholesky(): the matrix is not positive definite") from None


def qr(m) -> np.ndarray:
    """augment(Q, R) of an m x n matrix: Q m x m orthonormal, R m x n upper triangular,
    Q R = M, every diagonal element of R >= 0 (Householder's, LAPACK)."""
    a = _fixed(m, "qr()")
    q, r = np.linalg.qr(a, mode="complete")
    k = min(a.shape)
    signs = np.ones(a.shape[0])
    signs[:k] = np.where(np.diag(r)[:k] < 0, -1.0, 1.0)
    return np.hstack([q * signs, r * signs[:, None]])


def svd(m) -> np.ndarray:
    """stack(U, V) of an m x n matrix, m >= n: U m x n, V n x n, with M = U diag(s) V^T and
    s = svds(M); each column of U has its largest component (the first of equal ones)
    positive, V's column turned with it."""
    a = _fixed(m, "svd()")
    r, c = a.shape
    if r < c:
        raise InputError(f"svd() needs at least as many rows as columns, got {r}x{c}")
    u, _s, vt = np.linalg.svd(a, full_matrices=False)
    v = vt.T
    largest = u[np.argmax(np.abs(u), axis=0), np.arange(c)]
    signs = np.where(largest < 0, -1.0, 1.0)
    return np.vstack([u * signs, v * signs])


# -- registry entries -----------------------------------------------------------------------------
def r_cholesky(ctx, name, args):
    n = square(args, name)
    return func(args[0].unit ** 0.5, name, args, (n, n))


def _plain_matrix(ctx, name, args, parts: str):
    if args[0].unit.dimensionality:
        raise UnitError(
            f"{name}(): the matrix is in {pretty(args[0].unit)}; {parts}, and the result is "
            "one matrix of one unit: divide the matrix by its unit"
        )
    return ctx.convert(args[0], ctx.dimensionless, f"{name}(M)")


def r_qr(ctx, name, args):
    r, c = need(args, 0, name, "a matrix")
    plain = _plain_matrix(ctx, name, args, "Q is plain and R in the matrix's unit")
    return func(ctx.dimensionless, name, [plain], (r, r + c))


def r_svd(ctx, name, args):
    r, c = need(args, 0, name, "a matrix")
    if r < c:
        raise TemplateError(
            f"svd() needs at least as many rows as columns, got a {shape_text((r, c))}"
        )
    plain = _plain_matrix(ctx, name, args, "U and V are plain")
    return func(ctx.dimensionless, name, [plain], (r + c, c))


entry(
    "cholesky",
    1,
    r_cholesky,
    lambda m, shapes: cholesky(m),
    not_live("a Cholesky factor has no spreadsheet formula"),
    "cholesky(M): the lower triangular L with L L^T = M, M symmetric positive definite",
    mathcad=("cholesky",),
)
entry(
    "qr",
    1,
    r_qr,
    lambda m, shapes: qr(m),
    not_live("a QR decomposition has no spreadsheet formula"),
    "qr(M): augment(Q, R) with Q R = M, Q orthonormal, R upper triangular, diagonal >= 0",
)
entry(
    "svd",
    1,
    r_svd,
    lambda m, shapes: svd(m),
    not_live("a singular value decomposition has no spreadsheet formula"),
    "svd(M): stack(U, V) with M = U diag(svds(M)) V^T, U's columns largest component positive",
)
