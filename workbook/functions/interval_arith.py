"""Interval arithmetic: intervals [lo, hi] of numpy arrays, each operation rounded outward
(a few units in the last place, more than numpy's functions are off), so that an enclosure is
a proof. The one-argument built-ins' registry entries name their enclosures here
(``interval=``); :mod:`workbook.numerics.intervals` compiles a typed tree with them.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

_INF = np.inf
_EPS = float(np.finfo(float).eps)
_TINY = float(np.finfo(float).tiny)
#: units in the last place each result is widened by (numpy's elementary functions are
#: within 1-2 ulp; the rest of the margin covers the constants the rules use)
_ULPS = 4.0


class Iv:
    """Intervals [lo, hi] (numpy arrays of one shape); lo may be -inf, hi +inf."""

    __slots__ = ("lo", "hi")

    def __init__(self, lo, hi):
        self.lo, self.hi = lo, hi

    @staticmethod
    def point(v) -> Iv:
        v = np.asarray(v, dtype=float)
        return Iv(v, v)

    def contains_zero(self) -> np.ndarray:
        """Where 0 may be in the interval (also where it is NaN: unknown)."""
        return ~(self.lo > 0) & ~(self.hi < 0)


def _out(lo, hi, ulps: float = _ULPS) -> Iv:
    """[lo, hi] widened outward by ``ulps`` units of rounding (relative, and absolute below
    the normal range). A NaN (inf - inf, 0 * inf) stays NaN: an unknown enclosure, which the
    users of enclosures read as unbounded."""
    k = ulps * _EPS
    lo = np.asarray(lo, dtype=float)
    hi = np.asarray(hi, dtype=float)
    return Iv(lo - (np.abs(lo) * k + _TINY), hi + (np.abs(hi) * k + _TINY))


def add(a: Iv, b: Iv) -> Iv:
    return _out(a.lo + b.lo, a.hi + b.hi, 1)


def sub(a: Iv, b: Iv) -> Iv:
    return _out(a.lo - b.hi, a.hi - b.lo, 1)


def neg(a: Iv) -> Iv:
    if a.lo is a.hi:
        v = -a.lo
        return Iv(v, v)
    return Iv(-a.hi, -a.lo)


def scale(a: Iv, k: float) -> Iv:
    lo, hi = a.lo * k, a.hi * k
    return _out(np.minimum(lo, hi), np.maximum(lo, hi), 1)


def mul(a: Iv, b: Iv) -> Iv:
    if b.lo is b.hi:  # a number times an interval (a constant factor, a row's value)
        a, b = b, a
    if a.lo is a.hi:
        p, q = a.lo * b.lo, a.lo * b.hi
        return _out(np.minimum(p, q), np.maximum(p, q), 1)
    p = [a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi]
    return _out(np.minimum.reduce(p), np.maximum.reduce(p), 1)


def div(a: Iv, b: Iv) -> Iv:
    whole = b.contains_zero()
    inv = Iv(1.0 / np.where(whole, 1.0, b.hi), 1.0 / np.where(whole, 1.0, b.lo))
    q = mul(a, _out(inv.lo, inv.hi, 1))
    return Iv(np.where(whole, -_INF, q.lo), np.where(whole, _INF, q.hi))


def power(a: Iv, n: float) -> Iv:
    """a^n for a constant n (a whole n any sign of a; else a >= 0 is needed)."""
    if n == 0:
        return Iv.point(np.ones_like(a.lo))
    if n == int(n):
        k = int(n)
        if k < 0:
            return div(Iv.point(np.ones_like(a.lo)), power(a, -k))
        lo, hi = a.lo**k, a.hi**k
        if k % 2:
            return _out(lo, hi, 2 * k)
        zero = a.contains_zero()
        return _out(np.where(zero, 0.0, np.minimum(lo, hi)), np.maximum(lo, hi), 2 * k)
    neg_part = a.lo < 0
    lo, hi = np.maximum(a.lo, 0.0) ** n, np.maximum(a.hi, 0.0) ** n
    if n < 0:
        lo, hi = hi, lo
    r = _out(lo, hi, 8)
    return Iv(np.where(neg_part, -_INF, r.lo), np.where(neg_part, _INF, r.hi))


def _monotone(f: Callable, a: Iv, increasing: bool = True, ulps: float = _ULPS) -> Iv:
    lo, hi = f(a.lo), f(a.hi)
    return _out(lo, hi, ulps) if increasing else _out(hi, lo, ulps)


def _periodic(a: Iv, f: Callable, peak: float) -> Iv:
    """sin or cos: f at the ends, 1 where a point peak + 2 pi k is inside, -1 where a trough."""
    ends_lo = np.minimum(f(a.lo), f(a.hi))
    ends_hi = np.maximum(f(a.lo), f(a.hi))
    two_pi = 2 * math.pi
    top = np.ceil((a.lo - peak) / two_pi) * two_pi + peak
    bottom = np.ceil((a.lo - peak - math.pi) / two_pi) * two_pi + peak + math.pi
    # the test is made generous by a relative margin (pi is not exact)
    margin = 1e-12 * (1 + np.abs(a.lo) + np.abs(a.hi))
    wide = ~np.isfinite(a.lo) | ~np.isfinite(a.hi) | (a.hi - a.lo >= two_pi)
    has_top = wide | (top <= a.hi + margin)
    has_bottom = wide | (bottom <= a.hi + margin)
    r = _out(ends_lo, ends_hi)
    return Iv(
        np.where(has_bottom, -1.0, np.maximum(r.lo, -1.0)),
        np.where(has_top, 1.0, np.minimum(r.hi, 1.0)),
    )


def sin(a: Iv) -> Iv:
    return _periodic(a, np.sin, math.pi / 2)


def cos(a: Iv) -> Iv:
    return _periodic(a, np.cos, 0.0)


def tan(a: Iv) -> Iv:
    """tan, unbounded where a pole pi/2 + k pi may be inside."""
    k = np.floor((a.lo - math.pi / 2) / math.pi)
    pole = (k + 1) * math.pi + math.pi / 2
    margin = 1e-12 * (1 + np.abs(a.lo) + np.abs(a.hi))
    bad = ~np.isfinite(a.lo) | ~np.isfinite(a.hi) | (pole <= a.hi + margin)
    r = _monotone(np.tan, a)
    return Iv(np.where(bad, -_INF, r.lo), np.where(bad, _INF, r.hi))


def exp(a: Iv) -> Iv:
    r = _monotone(np.exp, a)
    return Iv(np.maximum(r.lo, 0.0), r.hi)


def _domain(a: Iv, low: float, f: Callable, strict: bool = False) -> Iv:
    """f increasing on (low, inf): unbounded where a reaches below its domain."""
    bad = (a.lo <= low) if strict else (a.lo < low)
    r = _monotone(f, Iv(np.where(bad, low + 1.0, a.lo), a.hi))
    return Iv(np.where(bad, -_INF, r.lo), np.where(bad, _INF, r.hi))


def sqrt(a: Iv) -> Iv:
    r = _domain(a, 0.0, np.sqrt)
    return Iv(np.where(np.isfinite(r.lo), np.maximum(r.lo, 0.0), r.lo), r.hi)


def absolute(a: Iv) -> Iv:
    zero = a.contains_zero()
    lo = np.where(zero, 0.0, np.minimum(np.abs(a.lo), np.abs(a.hi)))
    return Iv(lo, np.maximum(np.abs(a.lo), np.abs(a.hi)))


def hull(a: Iv, b: Iv) -> Iv:
    return Iv(np.minimum(a.lo, b.lo), np.maximum(a.hi, b.hi))


def _bounded(a: Iv, lo: float, hi: float) -> Iv:
    return Iv(np.clip(a.lo, lo, hi), np.clip(a.hi, lo, hi))


def _one(a: Iv) -> Iv:
    return Iv.point(np.ones_like(a.lo))


# -- the enclosures of the one-argument built-ins and of their derivatives, which their
# registry entries name (``interval=(value, derivative)``) -------------------------------------
def minus_sin(a: Iv) -> Iv:
    return neg(sin(a))


def tan_slope(a: Iv) -> Iv:
    return add(_one(a), power(tan(a), 2))


def ln(a: Iv) -> Iv:
    return _domain(a, 0.0, np.log, True)


def reciprocal(a: Iv) -> Iv:
    return div(_one(a), a)


def log10(a: Iv) -> Iv:
    return _domain(a, 0.0, np.log10, True)


def log10_slope(a: Iv) -> Iv:
    return scale(reciprocal(a), 1 / math.log(10))


def sqrt_slope(a: Iv) -> Iv:
    return div(Iv.point(np.full_like(a.lo, 0.5)), sqrt(a))


def tanh(a: Iv) -> Iv:
    return _bounded(_monotone(np.tanh, a), -1.0, 1.0)


def tanh_slope(a: Iv) -> Iv:
    return sub(_one(a), power(tanh(a), 2))


def atan_slope(a: Iv) -> Iv:
    return div(_one(a), add(_one(a), power(a, 2)))


def sinh(a: Iv) -> Iv:
    return _monotone(np.sinh, a)


def atan(a: Iv) -> Iv:
    return _bounded(_monotone(np.arctan, a), -math.pi / 2 - 1e-15, math.pi / 2 + 1e-15)


def cosh(a: Iv) -> Iv:
    m = absolute(a)
    return _monotone(np.cosh, m)


def sign(a: Iv) -> Iv:
    lo = np.where(a.lo > 0, 1.0, -1.0)
    hi = np.where(a.hi < 0, -1.0, 1.0)
    return Iv(lo, hi)
