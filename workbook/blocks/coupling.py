"""Centrifugal injection-advance coupling (Braginets, Kabelkov, Meremkulov 2003).

Every formula of the scene is the template's (templates/advance-coupling.toml): the steady
weight angle phi2(omega1), the closed forms, the lift-off speed, the entries of M, Phi and H
and the weights' stiffness k_w. This module reads them through the sheet
(``sheet.evaluate``, ``sheet.with_inputs`` for the families and the c2 variants) and does
what is the scene's own: the families and trends of Fig. 3, the 3-DOF dynamics
M q'' + Phi q' + H q = M0 + M(t) against its rigid-tooth limit (eigenvalues, the exact solution
by the matrix exponential), and a work-precision study of five scipy ODE methods.

q = (phi1, phi2, phi3); phi2 is the weight lever angle from phi20; the advance angle is
psi = phi3 - phi1. The dynamics is written relative to the steady rotation omega1*t*(1, 0, 1),
the rigid rotation mode of H, so the state stays bounded.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass

import numpy as np

from .. import expr as ex
from .. import typecheck as tc
from . import Finding, bench_block, cached, findings_block, table_block
from .solvers import METHODS, OdeRun, run_ode, work_precision


def _v(sheet, name: str, unit: str, **args):
    """A definition or input of the sheet as a number (or array) in ``unit``."""
    out = sheet.evaluate(name, **args).to(unit).magnitude
    return float(out) if np.ndim(out) == 0 else np.asarray(out, dtype=float)


def with_input(sheet, name: str, value: float, unit: str):
    """The sheet with one input replaced by ``value`` in ``unit``."""
    return sheet.with_inputs(**{name: f"{float(value)!r} {unit}"})


# ---------------------------------------------------------------------------------------------
# families of Fig. 3
# ---------------------------------------------------------------------------------------------
FAMILIES = {
    "c1": ("spring stiffness c1", "N/m", (1500.0, 3000.0, 4000.0, 6000.0)),
    "m": ("weight mass m", "kg", (0.65, 0.7, 0.75, 0.8)),
    "phi20": ("initial angle phi20", "rad", (0.4363, 0.5235, 0.6108, 0.6981)),
}
# the printed trends: phi2 falls as c1 rises, rises with m and with phi20
TRENDS = {"c1": -1, "m": +1, "phi20": +1}
TREND_TEXT = {
    "c1": "phi2 falls as c1 rises",
    "m": "phi2 rises with m",
    "phi20": "phi2 rises with phi20",
}


def speeds(sheet) -> np.ndarray:
    """The speeds of the template's steady table (rad/s)."""
    spec = sheet.table_spec("steady")
    return sheet.range_values(spec.range, "table steady")


def closed_form(sheet, ws, form: str = "printed") -> tuple[np.ndarray, np.ndarray]:
    """(value, denominator) of the template's closed form (phi2_lin or phi2_newton): NaN where
    its denominator is not positive (the template gives no value there)."""
    suffix = "lin" if form == "printed" else "newton"
    den = np.atleast_1d(_v(sheet, f"D_{suffix}", "N*m", omega1=ws))
    value = np.full(den.shape, math.nan)
    ok = den > 0
    if ok.any():
        value[ok] = _v(sheet, f"phi2_{suffix}", "rad", omega1=np.asarray(ws)[ok])
    return value, den


def family(sheet, key: str, ws) -> dict[float, dict[str, np.ndarray]]:
    """For each value of the family parameter: nonlinear root and both closed forms."""

    def build():
        out = {}
        for value in FAMILIES[key][2]:
            s = with_input(sheet, key, value, FAMILIES[key][1])
            printed, den = closed_form(s, ws, "printed")
            out[value] = {
                "root": np.atleast_1d(_v(s, "phi2", "rad", omega1=ws)),
                "printed": printed,
                "D": den,
                "newton": closed_form(s, ws, "newton")[0],
            }
        return out

    return cached(sheet, ("family", key, tuple(ws)), build)


def _family_table(sheet, key: str):
    import pandas as pd

    ws = speeds(sheet)
    fam = family(sheet, key, ws)
    unit = FAMILIES[key][1]
    cols = {"omega1 [rad/s]": ws}
    for value, d in fam.items():
        cols[f"phi2 {key}={value:g} {unit} [rad]"] = d["root"]
    for value, d in fam.items():
        cols[f"linear {key}={value:g} [rad]"] = d["printed"]
    return pd.DataFrame(cols)


