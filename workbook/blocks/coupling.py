"""Centrifugal injection-advance coupling (Braginets, Kabelkov, Meremkulov 2003).

Steady weight angle phi2(omega1) from the nonlinear equilibrium of the lever weights (root
finding on the stable branch, the weights resting on the stop below the lift-off speed), the
paper's linearised closed form beside it, and the 3-DOF dynamics M q'' + Phi q' + H q = M0 + M(t)
with the corrections listed in SCENES.md section 4, compared with its rigid-tooth limit and
integrated by five scipy methods in a work-precision study.

Conventions (SI inside): q = (phi1, phi2, phi3); phi2 is the weight lever angle measured from
its initial angle phi20; the advance angle is psi = phi3 - phi1 (the driven half ahead of the
driving half). The dynamics is written relative to the steady rotation omega1*t*(1, 0, 1),
which is the rigid rotation mode of H (H (1, 0, 1) = 0), so the state stays bounded.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, fields, replace

import numpy as np

from . import Finding, bench_block, block, findings_block, table_block
from .solvers import METHODS, OdeRun, run_ode, stable_root, work_precision

# ---------------------------------------------------------------------------------------------
# parameters
# ---------------------------------------------------------------------------------------------
_STEADY_SI = {  # the data of the steady equilibrium, in the SI units the blocks take
    "m": "kg",
    "c1": "N/m",
    "phi20": "rad",
    "lam_st": "m",
    "O1O": "m",
    "OC": "m",
    "OC1": "m",
    "OB": "m",
    "O1B": "m",
    "tan_gamma": "",
    "M_D0": "N*m",
}
_SI = {
    **_STEADY_SI,
    "J1": "kg*m^2",
    "J3": "kg*m^2",
    "Jx": "kg*m^2",
    "Jy": "kg*m^2",
    "Jxy": "kg*m^2",
    "beta": "N*s/m",
    "c2": "N/m",
    "omega_dyn": "rad/s",
    "pump_amp": "N*m",
    "pump_order": "",
    "t_end": "s",
}


@dataclass(frozen=True)
class Params:
    """Coupling data in SI units (the SCENES.md example by default)."""

    m: float = 0.7
    c1: float = 3000.0
    phi20: float = 0.5236
    lam_st: float = 1.0e-3
    O1O: float = 0.042
    OC: float = 0.036
    OC1: float = 0.052
    OB: float = 0.015
    O1B: float = 0.040
    tan_gamma: float = 1.0 / 3.0
    M_D0: float = 1.2
    J1: float = 0.02
    J3: float = 0.01
    Jx: float = 1.5e-4
    Jy: float = 1.5e-4
    Jxy: float = 0.0
    beta: float = 20.0
    c2: float = 1.0e8
    omega_dyn: float = 80.0
    pump_amp: float = 2.0
    pump_order: float = 4.0
    t_end: float = 0.2

    @classmethod
    def from_sheet(cls, sheet) -> Params:
        """Read the template inputs of the same names (any that exist) in SI units."""
        values = {}
        for f in fields(cls):
            q = sheet.values.get(f.name)
            if q is None or isinstance(q, str):
                continue
            values[f.name] = (
                float(q.to(_SI[f.name]).magnitude) if _SI[f.name] else float(q.to("").magnitude)
            )
        return cls(**values)

    @property
    def G(self) -> float:
        """Torque of the tooth reaction on the weights, M_D0*(OB/O1B)*tan(gamma) [N m]."""
        return self.M_D0 * self.OB / self.O1B * self.tan_gamma

    @property
    def k_ratio(self) -> float:
        """Rigid-tooth gear ratio: phi3 - phi1 = k*phi2, k = OB*tan(gamma)/O1B."""
        return self.OB * self.tan_gamma / self.O1B


def method_of(sheet) -> str:
    value = sheet.values.get("method", "auto")
    return value if isinstance(value, str) else "auto"


# ---------------------------------------------------------------------------------------------
# steady state
# ---------------------------------------------------------------------------------------------
def weight_force(phi, w, p: Params):
    """Generalized force on the weights at absolute lever angle phi (centrifugal - spring),
    without the tooth reaction G [N m]."""
    phi = np.asarray(phi, dtype=float)
    centrifugal = 2 * p.m * w**2 * (p.O1O - p.OC * np.cos(phi)) * p.OC * np.sin(phi)
    spring = 8 * p.c1 * (p.lam_st + p.OC1 * (np.cos(p.phi20) - np.cos(phi))) * p.OC1 * np.sin(phi)
    return centrifugal - spring


def weight_stiffness(phi, w, p: Params) -> float:
    """k_w = -dQ_w/dphi at the lever angle phi [N m/rad] (spring minus centrifugal softening)."""
    s, c = math.sin(phi), math.cos(phi)
    dcent = 2 * p.m * w**2 * p.OC * (p.OC * s * s + (p.O1O - p.OC * c) * c)
    dspring = 8 * p.c1 * p.OC1 * (p.OC1 * s * s + (p.lam_st + p.OC1 * (math.cos(p.phi20) - c)) * c)
    return dspring - dcent


@dataclass
class Steady:
    phi2: float  # rad, from phi20
    on_stop: bool
    margin: float  # F(phi20) [N m]: > 0 the weights lift off the stop
    iterations: int = 0
    reason: str = ""


def steady(w: float, p: Params) -> Steady:
    """Stable equilibrium of the weights at shaft speed w (rad/s)."""
    F = lambda phi: weight_force(phi, w, p) - p.G
    margin = float(F(np.asarray([p.phi20]))[0])
    if margin <= 0:
        return Steady(0.0, True, margin, 0, "on the stop")
    upper = math.pi - 1e-9 if p.G > 0 else math.pi - 1e-6
    r = stable_root(F, p.phi20, upper, n=512)
    if not r.converged:
        return Steady(math.nan, False, margin, r.iterations, r.reason)
    return Steady(r.x - p.phi20, False, margin, r.iterations, "root")


def lift_off_speed(p: Params) -> float:
    """Speed at which the weights leave the stop, F(phi20) = 0 [rad/s]."""
    s, A = math.sin(p.phi20), p.O1O - p.OC * math.cos(p.phi20)
    num = 8 * p.c1 * p.lam_st * p.OC1 * s + p.G
    den = 2 * p.m * A * p.OC * s
    return math.sqrt(num / den) if den > 0 and num >= 0 else math.nan


@dataclass
class Linear:
    value: float  # NaN when the denominator is not positive
    numerator: float
    denominator: float


def linear_phi2(w: float, p: Params, form: str = "printed") -> Linear:
    """The paper's closed form phi2 = N/D (one linearisation step about phi20), clamped at the stop.

    form "printed": the denominator as legible in the print,
        8 c1 (lam_st OC1 cos phi20 + OC1^2 sin^2 phi20) - 2 m w^2 (O1O - OC cos phi20) OC cos phi20;
    form "newton": the consistent first-order step -F(phi20)/F'(phi20), whose centrifugal part
        also has the term 2 m w^2 OC^2 sin^2 phi20.
    The numerator is F(phi20) (its last printed term 2 c2 O1B tan(gamma) OB Delta with the tooth
    deflection Delta = M_D0/(2 c2 O1B^2) is G: c2 drops out).
    """
    s, c = math.sin(p.phi20), math.cos(p.phi20)
    A = p.O1O - p.OC * c
    N = 2 * p.m * w**2 * A * p.OC * s - 8 * p.c1 * p.lam_st * p.OC1 * s - p.G
    D = 8 * p.c1 * (p.lam_st * p.OC1 * c + p.OC1**2 * s**2) - 2 * p.m * w**2 * A * p.OC * c
    if form == "newton":
        D -= 2 * p.m * w**2 * p.OC**2 * s**2
    value = max(0.0, N / D) if D > 0 else math.nan
    return Linear(value, N, D)


_STEADY_ARGS = {"omega1": "rad/s", **_STEADY_SI}


@block(args=_STEADY_ARGS, returns="rad", vectorized=False)
def phi2_root(omega1, m, c1, phi20, lam_st, O1O, OC, OC1, OB, O1B, tan_gamma, M_D0):
    """Steady weight angle: stable root of the nonlinear equilibrium (0 on the stop)."""
    p = Params(
        m=m,
        c1=c1,
        phi20=phi20,
        lam_st=lam_st,
        O1O=O1O,
        OC=OC,
        OC1=OC1,
        OB=OB,
        O1B=O1B,
        tan_gamma=tan_gamma,
        M_D0=M_D0,
    )
    return steady(float(omega1), p).phi2


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
    lo = float(sheet.values["omega_min"].to("rad/s").magnitude)
    hi = float(sheet.values["omega_max"].to("rad/s").magnitude)
    step = float(sheet.values["omega_step"].to("rad/s").magnitude)
    n = int(math.floor((hi - lo) / step * (1 + 1e-12) + 1e-9)) + 1
    ws = lo + step * np.arange(n)
    if abs(ws[-1] - hi) > 1e-9:
        ws = np.append(ws, hi)
    return ws


def family(p: Params, key: str, ws) -> dict[float, dict[str, np.ndarray]]:
    """For each value of the family parameter: nonlinear root and both linear forms."""
    out = {}
    for value in FAMILIES[key][2]:
        q = replace(p, **{key: value})
        st = [steady(w, q) for w in ws]
        out[value] = {
            "root": np.array([s.phi2 for s in st]),
            "on_stop": np.array([s.on_stop for s in st]),
            "printed": np.array([linear_phi2(w, q, "printed").value for w in ws]),
            "D": np.array([linear_phi2(w, q, "printed").denominator for w in ws]),
            "newton": np.array([linear_phi2(w, q, "newton").value for w in ws]),
        }
    return out


def _family_table(sheet, key: str):
    import pandas as pd

    p, ws = Params.from_sheet(sheet), speeds(sheet)
    fam = family(p, key, ws)
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


def mass_matrix(p: Params) -> np.ndarray:
    a11 = p.J1 + 2 * p.m * (p.O1O - p.OC * math.cos(p.phi20)) ** 2 + 2 * p.Jy
    a22 = 2 * p.m * p.OC**2 + 2 * p.Jx
    return np.array([[a11, -2 * p.Jxy, 0.0], [-2 * p.Jxy, a22, 0.0], [0.0, 0.0, p.J3]])


def tooth_vector(p: Params) -> np.ndarray:
    return np.array([p.O1B, p.OB * p.tan_gamma, -p.O1B])


def model(
    p: Params,
    w: float | None = None,
    c2: float | None = None,
    *,
    rigid: bool = False,
    damping: str = "corrected",
) -> LinearModel:
    """The coupling about its steady state at speed w, driven by the pump torque
    pump_amp*sin(pump_order*w*t) on the driven half (M_N0 = M_D0: balanced mean torques).

    rigid=True gives the rigid-tooth limit (2 DOF, phi3 = phi1 + k*phi2). If the weights sit on
    the stop, phi2 is held at 0 (one DOF fewer).
    """
    w = p.omega_dyn if w is None else w
    c2 = p.c2 if c2 is None else c2
    st = steady(w, p)
    s20 = math.sin(p.phi20)
    b22 = p.beta * p.OC**2 * s20**2 * (-1.0 if damping == "as printed" else 1.0)
    M3 = mass_matrix(p)
    Phi3 = np.diag([0.0, b22, 0.0])
    v = tooth_vector(p)
    H3 = 2 * c2 * np.outer(v, v)
    kw = weight_stiffness(p.phi20 + st.phi2, w, p)
    K3 = H3 + np.diag([0.0, 0.0 if st.on_stop else kw, 0.0])
    f0 = np.array([p.M_D0, p.G + kw * st.phi2, -p.M_D0])  # M0 = (M_D0, 0, -M_N0) + weights
    fp = np.array([0.0, 0.0, -p.pump_amp])
    k = p.k_ratio
    if rigid:
        C = np.array([[1.0, 0.0], [0.0, 1.0], [1.0, k]])
        x0 = np.array([0.0, st.phi2])
        K3 = K3 - H3  # the tooth does no work on a rigid-tooth motion (v . C = 0)
    else:
        C = np.eye(3)
        delta = p.M_D0 / (2 * c2 * p.O1B)  # v . q of the loaded tooth
        x0 = np.array([0.0, st.phi2, (p.OB * p.tan_gamma * st.phi2 - delta) / p.O1B])
    if st.on_stop:  # weights held on the stop: drop phi2 (and its constant force)
        f0 = f0.copy()
        f0[1] = 0.0
        if rigid:
            C, x0 = np.array([[1.0], [0.0], [1.0]]), np.array([0.0])
        else:
            C, x0 = C[:, [0, 2]], x0[[0, 2]]
    Omega = p.pump_order * w
    return LinearModel(
        C.T @ M3 @ C,
        C.T @ Phi3 @ C,
        C.T @ K3 @ C,
        C.T @ f0,
        C.T @ fp,
        Omega,
        C,
        x0,
        "rigid tooth" if rigid else "3 DOF",
    )


def eigen(p: Params, c2: float, w: float | None = None, damping: str = "corrected"):
    """Eigenvalues of the linear system without the rigid rotation mode, sorted by size.

    The rigid rotation r0 (K r0 = 0, Phi r0 = 0) is condensed out: in coordinates (r0, rest)
    its row says (M u)_r0 = 0 for every mode with lambda != 0, which leaves the Schur
    complement of M on the rest; no near-zero eigenvalue has to be told from round-off.
    """
    mdl = model(p, w, c2, damping=damping)
    n = mdl.n
    _, sv, vt = np.linalg.svd(mdl.K)
    r0 = vt[-1]
    basis = np.linalg.svd(np.column_stack([r0, np.eye(n)]))[0]  # r0 first, then its complement
    basis[:, 0] = r0
    T = basis
    Mr, Pr, Kr = T.T @ mdl.M @ T, T.T @ mdl.Phi @ T, T.T @ mdl.K @ T
    Mred = Mr[1:, 1:] - np.outer(Mr[1:, 0], Mr[0, 1:]) / Mr[0, 0]
    Pred, Kred = Pr[1:, 1:], Kr[1:, 1:]
    m = n - 1
    if m == 0:
        return np.empty(0, dtype=complex)
    Minv = np.linalg.inv(Mred)
    A = np.zeros((2 * m, 2 * m))
    A[:m, m:] = np.eye(m)
    A[m:, :m] = -Minv @ Kred
    A[m:, m:] = -Minv @ Pred
    lam = np.linalg.eigvals(A)
    return lam[np.argsort(np.abs(lam))]


def stiffness(p: Params, c2: float, w: float | None = None) -> dict:
    """Stiffness measures: ratio max|lambda|/min|lambda| and max|lambda| * t_end (the number of
    radians of the fastest mode over the run: about the steps an explicit method needs / 3)."""
    lam = eigen(p, c2, w)
    big, small = float(np.max(np.abs(lam))), float(np.min(np.abs(lam)))
    tooth = lam[np.argmax(np.abs(lam))]
    return {
        "lam": lam,
        "ratio": big / small,
        "index": big * p.t_end,
        "tooth_freq": abs(tooth.imag),
        "tooth_damping": -tooth.real / abs(tooth),
        "weight_freq": abs(lam[0].imag),
        "weight_damping": -lam[0].real / abs(lam[0]),
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

    def exact(self, t=None) -> np.ndarray:
        """Exact solution at t (default t_eval) from the matrix exponential of the system
        augmented with the forcing (z = (y, 1, sin, cos)): independent of any ODE method."""
        from scipy.linalg import expm

        t = self.t_eval if t is None else np.asarray(t, dtype=float)
        N = len(self.y0)
        Z = np.zeros((N + 3, N + 3))
        Z[:N, :N] = self.A
        Z[:N, N] = self.b
        Z[:N, N + 1] = self.g
        Z[N + 1, N + 2] = self.Omega
        Z[N + 2, N + 1] = -self.Omega
        z = np.concatenate([self.y0, [1.0, 0.0, 1.0]])
        out = np.empty((N, len(t)))
        dts = np.diff(t)
        uniform = len(dts) and np.allclose(dts, dts[0], rtol=1e-12, atol=0)
        # uniform grid: one propagator, refined by substeps so that |lambda h| stays small
        if uniform:
            h = dts[0]
            sub = max(1, int(math.ceil(np.max(np.abs(np.linalg.eigvals(self.A))) * h / 0.5)))
            E = np.linalg.matrix_power(expm(Z * (h / sub)), sub)
            out[:, 0] = (expm(Z * t[0]) @ z)[:N]
            z = expm(Z * t[0]) @ z
            for k in range(1, len(t)):
                z = E @ z
                out[:, k] = z[:N]
            return out
        for k, tk in enumerate(t):
            out[:, k] = (expm(Z * tk) @ z)[:N]
        return out


def error_of(problem: Problem, reference_outputs: np.ndarray):
    """Max-norm error of (phi2, psi) against reference outputs (rad)."""

    def err(run: OdeRun) -> float:
        if run.y.shape[1] != reference_outputs.shape[1]:
            return math.nan
        return float(np.max(np.abs(problem.model.outputs(run.y) - reference_outputs)))

    return err


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

_CACHE: dict = {}


def _cached(key, compute):
    """Results are stored only when complete (a Ctrl-C leaves no half-filled entry)."""
    if key not in _CACHE:
        value = compute()
        if len(_CACHE) > 512:  # many input variations (sweeps): start afresh
            _CACHE.clear()
        _CACHE[key] = value
    return _CACHE[key]


def auto_method(p: Params, c2: float | None = None) -> str:
    """The default solver: Radau when the tooth mode makes the run stiff (stiffness index
    |lambda_max|*t_end above AUTO_INDEX), LSODA otherwise. See docs/advance-coupling.md."""
    return "Radau" if stiffness(p, p.c2 if c2 is None else c2)["index"] > AUTO_INDEX else "LSODA"


def chosen_method(sheet, p: Params, c2: float | None = None) -> str:
    m = method_of(sheet)
    return auto_method(p, c2) if m == "auto" else m


def rtol_of(sheet) -> float:
    q = sheet.values.get("rtol")
    return 1e-5 if q is None else float(q.to("").magnitude)


def budget_of(sheet) -> float:
    q = sheet.values.get("max_time")
    return 20.0 if q is None else float(q.to("s").magnitude)


@dataclass
class Case:
    """One c2: the 3-DOF problem, its exact solution and the rigid-tooth limit."""

    c2: float
    problem: Problem
    exact: np.ndarray  # outputs (phi2, psi) of the exact 3-DOF solution
    rigid: np.ndarray  # outputs of the exact rigid-tooth solution
    delta: float  # max |3-DOF - rigid| (model difference)


def case(p: Params, c2: float, t_end: float | None = None, n_out: int = 401) -> Case:
    t_end = p.t_end if t_end is None else t_end

    def build():
        pr = Problem(model(p, c2=c2), t_end, n_out)
        rg = Problem(model(p, c2=c2, rigid=True), t_end, n_out)
        ex, rr = pr.model.outputs(pr.exact()), rg.model.outputs(rg.exact())
        return Case(c2, pr, ex, rr, float(np.max(np.abs(ex - rr))))

    return _cached(("case", p, c2, t_end, n_out), build)


def _dev(cs: Case, run: OdeRun, against: np.ndarray) -> float:
    if not run.ok or run.y.shape[1] != against.shape[1]:
        return math.nan
    return float(np.max(np.abs(cs.problem.model.outputs(run.y) - against)))


def study(
    p: Params,
    c2s,
    rtols,
    methods=METHODS,
    *,
    t_end=None,
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
            cs = case(p, c2, t_end)
            runs = {}

            def run_case(method, rtol, cs=cs, runs=runs):
                run = cs.problem.run(
                    method, rtol, max_time=max_time, max_steps=2_000_000, label=label
                )
                runs[(method, rtol)] = run
                return run

            for r in work_precision(
                run_case,
                lambda run, cs=cs: _dev(cs, run, cs.exact),
                methods,
                rtols,
                case=f"{c2:.0e}",
                label=None,
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

    return _cached(("study", p, tuple(c2s), tuple(rtols), tuple(methods), t_end, max_time), build)


def _blank(df):
    """NaN -> None, so that the workbook leaves the cell empty (charts skip it)."""
    return df.astype(object).where(df.notna(), None)


STUDY_T = 0.1  # s: the workbook's shortened study runs over min(t_end, STUDY_T)


def _study_for_sheet(sheet):
    p = Params.from_sheet(sheet)
    p = replace(p, t_end=min(p.t_end, STUDY_T))
    return p, study(p, STUDY_C2, STUDY_RTOLS, max_time=min(1.5, budget_of(sheet)))


@table_block
def work_precision_table(sheet):
    """Work-precision study (shortened for the workbook; the full one is `workbook bench`)."""
    _, df = _study_for_sheet(sheet)
    return _blank(df)


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
    _, df = _study_for_sheet(sheet)
    return _wide(df, CHOICE_C2)


@table_block
def wp_moderate(sheet):
    """Work-precision chart data at c2 = 1e8 N/m."""
    _, df = _study_for_sheet(sheet)
    return _wide(df, 1e8)


@table_block
def stiffness_table(sheet):
    """Eigenvalues (rigid rotation excluded) and stiffness measures for c2 = 1e6 .. 1e10 N/m."""
    import pandas as pd

    p = Params.from_sheet(sheet)
    rows = []
    for c2 in FULL_C2:
        s = stiffness(p, c2)
        cs = case(p, c2)
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
                "auto method": auto_method(p, c2),
            }
        )
    return pd.DataFrame(rows)


def default_run(p: Params, method: str, rtol: float, max_time: float, c2: float | None = None):
    cs = case(p, p.c2 if c2 is None else c2)
    return cs, cs.problem.run(method, rtol, max_time=max_time, label="advance-coupling dynamics")


@table_block
def histories(sheet):
    """Time histories of phi2 and the advance angle psi = phi3 - phi1 (3 DOF and rigid tooth)."""
    import pandas as pd

    p = Params.from_sheet(sheet)
    method, rtol = chosen_method(sheet, p), rtol_of(sheet)
    cs, run = _cached(
        ("history", p, method, rtol), lambda: default_run(p, method, rtol, budget_of(sheet))
    )
    t = cs.problem.t_eval
    out = cs.problem.model.outputs(run.y) if run.ok else np.full((2, len(t)), math.nan)
    if not run.ok:  # a partial run: keep what was reached
        k = run.y.shape[1]
        out[:, :k] = cs.problem.model.outputs(run.y)
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
    p: Params,
    method: str = "RK45",
    c2: float = STALL_C2,
    max_time: float = 0.5,
    max_steps: int = 20_000,
) -> tuple[OdeRun, float]:
    """An explicit method on a very stiff tooth: bounded by a budget and a step cap.
    Returns the run and the steps it would need at its stability limit (about index/3)."""
    cs = case(p, c2)
    run = cs.problem.run(
        method, 1e-5, max_time=max_time, max_steps=max_steps, label="advance-coupling stall"
    )
    need = stiffness(p, c2)["index"] / 3.3
    return run, need


def soft_spring_limit(p: Params, w: float, form: str = "printed") -> float:
    """Spring stiffness c1 below which the linear form's denominator is <= 0 at speed w."""
    s, c = math.sin(p.phi20), math.cos(p.phi20)
    A = p.O1O - p.OC * c
    cent = 2 * p.m * w**2 * (A * p.OC * c + (p.OC**2 * s**2 if form == "newton" else 0.0))
    return cent / (8 * (p.lam_st * p.OC1 * c + p.OC1**2 * s**2))


