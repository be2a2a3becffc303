"""Error estimates of the linear-algebra built-ins (lsolve, inverse, det, eigenvals,
eigenvecs): what the rounding of the matrix's elements (one unit in the last place, the
backward error of LAPACK's factorizations) can move the result by, from the condition
number; kept with the definition (:func:`workbook.functions.numerical.record`), so that a value
whose estimate is far above the sheet's tolerance is warned of (numerics.estimates)."""

from __future__ import annotations

import numpy as np

from .numerical import record, recording, reference, reference_note, reference_values

EPS = np.finfo(float).eps

#: eigenvalues closer than this (relative to the matrix's norm) are one cluster: a multiple
#: eigenvalue, whose perturbation goes as eps^(1/m), not as the condition number says
CLUSTER = 1e-4
#: an eigenvalue of a cluster whose condition number is above this (a first-order
#: estimate above about 1e-10 of the norm) comes of a defective or nearly defective matrix
DEFECTIVE = 1e6
#: an imaginary part this many times the eigenvalue's rounding is no rounding: a complex pair
COMPLEX = 10.0


def solved(what: str, cond: np.ndarray, x: np.ndarray, m=None, v=None) -> None:
    """lsolve's or inverse's estimate: the condition number times eps times the largest
    |element| of the result (per range point; matrix axes last in ``x``). Inside
    ``workbook bench``'s reference, the mpmath solution of ``m`` (and ``v``) is logged."""
    if reference() and m is not None:
        from .mpmatrix import solution

        reference_values(what, solution(m, v, x.shape))
        reference_note("mpmath", 1, 1)
    if not recording():
        return
    size = np.max(np.abs(x), axis=(-2, -1))
    record(what, x, cond * EPS * size * np.ones_like(size), relative=True, body=what)


def determinant(m: np.ndarray, value) -> None:
    """det's estimate: n eps times the largest singular value times the product of the n - 1
    largest (the change of det by a perturbation of eps |M|; |det| cond eps where M is
    regular, and finite where it is singular). Matrix axes last in ``m``."""
    if reference():
        from .mpmatrix import determinant as exact

        reference_values("det", exact(m))
        reference_note("mpmath", 1, 1)
    if not recording():
        return
    n = m.shape[-1]
    with np.errstate(all="ignore"):
        s = np.linalg.svd(m, compute_uv=False)
        error = n * EPS * s[..., 0] * np.prod(s[..., : n - 1], axis=-1)
    record("det", value, error, relative=True, body="det")


def eigen_errors(m: np.ndarray, lam: np.ndarray, vec: np.ndarray) -> tuple:
    """(error, multiple) per eigenvalue of ``m`` (matrix axes last): the error is
    kappa eps |M| (kappa = |y| |x| / |y^H x|, the left and right eigenvectors: rows of V^-1 and
    columns of V), for an eigenvalue of a cluster of m close ones at most eps^(1/m) |M| (a
    multiple eigenvalue: a defective matrix's kappa is unbounded); ``multiple`` marks
    those of a cluster whose kappa says the matrix is defective or nearly so."""
    norm = np.linalg.norm(m, axis=(-2, -1))[..., None]
    with np.errstate(all="ignore"):
        try:
            left = np.linalg.inv(vec)
            kappa = np.linalg.norm(left, axis=-1) * np.linalg.norm(vec, axis=-2)
        except np.linalg.LinAlgError:  # a defective matrix: parallel eigenvectors
            kappa = np.full(lam.shape, np.inf)
        kappa = np.where(np.isfinite(kappa), kappa, np.inf)
        first = kappa * EPS * norm
        near = np.abs(lam[..., :, None] - lam[..., None, :]) <= CLUSTER * norm[..., None]
        size = near.sum(axis=-1)
        capped = np.where(size > 1, EPS ** (1.0 / size) * norm, np.inf)
        error = np.minimum(first, capped)
        multiple = (size > 1) & (kappa > DEFECTIVE)
    return error, multiple


def vector_errors(m: np.ndarray, lam: np.ndarray, error: np.ndarray) -> np.ndarray:
    """Per eigenvector (unit length): the eigenvalue's error over its distance to the
    nearest other eigenvalue (first-order perturbation), at most 1."""
    gap = np.abs(lam[..., :, None] - lam[..., None, :])
    n = lam.shape[-1]
    gap = np.where(np.eye(n, dtype=bool), np.inf, gap).min(axis=-1)
    with np.errstate(all="ignore"):
        return np.minimum(np.where(gap > 0, error / gap, 1.0), 1.0)


def real_eigenvalues(m: np.ndarray, lam: np.ndarray, vec: np.ndarray, what: str):
    """The real eigenvalues (and their estimate, recorded): an imaginary part within the
    eigenvalue's rounding (a multiple eigenvalue of a defective matrix, which rounding splits
    into a pair) is dropped; a larger one is a complex eigenvalue, refused. Returns the real
    parts, or None where a complex eigenvalue is left (the caller refuses it)."""
    error, multiple = eigen_errors(m, lam, vec)
    norm = np.linalg.norm(m, axis=(-2, -1))[..., None]
    rounding = np.where(multiple, error, COMPLEX * error)
    big = np.abs(lam.imag) > np.maximum(rounding, 1e-9 * np.maximum(1.0, np.abs(lam.real)))
    if np.any(big & (np.abs(lam.imag) > 1e-12 * norm)):
        return None
    # the estimate is never below the imaginary part dropped (a multiple eigenvalue split
    # into a pair by rounding): the imaginary part is compared with the rounding above
    error = np.maximum(error, np.abs(lam.imag))
    if reference():
        from .mpmatrix import eigen

        values, vectors = eigen(m, lam.real, vec.real)
        reference_values(what, vectors if what == "eigenvecs" else values)
        reference_note("mpmath", 1, 1)
    if recording():
        notes = {}
        if np.any(multiple):
            k = np.argmax(np.where(multiple, error, -1.0).ravel())
            notes["named"] = (
                f"a defective or nearly defective matrix: the multiple eigenvalue "
                f"{float(lam.real.ravel()[k]):.10g} is known to about "
                f"{float(error.ravel()[k]):.3g} (eps^(1/m) of the matrix's norm)"
            )
        notes["relative"] = True
        notes["body"] = what
        if what == "eigenvecs":
            record(what, vec.real, vector_errors(m, lam, error), **notes)
        else:
            record(what, lam.real, error, **notes)
    return lam.real
