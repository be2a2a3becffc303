"""r0-synthesis: minimum cam radius for a pressure-angle limit (the VBA loop and the exact answer).

References used here, none of them the solver under test: the numbers of the reference example,
brute force over dense grids refined by scipy's bounded minimiser, mpmath at 40 digits, and a
central-difference derivative of the rise laws.
"""

from __future__ import annotations

import math
import re
import shutil
import zipfile

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

import workbook
from workbook.blocks import r0 as R
from workbook.errors import DomainError, InputError, LimitError, WorkbookError

SCENE = dict(
    H=16.0, phi_rise=math.radians(100), alpha_max=28.0, e=6.0, delta_sigma=1.0, law="stepped"
)
LAWS = ("stepped", "harmonic", "cycloidal", "polynomial345")


def with_params(sheet, H, phi_rise, alpha_max, e, delta_sigma, law):
    """The sheet with the inputs of a parameter dict (angles in rad / deg as in SCENE)."""
    return sheet.with_inputs(
        H=f"{H} mm",
        phi_rise=f"{phi_rise!r} rad",
        alpha_max=f"{alpha_max} deg",
        e=f"{e} mm",
        delta_sigma=delta_sigma,
        law=law,
    )


def reference_r0(H, phi_rise, alpha_max, e, delta_sigma, law, digits=40):
    """r0 in 40-digit arithmetic, the laws written out here: the largest required S0 from the
    ends, the stepped law's kink and the roots of its derivative (mpmath.findroot)."""
    import mpmath

    with mpmath.workdps(digits):
        H, e, ds = mpmath.mpf(H), mpmath.mpf(e), mpmath.mpf(delta_sigma)
        phi, pi = mpmath.mpf(phi_rise), mpmath.pi
        t = mpmath.tan(mpmath.radians(mpmath.mpf(alpha_max)))

        def s_ds(x):
            if law == "stepped":
                return (2 * x**2, 4 * x) if x <= 0.5 else (1 - 2 * (1 - x) ** 2, 4 * (1 - x))
            if law == "harmonic":
                return (1 - mpmath.cos(pi * x)) / 2, pi / 2 * mpmath.sin(pi * x)
            if law == "cycloidal":
                return x - mpmath.sin(2 * pi * x) / (2 * pi), 1 - mpmath.cos(2 * pi * x)
            return x**3 * (10 - 15 * x + 6 * x**2), 30 * x**2 * (1 - x) ** 2

        def g(x):
            s, d = s_ds(x)
            return abs(H * d / phi + ds * e) / t - H * s

        best = max(g(mpmath.mpf(0)), g(mpmath.mpf(1)), g(mpmath.mpf(1) / 2))
        pts = [mpmath.mpf(i) / 400 for i in range(401)]
        vals = [mpmath.diff(g, x) for x in pts[1:-1]]
        for a, b, fa, fb in zip(pts[1:-2], pts[2:-1], vals[:-1], vals[1:]):
            if fa > 0 > fb:
                try:
                    root = mpmath.findroot(lambda x: mpmath.diff(g, x), (a, b), solver="anderson")
                except (ValueError, ZeroDivisionError):
                    continue
                if a <= root <= b:
                    best = max(best, g(root))
        return float(mpmath.sqrt(max(best, 0) ** 2 + e**2))