@table_block
def family_c1(sheet):
    """Fig. 3a: phi2(omega1) for c1 = 1500, 3000, 4000, 6000 N/m (root, printed closed form)."""
    return _family_table(sheet, "c1")


@table_block
def family_m(sheet):
    """Fig. 3b: phi2(omega1) for m = 0.65 .. 0.8 kg."""
    return _family_table(sheet, "m")


@table_block
def family_phi20(sheet):
    """Fig. 3c: phi2(omega1) for phi20 = 0.4363 .. 0.6981 rad."""
    return _family_table(sheet, "phi20")


# ---------------------------------------------------------------------------------------------
# dynamics: linear 3-DOF model and its rigid-tooth limit
# ---------------------------------------------------------------------------------------------
@dataclass
class LinearModel:
    """M x'' + Phi x' + K x = f0 + fp*sin(Omega t) in coordinates x = C p (C maps reduced to q)."""

    M: np.ndarray
    Phi: np.ndarray
    K: np.ndarray
    f0: np.ndarray
    fp: np.ndarray
    Omega: float
    C: np.ndarray  # q = C x (3 x n)
    x0: np.ndarray
    name: str

    @property
    def n(self) -> int:
        return self.M.shape[0]

    def first_order(self):
        """A, b, g of y' = A y + b + g sin(Omega t), y = (x, x')."""
        n = self.n
        Minv = np.linalg.inv(self.M)
        A = np.zeros((2 * n, 2 * n))
        A[:n, n:] = np.eye(n)
        A[n:, :n] = -Minv @ self.K
        A[n:, n:] = -Minv @ self.Phi
        b = np.concatenate([np.zeros(n), Minv @ self.f0])
        g = np.concatenate([np.zeros(n), Minv @ self.fp])
        return A, b, g

    def y0(self) -> np.ndarray:
        return np.concatenate([self.x0, np.zeros(self.n)])

    def outputs(self, y: np.ndarray) -> np.ndarray:
        """(phi2, psi) rows from states y (2n x k): psi = phi3 - phi1, the advance angle."""
        q = self.C @ y[: self.n]
        return np.vstack([q[1], q[2] - q[0]])


def _matrix(sheet, names, unit) -> np.ndarray:
    """A symmetric 3x3 matrix from the template's entries (upper triangle, row by row)."""
    vals = {n: _v(sheet, n, unit) for n in names if n}
    out = np.zeros((3, 3))
    for (i, j), n in zip(((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)), names):
        if n:
            out[i, j] = out[j, i] = vals[n]
    return out


def model(sheet, *, rigid: bool = False, damping: str = "corrected") -> LinearModel:
    """The coupling about its steady state at omega_dyn, driven by the pump torque
    pump_amp*sin(pump_order*omega_dyn*t) on the driven half (M_N0 = M_D0: balanced torques).

    rigid=True gives the rigid-tooth limit (2 DOF, phi3 = phi1 + k_gear*phi2). If the weights
    sit on the stop, phi2 is held at 0 (one DOF fewer).
    """
    w = _v(sheet, "omega_dyn", "rad/s")
    phi2 = _v(sheet, "phi2", "rad", omega1=w)
    on_stop = _v(sheet, "F0", "N*m", omega1=w) <= 0
    M3 = _matrix(sheet, ("a11", "a12", "", "a22", "", "a33"), "kg*m^2")
    b22 = _v(sheet, "b22_printed" if damping == "as printed" else "b22", "N*m*s")
    Phi3 = np.diag([0.0, b22, 0.0])
    H3 = _matrix(sheet, ("c11", "c12", "c13", "c22", "c23", "c33"), "N*m")
    kw = _v(sheet, "k_w", "N*m")
    K3 = H3 + np.diag([0.0, 0.0 if on_stop else kw, 0.0])
    M_D0 = _v(sheet, "M_D0", "N*m")
    f0 = np.array([M_D0, _v(sheet, "Q2_dyn", "N*m"), -M_D0])  # M0 + the weights
    fp = np.array([0.0, 0.0, -_v(sheet, "pump_amp", "N*m")])
    k = _v(sheet, "k_gear", "")
    if rigid:
        C = np.array([[1.0, 0.0], [0.0, 1.0], [1.0, k]])
        x0 = np.array([0.0, phi2])
        K3 = K3 - H3  # the tooth does no work on a rigid-tooth motion
    else:
        C = np.eye(3)
        x0 = np.array([0.0, phi2, _v(sheet, "psi_dyn", "rad")])
    if on_stop:  # weights held on the stop: drop phi2 (and its constant force)
        f0[1] = 0.0
        keep = [0] if rigid else [0, 2]
        C, x0 = (
            (np.array([[1.0], [0.0], [1.0]]), np.array([0.0])) if rigid else (C[:, keep], x0[keep])
        )
    return LinearModel(
        C.T @ M3 @ C,
        C.T @ Phi3 @ C,
        C.T @ K3 @ C,
        C.T @ f0,
        C.T @ fp,
        _v(sheet, "Omega_pump", "rad/s"),
        C,
        x0,
        "rigid tooth" if rigid else "3 DOF",
    )


