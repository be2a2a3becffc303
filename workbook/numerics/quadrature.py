"""Definite integrals, one per row, split at the function's kinks.

Every piece of every row starts as one interval of a 21-point Gauss-Kronrod rule; intervals
whose error estimate is above their share of the tolerance are halved, all rows together
(one function call per level). A row whose first estimate is off by more than ``ROUGH``,
or whose error does not fall at least tenfold with a halving (an end-point singularity,
where it falls only about twofold), or that has not
converged after ``MAX_LEVELS`` halvings, is done again by ``scipy.integrate.tanhsinh``,
which is made for such integrands. In a large table, ``PROBE`` rows spread over it are tried
first: when every one of them goes to tanh-sinh (the same end-point singularity in every row,
as in a power-law velocity profile), so do all rows, without the Gauss-Kronrod pass that
would be thrown away. Either way every row ends with its error estimate below the tolerance.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from types import SimpleNamespace

import numpy as np

from ..errors import WorkbookError
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
from .estimates import ESTIMATE_LIMIT
from .kronrod import gk21

#: halvings of an interval before a row goes to tanh-sinh
MAX_LEVELS = 5
#: a first estimate this far off (relative to the integral of |f|) goes to tanh-sinh at once
ROUGH = 1e-3
#: an error this small relative to the integral of |f| is rounding: accepted (gk21's floor)
ROUNDING = 51 * np.finfo(float).eps
#: tanh-sinh: a piece's absolute error may be this share of the tolerance times the row's size
ATOL_SHARE = 1e-3
#: most intervals at once per row (on average) before the rest goes to tanh-sinh
MAX_INTERVALS_PER_ROW = 64
#: rows tried first in a table of at least 8 x PROBE rows (see the module's docstring)
PROBE = 32
#: tanh-sinh's first level for a nearly singular row (SciPy's default, 2, for the others)
CHECK_LEVEL = 3
#: a singular sub-tree whose |value| at a piece's end is below this share of its largest
#: |value| there (end, middle, other end) has its zero just outside the piece
NEAR = 0.1
#: a row whose |f| at an end times the interval's width is above this many times the
#: integral is computed a second time by tanh-sinh, in two halves
STEEP_END = 10.0

_WHY = {
    -1: "the error estimate did not fall below the tolerance (a singular or divergent integral?)",
    -2: "the refinement limit was reached (a singular or divergent integral?)",
    -3: "the function is not a finite number somewhere in the interval (a singularity?)",
}


def integrate(
    f: Fn,
    a,
    b,
    args=(),
    tol: Tolerance = DEFAULT,
    *,
    breaks: Sequence = (),
    var: str = "x",
    unit: str = "",
    label: Callable[[int], str] | None = None,
    enclose: Callable | None = None,
    singular: Sequence[Callable] = (),
    poles: Sequence = (),
) -> Result:
    """The integral of ``f(x, *args)`` from a to b for every row.

    ``breaks`` are points (one array each, per row) where f has a kink or a jump (piecewise
    joins, abs, min/max): the interval is split there, so that every piece is smooth.
    With ``enclose(lo, hi, *args) -> (F, D)`` (interval enclosures of f), narrow and steep
    features are located first (:func:`workbook.numerics.features.breaks`) and the interval
    is split there too. The error estimate is the sum of the pieces' (QUADPACK's, or
    tanh-sinh's). ``singular``: ``h(x, *args)`` per sub-tree of f whose zeros are singular
    points of f (:mod:`workbook.numerics.singular`); a row where one is 0 just outside a
    piece has a second tanh-sinh computation (see :func:`_tanhsinh`). ``poles``: points (per
    row) where a singular sub-tree is 0, break points too; a piece between two singular
    points is split once more (see :func:`_asymmetric`).
    """
    shape, (a, b, *rest) = rows(a, b, *args, *breaks, *poles)
    args, brk = rest[: len(args)], rest[len(args) :]
    brk, pole = brk[: len(breaks)], brk[len(breaks) :]
    pole = _snapped(pole, [a, b, *brk], np.abs(b - a))
    brk = [*brk, *pole]
    n = a.size
    if n == 0:
        return Result(np.empty(shape), np.empty(shape))
    sign = np.where(b < a, -1.0, 1.0)
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    if enclose is not None:
        brk = [*brk, *_features(f, enclose, args, lo, hi)]
    if brk:
        inner = np.clip(np.vstack(brk), lo, hi)
        pts = np.sort(np.vstack([lo, inner, hi]), axis=0)
        # break points a few units in the last place apart (a kink found by a root search
        # beside the same point found by the feature search) are one: tanh-sinh reports a
        # piece one ulp wide as not finite
        for k in range(1, pts.shape[0]):
            close = pts[k] - pts[k - 1] <= 16 * np.spacing(np.abs(pts[k]))
            pts[k] = np.where(close & (k < pts.shape[0] - 1), pts[k - 1], pts[k])
            if k == pts.shape[0] - 1:
                pts[k - 1] = np.where(close, pts[k], pts[k - 1])
    else:
        pts = np.vstack([lo, hi])
    pts = _asymmetric(f, pts, args, pole, lo, hi)
    left, right = pts[:-1], pts[1:]  # (pieces, rows)
    if _every_row_slow(f, left, right, args, tol, n):
        value, error, pending, evals = np.zeros(n), np.zeros(n), np.ones(n, dtype=bool), 0
    else:
        value, error, pending, evals = _adaptive(f, left, right, args, tol, n)
    if pending.any():
        pl, pr, at = _split_at_singular_middles(
            f, left[:, pending], right[:, pending], args, pending
        )
        if at is None and pole:
            inside = np.vstack(pole)[:, pending]
            inside = inside[(inside > lo[pending]) & (inside < hi[pending])]
            at = float(inside[0]) if inside.size else None
        try:
            v, e, ev = _tanhsinh(f, pl, pr, args, pending, tol, n, label, unit, singular)
        except NumericsError as err:
            if at is None:
                raise
            raise NumericsError(
                f"{err.message}; the integrand is singular at {var} = {num(at)}{_u(unit)}, "
                "inside the interval: the integral diverges beside it (a principal value, "
                "where the two sides cancel, is not an integral)"
            ) from None
        value[pending], error[pending] = v, e
        evals = max(evals, ev)
    # the integrand's size, for the rows whose estimate the check would report against their
    # value (few or none: it costs 16 evaluations a row)
    suspect = error > ESTIMATE_LIMIT * tol.rtol * np.abs(value)
    notes = {"scale": _scale(f, lo[suspect], hi[suspect], [g[suspect] for g in args])}
    return Result(
        (sign * value).reshape(shape), error.reshape(shape), evaluations=evals, notes=notes
    )


#: where a piece between two singular points is split (a fraction of it, not its middle)
ASYMMETRIC = 0.381966011250105


#: a pole this close (relative to the interval) to a break point or an end is that point
SNAP = 1e-9


def _snapped(pole: list, points: list, width: np.ndarray) -> list:
    """The poles, each moved onto a break point or an end within SNAP of the interval (a
    zero found by a root search beside the same point read from the tree: two break points
    a few ulps apart make a piece tanh-sinh cannot integrate)."""
    out = []
    for p in pole:
        p = p.copy()
        for q in points:
            near = np.abs(p - q) <= SNAP * width + 16 * np.spacing(np.abs(q))
            p = np.where(near, q, p)
        out.append(p)
    return out


def _asymmetric(f, pts, args, pole, lo, hi) -> np.ndarray:
    """The break points ``pts`` (points, rows), with one more inside each piece whose two
    ends are singular (a pole located there, or f not finite there). An integrand odd about
    the middle of such a piece (x/(x^2 - 0.25) on [-0.5, 0.5], tan(x) between its poles)
    is 0 at every symmetric rule, Gauss-Kronrod's or tanh-sinh's, with an estimate of 0:
    the principal value of a divergent integral. Split off the middle, each piece has one
    singular end, where a divergent integral does not converge (and is refused)."""
    if pts.shape[0] < 2:
        return pts
    singular = np.zeros(pts.shape, dtype=bool)
    # the ends and the inner break points apart: EXPR may refuse a value at an end (a
    # declared limit broken by a root's rounding there) or an inner integral at a break
    # point; then the poles decide there
    for part in (slice(0, 1), slice(1, -1), slice(-1, None)):
        at = pts[part]
        if not at.size:
            continue
        try:
            with np.errstate(all="ignore"):
                fp = call(f, at, [g[None, :] for g in args])
            singular[part] = ~np.isfinite(np.broadcast_to(np.asarray(fp, float), at.shape))
        except WorkbookError:
            continue
    for p in pole:
        inside = ((p > lo) & (p < hi))[None, :]
        singular |= inside & (np.abs(pts - p[None, :]) <= 16 * np.spacing(np.abs(p[None, :])))
    both = singular[:-1] & singular[1:] & (pts[1:] > pts[:-1])
    if not both.any():
        return pts
    extra = np.where(both, pts[:-1] + ASYMMETRIC * (pts[1:] - pts[:-1]), pts[:-1])
    return np.sort(np.vstack([pts, extra]), axis=0)


#: interior points where the integrand's size is sampled (an end may be singular)
_SCALE_AT = (np.arange(16) + 0.5) / 16


def _scale(f, lo, hi, args) -> float:
    """The integral's natural size: the width times the largest |f| at 16 interior points
    (the integral of a full period of a sine is 0, its estimate is not measured against 0)."""
    if lo.size == 0:
        return 0.0
    xs = lo[:, None] + (hi - lo)[:, None] * _SCALE_AT
    with np.errstate(all="ignore"):
        fs = np.abs(np.asarray(call(f, xs, [g[:, None] for g in args]), dtype=float))
    fs = np.where(np.isfinite(fs), fs, 0.0)
    return float(np.max((hi - lo) * fs.max(axis=1), initial=0.0))


#: rows of one call searched for features; of a larger table, PROBE rows spread over it are,
#: and all of them when one of those has a feature
FEATURE_ROWS = 2_000


def _features(f, enclose, args, lo, hi) -> list[np.ndarray]:
    """Break points at the narrow and steep features of every row (see numerics.features)."""
    from .features import breaks

    def search(sel):
        return breaks(
            lambda p, q, r: enclose(p, q, *[g[sel[r]] for g in args]),
            lambda x, r: f(x, *[g[sel[r]] for g in args]),
            lo[sel],
            hi[sel],
        )

    n = lo.size
    if n > FEATURE_ROWS and not search(np.linspace(0, n - 1, PROBE).astype(np.intp)):
        return []
    return search(np.arange(n))


def _every_row_slow(f, left, right, args, tol, n) -> bool:
    """True if the Gauss-Kronrod rule sends every one of PROBE rows spread over a large
    table to tanh-sinh: the rest is then sent there without trying it."""
    if n < 8 * PROBE:
        return False
    rows = np.linspace(0, n - 1, PROBE).astype(np.intp)
    pending = _adaptive(f, left[:, rows], right[:, rows], [g[rows] for g in args], tol, PROBE)[2]
    return bool(pending.all())


def _adaptive(f, left, right, args, tol, n):
    """Adaptive GK21 on all rows at once: (value, error, rows not converged, evaluations)."""
    piece, row = np.nonzero(right > left)
    lo, hi = left[piece, row], right[piece, row]
    length = np.bincount(row, hi - lo, minlength=n)
    value, error = np.zeros(n), np.zeros(n)
    pending = np.zeros(n, dtype=bool)
    evals = 0
    split_error = None
    for level in range(MAX_LEVELS + 1):
        if lo.size == 0:
            break
        k, e, absk = gk21(f, lo, hi, [g[row] for g in args])
        evals += 21 * 2**level
        bad = ~(np.isfinite(k) & np.isfinite(e))
        if bad.any():  # tanh-sinh says where it is not finite, or copes (no node at the ends)
            pending[row[bad]] = True
        if split_error is None:  # far off at once: not smooth, leave it to tanh-sinh
            pending[row[e > ROUGH * absk]] = True
        else:  # slow convergence: not smooth either
            pending |= np.bincount(row, e, minlength=n) > 0.1 * split_error
        total = value + np.bincount(row, k, minlength=n)
        share = (hi - lo) / np.where(length[row] > 0, length[row], 1.0)
        allowed = np.maximum(tol.atol, tol.rtol * np.abs(total[row])) * share
        # an error at the rounding level of the terms is as good as it gets (an integral of 0)
        allowed = np.maximum(allowed, ROUNDING * absk)
        ok = (e <= allowed) & ~pending[row]
        value += np.bincount(row[ok], k[ok], minlength=n)
        error += np.bincount(row[ok], e[ok], minlength=n)
        keep = ~ok & ~pending[row]
        lo, hi, row = lo[keep], hi[keep], row[keep]
        split_error = np.bincount(row, e[keep], minlength=n)
        if level == MAX_LEVELS or lo.size > MAX_INTERVALS_PER_ROW * n:
            pending[row] = True
            break
        mid = (lo + hi) / 2.0
        lo, hi, row = (
            np.concatenate([lo, mid]),
            np.concatenate([mid, hi]),
            np.concatenate([row, row]),
        )
    return value, error, pending, evals


#: times a piece whose middle is not finite is split there (a singular point at a middle
#: of the halves too)
MIDDLE_SPLITS = 4


def _split_at_singular_middles(f, left, right, args, pending):
    """The pieces (pieces, rows) of the pending rows, each split at its middle where f is
    not finite there. tanh-sinh's nodes are symmetric about the middle and SciPy's drops a
    node where f is not finite: at an interior singularity in the middle (1/(x - 0.5) on
    [0, 1]) the two sides cancel, and it converges to the principal value 0, which is no
    integral. As an end of two pieces the singular point is tanh-sinh's strength: an
    integrable one converges, a divergent one does not (and is refused). Also returns the
    first point split at (None: none)."""
    args = [g[None, pending] for g in args]
    first = None
    for _ in range(MIDDLE_SPLITS):
        mid = (left + right) / 2.0
        try:
            with np.errstate(all="ignore"):
                fm = np.broadcast_to(np.asarray(call(f, mid, args), dtype=float), mid.shape)
        except WorkbookError:  # (an inner integral refused there: tanh-sinh will say so)
            break
        # (a piece of a few doubles has no middle to split at: its nodes are its ends)
        room = 64 * np.spacing(np.abs(mid))
        bad = np.isinf(fm) & (mid - left > room) & (right - mid > room)  # a pole, not NaN
        if not bad.any():
            break
        first = float(mid[bad][0]) if first is None else first
        # each bad piece ends at its middle; its other half is a new piece (empty elsewhere)
        extra_left = np.where(bad, mid, right)
        extra_right = right.copy()
        right = np.where(bad, mid, right)
        left = np.vstack([left, extra_left])
        right = np.vstack([right, extra_right])
        # the empty pieces keep their row's order (left <= right per row after sorting)
        order = np.argsort(left, axis=0, kind="stable")
        left, right = np.take_along_axis(left, order, 0), np.take_along_axis(right, order, 0)
    return left, right, first


def _tanhsinh(f, left, right, args, pending, tol, n, label, unit, singular=()):
    from scipy.integrate import tanhsinh

    idx = np.flatnonzero(pending)
    args = [g[None, pending] for g in args]
    size = _size(f, left, right, args)
    scale = size if not tol.atol else np.ones(idx.size)

    def run(lo, hi, cols, minlevel=2):
        try:
            with np.errstate(all="ignore"):
                res = tanhsinh(
                    lambda x, inverse, *a: f(x, *a) * inverse,
                    lo,
                    hi,
                    args=(1.0 / scale[None, cols], *[g[:, cols] for g in args]),
                    rtol=max(tol.rtol, 1e-15),
                    # the integrand is divided by the row's size: a piece's error is allowed
                    # its share of the tolerance of the whole row, as in the Gauss-Kronrod
                    # pass (and a piece where f is 0 converges at once)
                    atol=tol.atol or ATOL_SHARE * max(tol.rtol, 1e-15),
                    minlevel=minlevel,
                )
        except NumericsError:
            # f refused at one of tanh-sinh's nodes: an inner integral at a node a few
            # doubles from an end (its interval [0, x] for x = 2e-323 holds 4 doubles, its
            # nodes fall on its singular end); QAGS's nodes keep away from the ends
            res = SimpleNamespace(
                integral=np.zeros(lo.shape),
                error=np.zeros(lo.shape),
                nfev=np.zeros(lo.shape, dtype=int),
                status=np.full(lo.shape, -3),
            )
        status = np.array(res.status)
        # an empty piece (a row with fewer break points repeats its lower bound) is 0, also
        # where f has no value at that point (sqrt(x)*ln(x) at 0)
        empty = np.broadcast_to(lo == hi, status.shape)
        if empty.any():
            res.integral, res.error = np.array(res.integral), np.array(res.error)
            res.integral[empty], res.error[empty], status[empty] = 0.0, 0.0, 0
        for p, i in np.argwhere(status != 0):  # QUADPACK's QAGS where tanh-sinh gives up
            done = quadpack(f, lo[p, i], hi[p, i], [g[:, [cols[i]]] for g in args], tol)
            if done is not None:
                res.integral[p, i] = done[0] / scale[cols][i]
                res.error[p, i] = done[1] / scale[cols][i]
                status[p, i] = 0
        if (status != 0).any():
            p, i = np.argwhere(status != 0)[0]
            raise NumericsError(
                f"integral(): {_WHY.get(int(status[p, i]), f'status {int(status[p, i])}')}: "
                f"on [{num(lo[p, i])}, {num(hi[p, i])}]{_u(unit)}"
                f"{row_text(label, idx[cols][i], n)} the estimate is "
                f"{num(scale[cols][i] * res.integral[p, i])} +- "
                f"{num(scale[cols][i] * res.error[p, i])}"
            )
        return res

    # tanh-sinh's own estimate (the difference between its last levels) can be far too small
    # when it stops at its first levels: on 1/sqrt(t + 1e-3) over [0, 0.79] (nearly singular
    # just outside the interval) it said 4.5e-11 for an error of 6e-8. A row whose integrand
    # is nearly singular beside a piece (a singular sub-tree's zero just outside it, or |f|
    # at an end STEEP_END times its mean) is integrated from level CHECK_LEVEL, whole and
    # again in two halves on other nodes: the halves' sum is its value, and the difference
    # between the two results is added to its error estimate. Another row (smooth, or
    # singular at an end itself, as the power-law profile: what tanh-sinh is made for) is
    # computed once.
    rounding, at_ends = _rounding(f, left, right, args)
    width = (right - left).sum(axis=0)
    steep = ~(at_ends * width <= STEEP_END * size)  # also where f is not finite there
    steep |= _nearly_singular(singular, left, right, args)
    value, error, evals = np.zeros(idx.size), np.zeros(idx.size), np.zeros(idx.size, dtype=int)
    plain = np.flatnonzero(~steep)
    if plain.size:
        once = run(left[:, plain], right[:, plain], plain)
        value[plain] = once.integral.sum(axis=0) * scale[plain]
        error[plain] = once.error.sum(axis=0) * scale[plain]
        evals[plain] = once.nfev.sum(axis=0)
    checked = np.flatnonzero(steep)
    if checked.size:
        lo, hi = left[:, checked], right[:, checked]
        mid = (lo + hi) / 2.0
        whole = run(lo, hi, checked, CHECK_LEVEL)
        halves = run(np.vstack([lo, mid]), np.vstack([mid, hi]), checked, CHECK_LEVEL)
        first = whole.integral.sum(axis=0) * scale[checked]
        value[checked] = halves.integral.sum(axis=0) * scale[checked]
        # either of the two may be the worse: the difference is added, not taken as a floor
        error[checked] = halves.error.sum(axis=0) * scale[checked] + np.abs(first - value[checked])
        evals[checked] = whole.nfev.sum(axis=0) + halves.nfev.sum(axis=0)
    return value, error + rounding, int(evals.max())


#: subintervals of QUADPACK's QAGS in the fallback (SciPy's default is 50)
QUADPACK_LIMIT = 500


def quadpack(f, lo: float, hi: float, args, tol: Tolerance) -> tuple[float, float] | None:
    """(value, error) of one piece by SciPy's ``quad`` (QUADPACK's QAGS: adaptive
    Gauss-Kronrod with Wynn's extrapolation, which integrates an x^-0.99 end or an interior
    logarithmic singularity), or None where it does not reach the tolerance either, or where
    the integral of |f| shows the extrapolation's value of a divergent integral."""
    import warnings

    from scipy.integrate import IntegrationWarning, quad

    def g(x: float) -> float:
        with np.errstate(all="ignore"):
            return float(np.asarray(f(np.array([[x]]), *args), dtype=float).ravel()[0])

    rtol = max(tol.rtol, 1e-14)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IntegrationWarning)
        try:
            value, error = quad(g, lo, hi, epsabs=0.0, epsrel=rtol, limit=QUADPACK_LIMIT)
            size, size_error = quad(
                lambda x: abs(g(x)), lo, hi, epsabs=0.0, epsrel=rtol, limit=QUADPACK_LIMIT
            )
        except (ValueError, ZeroDivisionError, OverflowError):
            return None
    if not all(np.isfinite(v) for v in (value, error, size, size_error)):
        return None
    if error > 100 * rtol * abs(value) + tol.atol or size_error > 100 * rtol * size:
        return None  # QUADPACK's own estimate says it failed too (on f, or on |f|)
    # Wynn's extrapolation gives a divergent integral its analytic continuation (x^-1.01 on
    # [0, 1]: -100): the integral of |f| is then negative, or below |the integral|
    if size < 0 or abs(value) > size + size_error + error:
        return None
    return value, error


