"""Minimum radius r0 of a disk cam with a translating (offset) roller follower.

Scene r0-synthesis: Parkhomenko, Porotnikov, Kucher (DonNTU) describe a VBA macro that finds
r0 by stepping r0 = e + dr, e + 2 dr, ... until the pressure angle stays within alpha_max at
every angle of the rise. The rise laws, the required S0, its maximum over the continuous angle
(``maximum``/``argmax``), r0, the macro's loop (the program ``loop_k``) and the checks are the
template's (templates/r0-synthesis.toml). Here:

* :func:`loop_refusals`, the refusals of the loop: the language has no error of a sheet's own
  wording (a piecewise definition with no piece names its conditions, a declared limit its
  value), and these messages name the step dr, the loop's r0 and the direct r0 and say what
  to change;
* the study that times the template's loop against the direct solution, whose error is
  measured against the same solution at the reference tolerance of ``workbook bench``.
"""

from __future__ import annotations

import time
import timeit

import numpy as np

from ..errors import InputError, LimitError
from . import bench_block, block, cached, table_block


def _mm(sheet, name: str, **args):
    out = sheet.evaluate(name, **args).to("mm").magnitude
    return float(out) if np.ndim(out) == 0 else np.asarray(out, dtype=float)


@block(
    args={"e": "mm", "dr": "mm", "r0_grid": "mm", "r0": "mm", "k": "", "cap": ""},
    returns="",
    vectorized=False,
)
def loop_refusals(e, dr, r0_grid, r0, k, cap):
    """The steps k of the template's loop r0 = e + k*dr, or the reason the loop has no
    answer (``r0`` is the direct answer, for the messages)."""
    if r0_grid <= e:
        raise InputError(
            "alpha_max does not bound r0: the pressure angle stays below it for every r0 > e "
            "(the required S0 is at most 0 at every angle of the grid), so choose r0 from "
            "other limits (roller, strength, undercutting)"
        )
    k = int(k)
    if k > cap:  # loop_k gives the steps it would need, without taking them
        raise LimitError(
            f"the loop would need {k:,} steps of dr = {dr:g} mm to reach r0 = "
            f"{e + k * dr:.6g} mm (cap {int(cap):,}); use a larger dr or the direct r0"
        )
    r = e + k * dr  # the loop's answer, for the messages
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
    return k


# -- error against run time -------------------------------------------------------------------
BENCH_DR = (1.0, 0.1, 0.01, 0.001)
BENCH_GRIDS = (13, 101, 1001, 10001, 100001)
WORKBOOK_GRIDS = (13, 101, 1001, 10001)


def _timed(func, min_time=0.02):
    """Best of three mean times per call of ``func``, each over at least ``min_time``."""
    t0 = time.perf_counter()
    out = func()
    once = time.perf_counter() - t0
    if once > min_time:
        return out, once
    reps = min(100_000, int(min_time / max(once, 1e-9)))
    return out, min(timeit.repeat(func, repeat=3, number=reps)) / reps


def run_bench(sheet, drs=BENCH_DR, grids=BENCH_GRIDS):
    """Loop error and run time against the direct answer, for every (dr, grid): the loop's
    time is a fresh sheet's ``loop_k``, the template's program, with what it needs: the grid's
    required S0 (the template's, at every angle) and the stepping."""
    import pandas as pd

    def row(r0, t_direct, dr, n):
        def fresh():
            return sheet.with_inputs(n_grid=n, dr=f"{dr!r} mm")

        _, t = _timed(lambda: fresh().evaluate("loop_k"))
        s = fresh()  # r0_loop: the loop's steps and its refusals
        k, r = int(s.evaluate("loop_k").magnitude), _mm(s, "r0_loop")
        return {
            **{"dr [mm]": dr, "angles": n, "steps": k, "r0 loop [mm]": r, "r0 direct [mm]": r0},
            **{"loop error [mm]": r - r0, "loop time [s]": t, "direct time [s]": t_direct},
            "loop/direct time": t / t_direct,
        }

    def build():
        r0, t_direct = _timed(lambda: _mm(sheet.with_inputs(), "r0"), min_time=0.05)
        return pd.DataFrame([row(r0, t_direct, dr, n) for dr in drs for n in grids])

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
    for n, sub in df.groupby("angles", sort=False):
        out[f"loop time, {n} angles [s]"] = sub["loop time [s]"].to_numpy()
        out[f"loop error, {n} angles [mm]"] = sub["loop error [mm]"].abs().to_numpy()
    return pd.DataFrame(out)


@table_block
def direct_point(sheet):
    """The direct method as one point: its run time, and its error against the same solution at
    the reference tolerance of ``workbook bench`` (1e-14)."""
    import pandas as pd

    from ..functions.numerical import current, sheet_tolerance, tolerance
    from ..numerics.bench import REFERENCE_RTOL

    df = run_bench(sheet, grids=WORKBOOK_GRIDS)
    r0 = float(df["r0 direct [mm]"].iloc[0])
    with tolerance(current(sheet_tolerance(sheet.spec.meta)).tighter(REFERENCE_RTOL)):
        ref = _mm(sheet.with_inputs(), "r0")
    return pd.DataFrame(
        {
            "direct time [s]": [float(df["direct time [s]"].iloc[0])],
            "direct error [mm]": [max(abs(r0 - ref), 1e-15)],  # a log axis cannot show 0
            "r0 direct [mm]": [r0],
            "r0 reference (tolerance 1e-14) [mm]": [ref],
        }
    )
