"""Centrifugal injection-advance coupling (Braginets, Kabelkov, Meremkulov 2003): the studies.

The model is the template's (templates/advance-coupling.toml): the steady weight angle, the
closed forms, the matrices M, Phi, H, the eigenvalues, the ODEs ``motion`` (3 DOF) and
``rigid`` (the rigid-tooth limit) and the solver choice ``method_used``. This module re-reads
it at changed inputs (``sheet.with_inputs``) for what is one scene's: the families and trends
of Fig. 3, the stiffness over c2, a work-precision study of five methods on the template's
ODE against its exact solution (matrix exponential of the linear system), prose findings.
"""

from __future__ import annotations

import math
import sys
from collections import namedtuple

import numpy as np

from ..engine import ode, oderun
from ..findings import Finding
from . import bench_block, cached, findings_block, table_block


def _v(sheet, name: str, unit: str, **args):
    """A definition or input of the sheet as a number (or array) in ``unit``."""
    out = sheet.evaluate(name, **args).to(unit).magnitude
    return float(out) if np.ndim(out) == 0 else np.asarray(out, dtype=float)


def with_input(sheet, name: str, value: float, unit: str = ""):
    """The sheet with one input replaced by ``value`` in ``unit``."""
    return sheet.with_inputs(**{name: f"{float(value)!r} {unit}".strip()})


# -- families of Fig. 3 ------------------------------------------------------------------------
FAMILY_TABLES = {"c1": "fig3a", "m": "fig3b", "phi20": "fig3c"}  # the vary tables
TRENDS = {"c1": -1, "m": +1, "phi20": +1}  # the printed trends: sign of d phi2 / d parameter
TREND_TEXT = {"c1": "phi2 falls as c1 rises", "m": "phi2 rises with m"}
TREND_TEXT["phi20"] = "phi2 rises with phi20"


def speeds(sheet) -> np.ndarray:
    """The speeds of the template's steady table (rad/s)."""
    return sheet.range_values(sheet.table_spec("steady").range, "table steady")


def closed_form(sheet, ws, form: str = "printed") -> tuple[np.ndarray, ...]:
    """(value, denominator, departure from the root) of phi2_lin (printed) or phi2_newton, and
    dev_lin or dev_newton: NaN where the denominator is not positive (no value there)."""
    suffix = "lin" if form == "printed" else "newton"
    den = np.atleast_1d(_v(sheet, f"D_{suffix}", "N*m", omega1=ws))
    value, dev, ok = np.full(den.shape, math.nan), np.full(den.shape, math.nan), den > 0
    if ok.any():
        value[ok] = _v(sheet, f"phi2_{suffix}", "rad", omega1=np.asarray(ws)[ok])
        dev[ok] = _v(sheet, f"dev_{suffix}", "", omega1=np.asarray(ws)[ok])
    return value, den, dev


def family(sheet, key: str, ws) -> dict[str, dict[str, np.ndarray]]:
    """For each value of the family input ``key`` (the template's vary table of Fig. 3): the
    root from the table, and both closed forms with their departures."""

    def build():
        name = FAMILY_TABLES[key]
        df, (values,) = sheet.computed_table(name), sheet.table_spec(name).vary.values()
        out = {}
        table_speeds = np.array_equal(np.asarray(ws, dtype=float), df.iloc[:, 0].to_numpy())
        for text in values:
            s = sheet.with_inputs(**{key: text})
            root = (
                df[f"phi2 {key}={text} [rad]"].to_numpy()
                if table_speeds
                else np.atleast_1d(_v(s, "phi2", "rad", omega1=ws))
            )
            member = out[text] = {"root": root}
            for form in ("printed", "newton"):
                member[form], _, member[f"dev {form}"] = closed_form(s, ws, form)
        return out

    return cached(sheet, ("family", key, tuple(ws)), build)


# -- the template's ODE, its exact solution and the rigid limit --------------------------------
def times(sheet) -> np.ndarray:
    """The times of the template's histories table (s)."""
    return sheet.range_values(sheet.table_spec("histories").range, "table histories")


def outputs(sheet, y: np.ndarray) -> np.ndarray:
    """(phi2, psi) rows from states y = (q, q') of ode motion: the template's P_out*q."""
    return _v(sheet, "P_out", "") @ y[:3]


