"""Minimum radius r0 of a disk cam with a translating (offset) roller follower.

Scene r0-synthesis: Parkhomenko, Porotnikov, Kucher (DonNTU) describe a VBA macro that finds
r0 by stepping r0 = e + dr, e + 2 dr, ... until the pressure angle stays within alpha_max at
every angle of the rise. The rise laws, the required S0, its maximum over the continuous angle
(``maximum``/``argmax``) and r0 are the template's (templates/r0-synthesis.toml). Here:

* :func:`loop_r0` is the macro's loop (r0 = e + k*dr, not r0 += dr, so no drift): on the grid,
  |alpha| <= alpha_max at every angle exactly when S0 = sqrt(r0^2 - e^2) reaches the grid's
  largest required S0 (``S0_grid``), so the loop steps k until it does; it refuses the cases
  the macro got wrong silently;
* the findings check r0 against brute force and the paper's Fig. 4 text, and the bench times
  the loop against the direct solution, whose error is measured against 40 digits (the
  template's own S0_req through SymPy and mpmath).
"""

from __future__ import annotations

import math
import time

import numpy as np

from ..errors import InputError, LimitError
from . import Finding, bench_block, block, cached, findings_block, table_block

LOOP_CAP = 100_000  # iterations of the r0 loop


def _mm(sheet, name: str, **args):
    out = sheet.evaluate(name, **args).to("mm").magnitude
    return float(out) if np.ndim(out) == 0 else np.asarray(out, dtype=float)


@block(args={"e": "mm", "dr": "mm", "r0_grid": "mm", "r0": "mm"}, returns="mm", vectorized=False)
def loop_r0(e, dr, r0_grid, r0):
    """r0 by the paper's VBA loop: e + k*dr until |alpha| <= alpha_max on the grid."""
    return loop(e, dr, r0_grid, r0)[0]


def loop(e: float, dr: float, r0_grid: float, r0: float, cap: int = LOOP_CAP) -> tuple[float, int]:
    """(r0, k) of the loop r0 = e + k*dr; ``r0`` is the direct answer (for the messages)."""
    if not dr > 0:
        raise InputError(f"the loop step dr = {dr:g} mm must be positive")
    if r0_grid <= e:
        raise InputError(
            "alpha_max does not bound r0: the pressure angle stays below it for every r0 > e "
            "(the required S0 is at most 0 at every angle of the grid), so choose r0 from "
            "other limits (roller, strength, undercutting)"
        )
    need = max(1, math.ceil((r0_grid - e) / dr - 1e-9))
    if need > cap:  # a hopeless run stops before it starts
        raise LimitError(
            f"the loop would need {need:,} steps of dr = {dr:g} mm to reach r0 = "
            f"{e + need * dr:.6g} mm (cap {cap:,}); use a larger dr or the direct r0"
        )
    for k in range(1, cap + 1):
        r = e + k * dr  # e + k*dr: r0 += dr would drift in floating point
        if r >= r0_grid:  # |alpha| <= alpha_max at every angle of the grid
            break
    if k == 1:
        raise InputError(
            f"the loop accepted its first candidate r0 = e + dr = {r:.6g} mm: dr = {dr:g} mm "
            f"is not smaller than r0 - e = {r0 - e:.6g} mm (direct r0 = {r0:.6g} mm), so the "
            "answer is set by dr, not by alpha_max; use a smaller dr"
        )
    if r < r0 * (1 - 1e-12):
        raise InputError(
            f"the grid misses the angle where the required S0 is largest: the loop would "
            f"accept r0 = {r:.6g} mm, below the direct r0 = {r0:.6g} mm, and the pressure angle "
            "exceeds alpha_max between the grid points; use a grid that holds the critical "
            "angle (an odd number of angles for the stepped law: phi_rise/2 on the grid)"
        )
    return r, k


# -- checks ---------------------------------------------------------------------------------
def _example(sheet) -> bool:
    """Are the sheet's inputs the template's (the listed example)?"""
    names = ("H", "phi_rise", "alpha_max", "e", "delta_sigma", "law")
    return all(sheet.evaluate(n) == sheet.spec.inputs[n].value for n in names)


LISTED_R0 = 38.2405  # the example's direct r0 and the loop's r0 for each dr
LISTED_LOOP = {"1 mm": 39.0, "0.1 mm": 38.3, "0.01 mm": 38.25}