def template_reference_r0(sheet, digits: int = 40) -> float:
    """r0 in ``digits``-digit arithmetic from the template's own S0_req (through SymPy): its
    largest value on each half of the rise from the ends and the roots of its derivative."""
    import mpmath
    import sympy as sp

    from workbook.numerics import symbolic

    x = symbolic.symbol("x")
    expr = symbolic.to_sympy(sheet, "S0_req", {"x": x}, true_pi=True)
    g = sp.lambdify(x, expr, "mpmath")
    dg = sp.lambdify(x, sp.diff(expr, x), "mpmath")
    e = mpmath.mpf(repr(mm(sheet.evaluate("e"))))
    with mpmath.workdps(digits):
        half = mpmath.mpf(1) / 2
        best = max(g(mpmath.mpf(0)), g(half), g(mpmath.mpf(1)))
        for lo, hi in ((0, half), (half, 1)):
            pts = [lo + (hi - lo) * mpmath.mpf(i) / 200 for i in range(201)]
            d = [dg(p) for p in pts[1:-1]]
            for a, b, fa, fb in zip(pts[1:-2], pts[2:-1], d[:-1], d[1:]):
                if fa > 0 > fb:  # a maximum between a and b
                    best = max(best, g(mpmath.findroot(dg, (a, b), solver="anderson")))
        return float(mpmath.sqrt(max(best, 0) ** 2 + e**2))


@pytest.fixture(scope="module")
def sheet():
    """With the optional part studies (left out by a plain load)."""
    return workbook.load("r0-synthesis", parts="all")


def mm(q) -> float:
    return float(q.to("mm").magnitude)


# -- independent references ---------------------------------------------------------------------
def law_arrays(law, x):
    """The four rise laws written out again (unit stroke), independent of the engine's."""
    x = np.asarray(x, dtype=float)
    if law == "stepped":
        return np.where(x <= 0.5, 2 * x * x, 1 - 2 * (1 - x) ** 2)
    if law == "harmonic":
        return 0.5 - 0.5 * np.cos(np.pi * x)
    if law == "cycloidal":
        return x - np.sin(2 * np.pi * x) / (2 * np.pi)
    return 10 * x**3 - 15 * x**4 + 6 * x**5


def law_slope(law, x, h=1e-6):
    """ds/dx by a central difference (the formulas extend smoothly past 0 and 1)."""
    x = np.asarray(x, dtype=float)
    return (law_arrays(law, x + h) - law_arrays(law, x - h)) / (2 * h)


def brute_r0(H, phi_rise, alpha_max, e, delta_sigma, law, n=200_001):
    """Dense grid, then scipy's bounded minimiser around the five best points."""
    t = math.tan(math.radians(alpha_max))

    def g(x):
        s, ds = law_arrays(law, x), law_slope_exact(law, x)
        return np.abs(H * ds / phi_rise + delta_sigma * e) / t - H * s

    xs = np.linspace(0.0, 1.0, n)
    vals = g(xs)
    best = float(vals.max())
    for i in np.argsort(vals)[-5:]:
        lo, hi = xs[max(i - 1, 0)], xs[min(i + 1, n - 1)]
        res = minimize_scalar(
            lambda x: -float(g(x)), bounds=(lo, hi), method="bounded", options={"xatol": 1e-15}
        )
        best = max(best, -float(res.fun))
    return math.hypot(max(best, 0.0), e)


def law_slope_exact(law, x):
    """ds/dx written out by hand (checked against law_slope in test_rise_laws)."""
    x = np.asarray(x, dtype=float)
    if law == "stepped":
        return np.where(x <= 0.5, 4 * x, 4 * (1 - x))
    if law == "harmonic":
        return 0.5 * np.pi * np.sin(np.pi * x)
    if law == "cycloidal":
        return 1 - np.cos(2 * np.pi * x)
    return 30 * x**2 - 60 * x**3 + 30 * x**4


def max_abs_alpha_dense(H, phi_rise, e, delta_sigma, law, r0, n=400_001):
    x = np.linspace(0.0, 1.0, n)
    S = H * law_arrays(law, x)
    Sp = H * law_slope_exact(law, x) / phi_rise
    S0 = math.sqrt(r0 * r0 - e * e)
    a = np.degrees(np.abs(np.arctan((Sp + delta_sigma * e) / (S0 + S))))
    return float(a.max())


# -- the numbers of the scene ---------------------------------------------------------------------
def test_direct_r0_is_scene_value(sheet):
    r0 = mm(sheet.evaluate("r0"))
    assert r0 == pytest.approx(38.2405, abs=1e-4)
    # and exact to floating point against a 40-digit evaluation
    ref = reference_r0(**SCENE)
    assert r0 == pytest.approx(ref, rel=1e-14)
    assert template_reference_r0(sheet) == pytest.approx(ref, rel=1e-15)  # from S0_req


