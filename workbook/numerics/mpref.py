"""``workbook bench``'s reference: the built-ins computed with mpmath on EXPR's typed tree.

Inside :func:`workbook.numerics.reference_methods`, root, integral and the extrema compute
each row by these methods, EXPR evaluated by :mod:`workbook.numerics.mpform` (every
operation in mpmath, not numpy):

- integral: ``mpmath.quad`` (tanh-sinh) at 32 digits on pieces
  (:func:`workbook.numerics.mpform.quad`, which EXPR's inner integrals use too): the kinks
  the tree shows, the narrow and steep features its interval enclosures locate, and 8 equal
  pieces; a piece whose estimate is above 1e-26 of the integral's scale is halved (256
  pieces at most);
- root in a bracket: bisection at 60 digits (to 1e-40 relative) on [A, B] or, where EXPR
  has the same sign at both ends, on the one of 64 sample intervals with a sign change; a
  bracket whose ends end far from 0 is a pole or a jump, not a root;
- root from a guess: the nearest sign change outward from the guess (both sides to the same
  distance, as the engine searches), past poles and jumps, then bisection as above;
- maximum, minimum, argmax, argmin: EXPR at 4,001 points and at the ends of the feature
  boxes, and at two points between each two (in doubles, to find candidates; 4 times denser,
  up to 4,096,000 intervals, while more than 1 % of those are off the line through their
  neighbours by a twentieth of the samples' range), then golden-section search at 32 digits
  around the local extrema whose parabola through three samples is within the sampling's
  error of the best (at least the 8 best, at most 64 more) and the ends; the best is the
  value.

Of a call with more than ``ROWS`` rows, ``ROWS`` rows spread over it are computed (the
others are NaN, filled with the engine's values by the hooks). EXPR without an mpmath form
returns None, and the hook falls back to :mod:`workbook.numerics.reference` (other
algorithms in doubles); :func:`workbook.functions.numerical.reference_note` records which.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np

from ..functions.numerical import reference_note
from .mpform import NoMpForm, NoValue, Unconverged, mp_form, quad
from .reference import ReferenceFailed

#: digits of the integral's and the extrema's reference
DIGITS = 32
#: digits of a root's reference (a multiple root is as exact as the cube root of rounding)
ROOT_DIGITS = 60
#: rows of one call computed at most (spread over it)
ROWS = 16
#: points of the extremum's sampling, and the local extrema polished
DENSE = 4000
CANDIDATES = 8
#: the densest sampling, and the local extrema polished at most
DENSE_MAX, POLISHED = 4000 * 4**5, 64
#: where between two samples EXPR is compared with the line through them (fractions of the
#: spacing: 1 - 1/golden ratio, and (1 + 1/sqrt 5)/2)
OFFSETS = (0.3819660112501051, 0.7236067977499789)


def context(digits: int):
    """A private mpmath context (the global ``mpmath.mp`` is left alone)."""
    ctx = mpmath.MPContext()
    ctx.dps = digits
    return ctx


# -- the methods on one row: g(x) is EXPR at an mpf x (the integral: mpform.quad) ---------------
def _bisect(ctx, g, lo, hi, glo):
    """A sign change of g in [lo, hi] to 1e-40 relative; refused when it is a pole or a jump."""
    scale = max(abs(glo), abs(g(hi)))
    flo = glo
    for _ in range(2000):
        mid = (lo + hi) / 2
        if hi - lo <= ctx.mpf(10) ** -40 * max(abs(lo), abs(hi), ctx.mpf(10) ** -300):
            break
        if mid in (lo, hi):
            break
        try:
            fm = g(mid)
        except (NoValue, ZeroDivisionError):  # EXPR has no value inside the sign change
            raise Unconverged(f"a pole or a jump at x = {float(mid):.6g}, not a root") from None
        if fm == 0:
            return mid
        if (fm > 0) == (flo > 0):
            lo, flo = mid, fm
        else:
            hi = mid
    ends = min(abs(flo), abs(g(hi)))
    if ends > scale * ctx.mpf(10) ** -12:
        raise Unconverged(f"a pole or a jump at x = {float(lo):.6g}, not a root")
    return (lo + hi) / 2


def root_in(ctx, g, a, b):
    """The one root of g in [a, b] (mpf)."""
    lo, hi = sorted((ctx.mpf(a), ctx.mpf(b)))
    glo, ghi = g(lo), g(hi)
    if glo == 0 or ghi == 0:
        return lo if glo == 0 else hi
    if (glo > 0) == (ghi > 0):
        xs = [lo + (hi - lo) * k / 64 for k in range(65)]
        fs = [g(x) for x in xs]
        change = [k for k in range(64) if (fs[k] > 0) != (fs[k + 1] > 0) or fs[k] == 0]
        if len(change) != 1:
            raise Unconverged(f"{len(change)} sign changes at 65 samples")
        k = change[0]
        if fs[k] == 0:
            return xs[k]
        lo, hi, glo = xs[k], xs[k + 1], fs[k]
    return _bisect(ctx, g, lo, hi, glo)


def root_near(ctx, g, guess):
    """The root of g nearest to ``guess`` whose sign change is no pole or jump (4 at most)."""
    x = ctx.mpf(guess)
    f0 = g(x)
    if f0 == 0:
        return x
    h, skipped = max(abs(x) * ctx.mpf("1e-6"), ctx.mpf("1e-9")), 0
    inner = ctx.zero
    for _ in range(400):
        found = []
        for t, s in ((x + h, x + inner), (x - h, x - inner)):
            try:
                ft, fs = g(t), g(s)
            except NoValue:
                continue
            if (ft > 0) != (fs > 0) or ft == 0:
                lo, hi = sorted((s, t))
                try:
                    found.append(_bisect(ctx, g, lo, hi, g(lo)))
                except Unconverged:
                    skipped += 1
                    if skipped > 4:
                        raise Unconverged("more than 4 poles or jumps near the guess") from None
        if found:
            return min(found, key=lambda r: abs(r - x))
        inner, h = h, h * ctx.mpf("1.25")
    raise Unconverged("no sign change around the guess")


def _golden(ctx, g, lo, hi, sgn):
    """(best value of sgn*g, where) on [lo, hi] by golden-section search to 1e-20 relative."""
    r = (ctx.sqrt(5) - 1) / 2
    c, d = hi - r * (hi - lo), lo + r * (hi - lo)
    fc, fd = sgn * g(c), sgn * g(d)
    tol = ctx.mpf(10) ** -20 * max(abs(lo), abs(hi), ctx.mpf(10) ** -300)
    while hi - lo > tol:
        if fc < fd:
            hi, d, fd = d, c, fc
            c = hi - r * (hi - lo)
            fc = sgn * g(c)
        else:
            lo, c, fc = c, d, fd
            d = lo + r * (hi - lo)
            fd = sgn * g(d)
    best = [(fc, c), (fd, d), (sgn * g(lo), lo), (sgn * g(hi), hi)]
    return min(best, key=lambda p: p[0])


def extremum(ctx, g, xs: np.ndarray, fs: np.ndarray, kind: str):
    """(value, where) of g's extremum, polished around the samples' best local extrema: those
    whose parabola through three samples peaks within the sampling's own error (the largest
    second difference of the best CANDIDATES) of the best, at most POLISHED, and the ends."""
    sgn = -1 if kind == "max" else 1
    s = sgn * np.where(np.isfinite(fs), fs, np.inf)
    n = xs.size
    local = [
        k for k in range(n) if (k == 0 or s[k] <= s[k - 1]) and (k == n - 1 or s[k] <= s[k + 1])
    ]
    vertex, curve = {}, {}
    for k in local:
        if 0 < k < n - 1 and np.all(np.isfinite(s[k - 1 : k + 2])):
            d2 = s[k - 1] - 2 * s[k] + s[k + 1]
            d1 = s[k + 1] - s[k - 1]
            vertex[k] = s[k] - d1 * d1 / (8 * d2) if d2 > 0 else s[k]
            curve[k] = abs(d2)
        else:
            vertex[k], curve[k] = s[k], 0.0
    ranked = sorted(local, key=lambda k: vertex[k])
    margin = max((curve[k] for k in ranked[:CANDIDATES]), default=0.0)
    near = [k for k in ranked if vertex[k] <= vertex[ranked[0]] + margin] if ranked else []
    chosen = {*ranked[:CANDIDATES], *near[:POLISHED], 0, n - 1}
    best = None
    for k in chosen:
        lo, hi = ctx.mpf(xs[max(k - 1, 0)]), ctx.mpf(xs[min(k + 1, n - 1)])
        cand = _golden(ctx, g, lo, hi, sgn)
        if best is None or cand[0] < best[0]:
            best = cand
    return sgn * best[0], best[1]


def samples(f, lo: float, hi: float, extra) -> tuple[np.ndarray, np.ndarray]:
    """EXPR at DENSE + 1 points of [lo, hi] and at ``extra``, 4 times denser (up to DENSE_MAX)
    while EXPR at OFFSETS between the samples is off the line through its neighbours by
    more than a twentieth of the samples' range in more than 1 % of the intervals: an EXPR that
    oscillates 2.4e4 times is sampled about 40 times a period, not once in 6 periods (nor
    aliased into a smooth curve); a jump or a narrow peak, a few intervals, is left to the
    feature boxes."""
    n, between = DENSE, []
    while True:
        grid = np.linspace(lo, hi, n + 1)
        with np.errstate(all="ignore"):
            fg = np.broadcast_to(np.asarray(f(grid), dtype=float), grid.shape)
        fin = fg[np.isfinite(fg)]
        scale = 0.05 * max(float(np.ptp(fin)) if fin.size else 0.0,
                           1e-12 * float(np.max(np.abs(fin), initial=0.0)))  # fmt: skip
        off, between = 0, []
        for frac in OFFSETS:  # two, so that no one frequency aliases both into a smooth curve
            x = grid[:-1] + frac * np.diff(grid)
            with np.errstate(all="ignore"):
                fx = np.broadcast_to(np.asarray(f(x), dtype=float), x.shape)
                line = fg[:-1] + frac * (fg[1:] - fg[:-1])
                off = max(off, int(np.count_nonzero(np.abs(fx - line) > scale)))
            between.append(x)
        if n >= DENSE_MAX or off <= max(2, 0.01 * n):
            break
        n *= 4
    xs = np.unique(np.concatenate([grid, *between, np.asarray(extra, dtype=float)]))
    xs = xs[(xs >= lo) & (xs <= hi)]
    with np.errstate(all="ignore"):
        fs = np.broadcast_to(np.asarray(f(xs), dtype=float), xs.shape)
    return xs, fs


# -- the hooks' side: every row of a call --------------------------------------------------------
def _rows(n: int) -> np.ndarray:
    return np.arange(n) if n <= ROWS else np.unique(np.linspace(0, n - 1, ROWS).astype(np.intp))


def _flat(of, shape) -> dict[str, np.ndarray]:
    """The arrays of the call's environment (``of.arrays``), each flat over ``shape``."""
    return {k: np.broadcast_to(a, shape).reshape(-1) for k, a in of.arrays.items()}