def linear_system(sheet):
    """A, b, g of the template's ode motion, y' = A y + b + g sin(Omega_pump t)."""

    def build():
        fun, t0, t1, y0 = ode.problem(sheet.defs.ode("motion"), sheet.evaluator.compile)
        om = _v(sheet, "Omega_pump", "rad/s")
        return (*oderun.linear_parts(fun, len(y0), om), om, y0)

    return cached(sheet, "linear system", build)


# one sheet (one c2): the output times, the exact 3-DOF outputs (phi2, psi), those of the
# rigid-tooth limit, and the largest difference between the two
Case = namedtuple("Case", "sheet t exact rigid delta")


def case(sheet) -> Case:
    def build():
        ts = times(sheet)
        ex_ = outputs(sheet, oderun.linear_solution(*linear_system(sheet), ts))
        rig = np.vstack([_v(sheet, "phi2_r", "rad", t=ts), _v(sheet, "psi_r", "rad", t=ts)])
        return Case(sheet, ts, ex_, rig, float(np.max(np.abs(ex_ - rig))))

    return cached(sheet, "case", build)


def run(sheet, method: str, rtol: float, t_eval=None, **bounds) -> oderun.OdeRun:
    """The template's ode motion with ``method`` and ``rtol`` (its atol follows rtol); the
    implicit methods get its constant Jacobian."""
    s = sheet.with_inputs(method=str(method), rtol=f"{float(rtol)!r}")
    A = linear_system(sheet)[0]
    return ode.run_sheet(s, "motion", t_eval=t_eval, jac=lambda t, y: A, **bounds)


def deviation(cs: Case, run_: oderun.OdeRun, against: np.ndarray) -> float:
    if not run_.ok or run_.y.shape[1] != against.shape[1]:
        return math.nan
    return float(np.max(np.abs(outputs(cs.sheet, run_.y) - against)))


# -- stiffness over c2, the work-precision study ----------------------------------------------
STUDY_C2 = (1e6, 1e8, 1e10)
STUDY_RTOLS = (1e-3, 1e-5, 1e-7)
FULL_C2 = (1e6, 1e7, 1e8, 1e9, 1e10)
FULL_RTOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)
CHOICE_C2 = 1e10  # the stiff case the default solver is judged on
STALL_C2 = 1e14  # the extreme case where explicit methods stall
STUDY_T = 0.1  # s: the workbook's shortened study runs over min(t_end, STUDY_T)


def at_c2(sheet, c2: float):
    return with_input(sheet, "c2", c2, "N/m")


STIFFNESS = (  # columns of the stiffness table: template definition, header, unit
    ("weight_re", "weight mode Re [1/s]", "1/s"),
    ("weight_im", "weight mode Im [rad/s]", "rad/s"),
    ("tooth_re", "tooth mode Re [1/s]", "1/s"),
    ("tooth_im", "tooth mode Im [rad/s]", "rad/s"),
    ("tooth_damping", "tooth damping ratio", ""),
    ("stiff_ratio", "stiffness ratio |lam|max/|lam|min", ""),
    ("stiff_index", "stiffness index |lam|max*t_end", ""),
)


@table_block
def stiffness_table(sheet):
    """Eigenvalues (rigid rotation excluded) and stiffness measures for c2 = 1e6 .. 1e10 N/m."""
    import pandas as pd

    rows = []
    for c2 in FULL_C2:
        s2, delta = at_c2(sheet, c2), case(at_c2(sheet, c2)).delta
        row = {"c2 [N/m]": c2} | {title: _v(s2, n, unit) for n, title, unit in STIFFNESS}
        row |= {"rigid-model difference [rad]": delta, "difference*c2 [N rad/m]": delta * c2}
        row["auto method"] = str(s2.with_inputs(method="auto").evaluate("method_used"))
        rows.append(row)
    return pd.DataFrame(rows)