def denominator_zero_speed(p: Params, form: str = "printed") -> float:
    """Speed at which the linear form's denominator passes through zero [rad/s]."""
    s, c = math.sin(p.phi20), math.cos(p.phi20)
    A = p.O1O - p.OC * c
    k = 8 * p.c1 * (p.lam_st * p.OC1 * c + p.OC1**2 * s**2)
    cent = 2 * p.m * (A * p.OC * c + (p.OC**2 * s**2 if form == "newton" else 0.0))
    return math.sqrt(k / cent) if cent > 0 else math.inf


# ---------------------------------------------------------------------------------------------
# findings
# ---------------------------------------------------------------------------------------------
SCENE_VALUES = ((50.0, 0.0), (80.0, 0.070), (110.0, 0.204))  # SCENES.md section 4, base case


def trend_holds(p: Params, key: str, ws) -> tuple[list[float], list[float], list[float]]:
    """Speeds where the printed trend holds strictly, where it fails, where it is vacuous
    (every member of the family on the stop)."""
    fam = family(p, key, ws)
    vals = np.array([fam[v]["root"] for v in FAMILIES[key][2]])  # members x speeds
    sign = TRENDS[key]
    holds, fails, vacuous = [], [], []
    for j, w in enumerate(ws):
        col = vals[:, j]
        if np.all(col == 0):
            vacuous.append(float(w))
            continue
        d = np.diff(col) * sign
        # on the stop two members may both be 0: the trend is then "not reversed"
        ok = np.all(d >= 0) and np.any(d > 0) and np.all((d > 0) | (col[1:] == 0) | (col[:-1] == 0))
        (holds if ok else fails).append(float(w))
    return holds, fails, vacuous