def _prepared(of, name: str, digits: int, *bounds):
    """(ctx, form, shape, flat bounds, row environments) or None without an mpmath form."""
    from .reference import ROWS as SCIPY_ROWS

    ctx = context(digits)
    shape = np.broadcast_shapes(of.shape, *(np.shape(b) for b in bounds))
    n = math.prod(shape)
    try:
        form = mp_form(of.evaluator, ctx, of.body)
    except NoMpForm as err:
        reference_note(f"scipy ({err}: no mpmath form)", min(n, SCIPY_ROWS), n)
        return None
    flat = [np.broadcast_to(np.asarray(b, dtype=float), shape).reshape(-1) for b in bounds]
    arrays = _flat(of, shape)
    used = of.names_read
    fixed = {k: float(np.asarray(v)) for k, v in of.env.items() if k in used and k not in arrays}
    rows = _rows(n)

    def env(i):
        return {**fixed, **{k: float(a[i]) for k, a in arrays.items()}}

    reference_note("mpmath", rows.size, n)
    return ctx, form, shape, flat, rows, env


def _each(name: str, var: str, prepared, one) -> np.ndarray:
    """``one(ctx, g, bounds, row)`` for every row computed; NaN in the others."""
    ctx, form, shape, flat, rows, env = prepared
    out = np.full(math.prod(shape), np.nan)
    for i in rows:
        e = env(i)

        def g(x, e=e):
            return form({**e, var: x})

        try:
            out[i] = float(one(ctx, g, [b[i] for b in flat], i))
        except (NoValue, Unconverged, ZeroDivisionError) as err:
            raise ReferenceFailed(f"mpmath {name}: {err}") from None
    return out.reshape(shape)


