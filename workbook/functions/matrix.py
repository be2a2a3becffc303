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

from ..errors import DomainError, InputError
from ..limits import ELEMENT_WORK, charge_matrix_work, check_elements
from . import matrix_estimates

#: A matrix whose condition number exceeds this is singular for inverse and lsolve.
SINGULAR_COND = 1e14


#: Work of a decomposition of an n x n matrix in products of n x n matrices (n^3
#: multiply-adds), measured with numpy at n = 1000: det 0.5, cond 3.6, inv 1.9, solve 0.5,
#: eigvals 10.3, eig 12.2, matrix_rank 2.3 (inverse and lsolve check the condition first).
CUBIC_WORK = {"det": 1, "inverse": 6, "lsolve": 5, "eigen": 13, "rank": 3}


def _points(*arrays) -> int:
    """Points of the range axes the arrays broadcast to (1 for plain matrices)."""
    return math.prod(np.broadcast_shapes(*(np.shape(a)[2:] for a in arrays)))


def charge_cubic(kind: str, m, what: str) -> None:
    """Count a decomposition of the square matrix ``m`` (at each of its range points)."""
    n = np.shape(m)[0]
    charge_matrix_work(CUBIC_WORK[kind] * float(n) ** 3 * _points(m), what)


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
    elements = math.prod(np.broadcast_shapes(a.shape, b.shape))
    charge_matrix_work(ELEMENT_WORK * float(elements), "an element-wise operation")
    return op(a, b)


def numbers(m) -> np.ndarray:
    """``m`` as an array of floats, or of complex numbers when it holds complex ones."""
    return np.asarray(m, dtype=complex if np.iscomplexobj(m) else float)


def _last(m):
    """Matrix axes last (numpy.linalg's layout)."""
    m = numbers(m)
    return np.moveaxis(m, (0, 1), (-2, -1))


def _first(m):
    return np.moveaxis(m, (-2, -1), (0, 1))


def build(rows: list[list]) -> np.ndarray:
    """A matrix from its elements (each a scalar or an array over the range)."""
    flat = np.broadcast_arrays(*[numbers(v) for row in rows for v in row])
    r, c = len(rows), len(rows[0])
    return np.stack(flat).reshape((r, c) + flat[0].shape)


def matmul(a, b):
    """Matrix product; two vectors of one length give their dot product (Mathcad's v*w)."""
    a, b = numbers(a), numbers(b)
    ra, rb = a.ndim - 2, b.ndim - 2
    a, b = pad(a, rb - ra), pad(b, ra - rb)
    (n, k), m = a.shape[:2], b.shape[1]
    charge_matrix_work(
        float(n) * k * m * _points(a, b), f"a product of {n} x {k} by {k} x {m} matrices"
    )
    check_elements(float(n) * m * _points(a, b), f"a product of {n} x {k} by {k} x {m} matrices")
    return _first(np.matmul(_last(a), _last(b)))


def dot(a, b):
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    ra, rb = a.ndim - 2, b.ndim - 2
    a, b = pad(a, rb - ra), pad(b, ra - rb)
    return _scalar(np.sum(a * b, axis=(0, 1)))


def _scalar(x):
    if np.ndim(x):
        return x
    return complex(x) if np.iscomplexobj(x) else float(x)


def transpose(m):
    return np.swapaxes(numbers(m), 0, 1)


def det(m):
    charge_cubic("det", m, "det()")
    value = np.linalg.det(_last(m))
    matrix_estimates.determinant(_last(m), value)
    return _scalar(value)


def _check_regular(m, what: str):
    """The matrix, matrix axes last, and its condition number (per range point)."""
    charge_cubic("inverse" if what.startswith("inverse") else "lsolve", m, what)
    mm = _last(m)
    with np.errstate(all="ignore"):
        cond = np.linalg.cond(mm)
    worst = float(np.max(np.where(np.isfinite(cond), cond, np.inf)))
    if not worst < SINGULAR_COND:
        shown = "infinite" if not math.isfinite(worst) else f"{worst:.3g}"
        raise DomainError(
            f"{what}: the matrix is singular (condition number {shown}, limit {SINGULAR_COND:g})"
        )
    return mm, cond


def inverse(m):
    mm, cond = _check_regular(m, "inverse()")
    out = np.linalg.inv(mm)
    matrix_estimates.solved("inverse", cond, out, mm)
    return _first(out)