@pytest.mark.parametrize("dr, expected", [("1 mm", 39.0), ("0.1 mm", 38.3), ("0.01 mm", 38.25)])
def test_loop_gives_listed_values(sheet, dr, expected):
    s = sheet.with_inputs(dr=dr)
    assert mm(s.evaluate("r0_loop")) == pytest.approx(expected, abs=1e-9)
    # the closed form of the loop (live in Excel) agrees
    assert mm(s.evaluate("r0_step")) == pytest.approx(expected, abs=1e-9)


def test_loop_steps_from_e_without_drift(sheet):
    s = sheet.with_inputs(dr="0.1 mm")
    k, r = s.evaluate("loop_k").magnitude, mm(s.evaluate("r0_loop"))
    assert k == 323 and r == 6.0 + 323 * 0.1
    drifted = 6.0
    for _ in range(323):
        drifted += 0.1  # what r0 += dr does
    assert drifted != r  # the accumulated sum has drifted; e + k*dr has not


def test_loop_is_the_templates_program(sheet):
    """The loop is the template's program loop_k; a run over the cap is not stepped: loop_k
    gives the steps it would need (the refusal names them)."""
    assert sheet.spec.definitions["loop_k"].program
    assert sheet.evaluate("loop_k").magnitude == 3225
    s = sheet.with_inputs(alpha_max="0.5 deg")
    assert s.evaluate("loop_k").magnitude == 277_449 > s.evaluate("loop_cap").magnitude
    with pytest.raises(LimitError, match="277,449 steps of dr = 0.01 mm .*cap 100,000"):
        s.evaluate("r0_loop")


def test_largest_pressure_angle_at_r0_is_alpha_max(sheet):
    r0 = mm(sheet.evaluate("r0"))
    alpha = sheet.evaluate("alpha", x=np.linspace(0, 1, 100_001)).to("deg").magnitude
    assert np.abs(alpha).max() == pytest.approx(28.0, abs=1e-9)
    assert float(sheet.evaluate("alpha", x=0.5).to("deg").magnitude) == pytest.approx(
        28.0, abs=1e-9
    )
    # over the continuous angle (independent dense evaluation with a finite-difference S')
    worst = max_abs_alpha_dense(16.0, math.radians(100), 6.0, 1.0, "stepped", r0)
    assert worst == pytest.approx(28.0, abs=1e-9)
    assert float(sheet.evaluate("alpha_top").to("deg").magnitude) == pytest.approx(28.0, abs=1e-9)


def test_evaluable_with_inputs(sheet):
    s = sheet.with_inputs(H="20 mm", alpha_max="30 deg", e="5 mm", dr="0.1 mm")
    r0 = mm(s.evaluate("r0"))
    assert r0 == pytest.approx(
        brute_r0(20.0, math.radians(100), 30.0, 5.0, 1.0, "stepped"), rel=1e-12
    )
    loop = mm(s.evaluate("r0_loop"))
    assert r0 <= loop <= r0 + 0.1 + 1e-12


# -- the direct solution against brute force, for all laws ----------------------------------------
CASES = [
    (law, ds, am, phr, e)
    for law in LAWS
    for ds in (1.0, -1.0)
    for am in (12.0, 28.0, 45.0, 70.0)
    for phr in (45.0, 100.0, 200.0)
    for e in (0.0, 6.0, 40.0)
]


@pytest.mark.slow
@pytest.mark.parametrize("law, ds, am, phr, e", CASES)
def test_direct_matches_refined_brute_force(sheet, law, ds, am, phr, e):
    p = dict(H=16.0, phi_rise=math.radians(phr), alpha_max=am, e=e, delta_sigma=ds, law=law)
    s = with_params(sheet, **p)
    if mm(s.evaluate("S0_crit")) <= 0:  # alpha_max does not bound r0: brute force must agree
        assert mm(s.evaluate("r0")) == e
        assert brute_r0(**p, n=20_001) <= e * (1 + 1e-12) + 1e-12
        return
    assert mm(s.evaluate("r0")) == pytest.approx(brute_r0(**p), rel=1e-11, abs=1e-11)


