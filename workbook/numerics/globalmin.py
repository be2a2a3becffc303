"""The global minimum of EXPR on a bracket by branch and bound on interval enclosures.

Every row starts as one box [lo, hi] and the best value known (from the samples and their
local refinement). Each level, EXPR's lower bound on every box (the larger of its interval
enclosure and the mean-value form f(c) + f'(X)(X - c)) is compared with the best value: a
box that cannot hold a value better by more than the tolerance is dropped, EXPR at the
centre of every other box may improve the best value, and the box is halved. A row ends when
no box is left (the best value is the global minimum within the tolerance: a proof), or
when it has too many boxes or levels: then the gap between the best value and the lowest
bound left is its error, not a guess.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: halvings at most
MAX_LEVELS = 64
#: live boxes of one row at most
MAX_BOXES = 64


@dataclass
class Certified:
    """Per row: the best value and where, how far the global minimum may be below it (the
    tolerance where the search ended with no box left); ``bound``: the lowest lower bound
    left (the value itself where none is left)."""

    value: np.ndarray
    where: np.ndarray
    gap: np.ndarray
    width: np.ndarray  # the width of the box the best point was found in (0: not improved)
    bound: np.ndarray


def global_min(g, h, lo, hi, best, best_x, allowed) -> Certified:
    """Minimise on [lo[i], hi[i]] for every row i.

    ``g(xlo, xhi, rows) -> (F, D)``: enclosures of the function minimised and of its
    derivative; ``h(x, rows)``: its value at points (as the engine computes it); ``best``,
    ``best_x``: the best value known per row and where; ``allowed(best, rows)``: the
    tolerance of those rows' values.
    """
    n = lo.size
    best, best_x = best.astype(float).copy(), best_x.astype(float).copy()
    width = np.zeros(n)
    gap = np.zeros(n)
    row = np.arange(n)
    blo, bhi = lo.astype(float).copy(), hi.astype(float).copy()
    span = np.maximum(np.abs(lo), np.abs(hi))
    tiny = 64 * np.spacing(span)
    for _ in range(MAX_LEVELS):
        if not row.size:
            break
        c = 0.5 * (blo + bhi)
        with np.errstate(all="ignore"):
            f, d = g(blo, bhi, row)
            fc, _ = g(c, c, row)
            hc = np.broadcast_to(np.asarray(h(c, row), dtype=float), c.shape)
        bound = _lower(f.lo, row)
        if d is not None:
            slope = np.maximum(np.abs(_full(d.lo, row)), np.abs(_full(d.hi, row)))
            with np.errstate(all="ignore"):
                mean_value = _lower(fc.lo, row) - slope * 0.5 * (bhi - blo)
            bound = np.fmax(bound, np.where(np.isnan(mean_value), -np.inf, mean_value))
        # better points at the centres
        ok = np.isfinite(hc)
        order = np.lexsort((hc[ok], row[ok]))
        r_ok, h_ok, c_ok, w_ok = row[ok][order], hc[ok][order], c[ok][order], (bhi - blo)[ok][order]
        first = np.r_[True, r_ok[1:] != r_ok[:-1]] if r_ok.size else np.zeros(0, dtype=bool)
        r1, h1 = r_ok[first], h_ok[first]
        better = h1 < best[r1]
        best[r1[better]] = h1[better]
        best_x[r1[better]] = c_ok[first][better]
        width[r1[better]] = w_ok[first][better]
        keep = ~(bound >= best[row] - allowed(best[row], row))  # NaN bound: kept
        crowded = np.bincount(row[keep], minlength=n)[row] > MAX_BOXES
        narrow = (bhi - blo) <= tiny[row]
        stop = keep & (crowded | narrow)
        if stop.any():
            np.maximum.at(gap, row[stop], best[row[stop]] - bound[stop])
        go = keep & ~stop
        row, blo, bhi = row[go], blo[go], bhi[go]
        mid = 0.5 * (blo + bhi)
        row = np.concatenate([row, row])
        blo, bhi = np.concatenate([blo, mid]), np.concatenate([mid, bhi])
    if row.size:  # out of levels
        with np.errstate(all="ignore"):
            f, _ = g(blo, bhi, row)
        np.maximum.at(gap, row, best[row] - _lower(f.lo, row))
    gap = np.where(np.isnan(gap), np.inf, gap)
    bound = best - gap
    # a dropped box could still beat the best value by up to the tolerance
    gap = np.maximum(gap, allowed(best, np.arange(n)))
    return Certified(best, best_x, gap, width, bound)


def _full(v, row) -> np.ndarray:
    return np.broadcast_to(np.asarray(v, dtype=float), row.shape)


def _lower(v, row) -> np.ndarray:
    out = _full(v, row)
    return np.where(np.isnan(out), -np.inf, out)