def root(of, a, b=None) -> np.ndarray | None:
    """The reference of root(EXPR, X, A, B) or root(EXPR, X, GUESS), or None (no mpmath form)."""
    bounds = (a,) if b is None else (a, b)
    prepared = _prepared(of, "root", ROOT_DIGITS, *bounds)
    if prepared is None:
        return None
    if b is None:
        return _each("root", of.var, prepared, lambda ctx, g, ab, i: root_near(ctx, g, ab[0]))
    return _each("root", of.var, prepared, lambda ctx, g, ab, i: root_in(ctx, g, ab[0], ab[1]))


def _feature_points(of, shape, lo, hi, rows) -> dict[int, list[float]]:
    """Row -> the ends of the boxes where EXPR's enclosures show a narrow or steep feature
    (every row computed is searched: there are at most ROWS)."""
    from .features import breaks

    enclose = of.enclosure(shape)
    if enclose is None:
        return {}
    f, at = of.over(shape), rows.astype(float)
    found = breaks(
        lambda p, q, r: enclose(p, q, at[r]), lambda x, r: f(x, at[r]), lo[rows], hi[rows]
    )
    return {int(r): [float(p[k]) for p in found] for k, r in enumerate(rows)}


def integral(of, a, b, breaks) -> np.ndarray | None:
    """The reference of integral(EXPR, X, A, B), or None (no mpmath form)."""
    prepared = _prepared(of, "integral", DIGITS, a, b, *breaks)
    if prepared is None:
        return None
    shape, flat, rows = prepared[2], prepared[3], prepared[4]
    lo, hi = np.minimum(flat[0], flat[1]), np.maximum(flat[0], flat[1])
    extra = _feature_points(of, shape, lo, hi, rows)

    def one(ctx, g, ab, i):
        lo, hi, *pts = ab
        return quad(ctx, g, lo, hi, [*pts, *extra.get(i, ())])

    return _each("integral", of.var, prepared, one)