def study(
    sheet, c2s, rtols, methods=oderun.SOLVERS, *, max_time=5.0, label="advance-coupling study"
):
    """Work-precision rows: every method x rtol at every c2; error against the exact solution
    and deviation from the rigid-tooth limit. A method that stops early at some rtol is not
    run at tighter ones."""
    import pandas as pd

    def build():
        if label:
            runs = f"{len(c2s) * len(rtols) * len(methods)} runs, each at most {max_time:g} s"
            print(f"[{label}] {runs}", file=sys.stderr, flush=True)
        rows = []
        for c2 in c2s:
            rows += _study_rows(case(at_c2(sheet, c2)), c2, methods, rtols, max_time, label)
        return pd.DataFrame(rows)

    return cached(sheet, ("study", tuple(c2s), tuple(rtols), tuple(methods), max_time), build)


def _study_rows(cs: Case, c2: float, methods, rtols, max_time: float, label) -> list[dict]:
    rigid = "deviation from rigid [rad]"

    def one(method, rtol):
        return run(cs.sheet, method, rtol, cs.t, max_time=max_time, label=label)

    done = oderun.work_precision(
        one,
        lambda x: deviation(cs, x, cs.exact),
        methods,
        rtols,
        extra_of=lambda x: {rigid: deviation(cs, x, cs.rigid)},
    )
    return [
        {"c2 [N/m]": c2, "method": r.method, "rtol": r.rtol, "error [rad]": r.error}
        | {rigid: r.extra.get(rigid, math.nan), "rigid-model difference [rad]": cs.delta}
        | {"run time [s]": r.elapsed, "f-evals": r.nfev, "steps": r.nsteps}
        | {"stopped": r.stop_reason}
        for r in done
    ]


def _blank(df):
    """NaN -> None, so that the workbook leaves the cell empty (charts skip it)."""
    return df.astype(object).where(df.notna(), None)


def _study_for_sheet(sheet):
    short = with_input(sheet, "t_end", min(_v(sheet, "t_end", "s"), STUDY_T), "s")
    return short, study(short, STUDY_C2, STUDY_RTOLS, max_time=min(1.5, _v(sheet, "max_time", "s")))


@table_block
def work_precision_table(sheet):
    """Work-precision study (shortened for the workbook; the full one is `workbook bench`)."""
    return _blank(_study_for_sheet(sheet)[1])


def _wide(df, c2: float):
    import pandas as pd

    sub = df[df["c2 [N/m]"] == c2]
    cols = {"rtol": sorted(sub["rtol"].unique(), reverse=True)}
    for m in oderun.SOLVERS:
        s = sub[sub["method"] == m].set_index("rtol")
        cols[f"time {m} [s]"] = [s["run time [s]"].get(r, math.nan) for r in cols["rtol"]]
        cols[f"error {m} [rad]"] = [s["error [rad]"].get(r, math.nan) for r in cols["rtol"]]
    return _blank(pd.DataFrame(cols))


@table_block
def wp_stiff(sheet):
    """Work-precision chart data at c2 = 1e10 N/m: run time and error per method."""
    return _wide(_study_for_sheet(sheet)[1], CHOICE_C2)


@table_block
def wp_moderate(sheet):
    """Work-precision chart data at c2 = 1e8 N/m."""
    return _wide(_study_for_sheet(sheet)[1], 1e8)


def stall_run(sheet, method="RK45", c2=STALL_C2, max_time=0.5, max_steps=20_000):
    """An explicit method on a very stiff tooth, bounded by a budget and a step cap: the run
    and the steps it would need at its stability limit (about stiff_index/3.3)."""
    s2 = at_c2(sheet, c2)
    r = run(
        s2, method, 1e-5, max_time=max_time, max_steps=max_steps, label="advance-coupling stall"
    )
    return r, _v(s2, "stiff_index", "") / 3.3


# -- findings ----------------------------------------------------------------------------------
def trend_holds(sheet, key: str, ws) -> tuple[list[float], list[float], list[float]]:
    """Speeds where the printed trend holds strictly, where it fails, where it is vacuous
    (every member of the family on the stop)."""
    fam = family(sheet, key, ws)
    vals = np.array([member["root"] for member in fam.values()])  # members x speeds
    holds, fails, vacuous = [], [], []
    for j, w in enumerate(ws):
        col = vals[:, j]
        if np.all(col == 0):
            vacuous.append(float(w))
            continue
        d = np.diff(col) * TRENDS[key]
        # on the stop two members may both be 0: the trend is then "not reversed"
        ok = np.all(d >= 0) and np.any(d > 0) and np.all((d > 0) | (col[1:] == 0) | (col[:-1] == 0))
        (holds if ok else fails).append(float(w))
    return holds, fails, vacuous