def power(m, n: int):
    """Matrix power M^n (n an integer; M^-1 is the inverse)."""
    if n < 0:
        m = inverse(m)
        n = -n
    side = np.shape(m)[0]
    charge_matrix_work(
        2.0 * max(n, 1).bit_length() * float(side) ** 3 * _points(m),
        f"a power {n} of a {side} x {side} matrix",
    )
    return _first(np.linalg.matrix_power(_last(m), n))


def lsolve(m, v):
    mm, cond = _check_regular(m, "lsolve()")
    vv = _last(v)
    extra = mm.ndim - vv.ndim
    if extra > 0:
        vv = vv.reshape((1,) * extra + vv.shape)
    elif extra < 0:
        mm = mm.reshape((1,) * -extra + mm.shape)
    out = np.linalg.solve(mm, vv)
    matrix_estimates.solved("lsolve", cond, out, mm, vv)
    return _first(out)


def _real(values, what: str, kind: str = "eigenvalues"):
    if np.any(np.abs(values.imag) > 1e-9 * np.maximum(1.0, np.abs(values.real))):
        raise DomainError(
            f"{what}: the matrix has complex {kind}; of a complex matrix they are complex "
            "values (write it with complex elements, M*(1 + 0i)), or take eigenparts(M)"
            if kind == "eigenvalues"
            else f"{what}: the polynomial has complex roots; of complex coefficients they are "
            "complex values (v*(1 + 0i)), or take polyrootparts(v)"
        )
    return values.real


def _order(lam):
    """Ascending eigenvalues; complex ones by real part (equal to 10 digits of the largest
    modulus: a conjugate pair's rounding does not split it), then imaginary part."""
    if np.iscomplexobj(lam):
        scale = np.max(np.abs(lam), axis=-1, keepdims=True)
        real = np.round(lam.real / np.where(scale > 0, scale, 1.0), 10)
        return np.lexsort((lam.imag, real), axis=-1)
    return np.argsort(lam, axis=-1)


def _real_eigen(m, lam, vec, what: str):
    """The eigenvalues' real parts where their imaginary parts are rounding (a defective
    matrix's multiple eigenvalue split into a pair), with their estimates recorded; else
    the refusal of complex eigenvalues."""
    if np.isrealobj(lam):
        lam = lam.astype(complex)
    real = matrix_estimates.real_eigenvalues(m, lam, vec, what.rstrip("()"))
    if real is None:
        return _real(lam, what)
    return real


def eigenvals(m):
    """Eigenvalues, ascending, as a column vector (of a complex matrix: complex, by real
    part, then imaginary part)."""
    charge_cubic("eigen", m, "eigenvals()")
    mm = _last(m)
    lam, vec = np.linalg.eig(mm)
    if not np.iscomplexobj(mm):
        lam = _real_eigen(mm, lam, vec, "eigenvals()")
    lam = np.take_along_axis(lam, _order(lam), axis=-1)
    return np.moveaxis(lam[..., None], (-2, -1), (0, 1))


def eigenvecs(m):
    """Unit eigenvectors as columns, in the order of eigenvals (ascending); each column's
    largest component is positive (a fixed sign; of a complex matrix: real and positive)."""
    charge_cubic("eigen", m, "eigenvecs()")
    mm = _last(m)
    lam, vec = np.linalg.eig(mm)
    if not np.iscomplexobj(mm):
        lam = _real_eigen(mm, lam, vec, "eigenvecs()")
        if np.iscomplexobj(vec):  # a multiple eigenvalue split by rounding: its vectors too
            vec = vec.real / np.linalg.norm(vec.real, axis=-2, keepdims=True)
    vec = np.take_along_axis(vec, _order(lam)[..., None, :], axis=-1)
    big = np.take_along_axis(vec, np.argmax(np.abs(vec), axis=-2)[..., None, :], axis=-2)
    if np.iscomplexobj(vec):
        vec = vec * (np.abs(big) / np.where(big == 0, 1.0, big))
    else:
        vec = vec * np.where(big < 0, -1.0, 1.0)
    return _first(vec)


def eigenparts(m):
    """Eigenvalues, complex ones included, as rows (Re, Im): by modulus, then by imaginary
    part (a conjugate pair: the negative imaginary part first)."""
    charge_cubic("eigen", m, "eigenparts()")
    return _first(_parts_by_modulus(np.linalg.eigvals(_last(m))))


def _parts_by_modulus(values: np.ndarray) -> np.ndarray:
    """Complex values as (Re, Im) in the last axis, by modulus, then by imaginary part; moduli
    equal to 10 digits are equal (a conjugate pair and a real value of the same modulus keep
    one order whatever the rounding of each)."""
    scale = np.max(np.abs(values), axis=-1, keepdims=True)
    modulus = np.round(np.abs(values) / np.where(scale > 0, scale, 1.0), 10)
    order = np.lexsort((values.real, values.imag, modulus), axis=-1)
    values = np.take_along_axis(values, order, axis=-1)
    return np.stack([values.real, values.imag], axis=-1)


