"""The hand calculation of the concave cam checked by the engine.

References are computed here independently (closed forms, plane geometry with numpy,
mpmath at 50 digits), not taken from the engine.
"""

import math

import mpmath
import numpy as np
import pytest

import workbook
from workbook.engine import analysis
from workbook.errors import DomainError

R1, R2, R3, RP, A, OMEGA = 20.0, 10.0, 50.0, 10.0, 20.0, 104.6  # mm, 1/s
D, C = R1 + R3, R3 - RP
K = D / C


@pytest.fixture(scope="module")
def concave():
    """The concave cam with its optional part hand-checks (left out by a plain load)."""
    return workbook.load("concave-cam", parts="hand-checks")


@pytest.fixture(scope="module")
def geometry():
    return workbook.load("concave-cam-geometry", parts="all")


@pytest.fixture(scope="module")
def relations(concave):
    return {r.text: r for r in analysis.relation_results(concave)}


# -- 1. derivative relations -----------------------------------------------------------------------
def test_every_velocity_and_acceleration_has_a_relation(concave):
    declared = {(r.child, r.parent) for r in concave.spec.relations}
    assert declared == {
        ("v1", "h1"),
        ("v2", "h2"),
        ("v3", "h3"),
        ("j1", "v1"),
        ("j2", "v2"),
        ("j3", "v3"),
        ("j9c", "v1"),
    }


def test_relations_that_hold(relations):
    for text in ("v1 = omega * d(h1)/d(phi)", "v3 = omega * d(h3)/d(phi)"):
        r = relations[text]
        assert r.holds and r.rel < 1e-9, (text, r.rel)
        # with the sheet's pi = 3.142 the sheet's degree is 3.142/pi of a true one
        assert r.pi_rel == pytest.approx(3.142 / math.pi - 1, rel=1e-3)
    # j2 is the second derivative of h2 (it is v2 that carries the factor psi = 1.5)
    second = [r for r in relations.values() if r.second and r.child == "j2"][0]
    assert second.holds and second.rel < 1e-9


def test_v2_carries_psi(relations):
    r = relations["v2 = omega * d(h2)/d(phi)"]
    assert not r.holds
    # v2 = 3 a omega sin(Theta - phi), omega dh2/dphi = 2 a omega sin(Theta - phi): largest at 22
    assert r.at == pytest.approx(22)
    assert r.max_abs == pytest.approx(A * 1e-3 * OMEGA * math.sin(math.radians(30)), rel=1e-3)
    assert r.rel == pytest.approx(1 / 3, rel=1e-9)


def test_j2_against_v2(relations):
    r = relations["j2 = omega * d(v2)/d(phi)"]
    assert not r.holds and r.at == pytest.approx(52)
    assert r.max_abs == pytest.approx(A * 1e-3 * OMEGA**2, rel=1e-9)  # a omega^2 at the top
    assert r.rel == pytest.approx(0.5, rel=1e-9)


@pytest.mark.parametrize("child,at", [("j1", 22.0), ("j3", 82.0)])
def test_formula_9_has_a_sign_error(relations, child, at):
    """omega d(v1)/dphi = omega^2 (R1+R3) ((k cos 2x + k^3 sin^4 x)/(1-k^2 sin^2 x)^1.5 - cos x):
    the paper prints -k^3 sin^4 x; the discrepancy is 2 k^3 sin^4 x/(...)^1.5 omega^2 (R1+R3)."""
    text = f"{child} = omega * d({'v1' if child == 'j1' else 'v3'})/d(phi)"
    r = relations[text]
    assert not r.holds and r.at == pytest.approx(at)
    x = math.radians(22)  # the relations are measured with the true pi
    s = math.sin(x)
    expected = 2 * K**3 * s**4 / (1 - K**2 * s**2) ** 1.5 * OMEGA**2 * D * 1e-3
    assert r.max_abs == pytest.approx(expected, rel=1e-9)
    assert 0.27 < r.rel < 0.29


@pytest.mark.slow
def test_check_lists_every_relation(concave):
    report = concave.check()
    assert report.ok
    lines = [f for f in report.findings if f.topic == "relations"]
    for r in concave.spec.relations:
        hit = [f for f in lines if f.what.startswith(r.text)]
        assert hit and hit[0].value is not None
    bad = {f.what.split(":")[0] for f in lines if f.verdict == "warning"}
    assert {b for b in bad if "d2" not in b} == {
        "v2 = omega * d(h2)/d(phi)",
        "j1 = omega * d(v1)/d(phi)",
        "j2 = omega * d(v2)/d(phi)",
        "j3 = omega * d(v3)/d(phi)",
    }
    text = report.text()
    assert "largest discrepancy at phi = 22 deg" in text
    assert "largest discrepancy at phi = 52 deg" in text


