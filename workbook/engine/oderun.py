"""Runs of y' = f(t, y) on plain magnitudes: bounded, timed, compared.

``run_ode`` drives scipy's solver classes step by step, in the style of ``solve_ivp`` (one
result object, methods swappable, ``t_eval`` from each step's dense output), but bounded: a
wall-clock budget and a step cap end a run that would otherwise take hours (an explicit method
on a very stiff system), and the result says why it stopped::

    run = run_ode(fun, (0, T), y0, method="Radau", rtol=1e-6, atol=1e-9, jac=J,
                  t_eval=ts, max_time=10, max_steps=200_000, label="tooth c2=1e10")
    run.ok, run.stop_reason, run.elapsed, run.nfev, run.y

``work_precision`` runs methods x tolerances (error against run time); ``linear_parts`` and
``linear_solution`` give the exact solution of a linear system with a harmonic forcing (the
reference of such a study). Ctrl-C is not caught: a KeyboardInterrupt leaves a run at once and
nothing half-made is kept. Long runs print a progress line to stderr every ``progress_every``
seconds. scipy is imported inside the functions. The ``[[ode]]`` sections of a worksheet are
:mod:`workbook.engine.ode`.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..errors import DomainError

SOLVERS = ("RK45", "DOP853", "Radau", "BDF", "LSODA")
IMPLICIT = ("Radau", "BDF", "LSODA")  # methods that use a Jacobian


@dataclass
class OdeRun:
    """One ODE run: the solution at t_eval (or at the steps), cost, and why it stopped."""

    method: str
    rtol: float
    atol: float
    t: np.ndarray
    y: np.ndarray  # shape (n, len(t))
    stop_reason: str  # "finished" | "time budget" | "step cap" | "stiff" | "failed: <message>"
    elapsed: float  # wall-clock seconds (time.perf_counter)
    nfev: int
    njev: int
    nlu: int
    nsteps: int
    t_reached: float
    t_final: float
    notes: list[str] = field(default_factory=list)
    sol: object = None  # scipy OdeSolution over [t0, t_reached] when run with dense_output

    @property
    def ok(self) -> bool:
        return self.stop_reason == "finished"

    @property
    def fraction(self) -> float:
        """Fraction of the time span covered."""
        span = self.t_final - self.t[0] if len(self.t) else 1.0
        return 1.0 if span == 0 else min(1.0, max(0.0, (self.t_reached - self.t[0]) / span))

    def summary(self) -> str:
        head = f"{self.method} rtol={self.rtol:.0e}: {self.stop_reason}"
        return (
            f"{head} at t = {self.t_reached:.6g} of {self.t_final:.6g} "
            f"({100 * self.fraction:.1f} %), {self.nsteps} steps, {self.nfev} f-evals, "
            f"{self.elapsed:.3g} s"
        )


def _progress(label: str, solver, t0: float, t1: float, nsteps: int, start: float) -> None:
    frac = (solver.t - t0) / (t1 - t0) if t1 != t0 else 1.0
    print(
        f"[{label}] t = {solver.t:.4g} of {t1:.4g} ({100 * frac:.1f} %), {nsteps} steps, "
        f"{time.perf_counter() - start:.1f} s",
        file=sys.stderr,
        flush=True,
    )


class _Points:
    """The output of a run: the state at every step, or at ``t_eval`` (interpolated from each
    step's dense output as the steps pass them)."""

    def __init__(self, t0: float, y0: np.ndarray, t_eval) -> None:
        self.size = len(y0)
        self.t_eval = None if t_eval is None else np.asarray(t_eval, dtype=float)
        self.ts: list = []
        self.ys: list = []
        self.next = 0
        if self.t_eval is None:
            self.ts, self.ys = [t0], [y0.copy()]
        elif self.t_eval.size and self.t_eval[0] == t0:
            self.ts.append(self.t_eval[:1])
            self.ys.append(y0[:, None].copy())
            self.next = 1

    def record(self, solver) -> None:
        """Keep what the step just taken gives."""
        if self.t_eval is None:
            self.ts.append(solver.t)
            self.ys.append(solver.y.copy())
            return
        hi = np.searchsorted(self.t_eval, solver.t, side="right")
        if hi > self.next:
            chunk = self.t_eval[self.next : hi]
            self.ts.append(chunk)
            self.ys.append(np.asarray(solver.dense_output()(chunk)).reshape(self.size, -1))
            self.next = hi

    def arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """The times and the states (one row per state)."""
        if self.t_eval is None:
            t = np.asarray(self.ts, dtype=float)
            return t, np.asarray(self.ys, dtype=float).T.reshape(self.size, -1)
        t = np.concatenate(self.ts) if self.ts else np.empty(0)
        return t, np.hstack(self.ys) if self.ys else np.empty((self.size, 0))


def _solver_class(method: str):
    """scipy's solver class of ``method``."""
    from scipy import integrate

    classes = {
        "RK45": integrate.RK45,
        "DOP853": integrate.DOP853,
        "Radau": integrate.Radau,
        "BDF": integrate.BDF,
        "LSODA": integrate.LSODA,
        "RK23": integrate.RK23,
    }
    if method not in classes:
        raise ValueError(f"unknown ODE method {method!r} (known: {', '.join(classes)})")
    return classes[method]


def _over_budget(elapsed: float, nsteps: int, max_time: float, max_steps: int):
    """(reason, note) of a run past its wall-clock budget or step cap, or None."""
    if elapsed > max_time:
        return "time budget", f"stopped after the wall-clock budget of {max_time:g} s"
    if nsteps >= max_steps:
        return "step cap", f"stopped after the step cap of {max_steps} steps"
    return None


def _blown_up(solver, blowup: float | None) -> str | None:
    """Why the state after the step just taken blows up (beyond ``blowup``), or None."""
    if blowup is None or np.all(np.abs(solver.y) <= blowup):
        return None
    k = int(np.argmax(~(np.abs(solver.y) <= blowup)))
    return (
        f"state {k} reached {solver.y[k]:.3g} at t = {solver.t:.6g} "
        f"(beyond {blowup:.3g}: the solution blows up)"
    )


def _solution(knots, pieces):
    """The run's steps' interpolants as one scipy OdeSolution."""
    from scipy.integrate import OdeSolution

    return OdeSolution(knots, pieces)


def run_ode(
    fun: Callable,
    t_span: Sequence[float],
    y0,
    *,
    method: str = "RK45",
    rtol: float = 1e-6,
    atol: float | np.ndarray = 1e-9,
    jac=None,
    t_eval=None,
    max_time: float = 30.0,
    max_steps: int = 1_000_000,
    first_step=None,
    max_step: float = np.inf,
    label: str | None = None,
    progress_every: float = 2.0,
    dense_output: bool = False,
    blowup: float | None = None,
    watch: Callable | None = None,
) -> OdeRun:
    """Integrate y' = fun(t, y) over t_span with scipy's solver ``method``, bounded in time.

    Like ``solve_ivp`` (t_eval values are interpolated from each step's dense output) but the
    run stops, with ``stop_reason`` saying why, after ``max_time`` wall-clock seconds or
    ``max_steps`` steps. ``jac`` is passed to the implicit methods only. With
    ``dense_output`` the run keeps every step's interpolant (``run.sol``, a scipy
    OdeSolution); with ``blowup`` it stops ("blow-up") when a state leaves the finite numbers
    or exceeds that magnitude. ``watch(solver, nsteps)`` is called after each step; a text it
    returns stops the run ("stiff", the text its note): how "auto" leaves an explicit method.
    """
    t0, t1 = float(t_span[0]), float(t_span[1])
    y0 = np.asarray(y0, dtype=float)
    options = dict(rtol=rtol, atol=atol, max_step=max_step)
    if first_step is not None:
        options["first_step"] = first_step
    if jac is not None and method in IMPLICIT:
        options["jac"] = jac
    start = time.perf_counter()
    solver = _solver_class(method)(fun, t0, y0, t1, **options)
    out = _Points(t0, y0, t_eval)
    nsteps = 0
    reason = None
    last_report = start
    notes: list[str] = []
    pieces, knots = [], [t0]
    while reason is None:
        message = solver.step()
        nsteps += 1
        if solver.status == "failed":
            reason = f"failed: {message}"
            break
        blown = _blown_up(solver, blowup)
        if blown:
            reason = "blow-up"
            notes.append(blown)
            break
        if dense_output:
            pieces.append(solver.dense_output())
            knots.append(solver.t)
        out.record(solver)
        if solver.status == "finished":
            reason = "finished"
            break
        if watch is not None:
            why = watch(solver, nsteps)
            if why:
                reason = "stiff"
                notes.append(why)
                break
        now = time.perf_counter()
        over = _over_budget(now - start, nsteps, max_time, max_steps)
        if over:
            reason, note = over
            notes.append(note)
        elif label and now - last_report >= progress_every:
            _progress(label, solver, t0, t1, nsteps, start)
            last_report = now
    elapsed = time.perf_counter() - start
    t_out, y_out = out.arrays()
    run = OdeRun(
        method,
        float(rtol),
        float(np.max(atol)),
        t_out,
        y_out,
        reason,
        elapsed,
        int(solver.nfev),
        int(getattr(solver, "njev", 0)),
        int(getattr(solver, "nlu", 0)),
        nsteps,
        float(solver.t),
        t1,
        notes,
    )
    if dense_output and pieces:
        run.sol = _solution(knots, pieces)
    if label and (elapsed > progress_every or not run.ok):
        print(f"[{label}] {run.summary()}", file=sys.stderr, flush=True)
    return run


@dataclass
class StudyRow:
    """One cell of a work-precision study."""

    case: str
    method: str
    rtol: float
    error: float
    elapsed: float
    nfev: int
    nsteps: int
    stop_reason: str
    extra: dict = field(default_factory=dict)


def work_precision(
    run_case: Callable[[str, float], OdeRun],
    error_of: Callable[[OdeRun], float],
    methods: Sequence[str],
    rtols: Sequence[float],
    *,
    case: str = "",
    label: str | None = None,
    skip_after_stall: bool = True,
    extra_of: Callable[[OdeRun], dict] | None = None,
) -> list[StudyRow]:
    """Run every method at every rtol (tight last); errors from ``error_of(run)``.

    When a method stops early (budget or step cap) at some rtol, its tighter rtols are not
    run (they would stall too) and are recorded with stop_reason "skipped (stalled at ...)".
    """
    rows: list[StudyRow] = []
    for method in methods:
        stalled = None
        for rtol in sorted(rtols, reverse=True):
            if stalled is not None and skip_after_stall:
                rows.append(
                    StudyRow(
                        case,
                        method,
                        rtol,
                        math.nan,
                        math.nan,
                        0,
                        0,
                        f"skipped (stopped at rtol {stalled:.0e})",
                    )
                )
                continue
            run = run_case(method, rtol)
            err = error_of(run) if run.ok else math.nan
            rows.append(
                StudyRow(
                    case,
                    method,
                    rtol,
                    err,
                    run.elapsed,
                    run.nfev,
                    run.nsteps,
                    run.stop_reason,
                    extra_of(run) if extra_of else {},
                )
            )
            if not run.ok:
                stalled = rtol
            if label:
                print(
                    f"[{label}] {case} {method} rtol={rtol:.0e}: error {err:.2e}, "
                    f"{run.elapsed:.3f} s, {run.stop_reason}",
                    file=sys.stderr,
                    flush=True,
                )
    return rows


# -- linear systems with a harmonic forcing ---------------------------------------------------
def linear_parts(fun: Callable, n: int, omega: float):
    """A, b, g of y' = fun(t, y) = A y + b + g sin(omega t), read off fun (a linear function
    is its own difference quotient) and checked at another point: a DomainError if fun is
    not of that form."""
    b = np.asarray(fun(0.0, np.zeros(n)), dtype=float)
    A = np.column_stack([np.asarray(fun(0.0, e), dtype=float) - b for e in np.eye(n)])
    g = np.asarray(fun(0.5 * math.pi / omega, np.zeros(n)), dtype=float) - b
    y, t = np.linspace(0.1, 0.3, n), 0.3 / omega
    want = A @ y + b + g * math.sin(omega * t)
    scale = max(np.max(np.abs(A)), np.max(np.abs(b)), np.max(np.abs(g)), 1e-300)
    if not np.allclose(fun(t, y), want, rtol=1e-9, atol=1e-12 * scale):
        raise DomainError(f"the system is not linear with a forcing in sin({omega:g} t)")
    return A, b, g


def linear_solution(A, b, g, omega: float, y0, ts) -> np.ndarray:
    """States (n x len(ts)) of y' = A y + b + g sin(omega t), y(ts[0]) = y0, on a uniform grid
    ts starting at 0, by the matrix exponential of the system augmented with the forcing
    (z = (y, 1, sin, cos)), with substeps so that |lambda h| <= 0.5: no ODE method."""
    from scipy.linalg import expm

    n, ts = len(y0), np.asarray(ts, dtype=float)
    Z = np.zeros((n + 3, n + 3))
    Z[:n, :n], Z[:n, n], Z[:n, n + 1] = A, b, g
    Z[n + 1, n + 2], Z[n + 2, n + 1] = omega, -omega
    z = np.concatenate([np.asarray(y0, dtype=float), [1.0, 0.0, 1.0]])
    h = ts[1] - ts[0] if len(ts) > 1 else 0.0
    sub = max(1, int(math.ceil(np.max(np.abs(np.linalg.eigvals(A))) * h / 0.5)))
    E = np.linalg.matrix_power(expm(Z * (h / sub)), sub)
    out = np.empty((n, len(ts)))
    for k in range(len(ts)):
        out[:, k] = z[:n]
        z = E @ z
    return out
