"""Numerical built-ins over a 10^4-row range: root and integral, engine against SciPy.

The engine side evaluates functions of tests/data/pipe-flow.toml for 10^4 arguments at
once, from a fresh Sheet each time, at the sheet's tolerance (1e-10 relative): Colebrook's
friction factor ``friction(Re)`` by ``root(EXPR, f, 0.005, 0.1)`` and the flow rate of a
1/7 power-law profile ``Q(R)`` by ``integral(...)``. The other sides compute the same
numbers in plain numpy at the same tolerance: a Python loop of ``brentq`` / ``quad``, and
one call of SciPy's vectorised ``find_root`` / ``tanhsinh``. Each line also gives the
largest relative error of every side against a tight reference (``brentq`` at 1e-15,
``quad`` at 1e-13) on 200 rows.

The baselines are set up as the engine is, so that the ratio measures the engine's own cost:
the integrand in SI units (m, m/s), the same relative tolerance; the loop of ``quad`` with
``epsabs=0`` (its default absolute tolerance, 1.5e-8, is looser than the engine's), the
direct ``tanhsinh`` with the engine's per-row rescaling (each row's integrand divided by its
size, |f| at the middle times the width, because tanh-sinh's error estimate is not
scale-invariant) and its absolute tolerance (a thousandth of the relative one, on the
rescaled integrand). The profile has no kink, so no side splits the interval (the engine
finds no break point in it either, and no narrow feature: its interval search runs on 32
rows spread over the table). What the engine still does besides: it first tries a 21-point
Gauss-Kronrod rule on 32 rows spread over the table (all go to tanh-sinh here, so the rest
does without trying); for the roots, it checks that each final bracket's values are those of
a root (not a pole or a jump): a table this long is not counted by interval arithmetic.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _timing import ROOT, Result, alternate, median, ms, report  # noqa: E402

TEMPLATE = ROOT / "tests" / "data" / "pipe-flow.toml"
LOOP_TARGET = 0.1  # engine / Python loop: at least 10x faster
DIRECT_TARGET = 1.5  # engine / SciPy's vectorised routine
RTOL = 1e-10
EPS, D, U_MAX = 0.05e-3, 0.1, 2.0  # the sheet's inputs in m, m, m/s


def colebrook(f, re):
    return 1 / np.sqrt(f) + 2 * np.log10(EPS / (3.7 * D) + 2.51 / (re * np.sqrt(f)))


def flow(r, radius):
    return 2 * np.pi * r * U_MAX * (1 - r / radius) ** (1 / 7)


def rescaled_tanhsinh(tanhsinh, radius: np.ndarray) -> np.ndarray:
    """tanhsinh as the engine calls it: each row's integrand divided by its size (|f| at the
    middle times the width), a piece's absolute error its share (1e-3) of the tolerance."""
    size = np.abs(flow(radius / 2, radius)) * radius
    size = np.where(np.isfinite(size) & (size > 0), size, 1.0)
    res = tanhsinh(
        lambda r, big_r, s: flow(r, big_r) / s,
        0,
        radius,
        args=(radius, size),
        rtol=RTOL,
        atol=1e-3 * RTOL,
    )
    return res.integral * size


def run(n: int = 10_000, reps: int = 5) -> list[Result]:
    """Ratios of the engine's time to a loop of brentq/quad and to find_root/tanhsinh."""
    from scipy.integrate import quad, tanhsinh
    from scipy.optimize import brentq
    from scipy.optimize.elementwise import find_root

    import workbook

    sheet = workbook.load(TEMPLATE)
    re = 4000.0 + 100.0 * np.arange(n)
    radius = (10.0 + np.arange(n)) / 1000.0  # m
    sample = np.linspace(0, n - 1, min(n, 200)).astype(int)

    def engine_root():
        return sheet.with_inputs().evaluate("friction", re).magnitude

    def engine_integral():
        return sheet.with_inputs().evaluate("Q", radius * 1000.0).to("m^3/s").magnitude

    lo, hi = np.full(n, 0.005), np.full(n, 0.1)
    sides = {
        "root": (
            engine_root,
            lambda: np.array([brentq(colebrook, 0.005, 0.1, args=(x,), rtol=RTOL) for x in re]),
            lambda: find_root(colebrook, (lo, hi), args=(re,), tolerances={"xrtol": RTOL}).x,
            np.array(
                [
                    brentq(colebrook, 0.005, 0.1, args=(x,), xtol=1e-16, rtol=1e-15)
                    for x in re[sample]
                ]
            ),
        ),
        "integral": (
            engine_integral,
            lambda: np.array(
                [quad(flow, 0, x, args=(x,), epsabs=0.0, epsrel=RTOL)[0] for x in radius]
            ),
            lambda: rescaled_tanhsinh(tanhsinh, radius),
            np.array(
                [
                    quad(flow, 0, x, args=(x,), epsabs=0, epsrel=1e-13, limit=200)[0]
                    for x in radius[sample]
                ]
            ),
        ),
    }
    out = []
    for name, (engine, loop, direct, ref) in sides.items():
        errors = {
            side: float(np.max(np.abs(fn()[sample] - ref) / np.abs(ref)))
            for side, fn in (("engine", engine), ("loop", loop), ("direct", direct))
        }
        accuracy = ", ".join(f"{k} {v:.1e}" for k, v in errors.items())
        te, tl = alternate(engine, loop, reps=max(1, reps // 2), warmup=0)
        te2, td = alternate(engine, direct, reps=reps)
        engine_t = median(te + te2)
        primitive = "brentq" if name == "root" else "quad"
        vector = "find_root" if name == "root" else "tanhsinh"
        out.append(
            Result(
                f"{name} over {n} rows: engine / Python loop of {primitive}",
                engine_t / median(tl),
                LOOP_TARGET,
                detail=f"engine {ms(engine_t)}, loop {ms(median(tl))}; max rel error: {accuracy}",
            )
        )
        out.append(
            Result(
                f"{name} over {n} rows: engine / SciPy {vector} called directly",
                engine_t / median(td),
                DIRECT_TARGET,
                detail=f"engine {ms(engine_t)}, {vector} {ms(median(td))}",
            )
        )
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10_000)
    ap.add_argument("--reps", type=int, default=5)
    args = ap.parse_args(argv)
    return report(run(args.n, args.reps))


if __name__ == "__main__":
    sys.exit(main())
