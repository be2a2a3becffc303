"""The ODE runner (workbook.engine.oderun) and the solving of [[ode]] sections (workbook.engine.ode)
against closed forms and scipy."""

from __future__ import annotations

import time

import numpy as np
import pytest

from workbook.engine import ode, oderun
from workbook.errors import DomainError, LimitError


def _stiff(t, y):
    return np.array([-1000.0 * (y[0] - np.cos(t)), -y[1]])


def test_auto_takes_an_implicit_method_for_a_stiff_system_and_says_why():
    s = ode.solve(_stiff, 0.0, 5.0, [0.0, 1.0], name="st", states=("a", "b"), rtol=1e-8, atol=1e-10)
    assert s.method == "LSODA"
    assert "stiff" in s.choice.reason and "decay rate 1000" in s.choice.reason
    assert "LSODA" in s.finding()
    t = np.linspace(0, 5, 11)
    # closed form of a' = -k (a - cos t), a(0) = 0
    k = 1000.0
    exact = (k * k * np.cos(t) + k * np.sin(t) - k * k * np.exp(-k * t)) / (k * k + 1)
    assert np.max(np.abs(s(0, t) - exact)) < 1e-7
    assert np.max(np.abs(s(1, t) - np.exp(-t))) < 1e-7


def test_auto_takes_an_explicit_method_when_not_stiff():
    f = lambda t, y: np.array([y[1], -y[0]])  # noqa: E731
    s = ode.solve(f, 0.0, 10.0, [1.0, 0.0], name="osc", states=("x", "v"), rtol=1e-10, atol=1e-12)
    assert s.method == "DOP853" and "watched for stiffness" in s.choice.reason
    t = np.linspace(0, 10, 7)
    assert np.max(np.abs(s(0, t) - np.cos(t))) < 1e-8
    coarse = ode.solve(f, 0.0, 10.0, [1.0, 0.0], name="osc", states=("x", "v"), rtol=1e-4)
    assert coarse.method == "RK45"


def test_the_dense_output_agrees_with_solve_ivp():
    from scipy.integrate import solve_ivp

    f = lambda t, y: np.array([y[1], (1 - y[0] ** 2) * y[1] - y[0]])  # noqa: E731 van der Pol
    s = ode.solve(f, 0, 8, [2.0, 0.0], name="vdp", states=("x", "v"), method="DOP853", rtol=1e-11)
    t = np.linspace(0, 8, 33)
    ref = solve_ivp(f, (0, 8), [2.0, 0.0], method="LSODA", rtol=1e-12, atol=1e-12, t_eval=t)
    assert np.max(np.abs(s(0, t) - ref.y[0])) < 1e-8


@pytest.mark.slow
@pytest.mark.parametrize("method", ["auto", "RK45", "Radau"])
def test_a_solution_that_blows_up_is_stopped_and_said_so(method):
    """y' = y^2, y(0) = 1 is 1/(1 - t): refused at and past the blow-up at t = 1 (and where
    the run's global error estimate leaves the tolerance before it), given before it."""
    s = ode.solve(lambda t, y: y**2, 0.0, 2.0, [1.0], name="bl", states=("y",), method=method)
    with pytest.raises(DomainError, match="blows up") as info:
        s(0, 2.0)
    assert "ode 'bl'" in str(info.value) and "t = 1" in str(info.value)
    with pytest.raises(DomainError, match="blows up"):
        s(0, 1.0)
    assert s(0, 0.5) == pytest.approx(2.0, rel=1e-5)


def test_growth_beyond_the_threshold_names_the_state():
    s = ode.solve(lambda t, y: 1000.0 * y, 0.0, 1.0, [1.0], name="g", states=("y",), method="RK45")
    with pytest.raises(DomainError, match="state 'y' reached") as info:
        s(0, 1.0)
    assert "blows up" in str(info.value)


def test_an_explicit_method_on_a_stiff_system_stops_at_its_budget():
    f = lambda t, y: np.array([-1e7 * (y[0] - np.cos(t))])  # noqa: E731
    start = time.perf_counter()
    with pytest.raises(LimitError, match="time budget") as info:
        ode.solve(f, 0, 100, [0.0], name="st", states=("y",), method="RK45", max_time=0.3)
    assert time.perf_counter() - start < 5  # a hang guard (the budget is 0.3 s), not a timing claim
    assert "Radau" in str(info.value)  # says what to do
    with pytest.raises(LimitError, match="step cap"):
        ode.solve(f, 0, 100, [0.0], name="st", states=("y",), method="RK45", max_steps=50)


def test_time_outside_the_range_is_an_error():
    s = ode.solve(lambda t, y: -y, 0.0, 1.0, [1.0], name="d", states=("y",))
    with pytest.raises(DomainError, match=r"y\(2\) is outside the time range"):
        s(0, np.array([0.5, 2.0]))
    assert s(0, 1.0) == pytest.approx(np.exp(-1.0), rel=1e-5)


