"""Roots, one per row: in a bracket where the function changes sign, or near a guess."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

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


def _tolerances(tol: Tolerance) -> dict:
    return {"xatol": tol.atol, "xrtol": max(tol.rtol, 4 * np.finfo(float).eps)}


def root_in(
    f: Fn,
    a,
    b,
    args=(),
    tol: Tolerance = DEFAULT,
    *,
    var: str = "x",
    unit: str = "",
    label: Callable[[int], str] | None = None,
    enclose: Callable | None = None,
) -> Result:
    """The root of ``f(x, *args) = 0`` in [a, b] for every row (Mathcad's ``root(f, x, a, b)``).

    [a, b] is sampled at ``tol.samples`` intervals and the interval with the sign change is
    refined by ``find_root``; the error estimate is the width of the final bracket.

    With ``enclose(lo, hi, *args) -> (F, D)`` (interval enclosures of f and its derivative,
    :mod:`workbook.numerics.intervals`), the roots in [a, b] are counted by
    :func:`workbook.numerics.isolate.isolate`: none (a sign change across a pole), more than
    one (also two roots closer than the samples, or a tangent touching), or a multiple root
    (the estimate is then the width of the region where f cannot be told from 0) are found
    with a proof, not missed between samples. Without it, the samples decide, and a sign
    change whose final bracket holds values far from 0 (a pole or a jump) is refused.
    """
    from scipy.optimize.elementwise import find_root

    shape, (a, b, *args) = rows(a, b, *args)
    n, k = a.size, max(int(tol.samples), 1)
    if n == 0:
        return Result(np.empty(shape), np.empty(shape))
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    xs = lo[:, None] + (hi - lo)[:, None] * np.linspace(0.0, 1.0, k + 1)
    with np.errstate(all="ignore"):  # an infinite sample (overflow, a pole) keeps its sign
        fs = call(f, xs, [g[:, None] for g in args])
    if np.isnan(fs).any():
        i, j = np.argwhere(np.isnan(fs))[0]
        raise NumericsError(
            f"root(): the function is not a number at {var} = {num(xs[i, j])}{_u(unit)}"
            f"{row_text(label, i, n)}, inside the bracket [{num(lo[i])}, {num(hi[i])}]{_u(unit)}"
        )
    # signs as booleans (a byte each, not a float): the sampling is a fair share of the time
    positive = fs > 0
    zero = fs == 0
    change = positive[:, :-1] != positive[:, 1:]
    if zero.any():  # a sampled exact zero counts once, even where it touches two intervals
        change &= ~(zero[:, :-1] | zero[:, 1:])
        count = change.sum(axis=1) + zero.sum(axis=1)
    else:
        count = change.sum(axis=1)
    if not np.isfinite(fs).all():  # a sign change at an infinite sample may be a pole
        evaluations_poles = _drop_poles(f, xs, fs, args, change, count)
    else:
        evaluations_poles = 0
    proven = None
    if enclose is not None and n <= CERTIFY_ROWS:
        proven = _counted(f, enclose, args, lo, hi, xs, fs, tol, var, unit, label)
        count = np.where(proven.one, 1, count)
    _one_root_each(count, change, zero, xs, fs, lo, hi, var, unit, label)
    value = np.empty(n)
    error = np.zeros(n)
    evaluations = k + 1 + evaluations_poles
    sampled = change.any(axis=1) | zero.any(axis=1)
    if proven is not None:  # a root the samples do not bracket, or a multiple one
        done = ~np.isnan(proven.value)
        value[done], error[done] = proven.value[done], proven.error[done]
        sampled &= ~done
    if zero.any():
        at_zero = zero.any(axis=1) & sampled
        value[at_zero] = xs[at_zero][zero[at_zero]]
        todo = np.flatnonzero(sampled & ~at_zero)
        todo_args = tuple(g[todo] for g in args)
    elif sampled.all():  # every row is refined (no copy of the arguments)
        todo, todo_args = np.arange(n), tuple(args)
    else:
        todo = np.flatnonzero(sampled)
        todo_args = tuple(g[todo] for g in args)
    if todo.size:
        j = np.argmax(change[todo], axis=1)
        xl, xr, fl, fr = xs[todo, j], xs[todo, j + 1], fs[todo, j], fs[todo, j + 1]
        unproven = np.ones(todo.size, dtype=bool) if proven is None else ~proven.one[todo]
        if not (np.isfinite(fl).all() and np.isfinite(fr).all()):
            xl, xr, fl, fr, ev = finite_ends(f, xl, xr, fl, fr, todo_args)
            evaluations += ev
            _not_infinite(xl, xr, fl, fr, todo, lo, hi, var, unit, label, n)
        res = find_root(f, (xl, xr), args=todo_args, tolerances=_tolerances(tol))
        _check_status(res, todo, lo, hi, label, n, unit)
        value[todo] = res.x
        error[todo] = _error(res, tol)
        evaluations += int(np.max(res.nfev))
        _not_a_pole(res, todo, fl, fr, xr - xl, lo, hi, var, unit, label, n, unproven)
    return Result(value.reshape(shape), error.reshape(shape), evaluations=evaluations)


def _one_root_each(count, change, zero, xs, fs, lo, hi, var, unit, label) -> None:
    """Refuse the first row whose bracket holds no root or more than one (its samples shown)."""
    n = lo.size
    none = np.flatnonzero(count == 0)
    if none.size:
        i = none[0]
        raise NumericsError(
            f"root(): no sign change of the function in [{num(lo[i])}, {num(hi[i])}]{_u(unit)}"
            f"{row_text(label, i, n)}: sampled at {var} = "
            + ", ".join(num(x) for x in xs[i])
            + f" with signs {''.join('+' if v > 0 else '-' for v in fs[i])}"
            + (f" ({none.size} of {n} rows)" if n > 1 else "")
            + "; choose bounds on either side of the root"
        )
    many = np.flatnonzero(count > 1)
    if many.size:
        i = many[0]
        where = [f"[{num(xs[i, j])}, {num(xs[i, j + 1])}]" for j in np.flatnonzero(change[i])] + [
            f"{var} = {num(xs[i, j])}" for j in np.flatnonzero(zero[i])
        ]
        raise NumericsError(
            f"root(): more than one root in [{num(lo[i])}, {num(hi[i])}]{_u(unit)}"
            f"{row_text(label, i, n)}: the function changes sign in {', '.join(where)}; "
            "narrow the bracket to one of them"
        )


def finite_ends(f, xl, xr, fl, fr, args) -> tuple:
    """Brackets [xl, xr] with a sign change whose end values may be infinite (overflow, a
    sample on a pole: an infinite value keeps its sign) bisected, on the sign, until both
    ends are finite; an end still infinite when the bracket is two adjacent doubles is a pole
    (:func:`_not_infinite` refuses it). Returns (xl, xr, fl, fr, evaluations)."""
    xl, xr, fl, fr = (np.array(v, dtype=float) for v in (xl, xr, fl, fr))
    evaluations = 0
    for _ in range(2100):  # bisection of the full range of doubles ends well within this
        todo = np.flatnonzero(~(np.isfinite(fl) & np.isfinite(fr)))
        if not todo.size:
            break
        a, b = xl[todo], xr[todo]
        m = 0.5 * (a + b)
        m = np.where(np.isfinite(m), m, 0.5 * a + 0.5 * b)
        inside = (m > a) & (m < b)
        if not inside.any():
            break
        todo, m = todo[inside], m[inside]
        with np.errstate(all="ignore"):
            fm = np.asarray(call(f, m, [g[todo] for g in args]), dtype=float)
        evaluations += 1
        fm = np.broadcast_to(fm, m.shape)
        nan = np.isnan(fm)
        if nan.any():  # no sign there: the end that is infinite moves in, keeping its value
            fm = np.where(nan, np.where(np.isfinite(fl[todo]), fr[todo], fl[todo]), fm)
        left = (fm > 0) == (fl[todo] > 0)
        xl[todo[left]], fl[todo[left]] = m[left], fm[left]
        xr[todo[~left]], fr[todo[~left]] = m[~left], fm[~left]
    return xl, xr, fl, fr, evaluations


def _drop_poles(f, xs, fs, args, change, count) -> int:
    """Sign changes between samples of which one is infinite, where the function stays
    infinite down to adjacent doubles (a pole), are no roots: cleared from ``change`` and
    ``count`` (in place) of rows with more than one. Returns the evaluations."""
    rows_, cols = np.nonzero(change & ~(np.isfinite(fs[:, :-1]) & np.isfinite(fs[:, 1:])))
    keep = count[rows_] > 1
    rows_, cols = rows_[keep], cols[keep]
    if not rows_.size:
        return 0
    *_, fl, fr, ev = finite_ends(
        f,
        xs[rows_, cols],
        xs[rows_, cols + 1],
        fs[rows_, cols],
        fs[rows_, cols + 1],
        tuple(g[rows_] for g in args),
    )
    pole = ~(np.isfinite(fl) & np.isfinite(fr))
    change[rows_[pole], cols[pole]] = False
    np.subtract.at(count, rows_[pole], 1)
    return ev


def _not_infinite(xl, xr, fl, fr, idx, lo, hi, var, unit, label, n) -> None:
    """Refuse a sign change at which the function stays infinite down to adjacent doubles:
    the sign change is a pole."""
    bad = np.flatnonzero(~(np.isfinite(fl) & np.isfinite(fr)))
    if bad.size:
        i = bad[0]
        row = idx[i]
        raise NumericsError(
            f"root(): the function changes sign at {var} = {num(0.5 * (xl[i] + xr[i]))}"
            f"{_u(unit)} in [{num(lo[row])}, {num(hi[row])}]{_u(unit)}{row_text(label, row, n)},"
            f" where its values are {num(fl[i])} and {num(fr[i])}: a pole, not a root"
        )


#: rows of one call whose roots are counted by interval arithmetic (the count costs about
#: three evaluations of f a row); a larger table is decided by its samples and the final
#: bracket's values (the pole-or-jump test), to stay near SciPy's find_root in time
CERTIFY_ROWS = 2_000
#: a value at the final bracket's ends larger than this times what a root's slope gives
#: there (the samples' secant times the bracket's width) is no root: a pole or a jump
NOT_A_ROOT = 1e3


@dataclass
class _Proven:
    """Per row: whether exactly one root is certain; its value where the samples' sign
    change does not give it (NaN: refine the samples' bracket), and its error."""

    one: np.ndarray
    value: np.ndarray
    error: np.ndarray


def _counted(f, enclose, args, lo, hi, xs, fs, tol, var, unit, label) -> _Proven:
    """Count the roots of every row by interval arithmetic; raise for a row with none (a sign
    change across a pole) or more than one; the one root where the samples miss it, or where
    it is multiple (its error: the half-width of the smallest interval around it at whose
    ends the function's sign is certain)."""
    from scipy.optimize.elementwise import find_root

    from .isolate import isolate

    n = lo.size
    span = np.maximum(np.abs(lo), np.abs(hi))
    min_width = np.maximum(np.maximum(tol.rtol * span, tol.atol), 64 * np.spacing(span))
    at = lambda p, q, r: enclose(p, q, *[g[r] for g in args])  # noqa: E731
    iso = isolate(at, lo, hi, min_width)
    finite = np.isfinite(fs)
    scale = np.max(np.where(finite, np.abs(fs), 0.0), axis=1)
    out = _Proven(np.zeros(n, dtype=bool), np.full(n, np.nan), np.zeros(n))
    boxes: dict[str, list] = {"root": [], "multiple": []}
    per_row = np.bincount(iso.row, minlength=n)
    # the common case, all rows at once: one root box, nothing unresolved, and the samples'
    # one sign change in it (the fast path refines it)
    easy = (per_row == 1) & ~np.isin(np.arange(n), list(iso.unresolved))
    first = np.searchsorted(iso.row, np.arange(n)).clip(0, max(iso.row.size - 1, 0))
    if iso.row.size:
        a, b = iso.lo[first], iso.hi[first]
        inside = (xs[:, :-1] < b[:, None]) & (xs[:, 1:] > a[:, None])
        sign_change = (fs[:, :-1] > 0) != (fs[:, 1:] > 0)
        easy &= ((inside & sign_change).sum(axis=1) == 1) & ~(fs == 0).any(axis=1)
    out.one[easy] = True
    for i in np.flatnonzero(~easy):
        found = [("root", a, b) for a, b in iso.roots(i)]
        poles = []
        for c in iso.unresolved.get(i, []):
            kind = _cluster_kind(f, c, [g[i : i + 1] for g in args], scale[i])
            if kind == "pole":
                poles.append(c)
            elif kind:
                found.append((kind, c.lo, c.hi))
        where = row_text(label, i, n)
        bracket = f"[{num(lo[i])}, {num(hi[i])}]{_u(unit)}{where}"
        if not found and poles:
            places = ", ".join(num(0.5 * (c.lo + c.hi)) for c in poles)
            raise NumericsError(
                f"root(): the function changes sign across a pole at {var} = {places}{_u(unit)}"
                f" in {bracket}: a pole, not a root (interval arithmetic finds no root there)"
            )
        if len(found) > 1:
            places = ", ".join(_place(kind, a, b) for kind, a, b in found)
            raise NumericsError(
                f"root(): more than one root in {bracket}: {places} (counted by interval "
                f"arithmetic); narrow the bracket to one of them"
            )
        if not found:
            continue  # no root: the samples' message says so
        kind, a, b = found[0]
        out.one[i] = True
        if kind == "touch":
            out.value[i], out.error[i] = 0.5 * (a + b), 0.5 * (b - a)
            continue
        boxes[kind].append((i, a, b))
    for kind, found in boxes.items():
        if not found:
            continue
        idx = np.asarray([i for i, _, _ in found])
        a = np.asarray([p for _, p, _ in found])
        b = np.asarray([q for _, _, q in found])
        res = find_root(f, (a, b), args=tuple(g[idx] for g in args), tolerances=_tolerances(tol))
        out.value[idx] = res.x
        out.error[idx] = _error(res, tol)
        if kind == "multiple":
            out.error[idx] = np.maximum(out.error[idx], _certain_bracket(at, res.x, idx, b - a))
    return out


def _certain_bracket(at, x, idx, width) -> np.ndarray:
    """Per row, the smallest d of width/2, width/4, ... at which the function's sign at x - d
    and x + d is certain (interval enclosures of the points) and opposite: the root is within
    d of x. A multiple root's d is far above the bracket's width (f is flat there)."""
    ds = 0.5 * width[:, None] * 2.0 ** -np.arange(60)[None, :]
    m = ds.shape[1]
    rows = np.repeat(idx, m)
    left = (x[:, None] - ds).ravel()
    right = (x[:, None] + ds).ravel()
    sign = []
    for p in (left, right):
        with np.errstate(all="ignore"):
            fv, _ = at(p, p, rows)
        lo_, hi_ = (np.broadcast_to(np.asarray(v, dtype=float), p.shape) for v in (fv.lo, fv.hi))
        sign.append(np.where(lo_ > 0, 1, np.where(hi_ < 0, -1, 0)).reshape(ds.shape))
    certain = (sign[0] * sign[1]) < 0
    # the last certain d before the first uncertain one, from the widest down
    last = np.argmin(certain, axis=1) - 1
    last = np.where(certain.all(axis=1), m - 1, last)
    return np.where(last >= 0, ds[np.arange(len(idx)), np.maximum(last, 0)], 0.5 * width)


def _place(kind: str, a: float, b: float) -> str:
    x = num(0.5 * (a + b))
    if kind == "root":
        return f"a root in [{num(a)}, {num(b)}]"
    if kind == "touch":
        return f"the function touches 0 near {x} (a double root?)"
    return f"a multiple root near {x}"


def _cluster_kind(f, c, args, scale: float) -> str | None:
    """An unresolved cluster: 'multiple' (a sign change with f near 0), 'touch' (f reaches 0
    without a sign change), 'pole' (a sign change with f large), or None (no root)."""
    xs = np.array([c.lo, 0.5 * (c.lo + c.hi), c.hi])
    with np.errstate(all="ignore"):
        v = np.asarray(call(f, xs, args), dtype=float)
    if not np.isfinite(v).all():
        return "pole" if c.unbounded else None
    small = np.abs(v) <= 1e-3 * scale
    if v[0] * v[2] < 0:
        if small[0] or small[2]:
            return "multiple"
        return "pole" if c.unbounded else None
    if v[0] == 0 or v[2] == 0:
        return "multiple"
    if abs(v[1]) <= 1e-12 * scale or v[1] * v[0] <= 0:
        return "touch"
    return None


def _not_a_pole(res, idx, fa, fb, width, lo, hi, var, unit, label, n, which) -> None:
    """Refuse a sign change whose final bracket holds values far from 0 (of the rows
    ``which`` of ``idx``): a root's values there are about the secant's slope times the
    bracket's width."""
    far = _far_from_zero(res, fa, fb, width)
    near = np.minimum(*(np.abs(np.asarray(v)) for v in res.f_bracket))
    bad = np.flatnonzero(far & which)
    if bad.size:
        i = bad[0]
        row = idx[i]
        what = "a pole" if near[i] > np.maximum(np.abs(fa[i]), np.abs(fb[i])) else "a jump"
        raise NumericsError(
            f"root(): the function changes sign at {var} = {num(res.x[i])}{_u(unit)} in "
            f"[{num(lo[row])}, {num(hi[row])}]{_u(unit)}{row_text(label, row, n)}, but its "
            f"values beside it are {num(res.f_bracket[0][i])} and {num(res.f_bracket[1][i])}:"
            f" {what}, not a root"
        )


def _no_sign_change(x0, step, poles, var: str, unit: str, row: str) -> NumericsError:
    """The error of a search from a guess that found no sign change but at poles or jumps."""
    seen = poles[np.isfinite(poles)]
    return NumericsError(
        f"root(): no sign change found searching from the guess {var} = {num(x0)}"
        f"{_u(unit)}{row} on either side (up to "
        f"{num(step * (2.0**_DOUBLINGS - 1))}{_u(unit)} away, or where the "
        "expression has a value"
        + (
            f"; the sign changes at {var} = {', '.join(num(x) for x in seen)} are poles"
            " or jumps, not roots"
            if seen.size
            else ""
        )
        + f"); give a bracket: root(EXPR, {var}, A, B)"
    )


def root_near(
    f: Fn,
    guess,
    args=(),
    tol: Tolerance = DEFAULT,
    *,
    var: str = "x",
    unit: str = "",
    label: Callable[[int], str] | None = None,
) -> Result:
    """A root of ``f(x, *args) = 0`` near ``guess`` for every row (``root(f, x, guess)``).

    The function is sampled on both sides of the guess at distances growing by 2 (from a
    quarter of the secant step, so that a root nearer than the secant says is not stepped
    over); the first interval where it changes sign, the nearest the guess, is refined by
    ``find_root`` (both sides at once: the nearer root). A side where the function leaves its
    domain (an error, or not a finite number) is not searched further. A sign change whose
    final bracket holds values far from 0 (a pole, a jump) is no root: the search goes on
    past it (``tan(x)`` from 1.5 finds 0, not the pole pi/2).
    """
    from scipy.optimize.elementwise import find_root

    shape, (x0, *args) = rows(guess, *args)
    n = x0.size
    if n == 0:
        return Result(np.empty(shape), np.empty(shape))
    h = np.where(x0 != 0, 1e-4 * np.abs(x0), 1e-4)
    try:
        f0 = call(f, x0, args)
        f1 = call(f, x0 + h, args)
    except WorkbookError as err:
        raise NumericsError(
            f"root(): at the guess {var} = {num(x0[0])}{_u(unit)}"
            f"{' (and others)' if n > 1 else ''} the expression has no value ({err.message})"
        ) from None
    with np.errstate(all="ignore"):
        slope = (f1 - f0) / h
        secant = np.where(slope != 0, -f0 / slope, np.inf)
    step = np.where(np.isfinite(secant), np.maximum(0.25 * np.abs(secant), h), 100 * h)
    value, error = np.where(f0 == 0, x0, np.nan), np.zeros(n)
    poles = np.full((2, n, 0), np.nan)  # per side and row: sign changes that are no root
    todo = np.flatnonzero(f0 != 0)
    evaluations = 2
    for _ in range(MAX_POLES + 1):
        if not todo.size:
            break
        targs = [g[todo] for g in args]
        brackets, ev = _brackets_both_sides(
            f, x0[todo], f0[todo], step[todo], targs, poles[:, todo]
        )
        evaluations += ev
        found = np.isfinite(brackets[..., 0]).any(axis=0)
        if not found.all():
            i = todo[np.flatnonzero(~found)[0]]
            raise _no_sign_change(x0[i], step[i], poles[:, i], var, unit, row_text(label, i, n))
        new_poles = np.full((2, n), np.nan)
        for side in (0, 1):  # the sign change on each side, then the nearer root of the two
            at = np.flatnonzero(np.isfinite(brackets[side, :, 0]))
            if not at.size:
                continue
            idx = todo[at]
            lo, hi = brackets[side, at, 0], brackets[side, at, 1]
            f_lo, f_hi = brackets[side, at, 2], brackets[side, at, 3]
            sided = tuple(g[idx] for g in args)
            pole = np.zeros(idx.size, dtype=bool)
            if not (np.isfinite(f_lo).all() and np.isfinite(f_hi).all()):
                lo, hi, f_lo, f_hi, ev = finite_ends(f, lo, hi, f_lo, f_hi, sided)
                evaluations += ev
                pole = ~(np.isfinite(f_lo) & np.isfinite(f_hi))
                new_poles[side, idx[pole]] = 0.5 * (lo[pole] + hi[pole])
                idx, lo, hi, f_lo, f_hi = (v[~pole] for v in (idx, lo, hi, f_lo, f_hi))
                sided = tuple(g[idx] for g in args)
                if not idx.size:
                    continue
            res = find_root(f, (lo, hi), args=sided, tolerances=_tolerances(tol))
            _check_status(res, idx, brackets[side, :, 0], brackets[side, :, 1], label, n, unit)
            evaluations += int(np.max(res.nfev))
            root = ~_far_from_zero(res, f_lo, f_hi, hi - lo)
            new_poles[side, idx[~root]] = res.x[~root]
            idx, x, e = idx[root], res.x[root], _error(res, tol)[root]
            distance = np.abs(value[idx] - x0[idx])
            take = ~(np.abs(x - x0[idx]) >= distance)  # nearer, or the first found (NaN)
            value[idx[take]] = x[take]
            error[idx[take]] = e[take]
        poles = np.concatenate([poles, new_poles[..., None]], axis=2)
        todo = todo[np.isnan(value[todo])]
    if todo.size:
        i = todo[0]
        seen = poles[:, i][np.isfinite(poles[:, i])]
        raise NumericsError(
            f"root(): searching from the guess {var} = {num(x0[i])}{_u(unit)}"
            f"{row_text(label, i, n)} finds only poles or jumps, not roots, at {var} = "
            f"{', '.join(num(x) for x in seen)}; give a bracket: root(EXPR, {var}, A, B)"
        )
    return Result(value.reshape(shape), error.reshape(shape), evaluations=evaluations)


#: how many times the distance from the guess doubles (from the first step) in root_near
_DOUBLINGS = 60
#: sign changes that are no root (poles, jumps) root_near searches past, at most
MAX_POLES = 4


def _far_from_zero(res, f_lo, f_hi, width) -> np.ndarray:
    """Where the final bracket of ``find_root`` holds values far from 0 for a root: a root's
    values there are about the secant's slope (over the search's bracket of ``width``, with
    values ``f_lo``, ``f_hi``) times the final bracket's width; a pole's or jump's are not."""
    near = np.minimum(*(np.abs(np.asarray(v)) for v in res.f_bracket))
    slope = (np.abs(f_lo) + np.abs(f_hi)) / width
    final = np.abs(res.bracket[1] - res.bracket[0])
    return (near > NOT_A_ROOT * slope * final) & (np.asarray(res.f_x) != 0)


def _brackets_both_sides(f, x0, f0, step, args, poles) -> tuple[np.ndarray, int]:
    """[side, row, (lo, hi, f(lo), f(hi))]: the interval nearest ``x0`` where ``f`` changes
    sign, on the right (side 0) and on the left (side 1), NaN where none was found; both
    sides are searched to the same distance, which stops at the first distance with a sign
    change. A sign change across one of ``poles`` [side, row, k] (NaN: none) is passed."""
    n = x0.size
    out = np.full((2, n, 4), np.nan)
    prev_x = np.stack([x0, x0])
    prev_f = np.stack([f0, f0])
    alive = np.stack([f0 != 0, f0 != 0]) & np.isfinite(np.stack([f0, f0]))
    evaluations = 2
    for k in range(1, _DOUBLINGS + 1):
        active = alive.any(axis=0) & ~np.isfinite(out[..., 0]).any(axis=0)
        if not active.any():
            break
        for side, sign in ((0, 1.0), (1, -1.0)):
            idx = np.flatnonzero(active & alive[side])
            if not idx.size:
                continue
            x = x0[idx] + sign * step[idx] * (2.0**k - 1)
            fx = _values(f, x, [a[idx] for a in args])
            evaluations += 1
            ok = ~np.isnan(fx)  # an infinite value (overflow, a pole) keeps its sign
            alive[side, idx[~ok]] = False
            a, b = np.minimum(prev_x[side, idx], x), np.maximum(prev_x[side, idx], x)
            p = poles[side, idx]
            across = ((p >= a[:, None]) & (p <= b[:, None])).any(axis=1)
            change = ok & (np.sign(fx) * np.sign(prev_f[side, idx]) <= 0) & ~across
            rows_ = idx[change]
            fa, fb = prev_f[side, idx], fx
            left = prev_x[side, idx] <= x
            out[side, rows_, 0], out[side, rows_, 1] = a[change], b[change]
            out[side, rows_, 2] = np.where(left, fa, fb)[change]
            out[side, rows_, 3] = np.where(left, fb, fa)[change]
            prev_x[side, idx], prev_f[side, idx] = x, fx
    return out, evaluations


def _values(f, x, args) -> np.ndarray:
    """f at every row, NaN where the expression has no value (the row is evaluated alone)."""
    try:
        with np.errstate(all="ignore"):
            return np.asarray(call(f, x, args), dtype=float)
    except WorkbookError:
        out = np.full(x.size, np.nan)
        for i in range(x.size):
            try:
                with np.errstate(all="ignore"):
                    out[i] = float(
                        np.asarray(call(f, x[i : i + 1], [a[i : i + 1] for a in args]))[0]
                    )
            except WorkbookError:
                pass
        return out


def _error(res, tol: Tolerance) -> np.ndarray:
    """The final bracket's width; where the function is exactly 0 (the search stops there,
    with a bracket that may still be wide), the tolerance asked for: the computed function's
    own rounding moves its zero by a few units in the last place."""
    width = np.abs(res.bracket[1] - res.bracket[0])
    x = np.abs(res.x)
    asked = np.maximum(tol.rtol * x + tol.atol, 4 * np.spacing(x))
    return np.where(np.asarray(res.f_x) == 0, np.minimum(asked, width), width)


def _check_status(res, idx, lo, hi, label, n, unit) -> None:
    bad = np.flatnonzero(~np.asarray(res.success))
    if bad.size:
        i = bad[0]
        row = idx[i]
        why = {-2: "did not converge", -3: "met a value that is not a finite number"}.get(
            int(res.status[i]), f"failed (status {int(res.status[i])})"
        )
        raise NumericsError(
            f"root(): the root search in [{num(lo[row])}, {num(hi[row])}]{_u(unit)}"
            f"{row_text(label, row, n)} {why}; last bracket [{num(res.bracket[0][i])}, "
            f"{num(res.bracket[1][i])}] with f = {num(res.f_bracket[0][i])}, "
            f"{num(res.f_bracket[1][i])}"
        )