def _with(load_text, extra: str):
    """concave-cam with EXTRA added to its text, its data files read where the template is."""
    src = workbook.load("concave-cam").spec.path
    text = src.read_text(encoding="utf-8") + extra
    return load_text(text, name="concave-cam", folder=src.parent)


@pytest.mark.parametrize(
    "relation,message",
    [
        ('relation = "v1 = omega * d(nothing)/d(phi)"', "not a function"),
        ('relation = "v1 = R1 * d(h1)/d(phi)"', "units do not work out"),
    ],
)
def test_a_relation_that_cannot_be_evaluated_fails_the_check(load_text, relation, message):
    sheet = _with(load_text, f"\n[[relations]]\n{relation}\n")
    report = sheet.check()
    assert not report.ok
    failed = [f for f in report.findings if f.verdict == "fail"]
    assert len(failed) == 1 and message in failed[0].note
    assert not report.failed  # the printed values are still reproduced


# -- 2. joins --------------------------------------------------------------------------------
def test_joins_of_h_v_j(concave):
    res = {r.function: r for r in analysis.join_results(concave)}
    assert set(res) == {"h", "v", "j"}
    for name in ("h", "v", "j"):
        r = res[name]
        assert not r.error and not r.gaps
        assert r.domain == (0.0, 104.0)
        assert [(o[0][0], o[1][0], o[2]) for o in r.overlaps] == [(name, name, "{22}")]
        assert [j.at for j in r.joins] == [22.0, 82.0]
    h22 = res["h"].joins[0]
    ev = concave.evaluate
    assert h22.jumps[0] == pytest.approx(
        (ev("h2", phi=22) - ev("h1", phi=22)).to("mm").magnitude, rel=1e-9
    )
    # first-derivative jump against central differences of each side's own formula
    step = 1e-4
    per_rad = 180 / 3.142  # the sheet's own degree
    d2 = (ev("h2", phi=22 + step) - ev("h2", phi=22 - step)).to("mm").magnitude / (2 * step)
    d1 = (ev("h1", phi=22 + step) - ev("h1", phi=22 - step)).to("mm").magnitude / (2 * step)
    assert h22.jumps[1] == pytest.approx((d2 - d1) * per_rad * 3.142 / math.pi, rel=1e-6)
    v22 = res["v"].joins[0]
    assert v22.jumps[0] == pytest.approx(3.138369 - 3.151546, abs=1e-5)
    j22 = res["j"].joins[0]
    assert j22.jumps[0] == pytest.approx(-378.998 - 1341.423, abs=1e-2)


def test_gaps_and_overlaps_are_found(sheet_from):
    text = (
        '[arguments]\nx = { unit = "" }\n[definitions]\n'
        '"f(x)" = ["1 if 0 <= x <= 1", "2 if 2 <= x <= 3", "3 if 2.5 <= x <= 4"]\n'
        "[sheet]\nhand_checks = true\n"
    )
    sheet = sheet_from(text, name="gaps")
    (r,) = analysis.join_results(sheet)
    assert r.gaps == ["Interval.open(1, 2)"]
    assert r.overlaps == [("2", "3", "Interval(5/2, 3)")]
    # the first true piece wins: "2" holds up to 3, where "3" takes over (a jump of 1)
    assert [(j.at, j.jumps[0]) for j in r.joins] == [(3.0, 1.0)]
    found = [f for f in sheet.check().findings if f.topic == "joins"]
    assert any("no piece applies" in f.what and f.verdict == "warning" for f in found)
    assert any("overlap" in f.what and f.verdict == "warning" for f in found)


# -- 3. geometry --------------------------------------------------------------------------------
def _centres():
    cos_t = (A**2 + D**2 - (R2 + R3) ** 2) / (2 * A * D)
    theta = math.acos(cos_t)
    o2 = np.array([A * math.cos(theta), A * math.sin(theta)])
    o3 = np.array([D, 0.0])
    return theta, o2, o3