@findings_block
def findings(sheet) -> list[Finding]:
    """r0 checks: continuous maximum, brute force, the loop, the paper's Fig. 4 claim."""
    out: list[Finding] = []
    r0, e = _mm(sheet, "r0"), _mm(sheet, "e")
    phi = float(sheet.evaluate("phi_of", x=float(sheet.evaluate("x_crit"))).to("deg").magnitude)
    out.append(
        Finding(
            "direct r0", f"r0 over the continuous angle (critical phi = {phi:.6g} deg)", r0, "mm"
        )
    )
    brute = _mm(sheet.with_inputs(n_grid=1_000_001), "r0_grid") - r0
    out.append(
        Finding(
            "direct r0",
            "brute force over 1,000,001 angles (r0_grid) minus direct r0",
            brute,
            "mm",
            "ok" if -1e-6 <= brute <= 1e-12 else "fail",
            "a dense grid can only fall short of the continuous maximum",
        )
    )
    top = float((sheet.evaluate("alpha_top") - sheet.evaluate("alpha_max")).to("deg").magnitude)
    ok = "ok" if abs(top) < 1e-9 else "fail"
    out.append(Finding("direct r0", "largest |alpha| at r0 minus alpha_max", top, "deg", ok))
    dr, n = _mm(sheet, "dr"), int(float(sheet.evaluate("n_grid").magnitude))
    try:
        r_loop = _mm(sheet, "r0_loop")
        out.append(
            Finding(
                "VBA loop",
                f"r0 by the loop (dr = {dr:g} mm, {n} angles, "
                f"{round((r_loop - e) / dr):,} steps) minus direct r0",
                r_loop - r0,
                "mm",
                "ok" if 0 <= r_loop - r0 <= dr + 1e-9 else "warning",
                "the loop overshoots by up to dr",
            )
        )
    except (InputError, LimitError) as err:
        out.append(Finding("VBA loop", "the loop cannot give r0", None, "", "warning", err.message))
    if _example(sheet):
        ok = "ok" if abs(r0 - LISTED_R0) <= 5e-5 else "fail"
        out.append(Finding("listed example", f"direct r0 (listed {LISTED_R0} mm)", r0, "mm", ok))
        odd = {"n_grid": n if n % 2 else 101}
        for dr_text, listed in LISTED_LOOP.items():
            r = _mm(sheet.with_inputs(dr=dr_text, **odd), "r0_loop")
            ok = "ok" if abs(r - listed) <= 1e-9 else "fail"
            what = f"loop r0 with dr = {dr_text} (listed {listed:g} mm)"
            out.append(Finding("listed example", what, r, "mm", ok))
    # the paper's Fig. 4 text: alpha at phi_rise/2 and phi_rise "does not depend on r0"
    x = np.array([0.0, 0.5, 1.0])
    at = [sheet.evaluate("alpha_r", x=x, r=f"{r!r} mm").to("deg").magnitude for r in (r0, 2 * r0)]
    for j, name in ((1, "phi_rise/2"), (2, "phi_rise")):
        change = float(at[1][j] - at[0][j])
        out.append(
            Finding(
                "Fig. 4",
                f"alpha at {name}: at 2*r0 minus at r0 (the paper says it does not depend on r0)",
                change,
                "deg",
                "info" if abs(change) > 1e-9 else "ok",
            )
        )
    return out


# -- error against run time -------------------------------------------------------------------
BENCH_DR = (1.0, 0.1, 0.01, 0.001)
BENCH_GRIDS = (13, 101, 1001, 10001, 100001)
WORKBOOK_GRIDS = (13, 101, 1001, 10001)


def _timed(func, min_time=0.02, max_reps=100_000):
    """Best-of-three mean time per call of ``func`` (repeats until min_time has passed)."""
    t0 = time.perf_counter()
    out = func()
    once = time.perf_counter() - t0
    reps = max(1, min(max_reps, int(min_time / max(once, 1e-9))))
    if reps == 1 and once > min_time:
        return out, once
    best = math.inf
    for _ in range(3):
        t0 = time.perf_counter()
        for _ in range(reps):
            func()
        best = min(best, (time.perf_counter() - t0) / reps)
    return out, best


