"""The global maximum or minimum of a function on [a, b], and where it is, for every row."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..functions.numerical import (
    DEFAULT,
    Fn,
    NumericsError,
    Result,
    Tolerance,
    call,
    num,
    row_text,
    rows,
)
from ..functions.numerical import unit_suffix as _u

#: the bracket is sampled at this many times ``Tolerance.samples`` intervals
OVERSAMPLE = 4


def extremum(
    f: Fn,
    a,
    b,
    args=(),
    tol: Tolerance = DEFAULT,
    *,
    kind: str = "max",
    need_where: bool = False,
    var: str = "x",
    unit: str = "",
    label: Callable[[int], str] | None = None,
    enclose: Callable | None = None,
) -> Result:
    """The largest (``kind="max"``) or smallest value of ``f(x, *args)`` on [a, b] per row.

    [a, b] is sampled at ``OVERSAMPLE * tol.samples`` intervals; every interior local extremum
    of the samples is refined by ``find_minimum`` (all rows and all candidates in one call) and
    compared with the end points, so the global extremum among all local ones is returned.
    ``where`` is its position (argmax/argmin). With ``need_where``, a function that is flat on
    [a, b] (all samples equal within the tolerance) is an error: it has no one argmax.

    With ``enclose(lo, hi, *args) -> (F, D)`` (interval enclosures of f and its derivative,
    :mod:`workbook.numerics.intervals`), the value is then certified by branch and bound
    (:func:`workbook.numerics.globalmin.global_min`): a peak narrower than the samples is
    found, and where the search cannot close (too many boxes), the gap between the value and
    the bound left is added to the error estimate. Without it, the value assumes no feature
    narrower than the samples' spacing.
    """

    shape, (a, b, *args) = rows(a, b, *args)
    n, k = a.size, OVERSAMPLE * max(int(tol.samples), 2)
    if n == 0:
        return Result(np.empty(shape), np.empty(shape), np.empty(shape), np.empty(shape))
    sgn = -1.0 if kind == "max" else 1.0
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    xs = lo[:, None] + (hi - lo)[:, None] * np.linspace(0.0, 1.0, k + 1)
    fs = sgn * call(f, xs, [g[:, None] for g in args])
    bad = ~np.isfinite(fs)
    if bad.any():
        i, j = np.argwhere(bad)[0]
        raise NumericsError(
            f"{kind}imum(): the function is not a finite number at {var} = {num(xs[i, j])}"
            f"{_u(unit)}{row_text(label, i, n)}, inside [{num(lo[i])}, {num(hi[i])}]{_u(unit)}"
        )
    spread = fs.max(axis=1) - fs.min(axis=1)
    scale = np.abs(fs).max(axis=1)
    flat = spread <= np.maximum(tol.rtol * scale, tol.atol)
    # interior local minima of the samples (of sgn*f), each bracketed by its neighbours
    mid = fs[:, 1:-1]
    cand = (mid <= fs[:, :-2]) & (mid <= fs[:, 2:]) & ~((mid == fs[:, :-2]) & (mid == fs[:, 2:]))
    ri, ci = np.nonzero(cand)
    ci = ci + 1
    best_v = np.where(fs[:, 0] <= fs[:, -1], fs[:, 0], fs[:, -1])
    best_x = np.where(fs[:, 0] <= fs[:, -1], xs[:, 0], xs[:, -1])
    best_ve = np.zeros(n)
    best_xe = np.zeros(n)
    evaluations = k + 1
    if ri.size:
        evaluations += _refine(f, sgn, xs, fs, ri, ci, args, tol, best_v, best_x, best_ve, best_xe)
    if enclose is not None:
        evaluations += _certify(
            f, enclose, args, lo, hi, fs, sgn, tol, best_v, best_x, best_ve, best_xe
        )
    if need_where:
        # flat samples, and no better value between them (branch and bound may find one)
        flat &= ~(best_v < fs.min(axis=1) - np.maximum(tol.rtol * scale, tol.atol))
        if flat.any():
            i = np.flatnonzero(flat)[0]
            raise NumericsError(
                f"arg{kind}(): the function is flat on [{num(lo[i])}, {num(hi[i])}]{_u(unit)}"
                f"{row_text(label, i, n)} (all {k + 1} samples equal {num(sgn * fs[i, 0])} "
                f"within the tolerance): it has no one arg{kind}"
            )
        _no_plateau(kind, xs, fs, best_v, tol, var, unit, label)
    # without enclosures nothing is known between the samples: the value rests on no feature
    # narrower than their spacing, which the result carries (``run`` prints it)
    notes = {} if enclose is not None else {"assumes": float(np.max((hi - lo) / k)), "unit": unit}
    notes["scale"] = float(np.max(scale))  # the size of EXPR on [A, B] (a maximum may be 0)
    return Result(
        (sgn * best_v).reshape(shape),
        best_ve.reshape(shape),
        best_x.reshape(shape),
        best_xe.reshape(shape),
        evaluations=evaluations,
        notes=notes,
    )


def _refine(f, sgn, xs, fs, ri, ci, args, tol, best_v, best_x, best_ve, best_xe) -> int:
    """Refine every interior local minimum of the samples (rows ``ri``, columns ``ci``) of
    ``sgn*f`` by ``find_minimum`` in one call, and keep each row's best where it beats the
    ends (in place); returns the evaluations."""
    from scipy.optimize.elementwise import find_minimum

    init = (xs[ri, ci - 1], xs[ri, ci], xs[ri, ci + 1])
    fa = tuple(g[ri] for g in args)
    # a minimum's place is known to about sqrt(eps) relative at best
    tols = {"xatol": tol.atol, "xrtol": max(tol.rtol, np.finfo(float).eps ** 0.5)}
    with np.errstate(all="ignore"):
        res = find_minimum(lambda x, *p: sgn * np.asarray(f(x, *p)), init, args=fa, tolerances=tols)
    ok = np.asarray(res.success) | (np.asarray(res.status) == -2)
    vals = np.where(ok, res.f_x, fs[ri, ci])
    where = np.where(ok, res.x, xs[ri, ci])
    span = xs[ri, ci + 1] - xs[ri, ci - 1]
    werr = np.where(ok, np.abs(res.bracket[1] - res.bracket[0]), span)
    verr = np.where(ok, np.abs(np.maximum(res.f_bracket[0], res.f_bracket[2]) - res.f_x), 0.0)
    # per row: the best candidate (the first one on ties, as numpy's argmax)
    order = np.lexsort((where, vals, ri))
    first = order[np.r_[True, ri[order][1:] != ri[order][:-1]]]
    rows_c = ri[first]
    better = vals[first] < best_v[rows_c]
    take = rows_c[better]
    best_v[take] = vals[first][better]
    best_x[take] = where[first][better]
    best_ve[take] = verr[first][better]
    best_xe[take] = werr[first][better]
    return int(np.max(res.nfev))


#: rows of one call certified by branch and bound; of a larger table, PROBE rows spread over
#: it are, and all of them when one of those finds a better value than its samples did
CERTIFY_ROWS = 2_000
PROBE = 64


def _certify(f, enclose, args, lo, hi, fs, sgn, tol, best_v, best_x, best_ve, best_xe) -> int:
    """Branch and bound from the samples' best (in place); the evaluations of f it took."""
    from ..functions.interval_arith import neg
    from .globalmin import global_min

    n = lo.size
    scale = np.abs(fs).max(axis=1)

    def g(p, q, r):
        fv, dv = enclose(p, q, *[a[r] for a in args])
        if sgn > 0:
            return fv, dv
        return neg(fv), None if dv is None else neg(dv)

    def h(x, r):
        return sgn * np.asarray(f(x, *[a[r] for a in args]), dtype=float)

    def run(sel):
        # the function's size: its samples', or its enclosure's on the bracket (a narrow dip
        # in a function that is 0 at every sample has the size of the dip)
        with np.errstate(all="ignore"):
            whole, _ = g(lo[sel], hi[sel], sel)
            top = np.maximum(np.abs(whole.lo), np.abs(whole.hi))
        size = np.maximum(scale[sel], np.where(np.isfinite(top), top, 0.0))
        floor = np.maximum(tol.rtol * size, tol.atol)
        # the rows' index into sel: the boxes carry rows of sel, allowed maps them back
        cert = global_min(
            lambda p, q, r: g(p, q, sel[r]),
            lambda x, r: h(x, sel[r]),
            lo[sel],
            hi[sel],
            best_v[sel],
            best_x[sel],
            lambda b, r, floor=floor: np.maximum(tol.rtol * np.abs(b), floor[r]),
        )
        improved = cert.value < best_v[sel]
        best_v[sel], best_x[sel] = cert.value, cert.where
        best_xe[sel] = np.where(improved, np.maximum(best_xe[sel], cert.width), best_xe[sel])
        if improved.any():
            _polish(h, sel[improved], best_v, best_x, best_xe, tol)
        # the gap to the lowest bound left, from the value after the polish (its error where
        # branch and bound found a better value than the samples did)
        gap = np.maximum(cert.gap, best_v[sel] - cert.bound)
        best_ve[sel] = np.where(improved, gap, np.maximum(best_ve[sel], gap))
        return improved

    if n <= CERTIFY_ROWS:
        run(np.arange(n))
    elif run(np.linspace(0, n - 1, PROBE).astype(np.intp)).any():
        run(np.arange(n))
    return 0