def eigenvec(m, z):
    """The unit eigenvector of the eigenvalue z (the eigenvalue nearest z, which must be within
    1e-9 of it relative to the largest eigenvalue), its largest component positive as in
    eigenvecs."""
    charge_cubic("eigen", m, "eigenvec()")
    lam, vec = np.linalg.eig(_last(m))
    z = np.asarray(z, dtype=float)
    k = np.argmin(np.abs(lam - z[..., None]), axis=-1)
    nearest = np.take_along_axis(lam, k[..., None], axis=-1)[..., 0]
    scale = np.maximum(np.max(np.abs(lam), axis=-1), np.finfo(float).tiny)
    off = np.abs(nearest - z) > 1e-9 * scale
    if np.any(off):
        i = np.argmax(np.broadcast_to(off, np.shape(off)).ravel())
        shown = complex(np.broadcast_to(nearest, np.shape(off)).ravel()[i])
        shown_text = f"{shown.real:.10g}" if not shown.imag else f"{shown:.10g}"
        given = float(np.broadcast_to(z, np.shape(off)).ravel()[i])
        raise InputError(
            f"eigenvec(M, z): z = {given:.10g} is not an eigenvalue of M (the nearest is "
            f"{shown_text}); take z from eigenvals(M)"
        )
    v = _real(np.take_along_axis(vec, k[..., None, None], axis=-1), "eigenvec()")
    big = np.take_along_axis(v, np.argmax(np.abs(v), axis=-2)[..., None, :], axis=-2)
    return _first(v * np.where(big < 0, -1.0, 1.0))


def rank(m):
    """The rank of a matrix (numpy's tolerance: singular values above the largest times the
    size times the machine epsilon)."""
    r, c = np.shape(m)[:2]
    work = CUBIC_WORK["rank"] * float(max(r, c)) * min(r, c) ** 2 * _points(m)
    charge_matrix_work(work, "rank()")
    return _scalar(np.linalg.matrix_rank(_last(m)).astype(float))


def _polynomial_roots(v, what: str) -> np.ndarray:
    """The roots (complex) of the polynomial v[0] + v[1] x + ... for each value of v."""
    coefficients = np.moveaxis(numbers(v)[:, 0], 0, -1)  # (..., n)
    if np.any(coefficients[..., -1] == 0):
        raise InputError(f"{what}: the last coefficient (of the highest power) is 0")
    if not np.all(np.isfinite(coefficients)):
        raise InputError(f"{what}: a coefficient is not a finite number")
    out = np.empty(coefficients.shape[:-1] + (coefficients.shape[-1] - 1,), dtype=complex)
    for index in np.ndindex(coefficients.shape[:-1]):
        out[index] = np.roots(coefficients[index][::-1])
    return out


def polyroots(v):
    """The roots of v[0] + v[1] x + ... + v[n] x^n, ascending (real roots only; of complex
    coefficients complex roots, by real part, then imaginary part)."""
    roots = _polynomial_roots(v, "polyroots()")
    if not np.iscomplexobj(v):
        roots = _real(roots, "polyroots()", "roots")
    roots = np.take_along_axis(roots, _order(roots), axis=-1)
    return np.moveaxis(roots[..., None], (-2, -1), (0, 1))


def polyrootparts(v):
    """The roots, complex ones included, as rows (Re, Im), ordered as eigenparts orders."""
    return _first(_parts_by_modulus(_polynomial_roots(v, "polyrootparts()")))


def histogram(intervals, data, *, counted: bool):
    """Mathcad's histogram: rows (midpoint, count) of ``intervals`` equal intervals between the
    smallest and largest value of ``data`` (``counted``), or of the intervals between the
    points of the vector ``intervals``. A value on an inner boundary counts in the upper
    interval; the last interval holds both its ends."""
    values = np.asarray(data, dtype=float)
    if values.ndim != 2:
        raise InputError("histogram(): the data must be a vector of numbers (not over a range)")
    values = values[:, 0]
    if not np.all(np.isfinite(values)):
        raise InputError("histogram(): a data value is not a finite number")
    if counted:
        lo, hi = float(values.min()), float(values.max())
        if lo == hi:
            raise InputError(
                f"histogram(n, data): every value is {lo:g}; give the intervals as a vector"
            )
        edges = np.linspace(lo, hi, int(np.asarray(intervals, dtype=float)) + 1)
    else:
        edges = np.asarray(intervals, dtype=float)
        if edges.ndim != 2:
            raise InputError("histogram(): the intervals must be a vector (not over a range)")
        edges = edges[:, 0]
        if not (np.all(np.isfinite(edges)) and np.all(np.diff(edges) > 0)):
            raise InputError("histogram(intervals, data): the interval points must increase")
    counts, _ = np.histogram(values, edges)
    return np.stack([(edges[:-1] + edges[1:]) / 2, counts.astype(float)], axis=1)


