"""The method of ``method = "auto"`` for an [[ode]]: an explicit method, watched along the run
for stiffness as LSODA watches its Adams steps, and continued by LSODA from where it turned
stiff. Split from :mod:`workbook.engine.ode`, which solves with it.

Stiffness is judged from the steps, not from the Jacobian alone: an explicit method's step is
held either by accuracy or by stability. Where the Jacobian's fastest decay rate d times the
step h sits near the method's stability limit on the negative real axis (h d about 3.3 for
RK45, 6.4 for DOP853) the step is held by stability: were the fast mode in the solution,
accuracy would hold h d far below 1. A run is stiff when two checks in a row (one, where very
stiff) find h d above 0.4 of that limit and an explicit method held there would still need
more than MIN_STEPS_LEFT steps. A saddle (Kepler near its perihelion: eigenvalues +-4) or an
oscillation is followed for accuracy, h d stays below 1, and the run stays explicit whatever
the span."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from ..language.odes import MAX_STEPS, MAX_TIME
from .oderun import run_ode

#: h times the fastest decay rate where each explicit method's stability region ends on the
#: negative real axis (measured: RK45 runs held there at 3.1 to 3.4, DOP853 at 6.4).
STABILITY_LIMIT = {"RK45": 3.3, "DOP853": 6.0}
#: A run held by stability is stiff only if it would still need more steps than this there
#: (fewer are cheaper to take than to change method for).
MIN_STEPS_LEFT = 200
#: The steps at which the Jacobian is estimated: every 5 up to 80 (a run stiff from
#: its start is seen within tens of steps), then every 80; a check that finds the step held by
#: stability is confirmed CONFIRM_AFTER steps later, unless an explicit method held there would
#: need more than SURE_STEPS_LEFT steps (confirming would cost more than a wrong switch).
WATCH_FIRST, WATCH_EARLY, WATCH_EVERY, CONFIRM_AFTER = 5, 5, 80, 5
SURE_STEPS_LEFT = 10_000
#: The step is held by stability where h times the fastest decay rate is above this fraction
#: of STABILITY_LIMIT (measured on non-stiff runs: at most 0.34 for RK45, 0.88 for DOP853).
HELD = 0.4
STIFF_METHOD = "LSODA"  # switches between Adams and BDF itself; the fastest stiff solver here


# -- stiffness and the choice of method -------------------------------------------------------
def jacobian(fun: Callable, t: float, y: np.ndarray) -> np.ndarray:
    """Forward-difference Jacobian of fun(t, y) with respect to y."""
    y = np.asarray(y, dtype=float)
    f0 = np.asarray(fun(t, y), dtype=float)
    jac = np.empty((len(f0), len(y)))
    for k in range(len(y)):
        h = math.sqrt(np.finfo(float).eps) * max(1.0, abs(y[k]))
        yk = y.copy()
        yk[k] += h
        jac[:, k] = (np.asarray(fun(t, yk), dtype=float) - f0) / h
    return jac


@dataclass(frozen=True)
class Choice:
    """The method "auto" chose, and why (said as a finding)."""

    method: str
    reason: str
    eigenvalues: np.ndarray
    index: float  # max(-Re lambda) * span at the start


def explicit_method(rtol: float) -> str:
    """The explicit method of "auto": DOP853 (8th order) for rtol below 1e-6, else RK45."""
    return "DOP853" if rtol < 1e-6 else "RK45"


def choose_method(
    fun: Callable, t0: float, t1: float, y0, rtol: float, time_unit: str = ""
) -> Choice:
    """The method "auto" starts with: explicit, or LSODA where the Jacobian at the start is not
    finite (nothing to watch the steps with)."""
    jac = jacobian(fun, t0, y0)
    if not np.all(np.isfinite(jac)):
        return Choice(
            "LSODA",
            "the Jacobian at the start is not finite; LSODA switches "
            "between explicit and implicit steps as it goes",
            np.array([]),
            math.nan,
        )
    lam = np.linalg.eigvals(jac)
    method = explicit_method(rtol)
    order = "8th order for rtol < 1e-6" if method == "DOP853" else "5th order"
    reason = (
        f"an explicit method ({order}), its steps watched for stiffness (a step held by "
        "stability, not accuracy)"
    )
    decay = float(np.max(-lam.real, initial=0.0))
    return Choice(method, reason, lam, decay * abs(t1 - t0))


@dataclass
class Stiff:
    """Where a watched explicit run turned stiff: the point, and what was seen there."""

    t: float
    y: np.ndarray
    step: float
    note: str


def stiffness_watch(
    fun: Callable, t1: float, method: str, time_unit: str = "", seen: list | None = None
) -> Callable:
    """A ``watch`` for :func:`run_ode` on an explicit ``method``: stiff when two checks in a
    row (or one, with more than SURE_STEPS_LEFT steps left) find the step held by stability
    (step times the fastest decay rate above HELD times STABILITY_LIMIT) with more than
    MIN_STEPS_LEFT such steps left. The point is appended to ``seen`` (a :class:`Stiff`)."""
    limit = STABILITY_LIMIT[method]
    due, held = [WATCH_FIRST], [False]
    unit = f" {time_unit}" if time_unit else ""
    rate = f" 1/{time_unit}" if time_unit else ""

    def watch(solver, nsteps: int) -> str | None:
        if nsteps < due[0]:
            return None
        jac = jacobian(fun, solver.t, solver.y)
        lam = np.linalg.eigvals(jac) if np.all(np.isfinite(jac)) else np.zeros(1)
        decay = float(np.max(-lam.real, initial=0.0))
        h = abs(float(solver.step_size or 0.0))
        left = decay * abs(t1 - solver.t) / limit
        now = h * decay > HELD * limit and left > MIN_STEPS_LEFT
        if now and (held[0] or left > SURE_STEPS_LEFT):
            fastest = lam[np.argmax(-lam.real)]
            note = (
                f"at t = {solver.t:.6g}{unit}, after {nsteps} steps, the step {h:.3g}{unit} "
                f"times the Jacobian's fastest decay rate {-fastest.real:.4g}{rate} is "
                f"{h * decay:.3g}, at {method}'s stability limit ({limit:g}), not held by "
                f"accuracy, with about {left:.3g} such steps left: stiff"
            )
            if seen is not None:
                seen.append(Stiff(float(solver.t), solver.y.copy(), h, note))
            return note
        held[0] = now
        step = CONFIRM_AFTER if now else WATCH_EARLY if nsteps < WATCH_EVERY else WATCH_EVERY
        due[0] = nsteps + step
        return None

    return watch


def auto_run(fun: Callable, t0: float, t1: float, y0, time_unit: str = "", **options):
    """The run of method "auto": an explicit method watched along the way
    (:func:`stiffness_watch`); where it turns stiff, LSODA goes on from that point within what
    is left of the budget, and the two runs are one (steps, dense output). (run, Choice saying
    what was used and why; its method is the one that reproduces the run from the start)."""
    choice = choose_method(fun, t0, t1, y0, options.get("rtol", 1e-6), time_unit)
    if choice.method not in STABILITY_LIMIT:
        return run_ode(fun, (t0, t1), y0, method=choice.method, **options), choice
    seen: list[Stiff] = []
    watch = stiffness_watch(fun, t1, choice.method, time_unit, seen)
    first = run_ode(fun, (t0, t1), y0, method=choice.method, watch=watch, **options)
    if first.stop_reason != "stiff":
        return first, choice
    at = seen[-1]
    rest = dict(options)
    rest["max_time"] = max(options.get("max_time", MAX_TIME) - first.elapsed, 1e-3)
    rest["max_steps"] = max(options.get("max_steps", MAX_STEPS) - first.nsteps, 1)
    t_eval = options.get("t_eval")
    if t_eval is not None:
        t_eval = np.asarray(t_eval, dtype=float)
        rest["t_eval"] = t_eval[(t_eval - at.t) * np.sign(t1 - t0) > 0]
    rest.setdefault("first_step", min(at.step, abs(t1 - at.t)))  # where the explicit one was
    second = run_ode(fun, (at.t, t1), at.y, method=STIFF_METHOD, **rest)
    run = joined(first, second, drop_first=t_eval is None)
    reason = (
        f"{first.method} from the start; {at.note}; {STIFF_METHOD} from there "
        f"({first.nsteps} explicit steps, {first.elapsed:.3g} s, before it)"
    )
    return run, Choice(STIFF_METHOD, reason, choice.eigenvalues, choice.index)


def joined(first, second, drop_first: bool):
    """One run of two: ``second`` starts where ``first`` stopped (its first column, the same
    point, dropped when ``drop_first``)."""
    from scipy.integrate import OdeSolution

    k = 1 if drop_first and second.t.size else 0
    sol = None
    if first.sol is not None and second.sol is not None:
        ts = np.concatenate([first.sol.ts, second.sol.ts[1:]])
        sol = OdeSolution(ts, list(first.sol.interpolants) + list(second.sol.interpolants))
    elif first.sol is not None and second.nsteps == 0:
        sol = first.sol
    return replace(
        second,
        t=np.concatenate([first.t, second.t[k:]]),
        y=np.hstack([first.y, second.y[:, k:]]),
        elapsed=first.elapsed + second.elapsed,
        nfev=first.nfev + second.nfev,
        nsteps=first.nsteps + second.nsteps,
        notes=first.notes + second.notes,
        sol=sol,
    )