def eigen(sheet, damping: str = "corrected"):
    """Eigenvalues of the linear system without the rigid rotation mode, sorted by size.

    The rigid rotation r0 (K r0 = 0, Phi r0 = 0) is condensed out: in coordinates (r0, rest)
    its row says (M u)_r0 = 0 for every mode with lambda != 0, which leaves the Schur
    complement of M on the rest; no near-zero eigenvalue has to be told from round-off.
    """
    mdl = model(sheet, damping=damping)
    n = mdl.n
    r0 = np.linalg.svd(mdl.K)[2][-1]
    T = np.linalg.svd(np.column_stack([r0, np.eye(n)]))[0]  # r0 first, then its complement
    T[:, 0] = r0
    Mr, Pr, Kr = T.T @ mdl.M @ T, T.T @ mdl.Phi @ T, T.T @ mdl.K @ T
    Mred = Mr[1:, 1:] - np.outer(Mr[1:, 0], Mr[0, 1:]) / Mr[0, 0]
    m = n - 1
    if m == 0:
        return np.empty(0, dtype=complex)
    Minv = np.linalg.inv(Mred)
    A = np.zeros((2 * m, 2 * m))
    A[:m, m:] = np.eye(m)
    A[m:, :m] = -Minv @ Kr[1:, 1:]
    A[m:, m:] = -Minv @ Pr[1:, 1:]
    lam = np.linalg.eigvals(A)
    return lam[np.argsort(np.abs(lam))]


def stiffness(sheet) -> dict:
    """Stiffness measures: ratio max|lambda|/min|lambda| and max|lambda| * t_end (the number of
    radians of the fastest mode over the run: about the steps an explicit method needs / 3)."""
    lam = eigen(sheet)
    big, small = float(np.max(np.abs(lam))), float(np.min(np.abs(lam)))
    tooth = lam[np.argmax(np.abs(lam))]
    return {
        "lam": lam,
        "ratio": big / small,
        "index": big * _v(sheet, "t_end", "s"),
        "tooth_damping": -tooth.real / abs(tooth),
    }


class Problem:
    """The ODE of a LinearModel with its constant Jacobian, and its exact solution."""

    def __init__(self, mdl: LinearModel, t_end: float, n_out: int = 401):
        self.model = mdl
        self.A, self.b, self.g = mdl.first_order()
        self.Omega = mdl.Omega
        self.y0 = mdl.y0()
        self.t_end = t_end
        self.t_eval = np.linspace(0.0, t_end, n_out)
        A, b, g, Om = self.A, self.b, self.g, self.Omega
        self.fun = lambda t, y: A @ y + b + g * math.sin(Om * t)
        self.jac = lambda t, y: A

    def atol(self, rtol: float) -> np.ndarray:
        """Absolute tolerances scaled per state: angles 1e-3 rad, rates Omega*1e-3 rad/s."""
        n = self.model.n
        scale = np.concatenate([np.full(n, 1.0), np.full(n, max(self.Omega, 1.0))])
        return rtol * 1e-3 * scale

    def run(
        self,
        method: str,
        rtol: float,
        *,
        max_time: float = 20.0,
        max_steps: int = 2_000_000,
        label: str | None = None,
    ) -> OdeRun:
        return run_ode(
            self.fun,
            (0.0, self.t_end),
            self.y0,
            method=method,
            rtol=rtol,
            atol=self.atol(rtol),
            jac=self.jac,
            t_eval=self.t_eval,
            max_time=max_time,
            max_steps=max_steps,
            label=label,
        )

    def exact(self) -> np.ndarray:
        """Exact solution at t_eval from the matrix exponential of the system augmented with
        the forcing (z = (y, 1, sin, cos)): independent of any ODE method."""
        from scipy.linalg import expm

        t = self.t_eval
        N = len(self.y0)
        Z = np.zeros((N + 3, N + 3))
        Z[:N, :N] = self.A
        Z[:N, N] = self.b
        Z[:N, N + 1] = self.g
        Z[N + 1, N + 2] = self.Omega
        Z[N + 2, N + 1] = -self.Omega
        z = np.concatenate([self.y0, [1.0, 0.0, 1.0]])
        out = np.empty((N, len(t)))
        out[:, 0] = z[:N]
        # one propagator for the uniform grid, refined by substeps so that |lambda h| stays small
        h = t[1] - t[0]
        sub = max(1, int(math.ceil(np.max(np.abs(np.linalg.eigvals(self.A))) * h / 0.5)))
        E = np.linalg.matrix_power(expm(Z * (h / sub)), sub)
        for k in range(1, len(t)):
            z = E @ z
            out[:, k] = z[:N]
        return out