def test_theta_and_transition_from_the_geometry(geometry):
    theta, o2, o3 = _centres()
    # O3 is at R1 + R3 from O1 and at R3 + R2 from O2
    assert np.linalg.norm(o3) == pytest.approx(R1 + R3)
    assert np.linalg.norm(o3 - o2) == pytest.approx(R3 + R2)
    b = o3 + (o2 - o3) * C / (R3 + R2)  # roller centre on O3-O2
    t = geometry.evaluate("theta_geom")
    p = geometry.evaluate("phiB_geom")
    assert t.check("[]") and str(t.units) == "degree"
    assert t.to("rad").magnitude == pytest.approx(theta, rel=1e-14)
    assert p.to("rad").magnitude == pytest.approx(math.atan2(b[1], b[0]), rel=1e-14)
    assert t.magnitude == pytest.approx(52.6168016, abs=1e-6)
    assert p.magnitude == pytest.approx(18.6289580, abs=1e-6)


def _lift_reference(phi_deg):
    """Roller-centre lift from plane geometry: intersect the follower ray with the pitch circles."""
    theta, o2, o3 = _centres()
    _, _, _ = theta, o2, o3
    b = o3 + (o2 - o3) * C / (R3 + R2)
    phib = math.atan2(b[1], b[0])
    x = math.radians(phi_deg)
    if x > 2 * theta - phib:
        x = 2 * theta - x  # the mirrored flank
    u = np.array([math.cos(x), math.sin(x)])
    if x <= phib:  # |r u - O3| = R3 - Rp, the root nearer O1
        centre, radius, root = o3, C, min
    else:  # |r u - O2| = R2 + Rp, the root farther out
        centre, radius, root = o2, R2 + RP, max
    r = root(np.roots([1.0, -2 * u @ centre, centre @ centre - radius**2]).real)
    return r - (R1 + RP)


def test_exact_lift_against_plane_geometry(geometry):
    phis = [0.0, 5.0, 18.0, 18.6, 19.0, 30.0, 52.0, 52.6, 70.0, 86.0, 87.0, 100.0, 105.0]
    got = geometry.evaluate("h_exact", phi=phis).to("mm").magnitude
    ref = [_lift_reference(p) for p in phis]
    assert np.allclose(got, ref, rtol=0, atol=1e-11)
    assert max(got) <= 10.0 + 1e-12


def test_exact_lift_is_c1_at_the_transition(geometry):
    pb = geometry.evaluate("phiBG").magnitude

    def h(x):
        return geometry.evaluate("h_exact", phi=x).to("mm").magnitude

    for e in (1e-2, 1e-4, 1e-6):
        # value: the change across the transition shrinks with the step (slope ~0.39 mm/deg)
        assert abs(h(pb + e) - h(pb - e)) < 1.0 * e
        # slope from the left and from the right agree to O(e)
        left = (h(pb) - h(pb - e)) / e
        right = (h(pb + e) - h(pb)) / e
        assert abs(right - left) < 2.0 * e * max(abs(left), 1.0) + 1e-8
    assert geometry.evaluate("hf", phi=pb).magnitude == pytest.approx(
        geometry.evaluate("hn", phi=pb).magnitude, abs=1e-12
    )
    assert geometry.evaluate("vf", phi=pb).magnitude == pytest.approx(
        geometry.evaluate("vn", phi=pb).magnitude, abs=1e-12
    )
    # the acceleration does jump: concave flank to convex nose
    assert (
        abs(geometry.evaluate("jf", phi=pb).magnitude - geometry.evaluate("jn", phi=pb).magnitude)
        > 1000
    )


@pytest.mark.slow
def test_paper_against_exact(geometry):
    units = {"v_exact_peak": "m/s", "v_exact_top": "m/s", "v_paper_peak": "m/s", "h_err": "mm"}
    units.update(v_paper_at="", h_err_at="")  # plain degrees
    g = {n: float(geometry.evaluate(n).to(u).magnitude) for n, u in units.items()}
    theta, o2, o3 = _centres()
    b = o3 + (o2 - o3) * C / (R3 + R2)
    psi = theta - math.atan2(b[1], b[0])
    v_peak = 2 * A * 1e-3 * OMEGA * math.sin(psi)  # lambda = 1 on the nose
    assert g["v_exact_peak"] == pytest.approx(v_peak, rel=1e-12)
    # maximum over the whole lift: at the transition (a kink), found to about 1e-8
    assert g["v_exact_top"] == pytest.approx(v_peak, rel=1e-7) and g["v_exact_top"] <= v_peak
    assert g["v_paper_peak"] == pytest.approx(3.151546, abs=1e-6)
    assert g["v_paper_at"] == pytest.approx(22.0, abs=1e-5)  # v1's end, where v2 takes over
    assert g["v_paper_peak"] / g["v_exact_peak"] - 1 == pytest.approx(0.3474, abs=1e-3)
    assert g["h_err"] == pytest.approx(-0.4746, abs=1e-3)
    assert g["h_err_at"] == pytest.approx(85.66, abs=0.01)
    report = geometry.check()
    assert report.ok
    text = report.text()
    assert "peak velocity of the paper" in text and "largest lift error" in text
    rel = [f for f in report.findings if f.topic == "relations"]
    assert rel and all(f.verdict == "ok" for f in rel), [f.what for f in rel if f.verdict != "ok"]