def _nearly_singular(singular, left, right, args) -> np.ndarray:
    """Per row: whether a singular sub-tree's zero is just outside one of its pieces (|h| at
    an end below NEAR of its largest |h| at the ends and middle, and not 0 but for rounding:
    a zero at the end itself is tanh-sinh's strength)."""
    out = np.zeros(left.shape[1], dtype=bool)
    mid = (left + right) / 2.0
    for h in singular:
        with np.errstate(all="ignore"):
            vals = [
                np.abs(np.broadcast_to(np.asarray(h(x, *args), dtype=float), x.shape))
                for x in (left, mid, right)
            ]
        top = np.maximum.reduce(vals)
        for end in (vals[0], vals[2]):
            near = (end > 1e3 * np.finfo(float).eps * top) & (end < NEAR * top)
            out |= (near & (right > left)).any(axis=0)
    return out


def _rounding(f, left, right, args) -> tuple[np.ndarray, np.ndarray]:
    """Per row, what rounding the nodes next to a piece's ends costs: a node a + t is a
    double, off from a + t by up to an ulp of a, which near an end-point singularity moves
    f a lot (1/sqrt(x - 0.3) on [0.3, 1]: about 2e-8, where tanh-sinh's estimate said 2e-10).
    Estimated as 2 d |f(a + d)| at each end a, d a few ulp of a (2 sqrt(d) for that f).
    Also, per row, the largest |f| there (inf where it is not finite)."""
    out = np.zeros(left.shape[1])
    top = np.zeros(left.shape[1])
    for end, inward in ((left, 1.0), (right, -1.0)):
        d = 4 * np.spacing(np.abs(end))
        inside = right > left
        at = np.where(inside, end + inward * d, end)  # (an empty piece: not beyond its end)
        try:
            with np.errstate(all="ignore"):
                fv = np.abs(np.broadcast_to(np.asarray(f(at, *args), dtype=float), end.shape))
        except NumericsError:
            # an inner integral over [0, x] for x a few subnormal doubles (its interval holds
            # no nodes but its ends): no value there, as where f overflows
            fv = np.full(end.shape, np.inf)
        out += np.where(np.isfinite(fv) & inside, 2 * d * fv, 0.0).sum(axis=0)
        top = np.maximum(
            top, np.where(inside, np.where(np.isfinite(fv), fv, np.inf), 0.0).max(axis=0)
        )
    return out, top


def _size(f, left, right, args) -> np.ndarray:
    """Per row, |f| at the middle of each piece times its width, summed (1 where that is 0
    or not finite): about the size of the integral.

    tanh-sinh's error estimate is not scale-invariant (one of its terms is the square of the
    difference between two levels), so that the same integral took a level more written in
    mm (a value of 10^6) than in m (10^-3); the integrand is divided by this size, and the
    result multiplied back, so that the levels do not depend on the sheet's units.
    """
    mid = (left + right) / 2.0
    with np.errstate(all="ignore"):
        fm = np.broadcast_to(np.asarray(f(mid, *args), dtype=float), mid.shape)
        size = (np.abs(fm) * (right - left)).sum(axis=0)
    return np.where(np.isfinite(size) & (size > 0), size, 1.0)