# ---------------------------------------------------------------------------------------------
# solver choice, study, cache
# ---------------------------------------------------------------------------------------------
AUTO_INDEX = 3000.0  # |lambda_max|*t_end above which "auto" takes Radau (from the study)
STUDY_C2 = (1e6, 1e8, 1e10)
STUDY_RTOLS = (1e-3, 1e-5, 1e-7)
FULL_C2 = (1e6, 1e7, 1e8, 1e9, 1e10)
FULL_RTOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)
CHOICE_C2 = 1e10  # the stiff case the default solver is judged on
STALL_C2 = 1e14  # the extreme case where explicit methods stall
STUDY_T = 0.1  # s: the workbook's shortened study runs over min(t_end, STUDY_T)


def at_c2(sheet, c2: float):
    return with_input(sheet, "c2", c2, "N/m")


def auto_method(sheet) -> str:
    """The default solver: Radau when the tooth mode makes the run stiff (stiffness index
    |lambda_max|*t_end above AUTO_INDEX), LSODA otherwise. See docs/advance-coupling.md."""
    return "Radau" if stiffness(sheet)["index"] > AUTO_INDEX else "LSODA"


def method_of(sheet) -> str:
    return str(sheet.evaluate("method"))


def chosen_method(sheet) -> str:
    m = method_of(sheet)
    return auto_method(sheet) if m == "auto" else m


@dataclass
class Case:
    """One sheet (one c2): the 3-DOF problem, its exact solution and the rigid-tooth limit."""

    c2: float
    problem: Problem
    exact: np.ndarray  # outputs (phi2, psi) of the exact 3-DOF solution
    rigid: np.ndarray  # outputs of the exact rigid-tooth solution
    delta: float  # max |3-DOF - rigid| (model difference)


def case(sheet, n_out: int = 401) -> Case:
    t_end = _v(sheet, "t_end", "s")

    def build():
        pr = Problem(model(sheet), t_end, n_out)
        rg = Problem(model(sheet, rigid=True), t_end, n_out)
        ex_, rr = pr.model.outputs(pr.exact()), rg.model.outputs(rg.exact())
        return Case(_v(sheet, "c2", "N/m"), pr, ex_, rr, float(np.max(np.abs(ex_ - rr))))

    return cached(sheet, ("case", n_out), build)


def _dev(cs: Case, run: OdeRun, against: np.ndarray) -> float:
    if not run.ok or run.y.shape[1] != against.shape[1]:
        return math.nan
    return float(np.max(np.abs(cs.problem.model.outputs(run.y) - against)))