# -- 4. domains and extreme inputs -----------------------------------------------------------------
@pytest.mark.filterwarnings("ignore::RuntimeWarning")  # numpy's own note on the sqrt
def test_domain_error_names_function_and_interval(concave):
    with pytest.raises(DomainError) as err:
        concave.evaluate("h1", phi=[0, 10, 40, 50, 150])
    msg = str(err.value)
    assert "h1" in msg and "sqrt of a negative number" in msg
    assert "|k*sin(phi * deg)| > 1" in msg and "phi from 40 to 50 deg" in msg
    with pytest.raises(DomainError, match=r"power 1.5 of a negative number"):
        concave.evaluate("j1", phi=40)
    # a table: the rows that leave the domain are error cells naming the cause, phi 5 .. 22 deg
    data = concave.with_inputs(R3="10.5 mm").table_data("flank_AB")
    h1 = next(c for c in data.columns if c.text == "h1")
    assert [data.columns[0].values[i] for i in sorted(h1.failed)] == [5, 10, 15, 20, 22]
    assert "sqrt of a negative number" in h1.failed[min(h1.failed)]


@pytest.mark.slow
def test_flank_domain_limit(concave):
    f = [x for x in concave.check().findings if x.topic == "domains" and x.what.startswith("h1")]
    # k sin(phi) = 1 at asin(1/k), in the sheet's degrees
    assert f[0].value == pytest.approx(math.degrees(math.asin(1 / K)) * math.pi / 3.142, abs=2e-3)


@pytest.mark.slow
def test_extreme_inputs_are_checked(concave):
    found = [f for f in concave.check().findings if f.topic == "extreme inputs"]
    rows = {f.what.split(" (")[0]: f for f in found}
    assert len(rows) == 10
    valid = {c for c, f in rows.items() if f.verdict == "ok"}
    assert valid == {"as printed", "very large R3", "omega x 10", "omega x 10, very large R3"}
    assert {f.verdict for c, f in rows.items() if c not in valid} == {"warning"}
    assert "|k*sin(phi * deg)| > 1" in rows["R3 close to Rp"].note
    assert rows["R3 close to Rp"].value is None
    assert "k is not a finite number" in rows["R3 = Rp"].note
    assert "here 1.5" in rows["lambda = 1.5 on the nose"].note
    assert "here 0.25" in rows["nose inside the base circle"].note
    base, fast = rows["as printed"], rows["omega x 10"]
    assert base.value == pytest.approx(
        concave.evaluate("v", phi=np.arange(105)).to("m/s").magnitude.max(), rel=1e-15
    )
    assert fast.value / base.value == pytest.approx(10, rel=1e-12)
    # the circles about O1 and O2 do not meet: the geometry has no flank centre O3
    with pytest.raises(workbook.WorkbookError, match="theta_geom"):
        workbook.load("concave-cam-geometry").with_inputs(a="5 mm").evaluate("theta_geom")


# -- 5. numerical stability ------------------------------------------------------------------------
def _reference_lift(phi_deg):
    mpmath.mp.dps = 50
    x = mpmath.mpf(phi_deg) * mpmath.mpf("3.142") / 180  # the sheet's own degree
    k = mpmath.mpf(D) / C
    return D * (mpmath.cos(x) - mpmath.sqrt(1 - k**2 * mpmath.sin(x) ** 2) / k) - (R1 + RP)


@pytest.mark.slow
def test_stability_of_the_lift(concave):
    df = concave.table("stability").set_index("phi [deg]")
    for phi in (1e-6, 1e-3, 1.0):
        ref = float(_reference_lift(repr(phi)))
        assert df.loc[phi, "stable form [mm]"] == pytest.approx(ref, rel=1e-15)
        printed_error = abs(df.loc[phi, "formula (1) [mm]"] / ref - 1)
        assert df.loc[phi, "relative difference"] == pytest.approx(printed_error, rel=1e-3)
    rel = df["relative difference"]
    assert rel[1e-6] > 0.1  # catastrophic cancellation
    assert 1e-8 < rel[1e-3] < 1e-5
    assert rel[1.0] < 1e-10
    f = [x for x in concave.check().findings if x.topic == "stability"]
    assert [x.verdict for x in f] == ["warning", "ok", "ok"]