@pytest.mark.slow
@pytest.mark.parametrize("law", LAWS)
def test_direct_matches_mpmath(sheet, law):
    ref = reference_r0(**dict(SCENE, law=law))
    assert mm(sheet.with_inputs(law=law).evaluate("r0")) == pytest.approx(ref, rel=1e-13)


@pytest.mark.slow
@pytest.mark.parametrize("law", LAWS)
def test_rise_laws(sheet, law):
    s = sheet.with_inputs(law=law)
    x = np.linspace(0, 1, 2001)
    S = s.evaluate("S", x=x).to("mm").magnitude
    Sp = s.evaluate("Sp", x=x).to("mm/rad").magnitude
    assert S[0] == pytest.approx(0, abs=1e-12) and S[-1] == pytest.approx(16.0, rel=1e-12)
    assert np.allclose(S, 16.0 * law_arrays(law, x), rtol=0, atol=1e-12)
    phi_rise = math.radians(100)
    # central differences with h = 1e-6 (error 2h at the stepped law's kink, ~1e-10 elsewhere)
    assert np.allclose(Sp, 16.0 * law_slope(law, x) / phi_rise, rtol=0, atol=5e-5)
    assert np.allclose(law_slope_exact(law, x), law_slope(law, x), rtol=0, atol=5e-6)
    assert np.allclose(Sp, 16.0 * law_slope_exact(law, x) / phi_rise, rtol=0, atol=1e-12)
    assert Sp[0] == pytest.approx(0, abs=1e-12) and Sp[-1] == pytest.approx(0, abs=1e-12)
    # and the workbook r0 for this law is the direct answer
    assert template_reference_r0(s) == pytest.approx(
        reference_r0(**dict(SCENE, law=law)), rel=1e-14
    )


def test_grid_maximum_aggregate(sheet):
    table = sheet.table("design")
    assert len(table) == 101
    assert mm(sheet.evaluate("S0_grid")) == table["S0 required [mm]"].max()
    # the stepped law's grid with 101 angles contains the critical angle phi_rise/2
    assert mm(sheet.evaluate("r0_grid")) == pytest.approx(mm(sheet.evaluate("r0")), rel=1e-15)


# -- extreme inputs: clear errors, not tracebacks or nonsense -------------------------------------
def test_negative_stroke(sheet):
    with pytest.raises(InputError, match="H = -20 mm must be positive"):
        sheet.with_inputs(H="-20 mm")


@pytest.mark.parametrize("angle", ["0 deg", "90 deg"])
def test_alpha_max_at_the_ends(sheet, angle):
    s = sheet.with_inputs(alpha_max=angle)
    for name in ("r0", "r0_loop"):
        with pytest.raises(InputError, match="no piece applies.* alpha_max < pi/2"):
            s.evaluate(name)


def test_alpha_max_near_90(sheet):
    s = sheet.with_inputs(alpha_max="89.9 deg")
    r0 = mm(s.evaluate("r0"))
    assert 6.0 < r0 < 6.001  # the limit hardly constrains r0 any more
    with pytest.raises(InputError, match="first candidate r0 = e \\+ dr"):
        s.evaluate("r0_loop")
    # e = 0: alpha -> 90 deg at the start of the rise as S0 -> 0, so r0 stays positive, tiny
    s0 = sheet.with_inputs(alpha_max="89.9 deg", e="0 mm")
    r0 = mm(s0.evaluate("r0"))
    assert 0 < r0 < 1e-3
    assert r0 == pytest.approx(
        brute_r0(16.0, math.radians(100), 89.9, 0.0, 1.0, "stepped"), rel=1e-9
    )