def study(
    sheet,
    c2s,
    rtols,
    methods=METHODS,
    *,
    max_time=5.0,
    label: str | None = "advance-coupling study",
):
    """Work-precision rows: every method x rtol at every c2; error against the exact solution
    and deviation from the exact rigid-tooth limit."""
    import pandas as pd

    def build():
        rows = []
        if label:
            print(
                f"[{label}] {len(c2s) * len(rtols) * len(methods)} runs: {len(methods)} methods"
                f" x {len(rtols)} rtols x c2 = {', '.join(f'{c:.0e}' for c in c2s)} N/m "
                f"(each run at most {max_time:g} s)",
                file=sys.stderr,
                flush=True,
            )
        for c2 in c2s:
            cs = case(at_c2(sheet, c2))
            runs = {}

            def run_case(method, rtol, cs=cs, runs=runs):
                runs[(method, rtol)] = cs.problem.run(method, rtol, max_time=max_time, label=label)
                return runs[(method, rtol)]

            for r in work_precision(
                run_case, lambda run, cs=cs: _dev(cs, run, cs.exact), methods, rtols, label=None
            ):
                run = runs.get((r.method, r.rtol))
                rows.append(
                    {
                        "c2 [N/m]": c2,
                        "method": r.method,
                        "rtol": r.rtol,
                        "error [rad]": r.error,
                        "deviation from rigid [rad]": _dev(cs, run, cs.rigid) if run else math.nan,
                        "rigid-model difference [rad]": cs.delta,
                        "run time [s]": r.elapsed,
                        "f-evals": r.nfev,
                        "steps": r.nsteps,
                        "stopped": r.stop_reason,
                    }
                )
            if label:
                print(f"[{label}] c2 = {c2:.0e} N/m done", file=sys.stderr, flush=True)
        return pd.DataFrame(rows)

    return cached(sheet, ("study", tuple(c2s), tuple(rtols), tuple(methods), max_time), build)


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
    for m in METHODS:
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


@table_block
def stiffness_table(sheet):
    """Eigenvalues (rigid rotation excluded) and stiffness measures for c2 = 1e6 .. 1e10 N/m."""
    import pandas as pd

    rows = []
    for c2 in FULL_C2:
        s2 = at_c2(sheet, c2)
        s, cs = stiffness(s2), case(s2)
        lam = s["lam"]
        rows.append(
            {
                "c2 [N/m]": c2,
                "weight mode Re [1/s]": float(lam[0].real),
                "weight mode Im [rad/s]": abs(lam[0].imag),
                "tooth mode Re [1/s]": float(lam[-1].real),
                "tooth mode Im [rad/s]": abs(lam[-1].imag),
                "tooth damping ratio": s["tooth_damping"],
                "stiffness ratio |lam|max/|lam|min": s["ratio"],
                "stiffness index |lam|max*t_end": s["index"],
                "rigid-model difference [rad]": cs.delta,
                "difference*c2 [N rad/m]": cs.delta * c2,
                "auto method": auto_method(s2),
            }
        )
    return pd.DataFrame(rows)


def default_run(sheet):
    """The sheet's own run (method, rtol, max_time): the case and the run, computed once."""
    method, rtol = chosen_method(sheet), _v(sheet, "rtol", "")

    def build():
        cs = case(sheet)
        run = cs.problem.run(
            method, rtol, max_time=_v(sheet, "max_time", "s"), label="advance-coupling dynamics"
        )
        return cs, run

    return cached(sheet, ("history", method), build)


@table_block
def histories(sheet):
    """Time histories of phi2 and the advance angle psi = phi3 - phi1 (3 DOF and rigid tooth)."""
    import pandas as pd

    cs, run = default_run(sheet)
    t = cs.problem.t_eval
    out = np.full((2, len(t)), math.nan)
    k = run.y.shape[1] if not run.ok else len(t)  # a partial run: keep what was reached
    out[:, :k] = cs.problem.model.outputs(run.y)[:, :k]
    return _blank(
        pd.DataFrame(
            {
                "t [s]": t,
                "phi2 [rad]": out[0],
                "advance psi [deg]": np.degrees(out[1]),
                "phi2 rigid tooth [rad]": cs.rigid[0],
                "advance psi rigid tooth [deg]": np.degrees(cs.rigid[1]),
                "phi2 - rigid [rad]": out[0] - cs.rigid[0],
            }
        )
    )


# ---------------------------------------------------------------------------------------------
# extreme cases
# ---------------------------------------------------------------------------------------------
def stall_run(
    sheet, method: str = "RK45", c2: float = STALL_C2, max_time: float = 0.5, max_steps=20_000
) -> tuple[OdeRun, float]:
    """An explicit method on a very stiff tooth: bounded by a budget and a step cap.
    Returns the run and the steps it would need at its stability limit (about index/3)."""
    s2 = at_c2(sheet, c2)
    run = case(s2).problem.run(
        method, 1e-5, max_time=max_time, max_steps=max_steps, label="advance-coupling stall"
    )
    return run, stiffness(s2)["index"] / 3.3


