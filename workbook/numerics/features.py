"""Narrow and steep features of an integrand, located by interval enclosures.

The bracket of every row is cut into boxes; a box where EXPR's enclosure spans more than
``SPREAD`` times the largest |EXPR| seen so far (at the boxes' centres) is halved, so that
the boxes end narrow where EXPR changes fast (a narrow peak, a steep step, a Lorentzian)
and wide where it is flat. The ends of the boxes are break points for the adaptive rule,
which then integrates smooth pieces instead of sampling past a feature between its nodes
(``exp(-((x - 3.7)/0.01)^2)`` on [0, 10] was 2.4e-118 for 0.0177). A box at an end of the
bracket is not halved below a sixteenth of it where EXPR is monotone in it (a steep end is
tanh-sinh's), nor a box where EXPR is unbounded (a singularity is tanh-sinh's, at a break
point the tree gives).
"""

from __future__ import annotations

import numpy as np

#: a box whose enclosure spans more than this share of the largest |EXPR| is halved
SPREAD = 0.25
#: ... or more than this share of the row's largest spread, before |EXPR| is known
RELATIVE = 1e-3
#: halvings at most
MAX_LEVELS = 40
#: boxes of one row at most
MAX_BOXES = 256


def breaks(g, h, lo: np.ndarray, hi: np.ndarray) -> list[np.ndarray]:
    """Break points per row (a list of arrays of the rows' length; a row with fewer repeats
    its lower bound), or [] when no row has a feature narrower than a sixteenth of its
    bracket away from its ends.

    ``g(xlo, xhi, rows) -> (F, D)``: EXPR's enclosures (D unused); ``h(x, rows)``: EXPR at
    points.
    """
    n = lo.size
    width0 = hi - lo
    with np.errstate(all="ignore"):
        ends = np.vstack([lo, 0.5 * (lo + hi), hi])
        rows3 = np.tile(np.arange(n), 3)
        v = np.abs(np.asarray(h(ends.ravel(), rows3), dtype=float))
    v = np.where(np.isfinite(v), v, 0.0)
    scale = np.zeros(n)
    np.maximum.at(scale, rows3, v)
    row = np.arange(n)
    blo, bhi = lo.astype(float).copy(), hi.astype(float).copy()
    done_row, done_lo, done_hi = [], [], []
    for _ in range(MAX_LEVELS):
        if not row.size:
            break
        c = 0.5 * (blo + bhi)
        with np.errstate(all="ignore"):
            f, d = g(blo, bhi, row)
            hc = np.abs(np.asarray(h(c, row), dtype=float))
        np.maximum.at(scale, row, np.where(np.isfinite(hc), hc, 0.0))
        spread = np.broadcast_to(np.asarray(f.hi - f.lo, dtype=float), row.shape)
        unbounded = ~np.isfinite(spread)
        w = bhi - blo
        at_end = (blo <= lo[row]) | (bhi >= hi[row])
        floor = np.where(at_end, width0[row] / 16, 1e-9 * width0[row])
        # until a centre meets the feature, the largest spread of the row's boxes is the scale
        widest = np.zeros(n)
        np.maximum.at(widest, row, np.where(unbounded, 0.0, spread))
        level = np.maximum(scale, RELATIVE * widest)[row]
        halve = ~unbounded & (spread > SPREAD * level) & (w > 2 * floor)
        # an end box at its floor is still halved where EXPR may turn inside it (its
        # derivative's enclosure holds 0, or is unknown): a peak there, not a steep end that
        # tanh-sinh takes (a peak at 0.035 of the bracket was integrated to 0 inside one end box)
        stuck = ~unbounded & (spread > SPREAD * level) & at_end & ~halve & (w > 1e-9 * width0[row])
        if stuck.any():
            if d is None:
                turns = np.ones(row.shape, dtype=bool)
            else:
                dlo = np.broadcast_to(np.asarray(d.lo, dtype=float), row.shape)
                dhi = np.broadcast_to(np.asarray(d.hi, dtype=float), row.shape)
                turns = ~(dlo > 0) & ~(dhi < 0)  # NaN bounds: may turn
            halve |= stuck & turns
        crowded = np.bincount(row[halve], minlength=n)[row] > MAX_BOXES // 2
        halve &= ~crowded
        done_row.append(row[~halve])
        done_lo.append(blo[~halve])
        done_hi.append(bhi[~halve])
        row, blo, bhi, c = row[halve], blo[halve], bhi[halve], c[halve]
        row = np.concatenate([row, row])
        blo, bhi = np.concatenate([blo, c]), np.concatenate([c, bhi])
    done_row.append(row)
    done_lo.append(blo)
    done_hi.append(bhi)
    row, blo, bhi = (np.concatenate(x) for x in (done_row, done_lo, done_hi))
    inner = (blo > lo[row]) & (bhi < hi[row]) & (bhi - blo < width0[row] / 16)
    if not inner.any():
        return []
    order = np.lexsort((blo, row))
    row, blo = row[order], blo[order]
    start = blo > lo[row]  # the boxes' lower ends inside the bracket are the break points
    row, points = row[start], blo[start]
    counts = np.bincount(row, minlength=n)
    out = np.repeat(lo[:, None], counts.max(), axis=1)
    slot = np.arange(row.size) - np.searchsorted(row, row)
    out[row, slot] = points
    return list(out.T)


def kink_points(g, h, lo: np.ndarray, hi: np.ndarray, min_width: np.ndarray) -> list[np.ndarray]:
    """Per row, the zeros in [lo, hi] of a sub-tree whose zeros are kinks of EXPR (the
    argument of abs, the difference of min's arguments; see numerics.kinks.switching),
    isolated by interval arithmetic and refined by ``find_root``; a cluster the intervals
    cannot resolve gives its middle. Arrays of the rows' length (a row with fewer repeats
    its lower bound), [] when no row has one."""
    from scipy.optimize.elementwise import find_root

    from .isolate import isolate

    iso = isolate(g, lo, hi, min_width)
    rows_, points = [iso.row], [0.5 * (iso.lo + iso.hi)]
    if iso.row.size:
        with np.errstate(all="ignore"):
            res = find_root(lambda x, r: h(x, r), (iso.lo, iso.hi), args=(iso.row.astype(float),))
        ok = np.asarray(res.success)
        points[0] = np.where(ok, res.x, points[0])
    for r, clusters in iso.unresolved.items():
        for c in clusters:
            if np.isfinite(c.lo) and np.isfinite(c.hi):
                rows_.append(np.array([r]))
                points.append(np.array([0.5 * (c.lo + c.hi)]))
    row, x = np.concatenate(rows_).astype(np.intp), np.concatenate(points)
    inside = (x > lo[row]) & (x < hi[row])
    row, x = row[inside], x[inside]
    if not row.size:
        return []
    order = np.lexsort((x, row))
    row, x = row[order], x[order]
    counts = np.bincount(row, minlength=lo.size)
    out = np.repeat(lo[:, None], counts.max(), axis=1)
    slot = np.arange(row.size) - np.searchsorted(row, row)
    out[row, slot] = x
    return list(out.T)