def _polish(h, idx, best_v, best_x, best_xe, tol) -> None:
    """A better point branch and bound found, refined by find_minimum in the box around it
    (where that box is a bracket of a minimum)."""
    from scipy.optimize.elementwise import find_minimum

    x, w = best_x[idx], np.maximum(best_xe[idx], 4 * np.spacing(np.abs(best_x[idx])))
    a, b = x - w, x + w
    with np.errstate(all="ignore"):
        fa, fx, fb = (np.asarray(h(v, idx), dtype=float) for v in (a, x, b))
        valid = (fx <= fa) & (fx <= fb)
        if not valid.any():
            return
        tols = {"xatol": tol.atol, "xrtol": max(tol.rtol, np.finfo(float).eps ** 0.5)}
        res = find_minimum(
            lambda t, r: h(t, r.astype(np.intp)),
            (a[valid], x[valid], b[valid]),
            args=(idx[valid].astype(float),),
            tolerances=tols,
        )
    ok = (np.asarray(res.success) | (np.asarray(res.status) == -2)) & (res.f_x <= fx[valid])
    rows_ = idx[valid][ok]
    best_v[rows_] = res.f_x[ok]
    best_x[rows_] = res.x[ok]
    best_xe[rows_] = np.abs(res.bracket[1] - res.bracket[0])[ok]


def _no_plateau(kind, xs, fs, best, tol: Tolerance, var: str, unit: str, label) -> None:
    """An extremum reached on a stretch of samples (a piece ``R otherwise`` at the top) has no
    one place: arg{kind} would silently pick an end of the stretch."""
    near = fs <= (best + np.maximum(tol.rtol * np.abs(best), tol.atol))[:, None]
    run = near[:, :-2] & near[:, 1:-1] & near[:, 2:]  # three samples in a row at the extremum
    if not run.any():
        return
    i, j = np.argwhere(run)[0]
    end = j + 2
    while end + 1 < near.shape[1] and near[i, end + 1]:
        end += 1
    raise NumericsError(
        f"arg{kind}(): the {kind}imum {num(-best[i] if kind == 'max' else best[i])} is reached "
        f"all along {var} = {num(xs[i, j])} .. {num(xs[i, end])}{_u(unit)}"
        f"{row_text(label, i, xs.shape[0])}: it has no one arg{kind} (narrow the interval)"
    )
