"""reducer-profile: tooth profile of a planetary roller reducer's cam.

References that this file does not take from the engine:
* the reference example's coordinates (computed independently in double precision);
* an mpmath implementation of formulas (1)-(5) written here from the paper, with derivatives
  by mpmath.diff at 30 digits (the normal of (5));
* the closed-form radius of curvature at a tooth valley of R(t) = e1 cos(Zt) + sqrt(r2^2 -
  e1^2 sin^2(Zt)): rho = (r2 - e1)^2 / (Z^2 (e1 - e1^2/r2) - (r2 - e1)).
"""

import math
import zipfile

import mpmath as mp
import numpy as np
import pytest

import workbook
from workbook.blocks import reducer
from workbook.errors import InputError, WorkbookError
from workbook.language import units as un


@pytest.fixture(scope="module")
def sheet():
    return workbook.load("reducer-profile")


# -- an independent implementation of (1)-(5) ---------------------------------------------


def ref_curve(k, n, e1, r2, sense):
    """(x_t(phi), y_t(phi)) of roller k with the corrected rotation, phi in radians (mpmath)."""
    Z = n - 1 if sense == "same" else n + 1
    ratio = -mp.mpf(1) / Z if sense == "same" else mp.mpf(1) / Z
    theta = 2 * mp.pi * k / n

    def rho(phi):
        return e1 * mp.cos(theta - phi) + mp.sqrt(r2**2 - e1**2 * mp.sin(theta - phi) ** 2)

    def xt(phi):
        a = ratio * phi
        return rho(phi) * mp.cos(theta) * mp.cos(a) + rho(phi) * mp.sin(theta) * mp.sin(a)

    def yt(phi):
        a = ratio * phi
        return -rho(phi) * mp.cos(theta) * mp.sin(a) + rho(phi) * mp.sin(theta) * mp.cos(a)

    return xt, yt


def ref_practical(k, phi_deg, n, e1, r2, rp, sense):
    """(x_t, y_t, x_k, y_k) by (5) with derivatives from mpmath.diff."""
    with mp.workdps(30):
        xt, yt = ref_curve(k, n, mp.mpf(e1), mp.mpf(r2), sense)
        phi = mp.radians(mp.mpf(phi_deg))
        dx, dy = mp.diff(xt, phi), mp.diff(yt, phi)
        length = mp.sqrt(dx**2 + dy**2)
        rps = rp if sense == "same" else -rp
        x, y = xt(phi), yt(phi)
        return [float(v) for v in (x, y, x + rps * dy / length, y - rps * dx / length)]


# -- the reference example -------------------------------------------------------------------

EXAMPLE = [  # phi, rho, a, x_t, y_t, x_k, y_k (n = 12, Z = 11, e1 = 2, r2 = 40, rp = 4, k = 0)
    (0, 42, 0.0, 42, 0, 46, 0),
    (90, 39.95, -8.182, 39.5433, 5.6855, 42.7369, 8.0940),
    (180, 38, None, 36.4607, 10.7058, 40.2987, 11.8328),
]


@pytest.mark.parametrize("row", EXAMPLE, ids=[f"phi={r[0]}" for r in EXAMPLE])
def test_reference_example_coordinates(sheet, row):
    phi, rho, a, xt, yt, xk, yk = row
    assert sheet.evaluate("rho", 0, phi).to("mm").magnitude == pytest.approx(rho, abs=5e-3)
    if a is not None:
        assert sheet.evaluate("a", phi).to("deg").magnitude == pytest.approx(a, abs=5e-4)
    assert sheet.evaluate("x_t", 0, phi).to("mm").magnitude == pytest.approx(xt, abs=1e-4)
    assert sheet.evaluate("y_t", 0, phi).to("mm").magnitude == pytest.approx(yt, abs=1e-4)
    table = sheet.table("rollers")
    r = table[(table["k"] == 0) & (table["phi [deg]"] == phi)].iloc[0]
    assert r["x_t [mm]"] == pytest.approx(xt, abs=1e-4)
    assert r["y_t [mm]"] == pytest.approx(yt, abs=1e-4)
    assert r["x_k [mm]"] == pytest.approx(xk, abs=1e-4)
    assert r["y_k [mm]"] == pytest.approx(yk, abs=1e-4)