def test_alpha_max_near_0(sheet):
    s = sheet.with_inputs(alpha_max="0.5 deg")
    r0 = mm(s.evaluate("r0"))
    assert r0 == pytest.approx(
        brute_r0(16.0, math.radians(100), 0.5, 6.0, 1.0, "stepped"), rel=1e-12
    )
    assert r0 > 2000  # metres of cam
    with pytest.raises(LimitError, match="steps"):
        s.evaluate("r0_loop")


def test_dr_larger_than_the_answer(sheet):
    with pytest.raises(InputError, match="set by dr, not by alpha_max"):
        sheet.with_inputs(dr="50 mm").evaluate("r0_loop")


def test_grid_missing_the_kink(sheet):
    s = sheet.with_inputs(n_grid=100)
    with pytest.raises(InputError, match="misses the angle where the required S0 is largest"):
        s.evaluate("r0_loop")
    # what the loop would have accepted exceeds alpha_max between grid points
    r_bad = 6.0 + 0.001 * math.ceil((mm(s.evaluate("r0_grid")) - 6.0) / 0.001)
    assert r_bad < mm(sheet.evaluate("r0"))
    assert max_abs_alpha_dense(16.0, math.radians(100), 6.0, 1.0, "stepped", r_bad) > 28.0
    # the direct answer does not depend on the grid
    assert mm(s.evaluate("r0")) == pytest.approx(mm(sheet.evaluate("r0")), rel=1e-15)


@pytest.mark.filterwarnings("ignore:invalid value encountered in sqrt:RuntimeWarning")
def test_e_not_below_r(sheet):
    with pytest.raises(DomainError, match="alpha_r is not a finite number"):
        sheet.evaluate("alpha_r", x=0, r="5 mm")  # e = 6 mm > r: sqrt(r^2 - e^2) of a negative


def test_bad_delta_sigma(sheet):
    with pytest.raises(InputError, match="abs\\(delta_sigma\\) == 1"):
        sheet.with_inputs(delta_sigma=0.5).evaluate("r0")


def test_absolute_not_signed_pressure_angle(sheet):
    """A signed check accepts designs where the follower is pushed hard the other way."""
    p = dict(SCENE, delta_sigma=-1.0, e=30.0)
    other = with_params(sheet, **p)
    r_abs = mm(other.evaluate("r0_loop"))
    x = np.arange(101) / 100
    s, ds = law_arrays("stepped", x), law_slope_exact("stepped", x)
    num = 16.0 * ds / p["phi_rise"] - 30.0
    k = 1
    while True:  # the same loop with a signed comparison
        r = 30.0 + k * 0.01
        a = np.degrees(np.arctan(num / (math.sqrt(r * r - 900.0) + 16.0 * s)))
        if a.max() <= 28.0:
            break
        k += 1
    assert np.degrees(np.arctan(-30.0 / math.sqrt(r * r - 900.0))) < -60.0  # alpha(0)
    assert r < r_abs
    a_abs = other.evaluate("alpha_r", x=x, r=f"{r_abs} mm").to("deg").magnitude
    assert np.abs(a_abs).max() <= 28.0


# -- error against run time ------------------------------------------------------------------------
@pytest.mark.slow
def test_bench_direct_faster_and_more_accurate(sheet):
    df = R.bench(sheet, quick=True)
    row = df[(df["dr [mm]"] == 0.001) & (df["angles"] == 101)].iloc[0]
    ratio = row["loop time [s]"] / row["direct time [s]"]
    direct_err = abs(row["r0 direct [mm]"] - reference_r0(**SCENE))
    print(
        f"\ndr = 0.001 mm, 101 angles: loop {row['loop time [s]']:.4g} s, error "
        f"{row['loop error [mm]']:.3g} mm; direct {row['direct time [s]']:.3g} s, error "
        f"{direct_err:.2g} mm; loop/direct time = {ratio:.0f}"
    )
    assert direct_err < 1e-13 < abs(row["loop error [mm]"])
    assert set(df["dr [mm]"]) == {1.0, 0.1, 0.01, 0.001}
    # the loop's error is below dr and does not depend on the grid (it contains phi_rise/2)
    assert (df["loop error [mm]"] >= 0).all() and (df["loop error [mm]"] < df["dr [mm]"]).all()


