"""Ordinary differential equations of a worksheet: ``[[ode]]`` sections.

A section declares states (unit, initial value, derivative expression), the time range and the
method; the engine types the expressions like any definition, integrates once with
:func:`run_ode` (a wall-clock budget and a step cap, dense output) and each state becomes a
function of time, ``x(t)``, usable in tables and charts::

    [[ode]]
    name = "fall"
    time = "t := 0 .. t_end"             # t is declared in [arguments] with its unit
    method = "auto"                      # auto | RK45 | DOP853 | Radau | BDF | LSODA
    rtol = 1e-8
    atol = 1e-10
    states = [
      { name = "x", unit = "m", initial = "x0", derivative = "v" },
      { name = "v", unit = "m/s", initial = "0 m/s", derivative = "-g - c/m*v" },
    ]

``method``, ``rtol``, ``atol`` and ``max_time`` may also be expressions of the sheet (a text
definition or choice input for the method), and a state may have its own ``atol``.

This module holds the sections' side on plain magnitudes (states in their declared units,
time in its unit): choosing a method, solving a section typed at load
(:mod:`workbook.language.odes` reads and types it), a sheet's run
with other settings (:func:`run_sheet`, for studies) and error against run time; the runs
themselves are :mod:`workbook.engine.oderun`. scipy is imported inside the functions.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import DomainError, LimitError, TemplateError
from ..language.odes import MAX_STEPS, MAX_TIME, METHODS, TypedOde, check_budget
from ..limits_time import budgeted, within_budget
from .odeauto import Choice, auto_run
from .oderun import OdeRun, run_ode, work_precision

#: A state whose magnitude exceeds this (in its declared unit) stops the run: it blows up.
BLOWUP = 1e100


# -- a run ------------------------------------------------------------------------------------
@dataclass
class Solution:
    """The states as functions of time over [t0, t1] (dense output), and how they were got."""

    name: str
    states: tuple[str, ...]
    t0: float
    t1: float
    method: str
    choice: Choice | None
    run: OdeRun
    notes: list[str] = field(default_factory=list)
    sizes: tuple = ()  # per state: None (a number) or n (a vector of n)
    rerun: Callable | None = (
        None  # (rtol, atol, max_time) -> OdeRun: the same run, other tolerances
    )
    atol: np.ndarray | None = None  # per number of the state vector
    blown: tuple[float, str] | None = None  # (time, message) of a blow-up: values before it
    _estimate: ErrorEstimate | None = None

    def estimate(self) -> ErrorEstimate:
        """The global error estimate of the states (computed once): the difference from a run
        of the same method at tolerances REFERENCE_FACTOR tighter, at every step of this run."""
        if self._estimate is None:
            self._estimate = estimate_error(self)
        return self._estimate

    def __call__(self, k: int, t) -> np.ndarray | float:
        """State k at time(s) t (magnitudes in the time unit); outside the span is an error.
        A vector state of n elements gives shape (n, 1) + shape of t."""
        arr = np.asarray(t, dtype=float)
        lo, hi = min(self.t0, self.t1), max(self.t0, self.t1)
        tol = 1e-12 * max(1.0, abs(hi - lo))
        bad = (arr < lo - tol) | (arr > hi + tol) | ~np.isfinite(arr)
        if np.any(bad):
            first = float(np.atleast_1d(arr)[np.atleast_1d(bad)][0])
            raise DomainError(
                f"{self.states[k]}({first:g}) is outside the time range of ode '{self.name}' "
                f"[{self.t0:g}, {self.t1:g}]",
                definition=self.states[k],
            )
        if self.blown is not None:
            self._before_blow_up(k, arr)
        sizes = self.sizes or (None,) * len(self.states)
        first = sum(1 if n is None else n for n in sizes[:k])
        # scipy's dense output takes one time or a line of them: a grid of the numerical
        # built-ins (rows x samples) is read as a line and given its shape back
        flat = np.clip(arr, lo, hi).reshape(-1) if arr.ndim else np.clip(arr, lo, hi)
        y = np.asarray(self.run.sol(flat))
        y = y.reshape(y.shape[:1] + arr.shape)
        if sizes[k] is not None:
            return y[first : first + sizes[k]].reshape((sizes[k], 1) + arr.shape)
        out = y[first]
        return float(out) if arr.ndim == 0 else out

    def reference(self) -> Solution | None:
        """The same states from the error estimate's reference run (tolerances
        REFERENCE_FACTOR tighter), or None where there is none."""
        est = self.estimate()
        if est.failed or est.ref is None or est.ref.sol is None:
            return None
        return replace(self, run=est.ref, _estimate=est)

    def _before_blow_up(self, k: int, arr: np.ndarray) -> None:
        """Refuse a time at or past the blow-up (the run has no values there), or past the
        first step where the global error estimate exceeds ESTIMATE_LIMIT times the tolerance
        (the run lags behind a singularity: RK45 reaches y' = y^2 at t = 1.0000003)."""
        t_b, message = self.blown
        trusted = self.estimate().trusted
        sign = np.sign(self.t1 - self.t0)
        if trusted is not None and (trusted - t_b) * sign < 0:
            message = (
                f"the global error estimate exceeds {ESTIMATE_LIMIT:g} times the tolerance "
                f"from there on, before the blow-up: {message}"
            )
            t_b = trusted
        past = (arr - t_b) * sign >= 0
        if np.any(past):
            first = float(np.atleast_1d(arr)[np.atleast_1d(past)][0])
            raise DomainError(
                f"{self.states[k]}({first:g}) is at or past t = {t_b:.6g}, where {message}",
                definition=self.states[k],
            )

    def finding(self) -> str:
        r = self.run
        head = f"ode '{self.name}': {self.method}"
        if self.choice is not None:
            head += f" (auto: {self.choice.reason})"
        return (
            f"{head}; rtol {r.rtol:g}, atol {r.atol:g}: {r.nsteps} steps, {r.nfev} evaluations, "
            f"{r.elapsed:.3g} s"
        )


def solve(
    fun: Callable,
    t0: float,
    t1: float,
    y0,
    *,
    name: str,
    states: tuple[str, ...],
    method: str = "auto",
    rtol: float = 1e-6,
    atol: float | np.ndarray = 1e-9,
    max_time: float = MAX_TIME,
    max_steps: int = MAX_STEPS,
    time_unit: str = "",
    sizes: tuple = (),
) -> Solution:
    """Integrate y' = fun(t, y) from t0 to t1; a run that does not finish is a LimitError
    (budget, step cap) or a DomainError (blow-up, solver failure) that says where and why."""
    y0 = np.asarray(y0, dtype=float)
    fun = budgeted(fun, f"ode '{name}'")  # the command's time budget, checked at each call
    if not np.all(np.isfinite(y0)):
        raise DomainError(f"ode '{name}': an initial value is not a finite number")
    if t1 == t0:
        raise TemplateError(f"ode '{name}': the time range is empty ({t0:g} .. {t1:g})")
    choice = None
    f0 = np.asarray(fun(t0, y0), dtype=float)
    if f0.shape != y0.shape or not np.all(np.isfinite(f0)):
        raise DomainError(f"ode '{name}': a derivative is not a finite number at the start")
    options = dict(
        rtol=rtol,
        atol=atol,
        max_time=max_time,
        max_steps=max_steps,
        dense_output=True,
        blowup=BLOWUP,
    )
    if method == "auto":
        run, choice = auto_run(fun, t0, t1, y0, time_unit, **options)
        method = choice.method
    else:
        run = run_ode(fun, (t0, t1), y0, method=method, **options)
    blown = None
    if not run.ok and blew_up(run):
        # the values before the blow-up are the run's: only those at or past it are refused
        blown = (float(run.t_reached), _refusal(run, name, flat_names(states, sizes), time_unit))
    elif not run.ok:
        _refuse(run, name, flat_names(states, sizes), time_unit)

    def rerun(r: float, a, seconds: float) -> OdeRun:
        return run_ode(
            fun, (t0, t1), y0, method=method, rtol=r, atol=a, max_time=within_budget(seconds),
            max_steps=max_steps, dense_output=True, blowup=BLOWUP,
        )  # fmt: skip

    return Solution(
        name,
        tuple(states),
        float(t0),
        float(t1),
        method,
        choice,
        run,
        sizes=tuple(sizes),
        rerun=rerun,
        atol=np.broadcast_to(np.asarray(atol, dtype=float), y0.shape).copy(),
        blown=blown,
    )


#: The reference of a state's error estimate runs at tolerances this much tighter (rtol at
#: least 1e-13); an estimate above ESTIMATE_LIMIT times the tolerance is a warning (a local
#: tolerance commonly gives global errors up to some tens of times it; more means they grew).
REFERENCE_FACTOR = 1000.0
ESTIMATE_LIMIT = 100.0
#: The reference run's wall-clock budget: this many times the run's own time, at least
#: REFERENCE_SECONDS (and at most MAX_TIME); a reference that needs more gives no estimate.
REFERENCE_SLOWER = 20.0
REFERENCE_SECONDS = 5.0
#: Where a state passes through zero its error is measured against this fraction of its largest
#: size over the run (a velocity crossing zero is not judged by its rtol near zero alone).
SIZE_FLOOR = 0.01


@dataclass(frozen=True)
class ErrorEstimate:
    """Per number of the state vector: the largest |y - y_ref| over the run's steps, where, and
    that error over the run's tolerance there (atol + rtol*|y_ref|, |y_ref| at least SIZE_FLOOR
    of its largest value); or why there is none."""

    errors: np.ndarray
    times: np.ndarray
    ratios: np.ndarray
    reference: str  # how the reference ran
    failed: str = ""  # why there is no estimate
    trusted: float | None = None  # a run that blew up: the first step beyond ESTIMATE_LIMIT
    ref: OdeRun | None = None  # the reference run (its dense output: the states' reference)

    @property
    def worst(self) -> int:
        return int(np.argmax(self.ratios)) if self.ratios.size else -1


def estimate_error(sol: Solution) -> ErrorEstimate:
    """The difference between a solution and a run at tolerances REFERENCE_FACTOR tighter."""
    r, sign = sol.run, (1.0 if sol.t1 >= sol.t0 else -1.0)
    rtol = max(r.rtol / REFERENCE_FACTOR, 1e-13)
    atol = sol.atol / REFERENCE_FACTOR
    budget = min(MAX_TIME, max(REFERENCE_SECONDS, REFERENCE_SLOWER * r.elapsed))
    ref = sol.rerun(rtol, atol, budget)
    how = f"{ref.method} at rtol {rtol:g}, atol {np.max(atol):g}"
    blown = sol.blown is not None and blew_up(ref)
    if not (ref.ok or blown):
        empty = np.empty(0)
        return ErrorEstimate(empty, empty, empty, how, f"the reference run {ref.summary()}")
    # a run that blew up is compared where both runs have values (before either stopped)
    stop = min(ref.t_reached * sign, r.t_reached * sign) * sign
    keep = (r.t - stop) * sign <= 0 if blown else np.ones(r.t.shape, dtype=bool)
    t, y = r.t[keep], r.y[:, keep]
    y_ref = np.asarray(ref.sol(t)).reshape(y.shape)
    diff = np.abs(y - y_ref)
    size = np.maximum(np.abs(y_ref), SIZE_FLOOR * np.max(np.abs(y_ref), axis=1, keepdims=True))
    scale = (atol * REFERENCE_FACTOR)[:, None] + r.rtol * size
    ratio = diff / scale
    at = np.argmax(ratio, axis=1)
    rows = np.arange(len(at))
    trusted = None
    if sol.blown is not None:  # values are given up to where the estimate leaves the tolerance
        over = np.flatnonzero(np.max(ratio, axis=0) > ESTIMATE_LIMIT)
        trusted = float(t[over[0]]) if over.size else stop
    return ErrorEstimate(diff[rows, at], t[at], ratio[rows, at], how, trusted=trusted, ref=ref)


def flat_names(states, sizes) -> list[str]:
    """A name per number of the state vector: x, or q[0], q[1], ... of a vector state."""
    sizes = sizes or (None,) * len(states)
    out = []
    for s, n in zip(states, sizes):
        out += [s] if n is None else [f"{s}[{i}]" for i in range(n)]
    return out


def blew_up(run) -> bool:
    """A run that stopped where its states grow without bound (past BLOWUP, or a solver that
    failed with states beyond 1e6), with the steps before it kept."""
    big = run.y.size and np.max(np.abs(run.y[:, -1])) > 1e6
    failed = run.stop_reason.startswith("failed") and big
    return run.sol is not None and (run.stop_reason == "blow-up" or failed)


def _refusal(run, name: str, states, time_unit: str) -> str:
    """What a run that blew up or failed says: where, and why."""
    at = f"t = {run.t_reached:.6g}{' ' + time_unit if time_unit else ''} of {run.t_final:g}"
    if run.stop_reason == "blow-up":
        note = run.notes[-1]
        k = int(note.split()[1])
        note = note.replace(f"state {k} ", f"state '{states[k]}' ", 1)
        return f"ode '{name}' stopped at {at}: {note}"
    big = ""
    if run.y.size and np.max(np.abs(run.y[:, -1])) > 1e6:
        big = " (the states grow without bound: the solution blows up)"
    return f"ode '{name}' ({run.method}) stopped at {at}: {run.stop_reason}{big}"


def _refuse(run, name: str, states, time_unit: str) -> None:
    at = f"t = {run.t_reached:.6g}{' ' + time_unit if time_unit else ''} of {run.t_final:g}"
    if run.stop_reason in ("time budget", "step cap"):
        budget = "its time budget" if run.stop_reason == "time budget" else "its step cap"
        advice = (
            f"{run.method} is an implicit method already: a looser rtol, or a shorter time range"
            if run.method in ("Radau", "BDF", "LSODA")
            else 'a stiff system wants method = "Radau" or "BDF" (or "auto")'
        )
        raise LimitError(
            f"ode '{name}' ({run.method}) stopped at {at}: {run.notes[-1]}; "
            f"{run.nsteps} steps. {budget.capitalize()} is max_time/max_steps in [[ode]]; "
            + advice,
            definition=name,
        )
    raise DomainError(_refusal(run, name, states, time_unit), definition=name)


# -- error against run time -------------------------------------------------------------------
def bench_rows(
    fun: Callable,
    t0: float,
    t1: float,
    y0,
    *,
    name: str,
    atol_ratio: float = 1e-3,
    rtols=(1e-3, 1e-6, 1e-9),
    methods=("RK45", "DOP853", "Radau", "BDF", "LSODA"),
    max_time: float = 10.0,
    points: int = 201,
) -> list[dict]:
    """Every method at every rtol against a tight reference ("auto" at rtol 1e-12: DOP853, then
    LSODA where it turns stiff), itself checked by a second method at the same tolerance: the
    largest error over ``points`` times, relative to the largest magnitude of each
    state, and the run time. The reference row's error is the two references' difference;
    an error at or below it is marked as not resolved by the reference."""
    y0 = np.asarray(y0, dtype=float)
    ts = np.linspace(t0, t1, points)
    tight = dict(rtol=1e-12, atol=1e-14, t_eval=ts, max_time=60.0)
    ref = auto_run(fun, t0, t1, y0, **tight)[0]
    check_method = "LSODA" if ref.method != "LSODA" else "Radau"
    second = run_ode(fun, (t0, t1), y0, method=check_method, **tight)
    for run in (ref, second):
        if not run.ok:
            raise LimitError(
                f"ode '{name}': the reference run ({run.method}) did not finish: {run.summary()}"
            )
    scale = np.maximum(np.max(np.abs(ref.y), axis=1), 1e-300)[:, None]
    ref_error = float(np.max(np.abs(second.y - ref.y) / scale))

    def case(method: str, rtol: float):
        return run_ode(
            fun,
            (t0, t1),
            y0,
            method=method,
            rtol=rtol,
            atol=rtol * atol_ratio * scale[:, 0],
            t_eval=ts,
            max_time=max_time,
        )

    def error(run) -> float:
        return float(np.max(np.abs(run.y - ref.y) / scale))

    rows = work_precision(case, error, methods, rtols, case=name)
    out = [
        {
            "ode": name,
            "method": r.method,
            "rtol": r.rtol,
            "error": r.error,
            "seconds": r.elapsed,
            "evaluations": r.nfev,
            "steps": r.nsteps,
            "stop": r.stop_reason,
            "resolved": bool(r.error > ref_error),
        }
        for r in rows
    ]
    out.append(
        {
            "ode": name,
            "method": f"reference {ref.method} (checked by {check_method})",
            "rtol": 1e-12,
            "error": ref_error,
            "seconds": ref.elapsed,
            "evaluations": ref.nfev,
            "steps": ref.nsteps,
            "stop": ref.stop_reason,
            "resolved": False,
        }
    )
    return out


# -- an [[ode]] of a sheet ----------------------------------------------------------------------
@dataclass(frozen=True)
class Settings:
    """A section's method and tolerances, evaluated on its sheet."""

    method: str
    rtol: float
    atol: np.ndarray  # per state, in the states' units
    max_time: float
    max_steps: int


def settings(typed: TypedOde, compile_expr: Callable) -> Settings:
    """Evaluate the method, rtol, atol (per state) and budget of a section."""
    spec, done = typed.spec, typed.settings

    def value(key: str):
        return compile_expr(done[key])({}) if key in done else getattr(spec, key)

    method, rtol, max_time = value("method"), float(value("rtol")), float(value("max_time"))
    if method not in METHODS:
        raise DomainError(
            f"ode '{spec.name}': method {method!r} is not one of {', '.join(METHODS)}",
            definition=spec.name,
        )
    for key, v, low in (("rtol", rtol, 1e-13), ("max_time", max_time, 0.0)):
        if not (math.isfinite(v) and v > low):
            raise DomainError(f"ode '{spec.name}': {key} = {v:g} is not above {low:g}")
    check_budget(f"ode '{spec.name}'", "max_time", max_time)
    atol = float(value("atol"))
    per_state = [compile_expr(a)({}) if a is not None else atol for a in typed.atols]
    per_state = per_state or [atol] * len(spec.states)
    atols = np.concatenate(
        [np.full(1 if n is None else n, float(v)) for v, n in zip(per_state, typed.sizes)]
    )
    if not np.all((atols > 0) & np.isfinite(atols)):
        raise DomainError(f"ode '{spec.name}': an atol is not a positive number")
    return Settings(method, rtol, atols, max_time, spec.max_steps)


def problem(typed: TypedOde, compile_expr: Callable):
    """(fun, t0, t1, y0) of a section, compiled with the numpy back end."""
    spec = typed.spec
    ders = [compile_expr(d) for d in typed.derivatives]
    var = spec.var
    parts, first = [], 0  # (name, first index, size or None)
    for s, n in zip(spec.states, typed.sizes):
        parts.append((s.name, first, n))
        first += 1 if n is None else n

    def fun(t, y):
        env = {var: float(t)}
        for name, k, n in parts:
            env[name] = float(y[k]) if n is None else y[k : k + n].reshape(n, 1)
        return np.concatenate([np.asarray(d(env), dtype=float).reshape(-1) for d in ders])

    y0 = np.concatenate(
        [np.asarray(compile_expr(i)({}), dtype=float).reshape(-1) for i in typed.initials]
    )
    t0, t1 = float(compile_expr(typed.first)({})), float(compile_expr(typed.last)({}))
    return fun, t0, t1, y0


def solve_typed(typed: TypedOde, compile_expr: Callable) -> Solution:
    """Compile the derivatives with the numpy back end and integrate."""
    from ..language import units as un

    spec = typed.spec
    fun, t0, t1, y0 = problem(typed, compile_expr)
    st = settings(typed, compile_expr)
    return solve(
        fun,
        t0,
        t1,
        y0,
        name=spec.name,
        states=tuple(s.name for s in spec.states),
        method=st.method,
        rtol=st.rtol,
        atol=st.atol,
        max_time=st.max_time,
        max_steps=st.max_steps,
        time_unit=un.pretty(typed.time_unit),
        sizes=typed.sizes,
    )


def run_sheet(
    sheet,
    name: str,
    *,
    t_eval=None,
    max_time: float | None = None,
    max_steps: int | None = None,
    label: str | None = None,
    jac=None,
) -> OdeRun:
    """One bounded run of the sheet's ``[[ode]] name`` with its own method and tolerances
    (give other ones with ``sheet.with_inputs``), timed: a run that stops early is returned,
    not raised (a study records it). ``t_eval`` in the time unit (default: the steps);
    ``jac(t, y)``: the Jacobian for the implicit methods, when the caller knows it (a linear
    system's matrix), else they estimate it by differences."""
    typed = sheet.defs.ode(name)
    fun, t0, t1, y0 = problem(typed, sheet.evaluator.compile)
    st = settings(typed, sheet.evaluator.compile)
    fun(t0, y0)  # what the derivatives share is computed before the clock starts
    options = dict(
        rtol=st.rtol,
        atol=st.atol,
        t_eval=t_eval,
        max_time=st.max_time if max_time is None else max_time,
        max_steps=st.max_steps if max_steps is None else max_steps,
        label=label,
        jac=jac,
    )
    if st.method == "auto":
        return auto_run(fun, t0, t1, y0, **options)[0]
    return run_ode(fun, (t0, t1), y0, method=st.method, **options)


def sheet_findings(sheet) -> list:
    """One finding per [[ode]]: the method, and why "auto" chose it; a run that failed."""
    from ..errors import WorkbookError
    from ..findings import Finding

    out = []
    for name in sheet.spec.odes:
        try:
            sol = sheet.evaluator.ode_solution(name)
        except WorkbookError as err:
            out.append(Finding(f"ode {name}", "the run did not finish", None, "", "fail", str(err)))
            continue
        if sol.blown is not None:
            note = f"{sol.blown[1]}; the values before t = {sol.blown[0]:.6g} are given"
            out.append(Finding(f"ode {name}", "the run did not finish", None, "", "fail", note))
        out.append(
            Finding(f"ode {name}", f"solved with {sol.method}", None, "", "info", sol.finding())
        )
        out.append(_estimate_finding(sheet, name, sol))
    return out


def _estimate_finding(sheet, name: str, sol: Solution):
    """The states' global error estimate: a warning when one exceeds ESTIMATE_LIMIT times its
    tolerance (or when there is no estimate), else for information."""
    from ..findings import Finding
    from ..language import units as un

    est = sol.estimate()
    topic = f"ode {name}"
    if est.failed:
        return Finding(topic, "no global error estimate", None, "", "warning", est.failed)
    typed = sheet.defs.ode(name)
    names = flat_names(sol.states, sol.sizes)
    units = [u for u, n in zip(typed.units, typed.sizes) for _ in range(1 if n is None else n)]
    k = est.worst
    unit = un.pretty(un.difference_unit(units[k]))  # an error is a difference: delta_degC
    t_unit = un.pretty(typed.time_unit)
    what = (
        f"global error estimate: {names[k]} off by up to {est.errors[k]:.3g} {unit}".rstrip()
        + f" at t = {est.times[k]:.6g} {t_unit}".rstrip()
        + f", {est.ratios[k]:.3g} times its tolerance (rtol {sol.run.rtol:g}, atol "
        f"{sol.atol[k]:g})"
    )
    note = f"the difference from a run of {est.reference}, at each step"
    if est.ratios[k] > ESTIMATE_LIMIT:
        note += (
            f"; over {ESTIMATE_LIMIT:g} times the tolerance: the values of this ode are less "
            "accurate than asked (tighten rtol and atol, or the solution is growing fast)"
        )
        return Finding(topic, what, None, "", "warning", note)
    return Finding(topic, what, None, "", "info", note)


def sheet_bench(sheet, quick: bool = False) -> list[dict]:
    """Error against run time of every method on each [[ode]] of the sheet."""
    rows = []
    for name in sheet.spec.odes:
        fun, t0, t1, y0 = problem(sheet.defs.ode(name), sheet.evaluator.compile)
        rtols = (1e-3, 1e-6) if quick else (1e-3, 1e-6, 1e-9)
        rows += bench_rows(fun, t0, t1, y0, name=name, rtols=rtols)
    return rows
