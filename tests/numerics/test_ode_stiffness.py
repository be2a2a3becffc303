"""Method "auto" judges stiffness from the steps the explicit method is held to: a saddle
(Kepler) stays explicit, problems stiff from the start or later go on with LSODA. References:
the Kepler orbit's period (it returns to its start) and SciPy's Radau at tight tolerances."""

from __future__ import annotations

import sys

import numpy as np
import pytest
from helpers.paths import ROOT
from scipy.integrate import solve_ivp

from workbook.engine import ode
from workbook.engine.odeauto import auto_run, jacobian

# the problems are the benchmark's (benchmarks/bench_ode.py times the same ones)
sys.path.insert(0, str(ROOT / "benchmarks"))
from ode_problems import HIRES_Y0, KEPLER_Y0, hires, kepler, late, robertson, vdp  # noqa: E402


@pytest.mark.slow
def test_kepler_over_50_periods_stays_explicit_and_returns_to_its_start():
    """A saddle pair of eigenvalues (+-4 at the perihelion) times the span 314 is 1256: the
    old test of the Jacobian at the start called it stiff. The orbit's period is 2 pi."""
    lam = np.linalg.eigvals(jacobian(kepler, 0.0, np.array(KEPLER_Y0)))
    assert np.max(-lam.real) == pytest.approx(4.0, rel=1e-6)
    for rtol, method in ((1e-6, "RK45"), (1e-9, "DOP853")):
        run, choice = auto_run(kepler, 0.0, 100 * np.pi, KEPLER_Y0, rtol=rtol, atol=1e-3 * rtol)
        assert run.ok and run.method == method == choice.method
        # the watch only reads the steps: the run is SciPy's own
        direct = solve_ivp(kepler, (0.0, 100 * np.pi), KEPLER_Y0, method=method, rtol=rtol,
                           atol=1e-3 * rtol)  # fmt: skip
        assert np.allclose(run.y[:, -1], direct.y[:, -1], rtol=1e-12, atol=1e-14)
    assert np.max(np.abs(run.y[:, -1] - KEPLER_Y0)) < 1e-3  # 50 periods on: 1.1e-4 at rtol 1e-9


def test_a_saddle_stays_explicit_over_five_periods():
    """Kepler over 5 periods at rtol 1e-6: RK45, the same steps as SciPy's."""
    run, choice = auto_run(kepler, 0.0, 10 * np.pi, KEPLER_Y0, rtol=1e-6, atol=1e-9)
    direct = solve_ivp(kepler, (0.0, 10 * np.pi), KEPLER_Y0, rtol=1e-6, atol=1e-9)
    assert run.ok and run.method == choice.method == "RK45"
    assert np.allclose(run.y[:, -1], direct.y[:, -1], rtol=1e-12, atol=1e-14)


@pytest.mark.slow
@pytest.mark.parametrize(
    "f, span, y0",
    [
        (robertson, (0.0, 40.0), [1.0, 0.0, 0.0]),
        (hires, (0.0, 321.8122), HIRES_Y0),
        (vdp, (0.0, 3000.0), [2.0, 0.0]),
        (late, (0.0, 10.0), [1.0, 0.0]),
    ],
    ids=["robertson", "hires", "van-der-pol-1000", "late-switch-on"],
)
def test_stiff_problems_go_on_with_lsoda_from_where_they_turn_stiff(f, span, y0):
    run, choice = auto_run(f, *span, y0, rtol=1e-6, atol=1e-9, dense_output=True)
    assert run.ok and choice.method == "LSODA" and run.method == "LSODA"
    assert "RK45 from the start" in choice.reason and "stability limit" in choice.reason
    switched = float(choice.reason.split("at t = ")[1].split(",")[0])
    assert span[0] < switched < span[1]
    explicit = int(choice.reason.split("after ")[1].split(" steps")[0])
    assert explicit <= 100
    # one run: steps increasing, the dense output continuous across the switch
    assert np.all(np.diff(run.t) > 0) and run.t[0] == span[0] and run.t[-1] == span[1]
    short = {vdp: 40.0, hires: 20.0}.get(f, span[1])  # Radau over all of it takes seconds
    ts = np.linspace(span[0], short, 41)
    ref = solve_ivp(f, (span[0], short), y0, method="Radau", rtol=1e-8, atol=1e-12, t_eval=ts)
    scale = np.max(np.abs(ref.y), axis=1, keepdims=True)
    assert np.max(np.abs(run.sol(ts) - ref.y) / scale) < 1e-3
    at = np.array([switched - 1e-12, switched + 1e-12])
    assert np.allclose(run.sol(at)[:, 0], run.sol(at)[:, 1], rtol=1e-8, atol=1e-12)


def test_late_switch_on_keeps_its_explicit_part_and_its_t_eval():
    ts = np.linspace(0.0, 10.0, 101)
    run, choice = auto_run(late, 0.0, 10.0, [1.0, 0.0], rtol=1e-8, atol=1e-11, t_eval=ts)
    switched = float(choice.reason.split("at t = ")[1].split(",")[0])
    assert 4.0 < switched < 5.0  # where k t-span turns large, before the middle of the switch
    assert np.array_equal(run.t, ts)
    # y1 = cos t once the start's transient has decayed (y1(0) = 1 = cos 0: none here)
    assert np.max(np.abs(run.y[0] - np.cos(ts))) < 1e-6


@pytest.mark.slow
def test_a_sheet_solution_of_a_stiff_run_has_an_error_estimate_from_lsoda():
    s = ode.solve(robertson, 0.0, 40.0, [1.0, 0.0, 0.0], name="rob", states=("a", "b", "c"),
                  rtol=1e-6, atol=1e-10)  # fmt: skip
    est = s.estimate()
    assert not est.failed and "LSODA" in est.reference
    ref = solve_ivp(robertson, (0, 40), [1, 0, 0], method="Radau", rtol=1e-12, atol=1e-16)
    true = np.abs(np.array([s(k, 40.0) for k in range(3)]) - ref.y[:, -1])
    assert np.all(est.errors >= true / 10)
