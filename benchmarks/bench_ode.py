"""ODE method "auto" against SciPy's solvers called directly, at the same tolerances.

A row per problem: the engine's ``auto`` (``workbook.engine.odeauto.auto_run``: an explicit
method watched for stiffness, LSODA from where it turns stiff) on a plain-numpy right-hand
side, against the fastest of SciPy's ``solve_ivp`` with Radau, BDF and LSODA on the stiff
problems (Robertson to t = 40, HIRES to 321.8122, Van der Pol with mu = 1000 over 3000) and of
RK45 and DOP853 on the non-stiff one (Kepler, eccentricity 0.5, over 50 periods: its
Jacobian has a saddle pair of eigenvalues up to +-4 near the perihelion). Both sides keep dense
output, rtol 1e-6 and atol 1e-9. Then the sheet: tests/data/robertson.toml solved from a fresh
Sheet (units, compiled derivatives) against the fastest direct stiff solver (for information:
a fresh sheet's fixed costs), and ``check`` of that sheet and of templates/advance-coupling.toml
against solving each [[ode]] once plus its global error estimate (the run at 1000 times
tighter tolerances). Times are medians of
alternated runs in process CPU time (the machine is shared).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _timing import ROOT, Result, alternate, median, ms, report  # noqa: E402

TEMPLATE = ROOT / "tests" / "data" / "robertson.toml"
COUPLING = ROOT / "templates" / "advance-coupling.toml"
TARGET = 1.5  # engine "auto" / the fastest fitting SciPy method called directly
CHECK_TARGET = 2.0  # check / (one solve + its error estimate)
RTOL, ATOL = 1e-6, 1e-9


def kepler(t, y):
    x, yy, vx, vy = y
    r3 = (x * x + yy * yy) ** 1.5
    return np.array([vx, vy, -x / r3, -yy / r3])


def robertson(t, y):
    y1, y2, y3 = y
    return np.array(
        [-0.04 * y1 + 1e4 * y2 * y3, 0.04 * y1 - 1e4 * y2 * y3 - 3e7 * y2**2, 3e7 * y2**2]
    )


def hires(t, y):
    y1, y2, y3, y4, y5, y6, y7, y8 = y
    return np.array(
        [
            -1.71 * y1 + 0.43 * y2 + 8.32 * y3 + 0.0007,
            1.71 * y1 - 8.75 * y2,
            -10.03 * y3 + 0.43 * y4 + 0.035 * y5,
            8.32 * y2 + 1.71 * y3 - 1.12 * y4,
            -1.745 * y5 + 0.43 * y6 + 0.43 * y7,
            -280 * y6 * y8 + 0.69 * y4 + 1.71 * y5 - 0.43 * y6 + 0.69 * y7,
            280 * y6 * y8 - 1.81 * y7,
            -280 * y6 * y8 + 1.81 * y7,
        ]
    )


def vdp(t, y):
    return np.array([y[1], 1000.0 * (1 - y[0] ** 2) * y[1] - y[0]])


E = 0.5
PROBLEMS = {  # name: (f, span, y0, stiff)
    "Kepler, e = 0.5, 50 periods": (
        kepler, (0.0, 100 * np.pi), [1 - E, 0, 0, np.sqrt((1 + E) / (1 - E))], False
    ),
    "Robertson to t = 40": (robertson, (0.0, 40.0), [1.0, 0.0, 0.0], True),
    "HIRES to t = 321.8122": (
        hires, (0.0, 321.8122), [1, 0, 0, 0, 0, 0, 0, 0.0057], True
    ),
    "Van der Pol, mu = 1000, to t = 3000": (vdp, (0.0, 3000.0), [2.0, 0.0], True),
}  # fmt: skip


def _problem_row(name: str, f, span, y0, stiff: bool, reps: int) -> Result:
    from scipy.integrate import solve_ivp

    from workbook.engine.odeauto import auto_run

    opts = dict(rtol=RTOL, atol=ATOL, dense_output=True)
    methods = ("Radau", "BDF", "LSODA") if stiff else ("RK45", "DOP853")

    def direct(m):
        return lambda: solve_ivp(f, span, y0, method=m, **opts)

    def engine():
        return auto_run(f, span[0], span[1], y0, **opts)

    times = {}
    for m in methods:
        te, td = alternate(engine, direct(m), reps=reps, clock=time.process_time)
        times[m] = median(td)
        times.setdefault("auto", []).extend(te)
    t_auto = median(times.pop("auto"))
    best = min(times, key=times.get)
    run, choice = engine()
    used = choice.method if choice.method == run.method else run.method
    if choice.method == "LSODA" and "from the start" in choice.reason:
        used = f"RK45 for {choice.reason.split('after ')[1].split(' steps')[0]} steps, LSODA"
    others = ", ".join(f"{m} {ms(t)}" for m, t in times.items())
    return Result(
        f"{name}: engine auto / fastest of {'/'.join(methods)}",
        t_auto / times[best],
        TARGET,
        detail=f"auto {ms(t_auto)} ({used}); {others}",
    )


def _sheet_row(reps: int) -> Result:
    from scipy.integrate import solve_ivp

    import workbook

    sheet = workbook.load(TEMPLATE)

    def engine():
        return sheet.with_inputs().evaluator.ode_solution("rob")

    def best_direct():
        return solve_ivp(robertson, (0.0, 40.0), [1.0, 0.0, 0.0], method="LSODA", rtol=RTOL,
                         atol=1e-10, dense_output=True)  # fmt: skip

    te, td = alternate(engine, best_direct, reps=reps, clock=time.process_time)
    return Result(
        "Robertson sheet (load, units, compiled derivatives): engine / SciPy LSODA directly",
        median(te) / median(td),
        TARGET,
        detail=f"engine {ms(median(te))} ({engine().method}), LSODA {ms(median(td))}",
        info=True,  # a fresh sheet's fixed costs, not the method
    )


def _check_row(path: Path, reps: int) -> Result:
    """``check`` of a sheet against solving each of its [[ode]] once plus its error estimate."""
    import workbook
    from workbook.compute.checks import run_checks

    sheet = workbook.load(path)

    def solve_and_estimate():
        fresh = sheet.with_inputs()
        for name in fresh.spec.odes:
            fresh.evaluator.ode_solution(name).estimate()

    def check():
        return run_checks(sheet.with_inputs())

    tc, ts = alternate(check, solve_and_estimate, reps=reps, clock=time.process_time)
    return Result(
        f"{path.stem}: check / (each ode solved once + its error estimate)",
        median(tc) / median(ts),
        CHECK_TARGET,
        detail=f"check {ms(median(tc))}, solve + estimate {ms(median(ts))}",
    )


def run(reps: int = 5) -> list[Result]:
    """A ratio per problem, then the sheet's."""
    out = [_problem_row(name, *p, reps=reps) for name, p in PROBLEMS.items()]
    out.append(_sheet_row(reps))
    return out + [_check_row(path, max(1, reps // 2)) for path in (TEMPLATE, COUPLING)]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=5)
    args = ap.parse_args(argv)
    return report(run(args.reps))


if __name__ == "__main__":
    sys.exit(main())