# -- 6. error against run time ---------------------------------------------------------------------
def test_derivatives_from_the_lift(concave):
    df = concave.table("derivatives")
    by = {round(s, 6): r for s, r in zip(df["step [deg]"], df.to_dict("records"))}
    # truncation orders: central h^2, five-point h^4
    assert by[1.0]["central v error"] / by[0.1]["central v error"] == pytest.approx(100, rel=0.05)
    assert by[1.0]["five-point v error"] / by[0.1]["five-point v error"] == pytest.approx(
        1e4, rel=0.05
    )
    # round-off: the central second difference gets worse below 0.01 deg
    assert by[1e-4]["central j error"] > 100 * by[1e-2]["central j error"]
    f = [x for x in concave.check().findings if x.topic == "derivatives"]
    assert len(f) == 4 and f[0].value == pytest.approx(df["central v error"].min())


def _mp_lift(x):
    """Formula (1) in the sheet's own radian x (pi = 3.142), 50 digits."""
    k = mpmath.mpf(D) / C
    return D * (mpmath.cos(x) - mpmath.sqrt(1 - k**2 * mpmath.sin(x) ** 2) / k) - (R1 + RP)


def test_derivative_references_against_mpmath(concave):
    """v1 and the corrected (9), the references of the derivatives table: mpmath.diff."""
    mpmath.mp.dps = 50
    deg = mpmath.mpf("3.142") / 180
    phis = [3.0, 8.0, 13.0, 18.0]
    v = concave.evaluate("v1", phi=phis).to("mm/s").magnitude
    j = concave.evaluate("j9c", phi=phis).to("mm/s^2").magnitude
    for p, vv, jj in zip(phis, v, j):
        x = mpmath.mpf(p) * deg
        assert vv == pytest.approx(float(OMEGA * mpmath.diff(_mp_lift, x)), rel=1e-13)
        assert jj == pytest.approx(float(OMEGA**2 * mpmath.diff(_mp_lift, x, 2)), rel=1e-13)


@pytest.mark.slow
def test_bench_command(capsys):
    from workbook.cli import main

    assert main(["bench", "concave-cam-geometry"]) == 0
    out = capsys.readouterr().out
    assert "h_err_at" in out and "argmax" in out and "vs ref." in out


# -- 7. where it shows -----------------------------------------------------------------------------
@pytest.mark.slow
def test_check_command(capsys):
    from workbook.cli import main

    assert main(["check", "concave-cam"]) == 0
    out = capsys.readouterr().out
    for topic in ("[relations]", "[joins]", "[domains]", "[pi rounding]", "[stability]"):
        assert topic in out
    assert "the sheet's pi = 3.142" in out


def test_workbook_holds_the_findings_and_tables(tmp_path, concave):
    import openpyxl

    path = concave.write_xlsx(tmp_path / "cc.xlsx")
    wb = openpyxl.load_workbook(path)
    assert {"Hand checks", "Derivatives"} <= set(wb.sheetnames)
    checks = [r for r in wb["Checks"].iter_rows(values_only=True)]
    topics = {r[0] for r in checks}
    assert {
        "relations",
        "joins",
        "stability",
        "extreme inputs",
        "derivatives",
        "pi rounding",
    } <= topics
    rel = [r for r in checks if r[0] == "relations" and str(r[1]).startswith("j1 = omega * d(v1)")]
    assert rel and rel[0][4] == pytest.approx(375.42, abs=0.01)
    assert len(wb["Charts"]._charts) == 4


@pytest.mark.slow
def test_geometry_workbook_recalculates_in_libreoffice(tmp_path, geometry):
    from helpers.recalc import cell_values, formula_values, recalculate, soffice

    if soffice() is None:
        pytest.skip("LibreOffice is not installed")
    path = geometry.write_xlsx(tmp_path / "geo.xlsx")
    cached = formula_values(path)
    new = cell_values(recalculate(path, tmp_path / "lo"))
    assert len(cached) > 600
    bad = [
        (k, v, new.get(k))
        for k, (f, v) in cached.items()
        if isinstance(v, float) and abs(new.get(k, math.inf) - v) > 1e-9 * max(1.0, abs(v))
    ]
    assert not bad, bad[:5]
    assert new[("Definitions", _definition_cell(path, "theta_geom"))] == pytest.approx(
        52.6168016, abs=1e-6
    )


def _definition_cell(path, name):
    import openpyxl

    ws = openpyxl.load_workbook(path)["Definitions"]
    for row in ws.iter_rows():
        if row[0].value == name:
            return row[1].coordinate
    raise KeyError(name)