def test_bench_is_declared(sheet):
    assert sheet.spec.meta["bench"] == "r0.bench"


def test_findings_all_pass(sheet):
    report = sheet.check()
    verdicts = {f.what: f.verdict for f in report.findings}
    assert report.ok, verdicts
    # an extremum of the piecewise rise law rests on its samples (a warning that says so)
    flagged = {f.what: f.verdict for f in report.findings if not f.topic.startswith("assumption")}
    assert not any(v in ("fail", "warning") for v in flagged.values()), verdicts
    listed = [f for f in report.findings if f.topic == "listed example"]
    assert [f.verdict for f in listed] == ["ok"] * 4
    assert [f.value for f in listed[1:]] == pytest.approx([39.0, 38.3, 38.25], abs=1e-9)
    # the listed lengths hold at the template's own inputs only
    changed = sheet.with_inputs(H="17 mm").check().findings
    assert not [f for f in changed if f.topic == "listed example"]
    fig4 = [f for f in report.findings if f.topic == "Fig. 4"]
    assert all(abs(f.value) > 1 for f in fig4)  # alpha at phi_rise/2 and phi_rise does change
    # the same from the paper's formula, written out here, at r0 and 2*r0
    r0, phi_rise = mm(sheet.evaluate("r0")), math.radians(100)
    for f, x in zip(fig4, (0.5, 1.0)):
        sp_, s_ = 16.0 * law_slope_exact("stepped", x) / phi_rise, 16.0 * law_arrays("stepped", x)
        alpha = [
            math.degrees(math.atan((sp_ + 6.0) / (math.sqrt(r * r - 36) + s_)))
            for r in (r0, 2 * r0)
        ]
        assert f.value == pytest.approx(alpha[1] - alpha[0], abs=1e-12)


# -- the workbook ---------------------------------------------------------------------------
def _definitions(path):
    import openpyxl

    wb = openpyxl.load_workbook(path)
    ws = wb["Definitions"]
    return {row[0].value: row[1].coordinate for row in ws.iter_rows(min_row=2)}


@pytest.mark.slow
def test_workbook_has_no_macro_and_live_r0(tmp_path, sheet):
    import openpyxl

    path = sheet.write_xlsx(tmp_path / "r0.xlsx")
    with zipfile.ZipFile(path) as z:
        names = z.namelist()
    assert not any("vba" in n.lower() for n in names)
    wb = openpyxl.load_workbook(path)
    ws = wb["Definitions"]
    cells = {row[0].value: row[1].value for row in ws.iter_rows(min_row=2)}
    assert str(cells["r0"]).startswith("=")  # a live formula
    assert str(cells["S0_crit"]).startswith("=")
    design = wb["Design"]
    assert str(design["E3"].value).startswith("=")  # required S0 at each angle
    assert {"Charts", "Error vs time", "Design", "Result"} <= set(wb.sheetnames)


def _recalc():
    pytest.importorskip("openpyxl")
    try:
        from helpers.recalc import cell_values, formula_values, recalculate, soffice
    except ImportError:
        pytest.skip("tests/helpers/recalc.py is not there")
    if soffice() is None:
        pytest.skip("LibreOffice is not installed")
    return cell_values, formula_values, recalculate


@pytest.mark.slow
def test_libreoffice_recalculates_to_engine_values(tmp_path, sheet):
    cell_values, formula_values, recalculate = _recalc()
    path = sheet.write_xlsx(tmp_path / "r0.xlsx")
    cached = formula_values(path)
    new = cell_values(recalculate(path, tmp_path / "lo"))
    bad = [
        (k, v, new.get(k))
        for k, (f, v) in cached.items()
        if isinstance(v, (int, float))
        and not isinstance(v, bool)
        and not (
            isinstance(new.get(k), (int, float)) and abs(new[k] - v) <= 1e-9 * max(1.0, abs(v))
        )
    ]
    assert len(cached) > 1000 and not bad, bad[:5]