def soft_spring_limit(sheet, w: float, form: str = "printed") -> float:
    """Spring stiffness c1 below which the closed form's denominator is <= 0 at speed w
    (the template's denominator is linear in c1: one secant step is exact)."""
    name = "D_lin" if form == "printed" else "D_newton"
    c1 = _v(sheet, "c1", "N/m")
    d1 = _v(sheet, name, "N*m", omega1=w)
    d2 = _v(with_input(sheet, "c1", 2 * c1, "N/m"), name, "N*m", omega1=w)
    return c1 - d1 * c1 / (d2 - d1)


def denominator_zero_speed(sheet, form: str = "printed") -> float:
    """Speed at which the closed form's denominator passes through zero [rad/s] (the
    template's denominator is k - c*omega1^2: its values at 0 and 1 rad/s give k and c)."""
    name = "D_lin" if form == "printed" else "D_newton"
    k = _v(sheet, name, "N*m", omega1=0.0)
    c = k - _v(sheet, name, "N*m", omega1=1.0)
    return math.sqrt(k / c) if c > 0 else math.inf


# ---------------------------------------------------------------------------------------------
# findings
# ---------------------------------------------------------------------------------------------
SCENE_VALUES = ((50.0, 0.0), (80.0, 0.070), (110.0, 0.204))  # the reference example, base case


def trend_holds(sheet, key: str, ws) -> tuple[list[float], list[float], list[float]]:
    """Speeds where the printed trend holds strictly, where it fails, where it is vacuous
    (every member of the family on the stop)."""
    fam = family(sheet, key, ws)
    vals = np.array([fam[v]["root"] for v in FAMILIES[key][2]])  # members x speeds
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


def _speeds_text(xs, all_speeds) -> str:
    """Speeds as runs of consecutive grid points: '55..65, 110 rad/s'."""
    if not xs:
        return "none"
    index = {w: i for i, w in enumerate(sorted(all_speeds))}
    xs = sorted(xs)
    runs, start, prev = [], xs[0], xs[0]
    for w in xs[1:]:
        if index.get(w, -9) != index.get(prev, -99) + 1:
            runs.append((start, prev))
            start = w
        prev = w
    runs.append((start, prev))
    return ", ".join(f"{a:g}" if a == b else f"{a:g}..{b:g}" for a, b in runs) + " rad/s"


def departures(sheet, key: str, ws, form: str = "printed", limit: float = 0.05):
    """Per family member: (value, speeds with |lin - root| > limit*root, max rel. departure,
    speeds where the denominator is <= 0)."""
    out = []
    for value, d in family(sheet, key, ws).items():
        root = d["root"]
        lin = d["printed"] if form == "printed" else d["newton"]
        mask = root > 0
        rel = np.full(len(ws), np.nan)
        rel[mask] = np.abs(lin[mask] - root[mask]) / root[mask]
        bad = mask & ((rel > limit) | np.isnan(lin))
        zero = [float(w) for w, v in zip(ws, lin) if np.isnan(v)]
        worst = float(np.nanmax(rel)) if mask.any() else 0.0
        out.append((value, [float(w) for w in ws[bad]], worst, zero))
    return out


def _is_example(sheet) -> bool:
    """Are the inputs that phi2 depends on those of the template (the reference example)?"""
    used = tc.dependencies(sheet.spec, ex.Name("phi2")) & set(sheet.spec.inputs)
    return all(sheet.values[n] == sheet.spec.inputs[n].value for n in used)