def _speeds_text(xs, ws) -> str:
    """Speeds of the grid ws as runs of consecutive points: '55..65, 110 rad/s'."""
    runs: list[list[int]] = []
    for i in sorted(int(np.argmin(np.abs(np.asarray(ws) - x))) for x in xs):
        if runs and i == runs[-1][1] + 1:
            runs[-1][1] = i
        else:
            runs.append([i, i])
    text = ", ".join(f"{ws[a]:g}" + (f"..{ws[b]:g}" if b > a else "") for a, b in runs)
    return text + " rad/s" if runs else "none"


def departures(sheet, key: str, ws, form: str = "printed"):
    """Per family member: (value, speeds where the template's departure dev_lin (dev_newton)
    exceeds its departure_limit, the largest, speeds where the denominator is <= 0)."""
    limit, out = _v(sheet, "departure_limit", ""), []
    for value, d in family(sheet, key, ws).items():
        mask, lin = d["root"] > 0, d[form]
        rel = np.where(mask, np.abs(d[f"dev {form}"]), np.nan)
        bad = mask & ((rel > limit) | np.isnan(lin))
        zero = [float(w) for w, v in zip(ws, lin) if np.isnan(v)]
        worst = float(np.nanmax(rel)) if mask.any() else 0.0
        out.append((value, [float(w) for w in ws[bad]], worst, zero))
    return out


@findings_block
def findings(sheet):
    """Printed trends, closed-form departures and the run (the steady values, the limits of
    the closed forms and the eigenvalues are the template's [[checks]])."""
    ws, out = speeds(sheet), []
    for key in FAMILY_TABLES:
        holds, fails, vacuous = trend_holds(sheet, key, ws)
        verdict = "ok" if holds and not fails else ("warning" if holds else "fail")
        note = f"holds at {_speeds_text(holds, ws)}; fails at {_speeds_text(fails, ws)}"
        if vacuous:
            note += f"; all weights on the stop at {_speeds_text(vacuous, ws)}"
        topic, n = "printed trends (Fig. 3)", float(len(holds))
        out.append(Finding(topic, TREND_TEXT[key], n, "speeds", verdict, note))
    for form, title in (("printed", "printed linear form"), ("newton", "Newton-step linear form")):
        topic = f"linear form vs nonlinear root ({form})"
        limit = f"{_v(sheet, 'departure_limit', 'percent'):g} %"
        for key in FAMILY_TABLES:
            for value, where, worst, zero in departures(sheet, key, ws, form):
                what = f"{title}, {key} = {value}: largest departure"
                note, verdict = f"within {limit} at every speed off the stop", "ok"
                if where:
                    note, verdict = f"more than {limit} at {_speeds_text(where, ws)}", "warning"
                if zero:
                    note += f"; denominator <= 0 at {_speeds_text(zero, ws)}: reported, not "
                    note += "divided by"
                out.append(Finding(topic, what + " from the root", 100 * worst, "%", verdict, note))
    return out + [history_finding(sheet)]


def history_finding(sheet) -> Finding:
    """The sheet's own run of ode motion: its cost, and its error against the exact solution."""
    from ..errors import WorkbookError

    c2, how = _v(sheet, "c2", "N/m"), "auto" if sheet.evaluate("method") == "auto" else "chosen"
    try:
        sol = sheet.evaluator.ode_solution("motion")
    except WorkbookError as err:
        what = f"time histories at c2 = {c2:.0e} N/m ({how})"
        return Finding("dynamics", what, None, "", "warning", str(err))
    cs, r = case(sheet), sol.run
    err = float(np.max(np.abs(outputs(sheet, r.sol(cs.t)) - cs.exact)))
    what = f"time histories: {sol.method} rtol {r.rtol:.0e} at c2 = {c2:.0e} N/m ({how})"
    note = f"{r.summary()}; error against the exact solution {err:.3g} rad"
    return Finding("dynamics", what, r.elapsed, "s", "ok", note)


