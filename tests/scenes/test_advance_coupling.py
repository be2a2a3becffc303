"""advance-coupling: steady curves and stiff dynamics of the centrifugal injection-advance coupling.

References are not taken from the code under test where that is possible: the steady roots
from mpmath.findroot on the equilibrium written out here from the paper, the values of the
reference example, eigenfrequencies from scipy.linalg.eigh on (K, M), the exact
solution (matrix exponential) checked against solve_ivp at rtol 1e-12 on the template's ODE,
and the rigid-tooth limit from a 2-DOF ODE written out here and integrated with solve_ivp at
rtol 1e-12.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import workbook
from workbook.blocks import coupling as cp
from workbook.compute.declared_checks import check_findings
from workbook.engine import ode, oderun
from workbook.errors import WorkbookError

# the reference example's dimensions (SI)
EX = dict(
    O1O=0.042,
    OC=0.036,
    OC1=0.052,
    lam=0.001,
    OB=0.015,
    O1B=0.040,
    tg=1 / 3,
    MD0=1.2,
    m=0.7,
    c1=3000.0,
    phi20=0.5236,
)


@pytest.fixture(scope="module")
def sheet():
    """With the optional part studies (left out by a plain load)."""
    return workbook.load("advance-coupling", parts="all")


def F_ref(phi, w, d):
    """The equilibrium of the paper, written out independently (mpmath numbers)."""
    import mpmath as mp

    G = d["MD0"] * d["OB"] / d["O1B"] * d["tg"]
    return (
        2 * d["m"] * w**2 * (d["O1O"] - d["OC"] * mp.cos(phi)) * d["OC"] * mp.sin(phi)
        - 8
        * d["c1"]
        * (d["lam"] + d["OC1"] * (mp.cos(d["phi20"]) - mp.cos(phi)))
        * d["OC1"]
        * mp.sin(phi)
        - G
    )


def root_ref(w, **changes):
    """Stable root by mpmath: scan from phi20 for the first + to - change, then findroot."""
    import mpmath as mp

    mp.mp.dps = 30
    d = {**EX, **changes}
    if F_ref(mp.mpf(d["phi20"]), w, d) <= 0:
        return 0.0
    xs = np.linspace(d["phi20"], math.pi - 1e-6, 4001)
    prev = F_ref(mp.mpf(xs[0]), w, d)
    for a, b in zip(xs[:-1], xs[1:]):
        cur = F_ref(mp.mpf(b), w, d)
        if prev > 0 >= cur:
            x = mp.findroot(lambda x: F_ref(x, w, d), (mp.mpf(a), mp.mpf(b)), solver="anderson")
            return float(x) - d["phi20"]
        prev = cur
    raise AssertionError("no root")


# -- steady state ------------------------------------------------------------------------------
def test_steady_values_match_reference(sheet):
    got = sheet.evaluate("phi2", omega1=[50, 80, 110]).to("rad").magnitude
    assert got[0] == 0.0  # on the stop at 50 rad/s
    assert abs(got[1] - 0.070) <= 1e-3
    assert abs(got[2] - 0.204) <= 1e-3


@pytest.mark.parametrize("w", [55.0, 80.0, 95.0, 110.0])
def test_root_against_mpmath(sheet, w):
    got = float(sheet.evaluate("phi2", omega1=w).to("rad").magnitude)
    assert got == pytest.approx(root_ref(w), abs=1e-11)


@pytest.mark.parametrize(
    "name,values,expected",
    [
        ("c1", ["1500 N/m", "3000 N/m", "4000 N/m", "6000 N/m"], [0.730, 0.204, 0.131, 0.067]),
        ("m", ["0.65 kg", "0.7 kg", "0.75 kg", "0.8 kg"], [0.181, 0.204, 0.228, 0.253]),
    ],
)
def test_families_at_110_match_reference(sheet, name, values, expected):
    for v, e in zip(values, expected):
        got = float(sheet.with_inputs(**{name: v}).evaluate("phi2", omega1=110).magnitude)
        assert abs(got - e) <= 1e-3, (name, v, got, e)


def variant(sheet, c2=None, t_end=None, **changes):
    """The sheet with some inputs changed (numbers in the SI units of the block module)."""
    for name, value in (("c2", c2), ("t_end", t_end)):
        if value is not None:
            changes[name] = f"{value} {'N/m' if name == 'c2' else 's'}"
    return sheet.with_inputs(**changes)


def test_root_is_on_the_stable_branch(sheet):
    """The template's k_w is -dF/dphi at the steady angle, and F falls there (stable)."""
    import mpmath as mp

    for w in (60.0, 80.0, 110.0):
        s = sheet.with_inputs(omega_dyn=f"{w} rad/s")
        phi = EX["phi20"] + float(s.evaluate("phi2", omega1=w).magnitude)
        slope = float(mp.diff(lambda x, w=w: F_ref(x, w, EX), mp.mpf(phi)))
        assert slope < 0  # a restoring generalized force
        assert float(s.evaluate("k_w").to("N*m").magnitude) == pytest.approx(-slope, rel=1e-9)