def _speeds_text(xs, all_speeds=None) -> str:
    """Speeds as runs of consecutive grid points: '55..65, 110 rad/s'."""
    if not xs:
        return "none"
    xs = sorted(xs)
    grid = sorted(all_speeds) if all_speeds is not None else xs
    index = {w: i for i, w in enumerate(grid)}
    runs, start, prev = [], xs[0], xs[0]
    for w in xs[1:]:
        if index.get(w, -9) != index.get(prev, -99) + 1:
            runs.append((start, prev))
            start = w
        prev = w
    runs.append((start, prev))
    return ", ".join(f"{a:g}" if a == b else f"{a:g}..{b:g}" for a, b in runs) + " rad/s"


def departures(p: Params, key: str, ws, form: str = "printed", limit: float = 0.05):
    """Per family member: (value, first speed with |lin - root| > limit*root, max rel. departure,
    speeds where the denominator is <= 0)."""
    out = []
    for value, d in family(p, key, ws).items():
        root = d["root"]
        lin = d["printed"] if form == "printed" else d["newton"]
        mask = root > 0
        rel = np.full(len(ws), np.nan)
        rel[mask] = np.abs(lin[mask] - root[mask]) / root[mask]
        bad = mask & ((rel > limit) | np.isnan(lin))
        where = [float(w) for w in ws[bad]]
        zero = [float(w) for w, v in zip(ws, lin) if np.isnan(v)]
        out.append((value, where, float(np.nanmax(rel)) if mask.any() else 0.0, zero))
    return out


