"""Ratio 1: h, v, j of the concave cam at N angles, sheet.evaluate against plain numpy.

The plain side is the same formulas written by hand in numpy without units: each piece is
computed only where its condition holds (boolean masks), as a careful hand-written version
would. Time: both sides alternately, medians. Memory: tracemalloc peak of one run of each
(numpy reports its array buffers to tracemalloc), measured in separate untimed runs.

Ratio 1b: ``sheet.evaluate(["h", "v", "j"], phi=...)`` (the three together, sharing what
they have in common) against hand-written numpy that computes the masks, sin, cos and the
square root of each piece once for all three.
"""

from __future__ import annotations

import argparse
import sys
import time
import tracemalloc
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _timing import Result, alternate, median, ms, report  # noqa: E402

TIME_TARGET = 1.5
SHARED_TARGET = 1.3
MEMORY_TARGET = 3.0

# The sheet's inputs (templates/concave-cam.toml), as plain numbers in mm, 1/s, degrees.
R1, R2, R3, Rp, a = 20.0, 10.0, 50.0, 10.0, 20.0
Theta, omega, PI = 52.0, 104.6, 3.142
deg = PI / 180
k = (R1 + R3) / (R3 - Rp)


def h1(phi):
    return (R1 + R3) * (np.cos(phi * deg) - 1 / k * np.sqrt(1 - k**2 * np.sin(phi * deg) ** 2)) - (
        R1 + Rp
    )


def h2(phi):
    return 2 * a * np.cos((Theta - phi) * deg) - (R1 + Rp)


def h3(phi):
    x = (2 * Theta - phi) * deg
    return (R1 + R3) * (np.cos(x) - 1 / k * np.sqrt(1 - k**2 * np.sin(x) ** 2)) - (R1 + Rp)


def v1(phi):  # mm/s -> m/s: / 1000, as the paper's 10^-3
    return (
        omega
        * (R1 + R3)
        * (
            k * np.sin(2 * phi * deg) / (2 * np.sqrt(1 - k**2 * np.sin(phi * deg) ** 2))
            - np.sin(phi * deg)
        )
        / 1000
    )


def v2(phi):
    return 3 * a * omega * np.sin((Theta - phi) * deg) / 1000


def v3(phi):
    return (
        -omega
        * (R1 + R3)
        * (
            k
            * np.sin((4 * Theta - 2 * phi) * deg)
            / (2 * np.sqrt(1 - k**2 * np.sin((2 * Theta - phi) * deg) ** 2))
            - np.sin((2 * Theta - phi) * deg)
        )
        / 1000
    )


def j1(phi):
    return (
        omega**2
        * (R1 + R3)
        * (
            (k * np.cos(2 * phi * deg) - k**3 * np.sin(phi * deg) ** 4)
            / (1 - k**2 * np.sin(phi * deg) ** 2) ** 1.5
            - np.cos(phi * deg)
        )
        / 1000
    )


def j2(phi):
    return -2 * a * omega**2 * np.cos((Theta - phi) * deg) / 1000


def j3(phi):
    x = (2 * Theta - phi) * deg
    return (
        omega**2
        * (R1 + R3)
        * (
            (k * np.cos((4 * Theta - 2 * phi) * deg) - k**3 * np.sin(x) ** 4)
            / (1 - k**2 * np.sin(x) ** 2) ** 1.5
            - np.cos(x)
        )
        / 1000
    )


def joined(phi, f1, f2, f3):
    """The piecewise definition: first true condition wins, each piece only where it holds."""
    out = np.empty_like(phi)
    m1 = (phi >= 0) & (phi <= 22)
    m2 = ~m1 & (phi >= 22) & (phi <= 82)
    m3 = ~m1 & ~m2 & (phi > 82) & (phi <= 104)
    if not (m1 | m2 | m3).all():
        raise ValueError("phi outside 0..104")
    out[m1] = f1(phi[m1])
    out[m2] = f2(phi[m2])
    out[m3] = f3(phi[m3])
    return out


def plain_hvj(phi: np.ndarray):
    """h [mm], v [m/s], j [m/s^2]: the template's formulas written literally in numpy."""
    return joined(phi, h1, h2, h3), joined(phi, v1, v2, v3), joined(phi, j1, j2, j3)


def _masks(phi):
    m1 = (phi >= 0) & (phi <= 22)
    m2 = ~m1 & (phi >= 22) & (phi <= 82)
    m3 = ~m1 & ~m2 & (phi > 82) & (phi <= 104)
    if not (m1 | m2 | m3).all():
        raise ValueError("phi outside 0..104")
    return m1, m2, m3