@findings_block
def findings(sheet):
    """Steady values, printed trends, closed-form departures, stiffness and the run."""
    F = Finding
    ws = speeds(sheet)
    out: list[Finding] = []
    example = _is_example(sheet)
    for w, ref in SCENE_VALUES:
        val = _v(sheet, "phi2", "rad", omega1=w)
        if example:
            ok = "ok" if abs(val - ref) <= 1e-3 else "fail"
            out.append(
                F(
                    "steady state",
                    f"phi2 at omega1 = {w:g} rad/s (reference example: {ref:.3f})",
                    val,
                    "rad",
                    ok,
                )
            )
        else:
            out.append(
                F(
                    "steady state",
                    f"phi2 at omega1 = {w:g} rad/s",
                    val,
                    "rad",
                    "info",
                    "inputs differ from the reference example",
                )
            )
    stop = [float(w) for w, f0 in zip(ws, _v(sheet, "F0", "N*m", omega1=ws)) if f0 <= 0]
    out.append(
        F(
            "steady state",
            "lift-off speed (weights leave the stop)",
            _v(sheet, "omega_lift", "rad/s"),
            "rad/s",
            "info",
            f"on the stop at {_speeds_text(stop, ws)}: phi2 = 0 there, not a root",
        )
    )
    for key in FAMILIES:
        holds, fails, vacuous = trend_holds(sheet, key, ws)
        verdict = "ok" if holds and not fails else ("warning" if holds else "fail")
        note = f"holds at {_speeds_text(holds, ws)}; fails at {_speeds_text(fails, ws)}"
        if vacuous:
            note += f"; all weights on the stop at {_speeds_text(vacuous, ws)}"
        out.append(
            F(
                "printed trends (Fig. 3)",
                TREND_TEXT[key],
                float(len(holds)),
                "speeds",
                verdict,
                note,
            )
        )
    for form, title in (("printed", "printed linear form"), ("newton", "Newton-step linear form")):
        for key in FAMILIES:
            for value, where, worst, zero in departures(sheet, key, ws, form):
                unit = FAMILIES[key][1]
                what = f"{title}, {key} = {value:g} {unit}: largest departure from the root"
                note, verdict = "within 5 % at every speed off the stop", "ok"
                if where:
                    note, verdict = f"more than 5 % at {_speeds_text(where, ws)}", "warning"
                if zero:
                    note += (
                        f"; denominator <= 0 at {_speeds_text(zero, ws)}: reported, not divided by"
                    )
                out.append(
                    F(
                        f"linear form vs nonlinear root ({form})",
                        what,
                        100 * worst,
                        "%",
                        verdict,
                        note,
                    )
                )
    wmax, c1 = float(ws[-1]), _v(sheet, "c1", "N/m")
    for form in ("printed", "newton"):
        out.append(
            F(
                "extreme cases",
                f"{form} linear form: denominator passes through zero at {wmax:g} rad/s "
                "for springs softer than",
                soft_spring_limit(sheet, wmax, form),
                "N/m",
                "info",
                f"with c1 = {c1:g} N/m it is zero at "
                f"{denominator_zero_speed(sheet, form):.4g} rad/s",
            )
        )
    c2 = _v(sheet, "c2", "N/m")
    lam = eigen(sheet)
    out.append(
        F(
            "dynamics",
            f"weight mode at c2 = {c2:.0e} N/m: Im lambda",
            abs(lam[0].imag),
            "rad/s",
            "info",
            f"Re lambda = {lam[0].real:.4g} 1/s",
        )
    )
    out.append(
        F(
            "dynamics",
            "tooth mode: Im lambda",
            abs(lam[-1].imag),
            "rad/s",
            "info",
            f"Re lambda = {lam[-1].real:.3g} 1/s (almost undamped)",
        )
    )
    out.append(
        F(
            "dynamics",
            "with the printed damping sign (-beta OC^2 sin^2 phi20) the weight mode grows: "
            "Re lambda",
            float(eigen(sheet, damping="as printed")[0].real),
            "1/s",
            "warning",
            "negative damping; the corrected sign is used",
        )
    )
    cs, run = default_run(sheet)
    note = run.summary()
    if run.ok:
        note += f"; error against the exact solution {_dev(cs, run, cs.exact):.3g} rad"
    how = "auto" if method_of(sheet) == "auto" else "chosen"
    out.append(
        F(
            "dynamics",
            f"time histories: {run.method} rtol {run.rtol:.0e} at c2 = {c2:.0e} N/m ({how})",
            run.elapsed,
            "s",
            "ok" if run.ok else "warning",
            note,
        )
    )
    return out


@findings_block
def study_findings(sheet):
    """Solver choice from the work-precision study, and the explicit solver's stall (the
    optional part studies: 45 solver runs and a stalled RK45, a few seconds)."""
    short, df = _study_for_sheet(sheet)
    out = choice_findings(short, df)
    run, need = stall_run(sheet)
    out.append(
        Finding(
            "extreme cases",
            f"RK45 at c2 = {STALL_C2:.0e} N/m stopped ({run.stop_reason})",
            run.fraction * 100,
            "% of the run",
            "ok" if not run.ok else "info",
            f"{run.nsteps} steps in {run.elapsed:.2f} s reached t = {run.t_reached:.3g} s; "
            f"the stability limit needs about {need:.3g} steps",
        )
    )
    return out