def extremum_of(of, a, b, kind: str, where: bool) -> np.ndarray | None:
    """The reference of maximum/minimum (or argmax/argmin: ``where``), or None (no mpmath
    form)."""
    prepared = _prepared(of, "argmax" if where else kind, DIGITS, a, b)
    if prepared is None:
        return None
    shape, flat, rows = prepared[2], prepared[3], prepared[4]
    lo, hi = np.minimum(flat[0], flat[1]), np.maximum(flat[0], flat[1])
    extra = _feature_points(of, shape, lo, hi, rows)
    f = of.over(shape)

    def one(ctx, g, ab, i):
        xs, fs = samples(lambda x: f(x, np.full(x.size, i)), lo[i], hi[i], extra.get(i, []))
        value, at = extremum(ctx, g, xs, fs, kind)
        return at if where else value

    return _each(kind, of.var, prepared, one)


#: terms of one row of a sum or product that the reference adds at most
SERIES_TERMS = 20_000


def series(of, lo, hi, kind: str) -> np.ndarray | None:
    """The reference of sum/product(EXPR, I, A, B): every term in mpmath at 32 digits, added
    (``fsum``) or multiplied exactly at that precision; None without an mpmath form."""
    prepared = _prepared(of, kind, DIGITS, lo, hi)
    if prepared is None:
        return None

    def one(ctx, g, ab, i):
        first, last = int(ab[0]), int(ab[1])
        if last - first + 1 > SERIES_TERMS:
            raise Unconverged(f"{last - first + 1} terms (the reference adds {SERIES_TERMS})")
        terms = [g(ctx.mpf(k)) for k in range(first, last + 1)]
        return ctx.fsum(terms) if kind == "sum" else ctx.fprod(terms)

    return _each(kind, of.var, prepared, one)