def _flank(x, sign):
    """h, v, j of a concave flank at the angle x (radians): sin, cos, sqrt once."""
    s, c = np.sin(x), np.cos(x)
    s2 = s * s
    q = 1 - k**2 * s2
    r = np.sqrt(q)
    h = (R1 + R3) * (c - r / k) - (R1 + Rp)
    v = sign * omega * (R1 + R3) * (k * np.sin(2 * x) / (2 * r) - s) / 1000
    j = omega**2 * (R1 + R3) * ((k * np.cos(2 * x) - k**3 * s2 * s2) / (q * r) - c) / 1000
    return h, v, j


def shared_hvj(phi: np.ndarray):
    """h, v, j by hand, sharing the masks, sin, cos and sqrt of each piece."""
    m1, m2, m3 = _masks(phi)
    h, v, j = np.empty_like(phi), np.empty_like(phi), np.empty_like(phi)
    h[m1], v[m1], j[m1] = _flank(phi[m1] * deg, 1)
    y = (Theta - phi[m2]) * deg
    cy = np.cos(y)
    h[m2] = 2 * a * cy - (R1 + Rp)
    v[m2] = 3 * a * omega * np.sin(y) / 1000
    j[m2] = -2 * a * omega**2 * cy / 1000
    h[m3], v[m3], j[m3] = _flank((2 * Theta - phi[m3]) * deg, -1)
    return h, v, j


def engine_together(sheet, phi: np.ndarray):
    return [q.magnitude for q in sheet.evaluate(["h", "v", "j"], phi=phi)]


def engine_hvj(sheet, phi: np.ndarray):
    return (
        sheet.evaluate("h", phi=phi).magnitude,
        sheet.evaluate("v", phi=phi).magnitude,
        sheet.evaluate("j", phi=phi).magnitude,
    )


def peak_bytes(fn) -> int:
    tracemalloc.start()
    tracemalloc.reset_peak()
    base = tracemalloc.get_traced_memory()[0]
    out = fn()
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    del out
    return peak - base


def run(n: int = 1_000_000, reps: int = 5, cpu: bool = False) -> list[Result]:
    import workbook

    sheet = workbook.load("concave-cam")
    phi = np.linspace(0.0, 104.0, n)
    # Same numbers on both sides (units: h in mm, v in m/s, j in m/s^2).
    for e, p in zip(engine_hvj(sheet, phi), plain_hvj(phi)):
        np.testing.assert_allclose(e, p, rtol=1e-9, atol=1e-9)
    for e, p in zip(engine_together(sheet, phi), shared_hvj(phi)):
        np.testing.assert_allclose(e, p, rtol=1e-9, atol=1e-9)
    te, tp = alternate(lambda: engine_hvj(sheet, phi), lambda: plain_hvj(phi), reps=reps)
    me, mp = peak_bytes(lambda: engine_hvj(sheet, phi)), peak_bytes(lambda: plain_hvj(phi))
    clock = time.process_time if cpu else time.perf_counter
    ts, tq = alternate(
        lambda: engine_together(sheet, phi), lambda: shared_hvj(phi), reps=reps, clock=clock
    )
    return [
        Result(
            f"evaluate h, v, j at {n:,} angles: engine / plain numpy (time)",
            median(te) / median(tp),
            TIME_TARGET,
            detail=f"engine {ms(median(te))}, numpy {ms(median(tp))}, medians of {reps}",
        ),
        Result(
            f"evaluate h, v, j at {n:,} angles: engine / plain numpy (peak memory, tracemalloc)",
            me / mp,
            MEMORY_TARGET,
            detail=f"engine {me / 2**20:.1f} MiB, numpy {mp / 2**20:.1f} MiB",
        ),
        Result(
            f"evaluate [h, v, j] together at {n:,} angles: engine / numpy sharing sin, cos, sqrt",
            median(ts) / median(tq),
            SHARED_TARGET,
            detail=f"engine {ms(median(ts))}, numpy {ms(median(tq))}, medians of {reps}"
            + (", CPU time" if cpu else ""),
        ),
    ]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument(
        "--cpu", action="store_true", help="time the shared evaluation in CPU time (loaded machine)"
    )
    args = ap.parse_args(argv)
    results = run(args.n, args.reps, args.cpu)
    return report(results)


if __name__ == "__main__":
    sys.exit(main())
