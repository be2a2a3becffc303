"""Roots of EXPR in a bracket counted by interval arithmetic (a proof where the tree allows).

The bracket is cut into boxes, all rows at once. A box where EXPR's enclosure excludes 0 has
no root; a box where the enclosure of the derivative excludes 0 has EXPR strictly monotone,
so it holds exactly one root if EXPR changes sign between its ends (certain signs: the ends'
own enclosures) and none otherwise. Every other box is halved, down to a width near the
tolerance or until a row has too many boxes; what is left is *unresolved*: a multiple root,
a tangent touching, a pole (the enclosure is unbounded there) or rounding noise, merged into
clusters of adjacent boxes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

#: halvings at most
MAX_LEVELS = 80
#: live boxes of one row at most (more: that row's remaining boxes are unresolved)
MAX_BOXES = 48


@dataclass
class Cluster:
    """Adjacent unresolved boxes: [lo, hi], and whether EXPR may be unbounded there."""

    lo: float
    hi: float
    unbounded: bool


@dataclass
class Isolation:
    """Boxes each holding exactly one simple root (``row``, ``lo``, ``hi``: arrays sorted by
    row, then place), and the unresolved clusters of the rows that have any."""

    row: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    unresolved: dict[int, list[Cluster]] = field(default_factory=dict)

    def roots(self, i: int) -> list[tuple[float, float]]:
        """The root boxes of row i."""
        at = slice(*np.searchsorted(self.row, [i, i + 1]))
        return list(zip(self.lo[at].tolist(), self.hi[at].tolist()))


def isolate(g, lo: np.ndarray, hi: np.ndarray, min_width: np.ndarray) -> Isolation:
    """Isolate the roots of EXPR on [lo[i], hi[i]] for every row i.

    ``g(xlo, xhi, rows) -> (F, D)``: enclosures of EXPR and of its derivative for the
    variable in [xlo, xhi] at the given rows (:func:`workbook.numerics.intervals.enclosure`).
    """
    n = lo.size
    found: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    pending: dict[int, list[tuple[float, float, bool]]] = {}
    row = np.arange(n)
    blo, bhi = lo.astype(float).copy(), hi.astype(float).copy()
    for _ in range(MAX_LEVELS):
        if not row.size:
            break
        with np.errstate(all="ignore"):
            f, d = g(blo, bhi, row)
        f_lo, f_hi = _full(f.lo, row), _full(f.hi, row)
        maybe = ~(f_lo > 0) & ~(f_hi < 0)  # NaN: unknown, so maybe
        if d is None:  # EXPR does not depend on the variable
            monotone = np.zeros(row.size, dtype=bool)
        else:
            monotone = (_full(d.lo, row) > 0) | (_full(d.hi, row) < 0)
        # a bounded enclosure is what makes EXPR continuous there (tan's derivative
        # excludes 0 on a box across its pole too)
        one = maybe & monotone & np.isfinite(f_lo) & np.isfinite(f_hi)
        if one.any():
            both = _sign(g, np.concatenate([blo[one], bhi[one]]), np.tile(row[one], 2))
            s_lo, s_hi = np.split(both, 2)
            known = (s_lo != 0) & (s_hi != 0)
            change = known & (s_lo != s_hi)
            found.append((row[one][change], blo[one][change], bhi[one][change]))
            # a monotone box whose end signs are not certain: keep halving it
            maybe = maybe & ~(one & _scatter(one, known))
        unbounded = ~np.isfinite(f_lo) | ~np.isfinite(f_hi)
        narrow = (bhi - blo) <= min_width[row]
        crowded = np.bincount(row[maybe], minlength=n)[row] > MAX_BOXES
        stop = maybe & (narrow | crowded)
        for r, a, b, u in zip(row[stop], blo[stop], bhi[stop], unbounded[stop]):
            pending.setdefault(int(r), []).append((float(a), float(b), bool(u)))
        go = maybe & ~stop
        row, blo, bhi = row[go], blo[go], bhi[go]
        mid = 0.5 * (blo + bhi)
        row = np.concatenate([row, row])
        blo, bhi = np.concatenate([blo, mid]), np.concatenate([mid, bhi])
    for r, a, b in zip(row, blo, bhi):  # out of levels
        pending.setdefault(int(r), []).append((float(a), float(b), False))
    rows_, los, his = (
        np.concatenate([x[k] for x in found]) if found else np.empty(0) for k in range(3)
    )
    order = np.lexsort((los, rows_))
    return Isolation(
        rows_[order].astype(np.intp),
        los[order],
        his[order],
        {r: _clusters(boxes) for r, boxes in pending.items()},
    )


def _full(v, row) -> np.ndarray:
    return np.broadcast_to(np.asarray(v, dtype=float), row.shape)


def _scatter(mask: np.ndarray, values: np.ndarray) -> np.ndarray:
    out = np.zeros(mask.shape, dtype=bool)
    out[mask] = values
    return out


def _sign(g, x: np.ndarray, row: np.ndarray) -> np.ndarray:
    """The certain sign of EXPR at the points x (0 where its enclosure holds 0)."""
    with np.errstate(all="ignore"):
        f, _ = g(x, x, row)
    lo, hi = _full(f.lo, row), _full(f.hi, row)
    return np.where(lo > 0, 1, np.where(hi < 0, -1, 0))


def _clusters(boxes: list[tuple[float, float, bool]]) -> list[Cluster]:
    out: list[Cluster] = []
    for a, b, u in sorted(boxes):
        if out and a <= out[-1].hi:
            out[-1].hi = max(out[-1].hi, b)
            out[-1].unbounded |= u
        else:
            out.append(Cluster(a, b, u))
    return out