@findings_block
def findings(sheet):
    """Steady values, printed trends, linear-form departures, stiffness and solver choice."""
    F = Finding
    p, ws = Params.from_sheet(sheet), speeds(sheet)
    out: list[Finding] = []
    base = Params()
    same = all(
        math.isclose(getattr(p, k), getattr(base, k), rel_tol=1e-9)
        for k in _STEADY_ARGS
        if k != "omega1"
    )
    for w, ref in SCENE_VALUES:
        val = steady(w, p).phi2
        if same:
            ok = abs(val - ref) <= 1e-3
            out.append(
                F(
                    "steady state",
                    f"phi2 at omega1 = {w:g} rad/s (SCENES.md: {ref:.3f})",
                    val,
                    "rad",
                    "ok" if ok else "fail",
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
                    "inputs differ from the SCENES.md example",
                )
            )
    wl = lift_off_speed(p)
    stop = [float(w) for w in ws if steady(w, p).on_stop]
    out.append(
        F(
            "steady state",
            "lift-off speed (weights leave the stop)",
            wl,
            "rad/s",
            "info",
            f"on the stop at {_speeds_text(stop, ws)}: phi2 = 0 there, not a root",
        )
    )
    for key in FAMILIES:
        holds, fails, vacuous = trend_holds(p, key, ws)
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
            for value, where, worst, zero in departures(p, key, ws, form):
                unit = FAMILIES[key][1]
                what = f"{title}, {key} = {value:g} {unit}: largest departure from the root"
                if not where:
                    note, verdict = "within 5 % at every speed off the stop", "ok"
                else:
                    note, verdict = (f"more than 5 % at {_speeds_text(where, ws)}", "warning")
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
    wmax = float(ws[-1])
    for form in ("printed", "newton"):
        c1z = soft_spring_limit(p, wmax, form)
        out.append(
            F(
                "extreme cases",
                f"{form} linear form: denominator passes through zero at "
                f"{wmax:g} rad/s for springs softer than",
                c1z,
                "N/m",
                "info",
                f"with c1 = {p.c1:g} N/m it is zero at {denominator_zero_speed(p, form):.4g} rad/s",
            )
        )
    # dynamics
    lam = eigen(p, p.c2)
    out.append(
        F(
            "dynamics",
            f"weight mode at c2 = {p.c2:.0e} N/m: Im lambda",
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
    lam_p = eigen(p, p.c2, damping="as printed")
    out.append(
        F(
            "dynamics",
            "with the printed damping sign (-beta OC^2 sin^2 phi20) the weight "
            "mode grows: Re lambda",
            float(lam_p[0].real),
            "1/s",
            "warning",
            "negative damping; the corrected sign is used",
        )
    )
    method, rtol = chosen_method(sheet, p), rtol_of(sheet)
    cs, run = _cached(
        ("history", p, method, rtol), lambda: default_run(p, method, rtol, budget_of(sheet))
    )
    note = run.summary()
    if run.ok:
        dev = _dev(cs, run, cs.exact)
        note += f"; error against the exact solution {dev:.3g} rad"
    out.append(
        F(
            "dynamics",
            f"time histories: {method} rtol {rtol:.0e} at c2 = {p.c2:.0e} N/m"
            f" ({'auto' if method_of(sheet) == 'auto' else 'chosen'})",
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
    F = Finding
    p = Params.from_sheet(sheet)
    ps, df = _study_for_sheet(sheet)
    out = choice_findings(ps, df, method_of(sheet), rtol_of(sheet))
    run, need = stall_run(p)
    out.append(
        F(
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


def choice_findings(p: Params, df, method: str, rtol: float) -> list[Finding]:
    """Is the default solver within 2x of the fastest run that reaches the rigid limit?"""
    F = Finding
    sub = df[df["c2 [N/m]"] == CHOICE_C2]
    if sub.empty:
        return []
    delta = float(sub["rigid-model difference [rad]"].iloc[0])
    tol = 2 * delta
    ok = sub[(sub["stopped"] == "finished") & (sub["deviation from rigid [rad]"] <= tol)]
    default = auto_method(p, CHOICE_C2) if method == "auto" else method
    out = [
        F(
            "solver choice",
            f"rigid-model difference at c2 = {CHOICE_C2:.0e} N/m",
            delta,
            "rad",
            "info",
            f"a run 'reaches the rigid limit' when it deviates from it by <= {tol:.3g} rad",
        )
    ]
    if ok.empty:
        out.append(
            F("solver choice", "no run of the study reaches the rigid limit", None, "", "warning")
        )
        return out
    best = ok.loc[ok["run time [s]"].idxmin()]
    # time the best and the default again side by side (best of 3)
    cs = case(p, CHOICE_C2)
    t_best = min(cs.problem.run(best["method"], best["rtol"]).elapsed for _ in range(3))
    runs = [cs.problem.run(default, rtol) for _ in range(3)]
    t_def = min(r.elapsed for r in runs)
    dev = _dev(cs, runs[0], cs.rigid)
    ratio = t_def / t_best
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
        rows = df[
            (df["c2 [N/m]"] == c2) & (df["stopped"] == "finished") & (df["error [rad]"] <= 1e-6)
        ]
        auto = auto_method(p, c2) if method == "auto" else method
        mine = df[(df["c2 [N/m]"] == c2) & (df["method"] == auto) & (df["rtol"] == rtol)]
        if rows.empty:
            continue
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


# ---------------------------------------------------------------------------------------------
# bench
# ---------------------------------------------------------------------------------------------
@bench_block
def bench(sheet, quick: bool = False):
    """Work-precision of RK45, DOP853, Radau, BDF, LSODA: error against run time (full study)."""
    p = Params.from_sheet(sheet)
    if quick:
        q = replace(p, t_end=0.02)
        df = study(q, (CHOICE_C2,), (1e-3, 1e-5), t_end=0.02, max_time=0.3, label=None)
    else:
        df = study(p, FULL_C2, FULL_RTOLS, max_time=10.0)
    return df