def test_bench_rows_cover_every_method_against_a_tight_reference():
    f = lambda t, y: np.array([y[1], -y[0]])  # noqa: E731
    rows = ode.bench_rows(f, 0.0, 6.0, [1.0, 0.0], name="osc", rtols=(1e-4, 1e-8))
    methods = {r["method"] for r in rows}
    assert {"RK45", "DOP853", "Radau", "BDF", "LSODA"} <= methods
    dop = {r["rtol"]: r["error"] for r in rows if r["method"] == "DOP853"}
    assert dop[1e-8] < dop[1e-4] and dop[1e-8] < 1e-6
    assert rows[-1]["method"].startswith("reference")


def test_bench_reference_is_checked_by_a_second_method():
    """The reference row's error is its difference from a second method at rtol 1e-12; against
    the closed form cos(t) it is not below the reference's true error and not above the sum of
    both; errors at or below it are not claimed as resolved."""
    f = lambda t, y: np.array([y[1], -y[0]])  # noqa: E731
    rows = ode.bench_rows(f, 0.0, 6.0, [1.0, 0.0], name="osc", rtols=(1e-3, 1e-9))
    ref = rows[-1]
    assert ref["method"] == "reference DOP853 (checked by LSODA)"
    ts = np.linspace(0.0, 6.0, 201)
    true = {}
    for method in ("DOP853", "LSODA"):
        run = oderun.run_ode(
            f, (0.0, 6.0), [1.0, 0.0], method=method, rtol=1e-12, atol=1e-14, t_eval=ts
        )
        true[method] = float(np.max(np.abs(run.y - np.array([np.cos(ts), -np.sin(ts)]))))
    assert true["DOP853"] <= ref["error"] <= true["DOP853"] + true["LSODA"]
    for r in rows[:-1]:
        assert r["resolved"] == (r["error"] > ref["error"])
    assert any(r["resolved"] for r in rows if r["rtol"] == 1e-3)


def test_work_precision_skips_tighter_rtols_after_a_stall():
    """A method stopped by its step cap at one rtol is recorded as skipped at tighter ones;
    the others are run and their error falls with rtol (closed form of y' = -y)."""
    ts = np.linspace(0.0, 2.0, 5)

    def case(method, rtol):
        cap = 3 if method == "RK45" and rtol < 1e-4 else 100_000
        return oderun.run_ode(
            lambda t, y: -y,
            (0.0, 2.0),
            [1.0],
            method=method,
            rtol=rtol,
            atol=1e-12,
            t_eval=ts,
            max_steps=cap,
        )

    def error(run):
        return float(np.max(np.abs(run.y[0] - np.exp(-ts))))

    rows = oderun.work_precision(case, error, ("RK45", "Radau"), (1e-3, 1e-6, 1e-9))
    got = {(r.method, r.rtol): r for r in rows}
    assert got["RK45", 1e-6].stop_reason == "step cap"
    assert got["RK45", 1e-9].stop_reason.startswith("skipped") and np.isnan(got["RK45", 1e-9].error)
    assert got["Radau", 1e-9].error < got["Radau", 1e-3].error / 1000


def test_linear_parts_and_the_matrix_exponential_against_solve_ivp():
    """A forced, damped oscillator with a stiff second mode: the parts read off the function,
    and its exact solution, against solve_ivp at rtol 1e-12; a nonlinear system is refused."""
    from scipy.integrate import solve_ivp

    A = np.array([[0, 1, 0, 0], [-400, -0.4, 50, 0], [0, 0, 0, 1], [30, 0, -9e4, -0.1]], float)
    b, g, om = np.array([0, 2.0, 0, -1.0]), np.array([0, 0, 0, 5.0]), 37.0

    def f(t, y):
        return A @ y + b + g * np.sin(om * t)

    A2, b2, g2 = oderun.linear_parts(f, 4, om)
    np.testing.assert_allclose(A2, A, atol=1e-9)
    np.testing.assert_allclose(b2, b, atol=1e-12)
    np.testing.assert_allclose(g2, g, atol=1e-12)
    ts = np.linspace(0, 0.5, 51)
    y0 = [0.01, 0, -0.02, 0]
    got = oderun.linear_solution(A2, b2, g2, om, y0, ts)
    ref = solve_ivp(f, (0, 0.5), y0, method="DOP853", rtol=1e-12, atol=1e-14, t_eval=ts)
    np.testing.assert_allclose(got, ref.y, atol=1e-9 * np.max(np.abs(ref.y)))
    with pytest.raises(DomainError, match="not linear"):
        oderun.linear_parts(lambda t, y: -(y**3), 2, om)