SPEEDS = [60.0, 70.0, 80.0, 90.0, 100.0, 110.0]


@pytest.mark.parametrize("w", SPEEDS)
def test_trend_phi2_falls_as_c1_rises(sheet, w):
    vals = [
        float(sheet.with_inputs(c1=f"{c} N/m").evaluate("phi2", omega1=w).magnitude)
        for c in (1500, 3000, 4000, 6000)
    ]
    nonzero = [v for v in vals if v > 0]
    assert len(nonzero) >= 2
    assert all(a > b for a, b in zip(nonzero, nonzero[1:]))
    assert all(a >= b for a, b in zip(vals, vals[1:]))


@pytest.mark.parametrize("w", SPEEDS)
def test_trend_phi2_rises_with_m(sheet, w):
    vals = [
        float(sheet.with_inputs(m=f"{m} kg").evaluate("phi2", omega1=w).magnitude)
        for m in (0.65, 0.7, 0.75, 0.8)
    ]
    assert all(b > a for a, b in zip(vals, vals[1:]))


@pytest.mark.parametrize("w", SPEEDS)
def test_trend_phi2_rises_with_phi20(sheet, w):
    vals = [
        float(sheet.with_inputs(phi20=f"{a} rad").evaluate("phi2", omega1=w).magnitude)
        for a in (0.4363, 0.5235, 0.6108, 0.6981)
    ]
    assert all(b > a for a, b in zip(vals, vals[1:]))


@pytest.mark.slow
def test_trend_findings_hold(sheet):
    ws = cp.speeds(sheet)
    for key in cp.FAMILY_TABLES:
        holds, fails, _ = cp.trend_holds(sheet, key, ws)
        assert not fails and len(holds) >= 10, key
    found = {f.what: f for f in cp.findings(sheet) + check_findings(sheet)}
    for text in cp.TREND_TEXT.values():
        assert found[text].verdict == "ok"
    assert found["phi2 at omega1 = 80 rad/s (reference example: 0.070)"].verdict == "ok"


def test_lift_off_speed_is_where_F_changes_sign(sheet):
    import mpmath as mp

    wl = float(sheet.evaluate("omega_lift").to("rad/s").magnitude)
    mp.mp.dps = 30
    ref = mp.findroot(lambda w: F_ref(mp.mpf(EX["phi20"]), w, EX), 50)
    assert wl == pytest.approx(float(ref), rel=1e-12)
    assert float(sheet.evaluate("phi2", omega1=wl - 0.01).magnitude) == 0.0
    assert float(sheet.evaluate("phi2", omega1=wl + 0.5).magnitude) > 0.0


def test_linear_forms(sheet):
    d = EX
    w = 90.0
    s, c = math.sin(d["phi20"]), math.cos(d["phi20"])
    A = d["O1O"] - d["OC"] * c
    G = d["MD0"] * d["OB"] / d["O1B"] * d["tg"]
    N = 2 * d["m"] * w**2 * A * d["OC"] * s - 8 * d["c1"] * d["lam"] * d["OC1"] * s - G
    D = (
        8 * d["c1"] * (d["lam"] * d["OC1"] * c + d["OC1"] ** 2 * s**2)
        - 2 * d["m"] * w**2 * A * d["OC"] * c
    )
    assert float(sheet.evaluate("phi2_lin", omega1=w).magnitude) == pytest.approx(N / D, rel=1e-12)
    # the consistent Newton step is -F(phi20)/F'(phi20): check against a numerical derivative
    import mpmath as mp

    dF = mp.diff(lambda x: F_ref(x, w, d), mp.mpf(d["phi20"]))
    newton = -float(F_ref(mp.mpf(d["phi20"]), w, d)) / float(dF)
    got = float(sheet.evaluate("phi2_newton", omega1=w).magnitude)
    assert got == pytest.approx(newton, rel=1e-9)
    # where the printed form departs by more than 5 % (base case): near lift-off and at 110
    dev = sheet.evaluate("dev_lin", omega1=[60, 90, 110]).to("percent").magnitude
    assert abs(dev[0]) > 5 and abs(dev[1]) < 5 and abs(dev[2]) > 5