def test_inputs_and_derived_scalars(sheet):
    assert sheet.evaluate("Z").magnitude == 11
    assert sheet.with_inputs(sense="opposite").evaluate("Z").magnitude == 13
    assert sheet.evaluate("rp_packing").to("mm").magnitude == pytest.approx(
        38 * math.sin(math.pi / 12), rel=1e-14
    )


# -- the practical profile against mpmath, at every table point --------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("n,sense", [(12, "same"), (12, "opposite"), (7, "same"), (7, "opposite")])
def test_practical_profile_matches_mpmath(sheet, n, sense):
    s = sheet.with_inputs(n=n, sense=sense, dphi="10 deg")
    table = s.table("rollers")
    rows = table.iloc[:: max(1, len(table) // 60)]
    for _, r in rows.iterrows():
        ref = ref_practical(int(r["k"]), r["phi [deg]"], n, 2, 40, 4, sense)
        got = [r["x_t [mm]"], r["y_t [mm]"], r["x_k [mm]"], r["y_k [mm]"]]
        assert got == pytest.approx(ref, abs=1e-10), (int(r["k"]), r["phi [deg]"])


@pytest.mark.slow
@pytest.mark.parametrize("sense", ["same", "opposite"])
def test_offset_lies_at_distance_rp_at_every_point(sheet, sense):
    s = sheet.with_inputs(sense=sense)
    t = s.table("rollers")
    dx, dy = t["x_k [mm]"] - t["x_t [mm]"], t["y_k [mm]"] - t["y_t [mm]"]
    assert np.max(np.abs(np.hypot(dx, dy) - 4.0)) < 1e-12
    # and it is the distance to the whole theoretical curve, not only to its own point:
    # nearest point on a dense independent sampling of the closed form R(psi), refined
    p = s.table("profile")
    Z = s.evaluate("Z").magnitude
    psi = np.linspace(0, 2 * np.pi, 400_001)
    R = 2 * np.cos(Z * psi) + np.sqrt(1600 - 4 * np.sin(Z * psi) ** 2)
    cx, cy = R * np.cos(psi), R * np.sin(psi)
    from scipy.spatial import cKDTree

    d, _ = cKDTree(np.column_stack([cx, cy])).query(p[["x_k [mm]", "y_k [mm]"]].to_numpy())
    # chord sampling overestimates the distance by at most (spacing)^2/(8 rho) ~ 1e-9 mm
    assert np.all(d >= 4.0 - 1e-12) and np.all(d - 4.0 < 1e-7)
    # the engine's own nearest-point check (Newton refined) reports rp to rounding
    f = {x.what: x for x in s.check().findings}
    gap = next(v for k, v in f.items() if k.startswith("distance of the practical"))
    assert gap.verdict == "ok" and gap.value < 1e-12


def test_normal_includes_the_cam_rotation(sheet):
    """Without da/dphi the tangent would vanish at theta_k - phi = 0; with it, it does not."""
    dx, dy = (sheet.evaluate(d, k=0, phi=np.array([0.0, 180.0])) for d in ("dx_t", "dy_t"))
    assert np.all(np.hypot(dx, dy).to("mm/deg").magnitude > 1e-3)


# -- closure: all n traces coincide ----------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize(
    "n,sense,Z", [(12, "same", 11), (12, "opposite", 13), (7, "same", 6), (7, "opposite", 8)]
)
def test_closure_holds(sheet, n, sense, Z):
    s = sheet.with_inputs(n=n, sense=sense)
    assert s.evaluate("Z").magnitude == Z and s.evaluate("turns").magnitude == Z
    c = reducer.closure(s)
    assert c["points"] == (n - 1) * 181
    assert c["max"] < 1e-9
    assert s.evaluate("dev_closed").to("mm").magnitude < 1e-9
    f = [x for x in s.check().findings if x.topic == "closure"]
    assert f[0].verdict == "ok" and f[0].value < 1e-9


@pytest.mark.slow
@pytest.mark.parametrize(
    "changes",
    [{"transform": "printed"}, {"ratio": "printed"}, {"transform": "printed", "ratio": "printed"}],
)
def test_printed_variants_do_not_close(sheet, changes):
    s = sheet.with_inputs(**changes)
    c = reducer.closure(s)
    assert c["max"] > 1.0  # millimetres apart
    f = [x for x in s.check().findings if x.topic == "closure"]
    closed = next(x for x in f if x.what.startswith("largest deviation"))
    bad = next(x for x in f if x.what.startswith("largest distance of the traces"))
    assert bad.verdict == "fail" and "do not coincide" in bad.note
    if "ratio" in changes:  # roller 0 itself leaves the closed form (k = 0: (4) is a rotation)
        assert closed.verdict == "warning" and closed.value > 1


@pytest.mark.slow
def test_printed_transform_is_not_a_rotation(sheet):
    s = sheet.with_inputs(transform="printed")
    # a rotation keeps the distance from the axis; the printed (4) does not
    # (roller 1: x and y both nonzero; |r|^2 = rho^2 (1 + 2 sin 2theta sin 2a))
    r_t = np.hypot(s.evaluate("x_t", 1, 90).magnitude, s.evaluate("y_t", 1, 90).magnitude)
    assert abs(r_t - s.evaluate("rho", 1, 90).magnitude) > 0.1
    default = {x.what: x for x in sheet.check().findings}
    shown = [x for x in default.values() if x.what.startswith("as printed")]
    assert len(shown) == 3 and all(x.value > 1 for x in shown)


# -- undercut -------------------------------------------------------------------------------


def valley_radius(n, e1, r2, sense):
    Z = n - 1 if sense == "same" else n + 1
    return (r2 - e1) ** 2 / (Z**2 * (e1 - e1**2 / r2) - (r2 - e1))


@pytest.mark.slow
@pytest.mark.parametrize("n,sense", [(12, "same"), (12, "opposite"), (7, "opposite")])
def test_smallest_concave_radius(sheet, n, sense):
    s = sheet.with_inputs(n=n, sense=sense)
    assert s.evaluate("kappa_max").magnitude > 0
    rho_min = s.evaluate("rho_min").to("mm").magnitude
    assert rho_min == pytest.approx(valley_radius(n, 2, 40, sense), rel=1e-9)


@pytest.mark.slow
def test_example_limit_is_7_525(sheet):
    assert sheet.evaluate("rho_min").to("mm").magnitude == pytest.approx(7.525, abs=5e-4)
    # at the valley, roller 0
    assert sheet.evaluate("phi_valley").to("deg").magnitude == pytest.approx(180, abs=1e-6)
    assert sheet.evaluate("rp_packing").to("mm").magnitude == pytest.approx(9.8351, abs=1e-4)


@pytest.mark.slow
def test_rp_7_5_regular(sheet):
    s = sheet.with_inputs(rp="7.5 mm")
    f = [x for x in s.check().findings if x.topic == "undercut"]
    assert not any(x.verdict == "fail" for x in f)
    assert any(x.verdict == "ok" and "regular" in x.what for x in f)
    assert s.table("profile")["regular"].all()
    assert s.table("undercut").empty


@pytest.mark.slow
def test_rp_7_6_undercut(sheet):
    s = sheet.with_inputs(rp="7.6 mm")
    report = s.check()
    assert not report.ok
    f = [x for x in report.findings if x.topic == "undercut"]
    verdict = next(x for x in f if x.what.startswith("INVALID PROFILE"))
    assert verdict.verdict == "fail" and "7.52475" in verdict.what
    uc = reducer.undercut(s)
    assert len(uc["cusps"]) == 22 and len(uc["loops"]) == 11
    # each cusp: the practical curve stops (its tangent vanishes) - an independent check
    for c in uc["cusps"][:4]:

        def xk(phi, sign):
            return ref_practical(0, float(phi), 12, 2, 40, 7.6, "same")[sign]

        h = 1e-4
        vx = (xk(c["phi"] + h, 2) - xk(c["phi"] - h, 2)) / (2 * h)
        vy = (xk(c["phi"] + h, 3) - xk(c["phi"] - h, 3)) / (2 * h)
        speed_far = abs(xk(c["phi"] + 20, 2) - xk(c["phi"] + 20 - 2 * h, 2)) / (2 * h)
        assert math.hypot(vx, vy) < 1e-4 * max(speed_far, 1e-3)
    # each loop: two different eccentric angles give the same point
    for lp in uc["loops"][:3]:
        p1 = ref_practical(0, lp["phi1"], 12, 2, 40, 7.6, "same")[2:]
        p2 = ref_practical(0, lp["phi2"], 12, 2, 40, 7.6, "same")[2:]
        assert abs(lp["phi2"] - lp["phi1"]) > 1
        assert p1 == pytest.approx(p2, abs=1e-9)
        assert p1 == pytest.approx([lp["x"], lp["y"]], abs=1e-9)
    # the first loop sits on the valley's symmetry line, polar angle 180/Z deg
    assert uc["loops"][0]["psi"] == pytest.approx(180 / 11, abs=1e-9)
    # the profile is still tabulated, marked invalid where the offset folds back
    prof = s.table("profile")
    assert (prof["regular"] == 0).sum() > 0
    assert s.evaluate("regular").magnitude == 0
    ut = s.table("undercut")
    assert list(ut["kind"]).count("cusp") == 22


@pytest.mark.slow
def test_packing_limit_verdict(sheet):
    s = sheet.with_inputs(e1="0.3 mm", rp="10.3 mm")  # convex; packing limit 10.275 mm
    f = [x for x in s.check().findings if x.topic == "undercut"]
    bad = next(x for x in f if x.what.startswith("INVALID PROFILE"))
    assert bad.verdict == "fail"
    assert "packing limit" in bad.what and "overlap" in bad.what
    margin = next(x for x in f if x.what.startswith("rp = 10.3 mm: margin"))
    assert margin.verdict == "fail" and margin.value == pytest.approx(10.275116 - 10.3, abs=1e-6)


@pytest.mark.slow
@pytest.mark.parametrize("factor,concave", [(0.98, False), (1.02, True)])
def test_concave_parts_exist_when_z2_e1_exceeds_r2(sheet, factor, concave):
    e1 = factor * 40 / 121
    s = sheet.with_inputs(e1=f"{e1} mm")
    assert (s.evaluate("kappa_max").magnitude > 0) is concave
    if not concave:
        with pytest.raises(InputError, match="no piece applies"):
            s.evaluate("rho_min")  # no concave part: no radius, never a number
        assert s.with_inputs(rp="9 mm").check().ok


# -- degenerate inputs ----------------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("sense", ["same", "opposite"])
def test_e1_zero_gives_circles(sheet, sense):
    s = sheet.with_inputs(e1="0 mm", sense=sense)
    t = s.table("rollers")
    assert np.allclose(np.hypot(t["x_t [mm]"], t["y_t [mm]"]), 40, atol=1e-12, rtol=0)
    assert np.allclose(np.hypot(t["x_k [mm]"], t["y_k [mm]"]), 44, atol=1e-12, rtol=0)
    report = s.check()
    assert report.ok
    assert any("circle" in x.what for x in report.findings)


@pytest.mark.parametrize("e1", ["45 mm", "40 mm"])
def test_e1_not_below_r2_is_refused_clearly(sheet, e1):
    s = sheet.with_inputs(e1=e1)
    f = s.check().findings
    # no number for no mechanism (the profile line says only Z, from n and sense)
    assert all(x.verdict != "ok" and x.value is None for x in f if x.topic != "profile")
    why = next(x for x in f if x.topic == "inputs")
    assert "not smaller than r2" in why.what and "cannot be assembled" in why.what
    with pytest.raises(InputError, match="not smaller than r2"):
        s.table("rollers")
    with pytest.raises(WorkbookError, match="turns.* no piece applies.* e1 < r2"):
        s.table("profile")


def test_fractional_roller_count_is_refused(sheet):
    s = sheet.with_inputs(n=12.5)
    f = s.check().findings
    assert all(x.verdict != "ok" and x.value is None for x in f)  # Z = 11.5 is no number
    with pytest.raises(InputError, match="no piece applies.* n == floor\\(n\\)"):
        s.evaluate("Z")
    assert "whole number" in next(x for x in f if x.topic == "inputs").what


# -- the symbolic converter -------------------------------------------------------------------


@pytest.mark.slow
def test_derivatives_are_those_of_the_profile(sheet):
    """diff(x_t), diff(y_t), and the tangent of (5), against central differences."""
    phi, k, h = np.array([7.0, 33.0, 200.0]), np.array([1.0, 5.0, 11.0]), 1e-5
    for f, d in (("x_t", "dx_t"), ("y_t", "dy_t"), ("x_k", "dx_k"), ("y_k", "dy_k")):
        up, down = (sheet.evaluate(f, k=k, phi=phi + s).to("mm").magnitude for s in (h, -h))
        got = sheet.evaluate(d, k=k, phi=phi).to("mm/deg").magnitude
        np.testing.assert_allclose(got, (up - down) / (2 * h), rtol=0, atol=1e-8)


# -- workbook, chart and CAD export ------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("sense,lobes", [("same", 11), ("opposite", 13)])
def test_profile_has_z_lobes(sheet, sense, lobes):
    p = sheet.with_inputs(sense=sense).table("profile")
    r = np.hypot(p["x_t [mm]"], p["y_t [mm]"]).to_numpy()[:-1]  # closed: drop the repeat
    peaks = (r > np.roll(r, 1)) & (r > np.roll(r, -1))
    assert peaks.sum() == lobes
    assert p["phi [deg]"].iloc[-1] == 360 * lobes


@pytest.mark.slow  # seconds of CPU: run by CI with the slow tests
def test_workbook_chart_has_equal_axes(sheet, tmp_path):
    spec = next(c for c in sheet.spec.charts if c.name == "tooth_profile")
    assert spec.equal_axes
    path = sheet.write_xlsx(tmp_path / "rp.xlsx")
    with zipfile.ZipFile(path) as z:
        xml = z.read("xl/charts/chart1.xml").decode()
    import re

    mins = [float(v) for v in re.findall(r'<c:min val="([^"]+)"/>', xml)]
    maxs = [float(v) for v in re.findall(r'<c:max val="([^"]+)"/>', xml)]
    assert len(mins) == len(maxs) == 2 and mins[0] == mins[1] and maxs[0] == maxs[1]
    assert maxs[0] >= 46 and mins[0] <= -46  # the practical profile fits
    assert 'c:w val="0.76' in xml and 'c:h val="0.76' in xml  # square plot area


@pytest.mark.slow
def test_invalid_profile_is_still_written(sheet, tmp_path):
    import openpyxl

    path = sheet.with_inputs(rp="7.6 mm").write_xlsx(tmp_path / "bad.xlsx")
    wb = openpyxl.load_workbook(path)
    text = " ".join(str(c.value) for row in wb["Checks"].iter_rows() for c in row if c.value)
    assert "INVALID PROFILE" in text and "cusp" in text and "loop" in text
    assert wb["Profile"].max_row > 1900


@pytest.mark.slow
def test_export_profile_csv(sheet, tmp_path):
    path = reducer.export_profile_csv(sheet, tmp_path / "cam.csv")
    lines = path.read_text().splitlines()
    assert lines[0] == "x_mm,y_mm,z_mm"
    pts = np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]])
    assert len(pts) == 11 * 180  # 2-degree steps over 11 turns, closing point left out
    r = np.hypot(pts[:, 0], pts[:, 1])
    assert r.max() == pytest.approx(46, abs=1e-9)  # tooth tip: r2 + e1 + rp
    assert np.all(pts[:, 2] == 0)
    with pytest.raises(InputError, match="invalid"):
        reducer.export_profile_csv(sheet.with_inputs(rp="7.6 mm"), tmp_path / "bad.csv")
    ok = reducer.export_profile_csv(
        sheet.with_inputs(rp="7.6 mm"), tmp_path / "bad.csv", allow_invalid=True
    )
    assert ok.exists()


