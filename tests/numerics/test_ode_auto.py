"""Method "auto" watches the run, a failed solve is remembered, and states carry a global
error estimate; references are scipy runs at tight tolerances and closed forms."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.paths import DATA
from scipy.integrate import solve_ivp

import workbook
from workbook.engine import ode
from workbook.errors import DomainError


def robertson(t, y):
    y1, y2, y3 = y
    return [-0.04 * y1 + 1e4 * y2 * y3, 0.04 * y1 - 1e4 * y2 * y3 - 3e7 * y2**2, 3e7 * y2**2]


@pytest.mark.slow
def test_robertson_turns_stiff_and_auto_goes_on_with_lsoda():
    sheet = workbook.load(DATA / "robertson.toml")
    sol = sheet.evaluator.ode_solution("rob")
    assert sol.method == "LSODA" and sol.choice.method == "LSODA"
    assert "RK45 from the start" in sol.choice.reason and ": stiff" in sol.choice.reason
    assert "LSODA from there" in sol.choice.reason
    assert sol.run.nsteps < 1000  # RK45 alone took 34,537 steps
    ref = solve_ivp(robertson, (0, 40), [1, 0, 0], method="Radau", rtol=1e-12, atol=1e-16)
    got = np.array([sol(k, 40.0) for k in range(3)])
    assert np.allclose(got, ref.y[:, -1], rtol=1e-5, atol=1e-10)
    found = [f for f in sheet.check().findings if f.topic == "ode rob"]
    assert "solved with LSODA" in found[0].what and "RK45 from the start" in found[0].note


def test_a_problem_that_is_not_stiff_stays_explicit(sheet_from):
    text = """
[inputs]
w = "3 1/s"

[arguments]
t = { unit = "s" }

[[ode]]
name = "spring"
time = "t := 0 .. 50"
states = [
  { name = "x", unit = "m", initial = "1", derivative = "v" },
  { name = "v", unit = "m/s", initial = "0", derivative = "-w^2*x" },
]
""".replace("v*1 s/s", "v")
    sheet = sheet_from(text)
    sol = sheet.evaluator.ode_solution("spring")
    assert sol.method == "RK45" and "then stopped" not in sol.choice.reason
    assert sol(0, 50.0) == pytest.approx(np.cos(150.0), abs=1e-4)


def test_run_sheet_auto_uses_the_same_watch():
    sheet = workbook.load(DATA / "robertson.toml")
    run = ode.run_sheet(sheet, "rob")
    assert run.ok and run.method == "LSODA"


BLOWS_UP = """
[inputs]
T = "2 s"
r = "1 1/s"

[arguments]
t = { unit = "s" }

[definitions]
a = "y(T)"
b = "y(T/2)"
c = "2*y(T)"

[[ode]]
name = "sq"
time = "t := 0 .. T"
states = [{ name = "y", unit = "", initial = "1", derivative = "r*y^2" }]
"""


def test_a_failed_solve_is_remembered_not_repeated(sheet_from, monkeypatch):
    calls = []
    solve_typed = ode.solve_typed

    def counted(*args, **kw):
        calls.append(1)
        return solve_typed(*args, **kw)

    monkeypatch.setattr(ode, "solve_typed", counted)
    sheet = sheet_from(BLOWS_UP)
    for name in ("a", "b", "c", "a"):
        with pytest.raises(DomainError, match="blows up"):
            sheet.evaluate(name)
    assert len(calls) == 1
    report = sheet.check()
    whats = [f.what for f in report.findings if f.topic == "ode sq"]
    assert whats[0] == "the run did not finish"
    assert len(calls) == 1


def test_an_implicit_run_over_its_budget_does_not_advise_an_implicit_method():
    from workbook.errors import LimitError

    with pytest.raises(LimitError) as err:
        ode.solve(
            robertson,
            0.0,
            4e10,
            [1.0, 0.0, 0.0],
            name="rob",
            states=("y1", "y2", "y3"),
            method="Radau",
            rtol=1e-10,
            atol=1e-14,
            max_steps=20,
        )
    assert "Radau is an implicit method already" in str(err.value)
    assert "wants method" not in str(err.value)


def test_a_growing_solution_warns_with_its_error_estimate(sheet_from):
    """y' = y^2, y(0) = 1 to t = 0.999999: the exact 1e6 is computed as about 777,669 at the
    default tolerances; the estimate says so instead of nothing."""
    text = BLOWS_UP.replace('T = "2 s"', 'T = "0.999999 s"')
    sheet = sheet_from(text)
    value = sheet.evaluate("a").magnitude
    true_error = 1e6 - value
    assert true_error > 1e5  # the run is this far off
    est = sheet.evaluator.ode_solution("sq").estimate()
    assert est.errors[0] >= true_error / 10
    warned = [f for f in sheet.check().findings if f.verdict == "warning"]
    assert any(f.what.startswith("global error estimate: y off by up to") for f in warned)


def test_an_accurate_run_reports_its_estimate_for_information(sheet_from):
    text = """
[inputs]
k = "2 1/s"

[arguments]
t = { unit = "s" }

[[ode]]
name = "decay"
time = "t := 0 .. 3"
rtol = 1e-8
atol = 1e-12
states = [{ name = "y", unit = "m", initial = "1", derivative = "-k*y" }]
"""
    sheet = sheet_from(text)
    sol = sheet.evaluator.ode_solution("decay")
    est = sol.estimate()
    ts = sol.run.t
    true = np.max(np.abs(sol.run.y[0] - np.exp(-2 * ts)))
    assert est.errors[0] >= true / 10 and est.errors[0] <= 10 * true + 1e-15
    f = [f for f in sheet.check().findings if f.what.startswith("global error estimate")]
    assert f[0].verdict == "info"


def test_root_integral_and_extrema_of_a_state_use_its_dense_output(sheet_from):
    """py = cos(2 t): a root at pi/4, the integral to 1 s sin(2)/2, the maximum on [0.5, 3.5]
    1 at pi (the closed form; the run at rtol 1e-10)."""
    text = """
[inputs]
w = "2 1/s"
t_a = "0.5 s"
t_b = "1 s"

[arguments]
t = { unit = "s" }

[definitions]
t0 = { expr = "root(py(t), t, t_a, t_b)", unit = "s" }
I = { expr = "integral(py(t), t, 0 s, t_b)", unit = "m*s" }
top = { expr = "maximum(py(t), t, t_a, 3.5 s)", unit = "m" }
at = { expr = "argmax(py(t), t, t_a, 3.5 s)", unit = "s" }
low = { expr = "minimum(pv(t), t, 0 s, 2 s)", unit = "m/s" }

[[ode]]
name = "osc"
time = "t := 0 .. 4"
rtol = 1e-10
atol = 1e-12
states = [
  { name = "py", unit = "m", initial = "1", derivative = "pv" },
  { name = "pv", unit = "m/s", initial = "0", derivative = "-w^2*py" },
]
"""
    sheet = sheet_from(text)
    value = {n: sheet.evaluate(n).magnitude for n in ("t0", "I", "top", "at", "low")}
    assert value["t0"] == pytest.approx(np.pi / 4, abs=1e-8)
    assert value["I"] == pytest.approx(np.sin(2) / 2, abs=1e-8)
    assert value["top"] == pytest.approx(1, abs=1e-8)
    assert value["at"] == pytest.approx(np.pi, abs=1e-4)  # a flat top: argmax to sqrt(tol)
    assert value["low"] == pytest.approx(-2, abs=1e-8)