def cross(a, b):
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    ra, rb = a.ndim - 2, b.ndim - 2
    a, b = pad(a, rb - ra), pad(b, ra - rb)
    return np.cross(a, b, axis=0)


def norm(v):
    return _scalar(np.sqrt(np.sum(np.square(np.asarray(v, dtype=float)), axis=(0, 1))))


def augment(*ms):
    ms = _same_range(ms)
    check_elements(sum(float(m.size) for m in ms), "augment()")
    return np.concatenate(ms, axis=1)


def stack(*ms):
    ms = _same_range(ms)
    check_elements(sum(float(m.size) for m in ms), "stack()")
    return np.concatenate(ms, axis=0)


def _same_range(ms):
    ms = [numbers(m) for m in ms]
    extra = max(m.ndim - 2 for m in ms)
    ms = [pad(m, extra - (m.ndim - 2)) for m in ms]
    shape = np.broadcast_shapes(*[m.shape[2:] for m in ms])
    return [np.broadcast_to(m, m.shape[:2] + shape) for m in ms]


def reduce(kind: str, *values, matrix: tuple[bool, ...]):
    """max/min/mean/sum over every element of the matrices (and the scalars) given."""
    parts = []
    for v, is_m in zip(values, matrix):
        v = numbers(v)
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
    if type(m) is not np.ndarray or m.dtype not in (float, complex):
        m = numbers(m)
    ii = _index_values(i, origin, shape[0], "row" if j is not None else "element", what)
    jj = _index_values(j, origin, shape[1], "column", what) if j is not None else 0
    if m.ndim > 2 and (np.ndim(ii) or np.ndim(jj)):
        raise InputError(
            f"{what}: an index that varies over a range into a matrix that also varies is not "
            "supported; index a matrix that does not depend on the range variable"
        )
    return _scalar(m[ii, jj])


def _index_values(i, origin: int, n: int, word: str, what: str):
    if isinstance(i, (int, float)) and math.isfinite(i):  # one index: no array work
        k = round(i)
        if abs(i - k) <= 1e-9 and 0 <= k - origin < n:
            return k - origin
    arr = np.asarray(i, dtype=float)
    k = np.rint(arr)
    if not np.all(np.isfinite(arr)) or np.any(np.abs(arr - k) > 1e-9):
        bad = np.atleast_1d(arr)[~np.atleast_1d(np.isfinite(arr) & (np.abs(arr - k) <= 1e-9))]
        raise InputError(f"{what}: {word} index {bad[0]:g} is not an integer")
    huge = np.abs(k) > 2.0**53  # beyond any array, and beyond an exact integer
    if np.any(huge):
        first = float(np.atleast_1d(k)[np.atleast_1d(huge)][0])
        raise InputError(
            f"{what}: {word} index {first:g} is out of range ({n} {word}s: "
            f"{origin} .. {origin + n - 1} with origin {origin})"
        )
    k = k.astype(int) - origin
    out = (k < 0) | (k >= n)
    if np.any(out):
        first = int(np.atleast_1d(k)[np.atleast_1d(out)][0]) + origin
        raise InputError(
            f"{what}: {word} index {first} is out of range ({n} {word}s: "
            f"{origin} .. {origin + n - 1} with origin {origin})"
        )
    return k if k.ndim else int(k)


def element_index(shape, indices, origin: int, what: str) -> tuple[int, int]:
    """(row, column) of ``v[i]`` or ``M[i, j]`` in a matrix of ``shape`` (checked)."""
    r, c = shape[:2]
    if len(indices) == 1:
        return _index_values(indices[0], origin, r, "element", what), 0
    return (
        _index_values(indices[0], origin, r, "row", what),
        _index_values(indices[1], origin, c, "column", what),
    )


def submatrix(m, ir: int, jr: int, ic: int, jc: int):
    return numbers(m)[ir : jr + 1, ic : jc + 1]