# -- LibreOffice recalculation -----------------------------------------------------------------


def _lo():
    from helpers.recalc import soffice

    if soffice() is None:
        pytest.skip("LibreOffice is not installed")


@pytest.mark.slow
def test_libreoffice_recalculates_the_live_profile(sheet, tmp_path):
    _lo()
    import shutil

    import openpyxl
    from helpers.recalc import cell_values, formula_values, recalculate

    path = sheet.write_xlsx(tmp_path / "rp.xlsx")
    cached = formula_values(path)
    listing = {k: v for k, (f, v) in cached.items() if k[0] == "Listing"}
    # phi itself (its step dphi is an input), a, rho_0, x_0, y_0, x_t, y_t over phi = 0, 2 .. 360,
    # and the range's row-count guard
    assert len(listing) == 181 * 7 + 1
    new = cell_values(recalculate(path, tmp_path / "lo"))
    bad = [
        k
        for k, (f, v) in cached.items()
        if isinstance(v, float) and abs(new.get(k, math.nan) - v) > 1e-9 * max(1.0, abs(v))
    ]
    assert not bad, bad[:5]
    # turn the eccentric the other way in the workbook itself: Z = 13, the live theoretical
    # profile follows (the engine with the same input is the reference)
    edited = tmp_path / "edited.xlsx"
    shutil.copy(path, edited)
    wb = openpyxl.load_workbook(edited)
    ws = wb["Inputs"]
    row = next(r for r in ws.iter_rows() if r[0].value == "sense")
    row[1].value = "opposite"
    wb.save(edited)
    values = cell_values(recalculate(edited, tmp_path / "lo2"))
    ref = sheet.with_inputs(sense="opposite").table("roller0")
    ws = openpyxl.load_workbook(path)["Listing"]
    heads = [c.value for c in ws[2]]
    col = {h: openpyxl.utils.get_column_letter(i + 1) for i, h in enumerate(heads)}
    for i in (0, 45, 90, 180):
        for h in ("x_t [mm]", "y_t [mm]", "a [deg]"):
            name, unit = h[:-1].split(" [")  # the workbook's header typesets the unit: a [°]
            shown = f"{name} [{un.typeset(un.unit(unit))}]"
            got = values[("Listing", f"{col[shown]}{3 + i}")]
            assert got == pytest.approx(ref[h].iloc[i], rel=1e-9, abs=1e-12), (h, i)