@pytest.mark.slow
def test_soft_spring_denominator_is_reported_not_divided(sheet):
    soft = sheet.with_inputs(c1="800 N/m")
    assert float(soft.evaluate("D_lin", omega1=110).magnitude) < 0
    with pytest.raises(WorkbookError, match="no piece applies"):
        soft.evaluate("phi2_lin", omega1=110)
    value, den, dev = cp.closed_form(soft, [110.0])
    assert math.isnan(value[0]) and den[0] < 0 and math.isnan(dev[0])
    # the root is still there
    assert float(soft.evaluate("phi2", omega1=110).magnitude) > 0
    c1_soft = float(sheet.evaluate("c1_soft_lin").to("N/m").magnitude)
    assert c1_soft == pytest.approx(990.95, abs=0.05)
    at = sheet.with_inputs(c1=f"{c1_soft!r} N/m")  # the denominator vanishes there
    assert abs(float(at.evaluate("D_lin", omega1=110).magnitude)) < 1e-12
    w0 = float(sheet.evaluate("omega_zero_newton").to("rad/s").magnitude)
    assert abs(float(sheet.evaluate("D_newton", omega1=w0).magnitude)) < 1e-12
    # Newton form: c1 = 1500 N/m passes through zero inside 50..110 rad/s
    ws = np.arange(50, 111, 5.0)
    deps = {v: z for v, _, _, z in cp.departures(sheet, "c1", ws, "newton")}
    assert deps["1500 N/m"] == [100.0, 105.0, 110.0]


def test_printed_and_corrected_forms_visible(sheet):
    d = sheet.spec.definitions
    assert "drops the square" in d["a11"].note
    assert float(sheet.evaluate("b22_printed").magnitude) == -float(sheet.evaluate("b22").magnitude)
    a11 = 0.02 + 2 * 0.7 * (0.042 - 0.036 * math.cos(0.5236)) ** 2 + 2 * 1.5e-4
    assert float(sheet.evaluate("a11").to("kg*m^2").magnitude) == pytest.approx(a11, rel=1e-12)


# -- dynamics -----------------------------------------------------------------------------------
def _undamped_freqs(c2):
    """Nonzero eigenfrequencies of (K, M) written out here from the paper (scipy.linalg.eigh)."""
    from scipy.linalg import eigh

    st = root_ref(80.0)
    phi = EX["phi20"] + st
    h = 1e-6
    d = EX
    kw = -(float(F_ref(phi + h, 80.0, d)) - float(F_ref(phi - h, 80.0, d))) / (2 * h)
    a11 = 0.02 + 2 * 0.7 * (0.042 - 0.036 * math.cos(0.5236)) ** 2 + 3e-4
    M = np.diag([a11, 2 * 0.7 * 0.036**2 + 3e-4, 0.01])
    v = np.array([0.040, 0.015 / 3, -0.040])
    K = 2 * c2 * np.outer(v, v) + np.diag([0, kw, 0])
    lam = eigh(K, M, eigvals_only=True)
    return np.sqrt(np.sort(lam[lam > 1e-6 * lam.max()]))


@pytest.mark.parametrize("c2,tooth", [(1e6, 707.0), (1e8, 7070.0)])
def test_eigenvalues(sheet, c2, tooth):
    s = variant(sheet, c2)
    lam = s.evaluate("lam").to("1/s").magnitude  # rows (Re, Im)
    assert lam.shape == (4, 2)  # rigid rotation mode excluded
    ref = _undamped_freqs(c2)
    got = np.sort(np.abs(lam[:, 1]))[::2]
    np.testing.assert_allclose(got, ref, rtol=2e-3)  # light damping shifts them a little
    assert abs(lam[-1, 1]) == pytest.approx(tooth, rel=0.01)  # reference example: ~707, ~7070
    assert np.all(lam[:, 0] < 0)
    assert np.all(s.evaluate("lam_printed").magnitude[:, 0] > 0)  # printed sign


def test_stiffness_grows_with_c2(sheet):
    idx = [float(variant(sheet, c2).evaluate("stiff_index")) for c2 in (1e6, 1e8, 1e10)]
    assert idx[1] / idx[0] == pytest.approx(10, rel=0.01)
    assert idx[2] / idx[1] == pytest.approx(10, rel=0.01)
    assert variant(sheet, 1e6).evaluate("method_used") == "LSODA"
    assert variant(sheet, 1e10).evaluate("method_used") == "Radau"