def size(kind: str, v, origin: int = 0) -> float:
    """rows, cols, length or last of a run-time value (workbook.engine.runtime); a number has 0 rows
    and columns (as Mathcad's rows of a scalar), so a vector grown from nothing starts at 0."""
    r, c = np.shape(v) if np.ndim(v) == 2 else (0, 0)
    if kind in ("length", "last") and c > 1:
        raise InputError(f"{kind}() takes a vector, got a {r}x{c} matrix")
    return float({"rows": r, "cols": c, "length": r, "last": r - 1 + origin}[kind])


def numpy_submatrix(m, ir, jr, ic, jc, origin=0.0, *, shapes):
    """submatrix(M, ir, jr, ic, jc): bounds made origin 0 at load, or (a run-time array)
    checked here against the shape M has."""
    origin = int(origin)
    if any(np.ndim(b) for b in (ir, jr, ic, jc)):
        raise InputError("submatrix(): a bound that varies over a range; give one number")
    bounds = [int(round(float(b))) - origin for b in (ir, jr, ic, jc)]
    if origin or shapes[0] is not None and np.ndim(m) >= 2:
        r, c = np.shape(m)[:2]
        ir, jr, ic, jc = bounds
        if not (0 <= ir <= jr < r and 0 <= ic <= jc < c):
            raise InputError(
                f"submatrix(M, {ir + origin}, {jr + origin}, {ic + origin}, {jc + origin}) is "
                f"outside the {r}x{c} matrix (origin {origin})"
            )
    return submatrix(m, *bounds)


def csort(m, j, origin: int):
    """The rows of ``m`` sorted by column ``j`` (stable, smallest first)."""
    m = np.asarray(m, dtype=float)
    k = int(round(float(j))) - origin
    if m.ndim != 2:
        raise InputError("csort(): the matrix varies over a range; sort a fixed matrix")
    if not 0 <= k < m.shape[1]:
        raise InputError(
            f"csort(): column {k + origin} is outside the {m.shape[0]}x{m.shape[1]} matrix"
        )
    return m[np.argsort(m[:, k], kind="stable")]


#: The largest identity(n); Excel gets it as an array constant up to MAX_EXCEL_IDENTITY.
MAX_IDENTITY = 2000
MAX_EXCEL_IDENTITY = 30


def numpy_statistic(kind: str):
    """stdev, var or median of every element of the matrices (and the numbers) given."""
    fn = {"stdev": np.std, "var": np.var, "median": np.median}[kind]

    def hook(*values, shapes):
        parts = []
        for v, shape in zip(values, shapes):
            v = np.asarray(v, dtype=float)
            parts.append(v[None, ...] if shape is None else v.reshape((-1,) + v.shape[2:]))
        shape = np.broadcast_shapes(*[p.shape[1:] for p in parts])
        flat = np.concatenate([np.broadcast_to(p, p.shape[:1] + shape) for p in parts], axis=0)
        return _scalar(fn(flat, axis=0))

    return hook


def _array_arg(v, shape, what: str, vector: bool = False):
    """The array a sort gets; a run-time value is checked here (a number, a matrix where a
    vector is wanted, a nested array are errors)."""
    if shape is None:
        raise InputError(
            f"{what} takes a {'vector' if vector else 'vector or matrix'}, got a number"
        )
    if vector and shape[1] != 1:
        raise InputError(f"{what} takes a vector, got a {shape[0]}x{shape[1]} matrix")
    m = np.asarray(v)
    if m.dtype == object:
        raise InputError(f"{what}: a nested array (an element that is an array) is not sorted")
    return m.astype(float)


def numpy_sort(v, *, shapes):
    """sort(v): ascending (each point of a range on its own)."""
    return np.sort(_array_arg(v, shapes[0], "sort()", vector=True), axis=0)


def numpy_reverse(v, *, shapes):
    """reverse(v): the elements (the rows of a matrix) last first; a nested array too."""
    if shapes[0] is None:
        raise InputError("reverse() takes a vector or matrix, got a number")
    return np.flip(np.asarray(v), axis=0).copy()


def rsort(m, i, origin: int, shape):
    """The columns of ``m`` (of ``shape``; None: a number) sorted by row ``i`` (stable,
    smallest first)."""
    m = _array_arg(m, shape, "rsort()")
    k = int(round(float(i))) - origin
    if m.ndim != 2:
        raise InputError("rsort(): the matrix varies over a range; sort a fixed matrix")
    if not 0 <= k < m.shape[0]:
        raise InputError(
            f"rsort(): row {k + origin} is outside the {m.shape[0]}x{m.shape[1]} matrix"
        )
    return m[:, np.argsort(m[k, :], kind="stable")]