@findings_block
def study_findings(sheet):
    """Solver choice from the work-precision study, and the explicit solver's stall (the
    optional part studies: 45 solver runs and a stalled RK45, about 12 s of CPU)."""
    short, df = _study_for_sheet(sheet)
    r, need = stall_run(sheet)
    what = f"RK45 at c2 = {STALL_C2:.0e} N/m stopped ({r.stop_reason})"
    note = f"{r.nsteps} steps in {r.elapsed:.2f} s reached t = {r.t_reached:.3g} s; "
    note += f"the stability limit needs about {need:.3g} steps"
    verdict = "ok" if not r.ok else "info"
    stall = Finding("extreme cases", what, r.fraction * 100, "% of the run", verdict, note)
    return choice_findings(short, df) + [stall]


def choice_findings(sheet, df) -> list[Finding]:
    """Is the default solver within the template's choice_time_ratio (2x) of the fastest run
    that reaches the rigid limit? And
    per c2 of the study: the fastest run with error <= 1e-6 rad beside what auto takes."""
    topic, sub = "solver choice", df[df["c2 [N/m]"] == CHOICE_C2]
    if sub.empty:
        return []
    tol = 2 * float(sub["rigid-model difference [rad]"].iloc[0])
    ok = sub[(sub["stopped"] == "finished") & (sub["deviation from rigid [rad]"] <= tol)]
    stiff = at_c2(sheet, CHOICE_C2)
    default, rtol = str(stiff.evaluate("method_used")), _v(sheet, "rtol", "")
    what = f"rigid-model difference at c2 = {CHOICE_C2:.0e} N/m"
    note = f"a run 'reaches the rigid limit' when it deviates from it by <= {tol:.3g} rad"
    out = [Finding(topic, what, tol / 2, "rad", "info", note)]
    if ok.empty:
        what = "no run of the study reaches the rigid limit"
        return out + [Finding(topic, what, None, "", "warning")]
    best = ok.loc[ok["run time [s]"].idxmin()]
    cs = case(stiff)  # time the best and the default again side by side (best of 3)
    t_best = min(run(stiff, best["method"], best["rtol"], cs.t).elapsed for _ in range(3))
    runs = [run(stiff, default, rtol, cs.t) for _ in range(3)]
    t_def = min(r.elapsed for r in runs)
    dev, ratio = deviation(cs, runs[0], cs.rigid), t_def / t_best
    what = f"fastest run reaching the rigid limit: {best['method']} rtol {best['rtol']:.0e}"
    note = f"deviation {best['deviation from rigid [rad]']:.3g} rad"
    out.append(Finding(topic, what, t_best, "s", "info", note))
    verdict = "ok" if ratio <= _v(sheet, "choice_time_ratio", "") and dev <= tol else "warning"
    note = f"{t_def:.3g} s, deviation from the rigid limit {dev:.3g} rad (<= {tol:.3g})"
    out.append(
        Finding(
            topic, f"default {default} rtol {rtol:.0e}: time / fastest", ratio, "", verdict, note
        )
    )
    for c2 in sorted(df["c2 [N/m]"].unique()):
        at = df[df["c2 [N/m]"] == c2]
        rows = at[(at["stopped"] == "finished") & (at["error [rad]"] <= 1e-6)]
        if rows.empty:
            continue
        auto = str(at_c2(sheet, c2).evaluate("method_used"))
        mine = at[(at["method"] == auto) & (at["rtol"] == rtol)]
        fast = rows.loc[rows["run time [s]"].idxmin()]
        note = f"fastest with error <= 1e-6 rad: {fast['method']} rtol {fast['rtol']:.0e}"
        if not mine.empty:
            e, t = mine["error [rad]"].iloc[0], mine["run time [s]"].iloc[0]
            note += f"; {auto} rtol {rtol:.0e}: error {e:.2g} rad, {t:.3g} s"
        what, t = f"c2 = {c2:.0e} N/m: auto takes {auto}", float(fast["run time [s]"])
        out.append(Finding(topic, what, t, "s", "info", note))
    return out


@bench_block
def bench(sheet, quick: bool = False):
    """Work-precision of RK45, DOP853, Radau, BDF, LSODA: error against run time (full study)."""
    if quick:
        short = with_input(sheet, "t_end", 0.02, "s")
        return study(short, (CHOICE_C2,), (1e-3, 1e-5), max_time=0.3, label=None)
    return study(sheet, FULL_C2, FULL_RTOLS, max_time=10.0)