@pytest.mark.slow
@pytest.mark.parametrize("alpha_max, H", [(35.0, 16.0), (22.0, 20.0)])
def test_changing_alpha_max_in_excel_moves_r0(tmp_path, sheet, alpha_max, H):
    import openpyxl

    cell_values, _, recalculate = _recalc()
    path = sheet.write_xlsx(tmp_path / "r0.xlsx")
    edited = tmp_path / "edited.xlsx"
    shutil.copy(path, edited)
    wb = openpyxl.load_workbook(edited)
    for row in wb["Inputs"].iter_rows():
        if row[0].value == "alpha_max":
            row[1].value = alpha_max
        if row[0].value == "H":
            row[1].value = H
    wb.save(edited)
    values = cell_values(recalculate(edited, tmp_path / "lo"))
    changed = sheet.with_inputs(alpha_max=f"{alpha_max} deg", H=f"{H} mm")
    got = values[("Definitions", _definitions(path)["r0"])]
    assert got == pytest.approx(mm(changed.evaluate("r0")), rel=1e-12)
    assert abs(got - 38.2405) > 1  # it moved
    # the grid's answer is MAX over the Design table's live column: it follows too
    for name in ("S0_grid", "r0_grid", "r0_step"):
        got = values[("Definitions", _definitions(path)[name])]
        assert got == pytest.approx(mm(changed.evaluate(name)), rel=1e-12), name
    # Fig. 4's range of radii (r4_lo .. r4_hi, from r0) is live too: its first and last rows
    from helpers.recalc import formula_values

    # a range cell ends with "+$C$n", its table's row-count guard
    cells = {
        re.sub(r"\+\$[A-Z]+\$\d+$", "", f): key
        for key, (f, _) in formula_values(path).items()
        if key[0] == "Chart data"
    }
    for bound in ("r4_lo", "r4_hi"):
        got = values[cells[f"=({bound})"]]
        assert got == pytest.approx(mm(changed.evaluate(bound)), rel=1e-12), bound


def test_errors_are_engine_errors(sheet):
    for change in (dict(H="-1 mm"), dict(alpha_max="0 deg"), dict(dr="100 mm"), dict(n_grid=10)):
        with pytest.raises(WorkbookError):
            sheet.with_inputs(**change).evaluate("r0_loop")


# -- the engine's table aggregate used by this sheet ---------------------------------------------
AGG = """
[inputs]
a = "2 mm"
[arguments]
x = { unit = "" }
[definitions]
"f(x)" = { expr = "a*(x - 0.3)^2", unit = "mm" }
top = "%s"
[[tables]]
name = "t"
range = "x := 0, 0.1 .. 1"
columns = { f = "mm" }
"""


def test_max_over_and_min_over(sheet_from):

    s = sheet_from(AGG % "max_over(t, f) - min_over(t, f)")
    x = np.linspace(0, 1, 11)
    vals = 2 * (x - 0.3) ** 2
    assert mm(s.evaluate("top")) == pytest.approx(vals.max() - vals.min(), rel=1e-15)
    assert mm(s.with_inputs(a="4 mm").evaluate("top")) == pytest.approx(
        2 * (vals.max() - vals.min()), rel=1e-15
    )


@pytest.mark.parametrize(
    "expr, message",
    [
        ("max_over(u, f)", "'u' is not a range table"),
        ("max_over(t, g)", "table 't' has no column 'g'"),
        ("max_over(t)", "write max_over\\(table, column\\)"),
    ],
)
def test_max_over_errors(sheet_from, expr, message):

    from workbook.errors import TemplateError

    with pytest.raises(TemplateError, match=message):
        sheet_from(AGG % expr)