#: digits of diff's reference
DIFF_DIGITS = 50


def derivative(of, order: int, x) -> np.ndarray:
    """The reference of diff(EXPR, X, N) at the points ``x``: ``mpmath.diff`` (finite
    differences at 50 digits, steps chosen by mpmath) on EXPR's mpmath form, not SymPy's
    formula of the derivative; refused (ReferenceFailed) without an mpmath form."""
    try:
        mp_form(of.evaluator, context(DIFF_DIGITS), of.body)
    except NoMpForm as err:
        raise ReferenceFailed(f"mpmath diff: {err} has no mpmath form") from None
    prepared = _prepared(of, "diff", DIFF_DIGITS, x)
    return _each("diff", of.var, prepared, lambda ctx, g, at, i: ctx.diff(g, ctx.mpf(at[0]), order))


# -- roots inside the rounding noise: polished in extended precision ----------------------------
#: rows of one call polished at most (a table of multiple roots keeps its noise-limited
#: estimates beyond that)
POLISH_ROWS = 64


def polish_roots(of, result, shape, tol) -> int:
    """Roots checked, and polished where needed, on EXPR's mpmath form at 60 digits, in
    place. A root is certain within its estimate e where EXPR's signs at value -/+ e differ
    in mpmath. A root whose estimate is above the tolerance (a multiple root, hidden within
    the rounding of EXPR in doubles), and one whose signs there do not differ (an estimate
    too small: the nearest sign change is sought outward, 4 times wider at each step), is
    polished by bisection to 1e-40, and its estimate becomes the rounding of the double it is
    returned as. Every row of a call of at most POLISH_ROWS rows is checked (unless EXPR
    has an inner integral); of a larger call, only the rows whose estimate is above the
    tolerance. Rows without an mpmath form,
    or where no sign change is found, keep their value and estimate. Returns the number of
    rows changed; ``result.notes["certified"]`` marks the rows checked or polished."""

    value = np.ravel(result.value).copy()
    error = np.ravel(result.error).copy()
    finite = np.isfinite(value) & np.isfinite(error)
    noisy = finite & (error > np.maximum(tol.rtol * np.abs(value), tol.atol))
    # an inner integral costs an mpmath quadrature per evaluation: only noisy rows then
    check_all = value.size <= POLISH_ROWS and not _has_integral(of.evaluator, of.body)
    rows = np.flatnonzero(finite if check_all else noisy)
    certified = result.notes["certified"] = np.zeros(value.size, dtype=bool)
    if not rows.size or rows.size > POLISH_ROWS:
        return 0
    ctx = context(ROOT_DIGITS)
    try:
        form = mp_form(of.evaluator, ctx, of.body)
    except NoMpForm:
        return 0
    arrays = _flat(of, shape)
    used = of.names_read
    fixed = {k: float(np.asarray(v)) for k, v in of.env.items() if k in used and k not in arrays}
    done = 0
    f = of.over(shape)
    for i in rows:
        env = {**fixed, **{k: float(a[i]) for k, a in arrays.items()}}

        def g(x, env=env):
            return form({**env, of.var: x})

        try:
            probe = value[i] + np.array([-1.0, 1.0]) * max(0.1 * abs(value[i]), 1e-3)
            if not _same_function(ctx, g, f, probe, i):
                continue
            x = checked_root(ctx, g, value[i], error[i], bool(noisy[i]))
        except (NoValue, Unconverged, ZeroDivisionError):
            continue
        if x is True:  # certain within its estimate at 60 digits
            certified[i] = True
            continue
        if x is None:
            continue
        certified[i] = True
        value[i] = float(x)
        error[i] = max(abs(float(x - ctx.mpf(value[i]))), np.spacing(abs(value[i])))
        done += 1
    result.value = value.reshape(np.shape(result.value))
    result.error = error.reshape(np.shape(result.error))
    return done