def run_bench(sheet, drs=BENCH_DR, grids=BENCH_GRIDS):
    """Loop error and run time against the direct answer, for every (dr, grid): the loop's
    time is the grid's required S0 (the template's, at every angle) and the stepping."""
    import pandas as pd

    def build():
        e = _mm(sheet, "e")
        r0, t_direct = _timed(lambda: _mm(sheet.with_inputs(), "r0"), min_time=0.05)
        rows = []
        for dr in drs:
            for n in grids:

                def run(dr=dr, n=n):
                    return loop(e, dr, _mm(sheet.with_inputs(n_grid=n), "r0_grid"), r0)

                (r, k), t_loop = _timed(run, min_time=0.02)
                rows.append(
                    {
                        "dr [mm]": dr,
                        "angles": n,
                        "steps": k,
                        "r0 loop [mm]": r,
                        "r0 direct [mm]": r0,
                        "loop error [mm]": r - r0,
                        "loop time [s]": t_loop,
                        "direct time [s]": t_direct,
                        "loop/direct time": t_loop / t_direct,
                    }
                )
        return pd.DataFrame(rows)

    return cached(sheet, ("bench", tuple(drs), tuple(grids)), build).copy()


@bench_block
def bench(sheet, quick: bool = False):
    """Error against run time: the VBA loop for dr = 1 .. 0.001 mm on 13 .. 100001 angles."""
    return run_bench(sheet, grids=(13, 101) if quick else BENCH_GRIDS)


@table_block
def bench_table(sheet):
    """The error-against-run-time table of the workbook (grids up to 10001 angles)."""
    return run_bench(sheet, grids=WORKBOOK_GRIDS)


@table_block
def bench_chart(sheet):
    """The same measurements, one column pair per grid, for the log-log chart."""
    import pandas as pd

    df = run_bench(sheet, grids=WORKBOOK_GRIDS)
    out = {"dr [mm]": list(BENCH_DR)}
    for n in WORKBOOK_GRIDS:
        sub = df[df["angles"] == n]
        out[f"loop time, {n} angles [s]"] = sub["loop time [s]"].to_numpy()
        out[f"loop error, {n} angles [mm]"] = np.abs(sub["loop error [mm]"].to_numpy())
    return pd.DataFrame(out)


@table_block
def direct_point(sheet):
    """The direct method as one point: its run time, and its error against 40-digit mpmath."""
    import pandas as pd

    df = run_bench(sheet, grids=WORKBOOK_GRIDS)
    r0 = float(df["r0 direct [mm]"].iloc[0])
    ref = reference_r0(sheet)
    return pd.DataFrame(
        {
            "direct time [s]": [float(df["direct time [s]"].iloc[0])],
            "direct error [mm]": [max(abs(r0 - ref), 1e-15)],  # a log axis cannot show 0
            "r0 direct [mm]": [r0],
            "r0 reference (mpmath, 40 digits) [mm]": [ref],
        }
    )


def reference_r0(sheet, digits: int = 40) -> float:
    """r0 in ``digits``-digit arithmetic: the template's S0_req through SymPy, its largest value
    on each half of the rise from the ends and the roots of its derivative (mpmath)."""
    import mpmath
    import sympy as sp

    from .. import symbolic

    x = symbolic.symbol("x")
    expr = symbolic.to_sympy(sheet, "S0_req", {"x": x}, true_pi=True)
    g = sp.lambdify(x, expr, "mpmath")
    dg = sp.lambdify(x, sp.diff(expr, x), "mpmath")
    e = mpmath.mpf(repr(_mm(sheet, "e")))
    with mpmath.workdps(digits):
        half = mpmath.mpf(1) / 2
        best = max(g(mpmath.mpf(0)), g(half), g(mpmath.mpf(1)))
        for lo, hi in ((0, half), (half, 1)):
            pts = [lo + (hi - lo) * mpmath.mpf(i) / 200 for i in range(201)]
            d = [dg(p) for p in pts[1:-1]]
            for a, b, fa, fb in zip(pts[1:-2], pts[2:-1], d[:-1], d[1:]):
                if fa > 0 > fb:  # a maximum between a and b
                    best = max(best, g(mpmath.findroot(dg, (a, b), solver="anderson")))
        return float(mpmath.sqrt(max(best, 0) ** 2 + e**2))
