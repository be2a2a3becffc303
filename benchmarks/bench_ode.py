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
tighter tolerances). Last, the coupling's default solver at its stiff case (c2 = 1e10 N/m)
against the fastest method and tolerance of a study that still reaches the rigid limit. Times
are medians of alternated runs in process CPU time (the machine is shared).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _timing import ROOT, Result, alternate, median, ms, report  # noqa: E402
from ode_problems import PROBLEMS, robertson  # noqa: E402

TEMPLATE = ROOT / "tests" / "data" / "robertson.toml"
COUPLING = ROOT / "templates" / "advance-coupling.toml"
TARGET = 1.5  # engine "auto" / the fastest fitting SciPy method called directly
CHECK_TARGET = 2.0  # check / (one solve + its error estimate)
RTOL, ATOL = 1e-6, 1e-9


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


def _default_solver_row(reps: int) -> Result:
    """The coupling's default method at rtol 1e-5 against the fastest study run (method and
    rtol) that ends within twice the rigid limit's deflection of the rigid motion."""
    import workbook
    from workbook.blocks import coupling as cp

    sheet = workbook.load(COUPLING, parts="all").with_inputs(t_end="0.1 s")
    df = cp.study(sheet, (1e10,), (1e-3, 1e-4, 1e-5, 1e-6, 1e-7), max_time=2.0, label=None)
    stiff = sheet.with_inputs(c2="1e10 N/m")
    case = cp.case(stiff)
    ok = df[(df["stopped"] == "finished") & (df["deviation from rigid [rad]"] <= 2 * case.delta)]
    best = ok.loc[ok["run time [s]"].idxmin()]
    method = str(stiff.evaluate("method_used"))
    td, tb = alternate(
        lambda: cp.run(stiff, method, 1e-5, case.t),
        lambda: cp.run(stiff, best["method"], best["rtol"], case.t),
        reps=reps,
        clock=time.process_time,
    )
    return Result(
        "advance-coupling at c2 = 1e10 N/m: default solver / fastest run reaching the rigid limit",
        median(td) / median(tb),
        2.0,
        detail=f"{method} rtol 1e-5 {ms(median(td))}, {best['method']} rtol "
        f"{best['rtol']:g} {ms(median(tb))}",
    )


def run(reps: int = 5) -> list[Result]:
    """A ratio per problem, then the sheets'."""
    out = [_problem_row(name, *p, reps=reps) for name, p in PROBLEMS.items()]
    out.append(_sheet_row(reps))
    out += [_check_row(path, max(1, reps // 2)) for path in (TEMPLATE, COUPLING)]
    return out + [_default_solver_row(reps)]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=5)
    args = ap.parse_args(argv)
    return report(run(args.reps))


if __name__ == "__main__":
    sys.exit(main())
