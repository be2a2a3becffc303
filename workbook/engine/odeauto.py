"""The method of ``method = "auto"`` for an [[ode]]: the Jacobian at the start decides, and an
explicit run is watched for stiffness along the way (moved to an implicit method when it
turns stiff). Split from :mod:`workbook.engine.ode`, which solves with it."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .oderun import run_ode

#: "auto" takes an implicit method when max(-Re lambda) * span of the Jacobian at the start
#: exceeds this: an explicit method would then need more than about STIFF_INDEX/3.3 steps for
#: stability alone, whatever the tolerance.
STIFF_INDEX = 500.0
MAX_TIME = 30.0  # wall-clock budget of one run, seconds
MAX_STEPS = 1_000_000


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
    index: float  # max(-Re lambda) * span


def choose_method(
    fun: Callable, t0: float, t1: float, y0, rtol: float, time_unit: str = ""
) -> Choice:
    """Explicit unless the Jacobian at the start says the run is stiff (see STIFF_INDEX)."""
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
    span = abs(t1 - t0)
    decay = float(np.max(-lam.real, initial=0.0))
    index = decay * span
    unit = f" 1/{time_unit}" if time_unit else ""
    fastest = lam[np.argmax(-lam.real)] if lam.size else 0.0
    where = (
        f"the Jacobian at t = {t0:g} has its fastest decaying eigenvalue {_complex(fastest)}{unit}"
    )
    if index > STIFF_INDEX:
        method = "Radau" if len(y0) <= 200 else "BDF"
        reason = (
            f"{where}; times the span {span:g} that is {index:.3g} > {STIFF_INDEX:g}: stiff "
            f"(an explicit method would need about {index / 3.3:.3g} steps for stability alone)"
        )
        return Choice(method, reason, lam, index)
    method = "DOP853" if rtol < 1e-6 else "RK45"
    reason = (
        f"{where}; times the span {span:g} that is {index:.3g} <= {STIFF_INDEX:g}: not stiff, "
        f"an explicit method ({'8th order for rtol < 1e-6' if method == 'DOP853' else '5th order'})"
    )
    return Choice(method, reason, lam, index)


#: An explicit run of "auto" looks at the Jacobian after this many steps and at each doubling
#: (10, 20, 40, ...): a stiff stretch makes an explicit method take many steps, so it is seen,
#: and a run that is not stiff pays for a few Jacobians only.
WATCH_FIRST = 10


def stiffness_watch(fun: Callable, t1: float, time_unit: str = "") -> Callable:
    """A ``watch`` for :func:`run_ode`: stiff when, at the current point, the fastest decay rate
    times the remaining span exceeds STIFF_INDEX and the step is held by stability (step times
    that rate above 1; an explicit step that follows the solution is shorter)."""
    due = [WATCH_FIRST]
    unit = f" {time_unit}" if time_unit else ""
    rate = f" 1/{time_unit}" if time_unit else ""

    def watch(solver, nsteps: int) -> str | None:
        if nsteps < due[0]:
            return None
        due[0] *= 2
        jac = jacobian(fun, solver.t, solver.y)
        if not np.all(np.isfinite(jac)):
            return None
        lam = np.linalg.eigvals(jac)
        decay = float(np.max(-lam.real, initial=0.0))
        index, h = decay * abs(t1 - solver.t), float(solver.step_size or 0.0)
        if index > STIFF_INDEX and h * decay > 1.0:
            fastest = lam[np.argmax(-lam.real)]
            return (
                f"at t = {solver.t:.6g}{unit}, after {nsteps} steps, the Jacobian's fastest "
                f"decaying eigenvalue is {_complex(fastest)}{rate}"
                f"; times the remaining span that is {index:.3g} > {STIFF_INDEX:g}, and the "
                f"step {h:.3g}{unit} is held by stability: stiff"
            )
        return None

    return watch


def auto_run(fun: Callable, t0: float, t1: float, y0, time_unit: str = "", **options):
    """The run of method "auto": the method the Jacobian at the start says, and an explicit run
    watched along the way (:func:`stiffness_watch`); when it turns stiff, an implicit method
    runs again from the start within what is left of the budget. (run, Choice saying what was
    used and why)."""
    choice = choose_method(fun, t0, t1, y0, options.get("rtol", 1e-6), time_unit)
    if choice.method not in ("RK45", "DOP853"):
        return run_ode(fun, (t0, t1), y0, method=choice.method, **options), choice
    first = run_ode(
        fun,
        (t0, t1),
        y0,
        method=choice.method,
        watch=stiffness_watch(fun, t1, time_unit),
        **options,
    )
    if first.stop_reason != "stiff":
        return first, choice
    method = "Radau" if len(y0) <= 200 else "BDF"
    budget = dict(options)
    budget["max_time"] = max(options.get("max_time", MAX_TIME) - first.elapsed, 1e-3)
    budget["max_steps"] = max(options.get("max_steps", MAX_STEPS) - first.nsteps, 1)
    run = run_ode(fun, (t0, t1), y0, method=method, **budget)
    run.elapsed += first.elapsed  # what the result cost, the explicit start included
    run.nfev += first.nfev
    reason = (
        f"{choice.reason}; {first.method} then stopped: {first.notes[-1]}; {method} from the start "
        f"({first.nsteps} explicit steps, {first.elapsed:.3g} s, before it)"
    )
    return run, Choice(method, reason, choice.eigenvalues, choice.index)


def _complex(z) -> str:
    z = complex(z)
    if abs(z.imag) <= 1e-12 * max(1.0, abs(z.real)):
        return f"{z.real:.4g}"
    return f"{z.real:.4g} {'+' if z.imag >= 0 else '-'} {abs(z.imag):.4g}i"