def _same_function(ctx, g, f, xs: np.ndarray, row: int) -> bool:
    """Whether EXPR's mpmath form computes what numpy computes at ``xs`` of ``row`` (to 1e-6
    of their size; away from a root, where rounding is not all there is): not where the
    numpy side reads values the mpmath form cannot see (a sweep's inputs varied per case)."""
    from ..errors import WorkbookError

    try:
        with np.errstate(all="ignore"):
            want = np.asarray(f(xs, np.full(xs.size, row)), dtype=float)
    except WorkbookError:  # outside EXPR's domain there (a probe past a bound)
        return False
    want = np.broadcast_to(want, xs.shape)
    keep = np.isfinite(want)
    if not keep.any():
        return False
    try:
        got = np.array([float(g(ctx.mpf(float(x)))) for x in xs[keep]])
    except (NoValue, ZeroDivisionError):
        return False
    want = want[keep]
    return bool(np.all(np.abs(got - want) <= 1e-6 * np.maximum(np.abs(want), np.abs(got)) + 1e-300))


def _has_integral(evaluator, body) -> bool:
    """Whether EXPR calls integral, also through the sheet's functions."""
    from ..language import typed as ty

    stack, seen = [body], set()
    while stack:
        n = stack.pop()
        if isinstance(n, ty.TFunc) and n.func == "integral":
            return True
        if isinstance(n, ty.TCall) and n.name not in seen:
            seen.add(n.name)
            stack.append(evaluator.defs.function(n.name).body)
        stack.extend(ty.children(n))
    return False


def checked_root(ctx, g, v: float, e: float, polish: bool):
    """True where the root is certain within e and need not be polished; else the root
    polished in mpmath (None where no sign change is found near v, or two)."""
    d = max(e, 4 * float(np.spacing(abs(v))), float(np.finfo(float).tiny))
    certain = True
    for _ in range(40):
        lo, hi = ctx.mpf(v) - ctx.mpf(d), ctx.mpf(v) + ctx.mpf(d)
        glo, ghi = g(lo), g(hi)
        if glo == 0 or ghi == 0:
            return True if certain and not polish else (lo if glo == 0 else hi)
        if (glo > 0) != (ghi > 0):
            break
        certain = False
        d *= 4
    else:
        return None
    if certain and not polish:
        return True
    # two roots within the noise (a cluster the doubles cannot tell apart): the value keeps
    # its estimate, which covers them both
    xs = [lo + (hi - lo) * k / 64 for k in range(65)]
    fs = [g(x) for x in xs]
    if sum((p > 0) != (q > 0) or p == 0 for p, q in zip(fs, fs[1:])) > 1:
        return None
    return _bisect(ctx, g, lo, hi, glo)