@pytest.mark.slow
def test_exact_solution_matches_tight_solve_ivp(sheet):
    from scipy.integrate import solve_ivp

    s = variant(sheet, 1e8, 0.1)
    cs = cp.case(s)
    fun, t0, t1, y0 = ode.problem(s.typer.ode("motion"), s.evaluator.compile)
    sol = solve_ivp(fun, (t0, t1), y0, method="DOP853", rtol=1e-12, atol=1e-15, t_eval=cs.t)
    err = np.max(np.abs(cp.outputs(s, sol.y) - cs.exact))
    assert err < 1e-10


def _rigid_reference(t_end, n_out=401):
    """The rigid-tooth limit written out here: q = (phi1, phi2), phi3 = phi1 + k*phi2."""
    from scipy.integrate import solve_ivp

    d = EX
    w = 80.0
    st = root_ref(w)
    phi = d["phi20"] + st
    h = 1e-6
    kw = -(float(F_ref(phi + h, w, d)) - float(F_ref(phi - h, w, d))) / (2 * h)
    k = d["OB"] * d["tg"] / d["O1B"]
    a11 = 0.02 + 2 * 0.7 * (0.042 - 0.036 * math.cos(0.5236)) ** 2 + 3e-4
    a22 = 2 * 0.7 * 0.036**2 + 3e-4
    J3 = 0.01
    M = np.array([[a11 + J3, J3 * k], [J3 * k, a22 + J3 * k * k]])
    b22 = 20 * 0.036**2 * math.sin(0.5236) ** 2
    Minv = np.linalg.inv(M)
    Om = 4 * w

    def f(t, y):
        x, v = y[:2], y[2:]
        pump = 2.0 * math.sin(Om * t)
        force = np.array([-pump, -kw * (x[1] - st) - k * pump]) - np.array([0.0, b22 * v[1]])
        return np.concatenate([v, Minv @ force])

    ts = np.linspace(0, t_end, n_out)
    sol = solve_ivp(
        f, (0, t_end), [0.0, st, 0.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-15, t_eval=ts
    )
    return np.vstack([sol.y[1], k * sol.y[1]])


@pytest.mark.slow
def test_rigid_limit_and_default_solver_at_c2_1e10(sheet):
    ref = _rigid_reference(0.2)
    cs = cp.case(variant(sheet, 1e10))
    np.testing.assert_allclose(cs.rigid, ref, atol=1e-11)  # our rigid model = written-out one
    # the model difference falls like 1/c2: the study's prediction for c2 = 1e10
    d8, d9 = cp.case(variant(sheet, 1e8)).delta, cp.case(variant(sheet, 1e9)).delta
    predicted = d9 / 10
    assert cs.delta == pytest.approx(predicted, rel=0.2)
    assert d8 / d9 == pytest.approx(10, rel=0.2)
    tol = 2 * predicted
    method = str(variant(sheet, 1e10).evaluate("method_used"))
    run = cp.run(variant(sheet, 1e10), method, 1e-5, cs.t)
    assert run.ok
    dev = np.max(np.abs(cp.outputs(sheet, run.y) - ref))
    assert dev <= tol, (method, dev, tol)


@pytest.mark.slow
def test_default_solver_reaches_the_rigid_limit(sheet):
    """One study at c2 = 1e10 N/m: the default method at rtol 1e-5 finishes within twice the
    rigid limit's deflection of the rigid motion (its speed against the fastest such run is
    measured in benchmarks/bench_ode.py)."""
    p = variant(sheet, t_end=0.1)
    df = cp.study(p, (1e10,), (1e-3, 1e-4, 1e-5, 1e-6, 1e-7), max_time=2.0, label=None)
    stiff = variant(p, 1e10)
    tol = 2 * cp.case(stiff).delta
    ok = df[(df["stopped"] == "finished") & (df["deviation from rigid [rad]"] <= tol)]
    method = str(stiff.evaluate("method_used"))
    assert not ok[(ok["method"] == method) & (ok["rtol"] == 1e-5)].empty, df


@pytest.mark.slow
def test_errors_fall_with_rtol_at_moderate_c2(sheet):
    """The time budget of each run is a guard against a runaway, not a measure: wide enough
    that a loaded machine (Radau at rtol 1e-9 took 5 s beside other work) gives the error."""
    p = variant(sheet, t_end=0.1)
    df = cp.study(p, (1e6,), (1e-3, 1e-6, 1e-9), max_time=60.0, label=None)
    for m in oderun.SOLVERS:
        e = df[df["method"] == m].sort_values("rtol", ascending=False)["error [rad]"].to_numpy()
        assert e[-1] < e[0] / 100, (m, e)


# -- extreme cases ------------------------------------------------------------------------------
@pytest.mark.slow
def test_explicit_method_on_a_very_stiff_tooth_is_bounded(sheet):
    run, need = cp.stall_run(sheet, "RK45", c2=1e14, max_time=0.3, max_steps=10**7)
    assert not run.ok and run.stop_reason == "time budget"
    assert run.fraction < 0.5 and need > 1e5
    run, _ = cp.stall_run(sheet, "DOP853", c2=1e14, max_time=30, max_steps=500)
    assert run.stop_reason == "step cap" and run.nsteps == 500
    assert "step cap" in run.summary()


@pytest.mark.slow
def test_weights_on_the_stop_dynamics(sheet):
    p = variant(sheet, t_end=0.05, omega_dyn="50 rad/s")
    assert float(p.evaluate("F0", omega1=50).magnitude) <= 0  # on the stop
    assert float(p.evaluate("free")) == 0  # phi2 held on the stop
    run = cp.run(p, "Radau", 1e-6, cp.times(p))
    assert run.ok
    assert np.all(cp.outputs(p, run.y)[0] == 0.0)
    assert np.all(p.evaluate("phi2_r", t=cp.times(p)).magnitude == 0.0)


@pytest.mark.slow
def test_run_ode_progress_goes_to_stderr(sheet, capsys):
    s = variant(sheet, 1e8, 0.05)
    fun, t0, t1, y0 = ode.problem(s.typer.ode("motion"), s.evaluator.compile)
    oderun.run_ode(fun, (t0, t1), y0, method="RK45", rtol=1e-6, label="probe", progress_every=0.0)
    err = capsys.readouterr().err
    assert "[probe] t = " in err and "finished" in err


@pytest.mark.slow
def test_ctrl_c_leaves_no_partial_state(sheet, monkeypatch):
    p = variant(sheet, t_end=0.013)
    calls = {"n": 0}
    real = cp.run

    def interrupted(*a, **k):
        calls["n"] += 1
        if calls["n"] == 3:
            raise KeyboardInterrupt
        return real(*a, **k)

    monkeypatch.setattr(cp, "run", interrupted)
    from workbook import blocks

    before = blocks.kept()
    with pytest.raises(KeyboardInterrupt):
        cp.study(p, (1e6,), (1e-3, 1e-4), label=None)
    assert not any(k[2][0] == "study" for k in blocks.kept() - before)


@pytest.mark.slow
def test_ctrl_c_during_write_keeps_old_file(tmp_path, monkeypatch):
    sheet = workbook.load("advance-coupling")
    out = tmp_path / "ac.xlsx"
    out.write_bytes(b"old")

    def boom(sheet):
        raise KeyboardInterrupt

    from workbook import blocks

    monkeypatch.setattr(blocks.get("coupling.stiffness_table", "table"), "func", boom)
    with pytest.raises(KeyboardInterrupt):
        sheet.write_xlsx(out, force=True)
    assert out.read_bytes() == b"old"
    assert [f.name for f in tmp_path.iterdir()] == ["ac.xlsx"]


# -- solver helpers -----------------------------------------------------------------------------
@pytest.mark.slow
def test_bench_quick_runs_every_method(sheet):
    df = cp.bench(sheet, quick=True)
    assert set(df["method"]) == set(oderun.SOLVERS)
    assert {"error [rad]", "run time [s]", "stopped"} <= set(df.columns)


@pytest.fixture(scope="module")
def written(tmp_path_factory, sheet):
    return sheet.write_xlsx(tmp_path_factory.mktemp("ac") / "ac.xlsx")


@pytest.mark.slow
def test_workbook_writes(written):
    import openpyxl

    wb = openpyxl.load_workbook(written)
    for name in ("Families", "Dynamics", "Stiffness", "Solvers", "Checks"):
        assert name in wb.sheetnames
    text = " ".join(str(c) for row in wb["Checks"].iter_rows(values_only=True) for c in row if c)
    assert "phi2 falls as c1 rises" in text and "time / fastest" in text


@pytest.mark.slow
def test_live_formulas_recalculate_in_libreoffice(tmp_path, written):
    """The closed forms, matrix entries and mode estimates are live: LibreOffice gets the
    engine's numbers."""
    recalc = pytest.importorskip("helpers.recalc")
    if recalc.soffice() is None:
        pytest.skip("LibreOffice is not installed")
    cached = recalc.formula_values(written)
    new = recalc.cell_values(recalc.recalculate(written, tmp_path / "lo"))
    assert len(cached) > 50
    bad = []
    for key, (formula, value) in cached.items():
        got = new.get(key)
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            if not isinstance(got, (int, float)) or abs(got - value) > 1e-9 * max(1.0, abs(value)):
                bad.append((key, formula[:60], value, got))
    assert not bad, bad[:5]