@pytest.mark.slow  # seconds of CPU: run by CI with the slow tests
def test_tables_over_the_row_limit_are_refused_before_they_are_computed(sheet):
    """n = 400 at its coarsest documented step writes; a finer step is refused by name."""
    from workbook.errors import LimitError

    reducer.validate(sheet.with_inputs(n=400, dphi="2 deg"))  # 72,400 rows: within the limit
    with pytest.raises(LimitError, match=r"1,440,400 rows .*limit 75,000"):
        reducer.validate(sheet.with_inputs(n=400, dphi="0.1 deg"))
    f = sheet.with_inputs(n=400, dphi="0.1 deg").check().findings
    assert any(x.topic == "inputs" and x.verdict == "fail" and "75,000" in x.what for x in f)


@pytest.mark.parametrize("sense, table", [("same", "rollers"), ("opposite", "profile")])
def test_row_count_is_the_templates(sheet, sense, table):
    """The template's rows: the longer of the table of every roller and the closed profile."""
    s = sheet.with_inputs(sense=sense)
    rows = s.evaluate("rows").magnitude
    assert rows == len(s.table(table)) == max(len(s.table("rollers")), len(s.table("profile")))
    assert rows == {"same": 12 * 181, "opposite": 13 * 180 + 1}[sense]


@pytest.mark.slow
def test_polar_angles_of_the_undercut_are_the_templates(sheet):
    s = sheet.with_inputs(rp="7.6 mm")
    uc = reducer.undercut(s)
    for c in uc["cusps"][:4]:
        x, y = (s.evaluate(n, 0, c["phi"]).to("mm").magnitude for n in ("x_k", "y_k"))
        assert c["psi"] == pytest.approx(math.degrees(math.atan2(y, x)), abs=1e-12)
    assert uc["loops"][0]["psi"] == pytest.approx(180 / 11, abs=1e-12)


def test_sign_changes_end_where_one_ulp_exceeds_the_tolerance(monkeypatch):
    """Far out (phi ~ 35,640 deg, one ulp 7e-12 deg) the bisection stops at brentq's
    tolerance of a few ulps instead of looping for ever; the root is the exact one."""
    root = 35640.123456789

    def linear(_sheet, name, k, phi):
        return np.asarray(phi, dtype=float) - root

    monkeypatch.setattr(reducer, "profile_values", linear)
    (found,) = reducer.sign_changes(None, np.array([35640.0]), np.array([35640.25]))
    assert found == pytest.approx(root, abs=1e-10)