def choice_findings(sheet, df) -> list[Finding]:
    """Is the default solver within 2x of the fastest run that reaches the rigid limit?"""
    F = Finding
    sub = df[df["c2 [N/m]"] == CHOICE_C2]
    if sub.empty:
        return []
    tol = 2 * float(sub["rigid-model difference [rad]"].iloc[0])
    ok = sub[(sub["stopped"] == "finished") & (sub["deviation from rigid [rad]"] <= tol)]
    stiff = at_c2(sheet, CHOICE_C2)
    default, rtol = chosen_method(stiff), _v(sheet, "rtol", "")
    out = [
        F(
            "solver choice",
            f"rigid-model difference at c2 = {CHOICE_C2:.0e} N/m",
            tol / 2,
            "rad",
            "info",
            f"a run 'reaches the rigid limit' when it deviates from it by <= {tol:.3g} rad",
        )
    ]
    if ok.empty:
        return out + [
            F("solver choice", "no run of the study reaches the rigid limit", None, "", "warning")
        ]
    best = ok.loc[ok["run time [s]"].idxmin()]
    # time the best and the default again side by side (best of 3)
    cs = case(stiff)
    t_best = min(cs.problem.run(best["method"], best["rtol"]).elapsed for _ in range(3))
    runs = [cs.problem.run(default, rtol) for _ in range(3)]
    t_def = min(r.elapsed for r in runs)
    dev, ratio = _dev(cs, runs[0], cs.rigid), t_def / t_best
    out.append(
        F(
            "solver choice",
            f"fastest run reaching the rigid limit: {best['method']} rtol {best['rtol']:.0e}",
            t_best,
            "s",
            "info",
            f"deviation {best['deviation from rigid [rad]']:.3g} rad",
        )
    )
    out.append(
        F(
            "solver choice",
            f"default {default} rtol {rtol:.0e}: time / fastest",
            ratio,
            "",
            "ok" if ratio <= 2 and dev <= tol else "warning",
            f"{t_def:.3g} s, deviation from the rigid limit {dev:.3g} rad (<= {tol:.3g})",
        )
    )
    for c2 in sorted(df["c2 [N/m]"].unique()):
        at = df[df["c2 [N/m]"] == c2]
        rows = at[(at["stopped"] == "finished") & (at["error [rad]"] <= 1e-6)]
        if rows.empty:
            continue
        auto = chosen_method(at_c2(sheet, c2))
        mine = at[(at["method"] == auto) & (at["rtol"] == rtol)]
        fast = rows.loc[rows["run time [s]"].idxmin()]
        note = f"fastest with error <= 1e-6 rad: {fast['method']} rtol {fast['rtol']:.0e}"
        if not mine.empty:
            note += (
                f"; {auto} rtol {rtol:.0e}: error {mine['error [rad]'].iloc[0]:.2g} rad, "
                f"{mine['run time [s]'].iloc[0]:.3g} s"
            )
        out.append(
            F(
                "solver choice",
                f"c2 = {c2:.0e} N/m: auto takes {auto}",
                float(fast["run time [s]"]),
                "s",
                "info",
                note,
            )
        )
    out.append(
        F(
            "solver choice",
            "why",
            None,
            "",
            "info",
            "the tooth mode is almost undamped and, for c2 >= 1e9 N/m, far faster than the "
            "weights: explicit methods (RK45, DOP853) must follow it with about "
            "|lambda|*t_end/3 steps, LSODA falls back to small steps, BDF of high order is "
            "not stable near the imaginary axis; Radau (L-stable) steps over it. So 'auto' "
            f"takes Radau when |lambda_max|*t_end > {AUTO_INDEX:g}, LSODA (cheapest in the "
            "study at small c2) otherwise",
        )
    )
    return out


@bench_block
def bench(sheet, quick: bool = False):
    """Work-precision of RK45, DOP853, Radau, BDF, LSODA: error against run time (full study)."""
    if quick:
        short = with_input(sheet, "t_end", 0.02, "s")
        return study(short, (CHOICE_C2,), (1e-3, 1e-5), max_time=0.3, label=None)
    return study(sheet, FULL_C2, FULL_RTOLS, max_time=10.0)
