"""Sweeps: outputs over a grid of inputs, locally (vector, serial, process pool) and on Dask.

References: the Mathcad listing's printed v1(22) = 3.152 m/s, the velocity formula of the
paper written out here in numpy, and the coupling's equilibrium F(phi) = 0 solved here with
scipy's brentq, independently of the engine.
"""

import io
import math
import zipfile
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from helpers.sheets import SINE_TABLE, write_template

import workbook
from workbook import sweep as sw
from workbook.cli import main

V_PEAK = "max of v(phi) over phi := 0, 0.5 .. 104"
R3_GRID = "40mm..60mm:21"
PHI2 = "phi2(omega_dyn)"
C1_GRID = "1500N/m..6000N/m:10"
HAS_COUPLING = "advance-coupling" in workbook.list_templates()


def paper_v1(phi_deg, R3, R1=20.0, Rp=10.0, omega=104.6, pi=3.142):
    """Formula of section 2.3 of the paper (m/s with mm inputs: the paper's 10^-3)."""
    d = phi_deg * pi / 180
    k = (R1 + R3) / (R3 - Rp)
    return (
        1e-3
        * omega
        * (R1 + R3)
        * (k * np.sin(2 * d) / (2 * np.sqrt(1 - k**2 * np.sin(d) ** 2)) - np.sin(d))
    )


def paper_v2(phi_deg, a=20.0, omega=104.6, Theta=52.0, pi=3.142):
    """Nose velocity, formula (15) with psi = 1.5 as printed (m/s with mm)."""
    return 1e-3 * 3 * a * omega * np.sin((Theta - phi_deg) * pi / 180)


def test_peak_velocity_over_R3_matches_the_paper_and_its_formula(concave):
    res = sw.sweep(
        concave,
        {"R3": R3_GRID},
        {"v_peak": V_PEAK, "phi_at": "argmax of v(phi) over phi := 0, 0.5 .. 104"},
    )
    t = res.table
    assert res.mode == "vector" and res.failed == 0 and len(t) == 21
    assert list(t.columns) == ["R3 [mm]", "v_peak [m/s]", "phi_at [deg]", "error"]
    R3 = np.linspace(40, 60, 21)
    assert t["R3 [mm]"].to_numpy() == pytest.approx(R3, abs=1e-12)
    # the peak is at the end of the concave flank, v1(22); from R3 = 51 mm on, v1(22) is
    # below the nose's v2 at the next grid point, 22.5 deg (v2 does not depend on R3)
    flank, nose = paper_v1(22.0, R3), paper_v2(22.5)
    assert t["v_peak [m/s]"].to_numpy() == pytest.approx(np.maximum(flank, nose), rel=1e-12)
    assert t["phi_at [deg]"].tolist() == [22.0 if f > nose else 22.5 for f in flank]
    assert t["phi_at [deg]"].iloc[0] == 22.0 and t["phi_at [deg]"].iloc[-1] == 22.5
    printed = t.loc[t["R3 [mm]"] == 50, "v_peak [m/s]"].item()
    assert printed == pytest.approx(3.152, abs=5e-4)  # Mathcad listing: v1(22) = 3.152


@pytest.mark.slow
def test_vector_serial_and_processes_give_identical_tables(concave):
    outs = {
        "v_peak": V_PEAK,
        "h22": "h(22)",
        "k": "k",
        "j_min": "min of j(phi) over phi := 0 .. 104",
    }
    tables = {
        mode: sw.sweep(concave, {"R3": R3_GRID}, outs, mode=mode, workers=2).table
        for mode in ("vector", "serial", "processes")
    }
    pd.testing.assert_frame_equal(tables["vector"], tables["serial"], check_exact=True)
    pd.testing.assert_frame_equal(tables["vector"], tables["processes"], check_exact=True)


def test_a_failed_case_is_recorded_and_the_others_go_on(concave):
    # R3 <= Rp = 10 mm breaks k = (R1 + R3)/(R3 - Rp); small R3 leaves sqrt's domain
    res = sw.sweep(concave, {"R3": "5mm..60mm:12"}, {"v_peak": V_PEAK})
    t = res.table
    bad = t["error"].notna()
    assert bad.sum() == 5 and res.failed == 5
    assert t.loc[bad, "R3 [mm]"].tolist() == [5.0, 10.0, 15.0, 20.0, 25.0]
    assert "not a finite number" in t["error"][0]
    assert t.loc[bad, "v_peak [m/s]"].isna().all()
    good = t.loc[~bad]
    assert good["v_peak [m/s]"].to_numpy() == pytest.approx(
        np.maximum(paper_v1(22.0, good["R3 [mm]"].to_numpy()), paper_v2(22.5)), rel=1e-12
    )
    assert res.mode == "vector"  # the failing cases were split off and done one by one
    serial = sw.sweep(concave, {"R3": "5mm..60mm:12"}, {"v_peak": V_PEAK}, mode="serial")
    pd.testing.assert_frame_equal(t, serial.table, check_exact=True)
    # an input bound (positive = true) fails the case, not the sweep
    res = sw.sweep(concave, {"R3": "-5mm,50mm"}, {"v_peak": V_PEAK})
    assert "must be positive" in res.table["error"][0] and res.table["error"][1] is None


@pytest.mark.slow
def test_vector_blocks_split_around_failing_cases(concave, monkeypatch):
    grid = {"R3": "5mm..60mm:23", "R1": "15mm..25mm:5"}
    outs = {"v": V_PEAK, "k": "k"}
    serial = sw.sweep(concave, grid, outs, mode="serial").table
    assert 0 < serial["error"].notna().sum() < len(serial)
    for points in (1_000_000, 2000, 209):  # one block; several; one case per block
        monkeypatch.setattr(sw.vector, "VECTOR_POINTS", points)
        res = sw.sweep(concave, grid, outs)
        assert res.mode == "vector"
        pd.testing.assert_frame_equal(res.table, serial, check_exact=True)


def test_a_table_aggregate_is_not_vectorised(sheet_from):
    sheet = sheet_from(SINE_TABLE)
    res = sw.sweep(sheet, {"R": "10mm,20mm"}, {"top": "max_over(t, y)"})
    assert res.mode == "serial"
    assert res.table["top [mm]"].tolist() == pytest.approx([10.0, 20.0], rel=1e-15)


def test_two_inputs_make_a_grid_and_one_series_per_value(tmp_path, concave):
    res = sw.sweep(concave, {"R2": "8mm,10mm", "R3": "40mm..60mm:5"}, {"v_peak": V_PEAK})
    t = res.table
    assert len(t) == 10 and t["R2 [mm]"].tolist() == [8.0] * 5 + [10.0] * 5
    direct = concave.with_inputs(R2="8 mm", R3="45 mm")
    phi = np.arange(0, 104.01, 0.5)
    assert t["v_peak [m/s]"][1] == pytest.approx(
        direct.evaluate("v", phi=phi).to("m/s").magnitude.max(), rel=1e-12
    )
    out = sw.write(res, tmp_path / "grid.xlsx")
    chart = zipfile.ZipFile(out).read("xl/charts/chart1.xml").decode()
    assert chart.count("<c:ser>") == 2 and "R2 = 8" in chart


def test_template_outputs_and_the_reduction_forms(tmp_path):
    path = write_template(
        tmp_path,
        """
[inputs]
R = "10 mm"
omega = "100 1/s"

[arguments]
t = { unit = "s" }

[definitions]
"x(t)" = { expr = "R*cos(omega*t)", unit = "mm" }

[sweep.outputs]
x_max = "max of x(t) over t := 0, 0.001 .. 0.0628"
t_min = "argmin of x(t) over t := 0, 0.001 .. 0.0628"
x_mean = { expr = "mean of x(t) over t := 0, 0.001 .. 0.0628", unit = "cm" }
twoR = "2*R"

[sweep]
units = { twoR = "cm" }
""",
    )
    res = sw.sweep(workbook.load(path), {"R": "10mm,20mm"})
    t = res.table
    assert list(t.columns) == [
        "R [mm]",
        "x_max [mm]",
        "t_min [s]",
        "x_mean [cm]",
        "twoR [cm]",
        "error",
    ]
    assert t["x_max [mm]"].tolist() == [10.0, 20.0]
    assert t["t_min [s]"][0] == pytest.approx(0.031, abs=1e-12)  # pi/omega = 0.0314 on a 1 ms grid
    tt = np.linspace(0, 0.062, 63)
    tt = np.append(tt, 0.0628)
    assert t["x_mean [cm]"][1] == pytest.approx(np.mean(2.0 * np.cos(100 * tt)), rel=1e-12)
    assert t["twoR [cm]"].tolist() == [2.0, 4.0]


@pytest.mark.slow
@pytest.mark.parametrize(
    "output, message",
    [
        ("v_peak=max of w(phi) over phi := 0 .. 104", "unknown function 'w'"),
        ("v_peak[kg]=max of v(phi) over phi := 0 .. 104", "cannot show"),
        ("v_peak=max of v(phi) over psi := 0 .. 104", "not declared in [arguments]"),
        ("v_peak=max of v(phi) 0 .. 104", "write a reduction as"),
        ("v peak=h(22)", "cannot read the name"),
    ],
)
def test_bad_outputs_are_one_error_and_write_nothing(tmp_path, capsys, output, message):
    out = tmp_path / "s.xlsx"
    out.write_bytes(b"old")
    code = main(
        [
            "sweep",
            "concave-cam",
            "--vary",
            "R3=40mm..60mm:3",
            "--output",
            output,
            "--out",
            str(out),
            "--force",
        ]
    )
    assert code == 2
    assert message in capsys.readouterr().err
    assert out.read_bytes() == b"old"


@pytest.mark.slow
def test_bad_vary_is_refused(capsys):
    for vary, message in [
        ("R3=40kg..60kg:3", "[mass]"),
        ("R9=40mm..60mm:3", "not an input"),
        ("R3=40mm..60mm", "cannot read"),
    ]:
        code = main(
            [
                "sweep",
                "concave-cam",
                "--vary",
                vary,
                "--output",
                "h22=h(22)",
                "--out",
                "/tmp/never.csv",
            ]
        )
        assert code == 2
        assert message in capsys.readouterr().err, vary


@pytest.mark.slow
def test_command_line_writes_a_table_and_a_chart(tmp_path, capsys):
    out = tmp_path / "r3.xlsx"
    code = main(
        [
            "sweep",
            "concave-cam",
            "--vary",
            f"R3={R3_GRID}",
            "--output",
            f"v_peak={V_PEAK}",
            "--out",
            str(out),
        ]
    )
    assert code == 0
    assert "21 cases, 1 outputs, vector" in capsys.readouterr().out
    import openpyxl

    wb = openpyxl.load_workbook(out)
    assert wb.sheetnames == ["Sweep", "Charts", "About"]
    ws = wb["Sweep"]
    assert [c.value for c in ws[1]] == ["R3 [mm]", "v_peak [m/s]", "error"]
    assert ws["B12"].value == pytest.approx(paper_v1(22.0, 50.0), rel=1e-12)
    assert "xl/charts/chart1.xml" in zipfile.ZipFile(out).namelist()


def test_progress_is_shown_for_long_sweeps():
    stream = io.StringIO()
    p = sw.Progress(3, stream=stream, every=0.0)
    for ok in (True, False, True):
        p(ok)
    text = stream.getvalue()
    assert "sweep: 3/3 cases (1 failed)" in text


# -- the solver path: the coupling's steady phi2 over the spring stiffness c1 -------------------
def coupling_reference(c1, w=80.0):
    """phi2 from F(phi) = 0 (the template's note), solved here: first + to - sign change."""
    from scipy.optimize import brentq

    m, phi20, lam, O1O, OC, OC1, OB, O1B, tg, M = (
        0.7,
        0.5236,
        1e-3,
        0.042,
        0.036,
        0.052,
        0.015,
        0.040,
        1 / 3,
        1.2,
    )
    G = M * OB / O1B * tg

    def F(phi):
        return (
            2 * m * w**2 * (O1O - OC * np.cos(phi)) * OC * np.sin(phi)
            - 8 * c1 * (lam + OC1 * (np.cos(phi20) - np.cos(phi))) * OC1 * np.sin(phi)
            - G
        )

    if F(phi20) <= 0:
        return 0.0
    grid = np.linspace(phi20, math.pi, 20001)
    f = F(grid)
    i = np.flatnonzero((f[:-1] > 0) & (f[1:] <= 0))[0]
    return brentq(F, grid[i], grid[i + 1], xtol=1e-15) - phi20


@pytest.fixture(scope="module")
def coupling():
    if not HAS_COUPLING:
        pytest.skip("templates/advance-coupling.toml is not there")
    return workbook.load("advance-coupling")


@pytest.mark.slow
def test_steady_phi2_over_c1_serial_and_processes(coupling):
    outs = {"phi2_steady": PHI2}
    serial = sw.sweep(coupling, {"c1": C1_GRID}, outs, mode="serial")
    pool = sw.sweep(coupling, {"c1": C1_GRID}, outs, mode="processes", workers=2)
    auto = sw.sweep(coupling, {"c1": C1_GRID}, outs)
    assert pool.mode == "processes"
    # phi2 is the template's root(): vectorised over the cases, no solver block to wait for
    assert auto.mode == "vector" and not sw.vector_blockers(coupling, auto.outputs, auto.varies)
    pd.testing.assert_frame_equal(serial.table, pool.table, check_exact=True)
    pd.testing.assert_frame_equal(serial.table, auto.table, check_exact=False, rtol=1e-12, atol=0)
    t = serial.table
    assert serial.failed == 0 and list(t.columns) == ["c1 [N/m]", "phi2_steady [rad]", "error"]
    ref = [coupling_reference(c) for c in t["c1 [N/m]"]]
    assert t["phi2_steady [rad]"].to_numpy() == pytest.approx(ref, abs=1e-10)
    assert np.all(np.diff(t["phi2_steady [rad]"]) < 0)  # stiffer springs, smaller angle


# -- Dask: the same sweeps on a LocalCluster started here ------------------------------------
@pytest.fixture(scope="module")
def cluster():
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as c:
        yield c


def _csv(tmp_path: Path, name: str, result) -> str:
    return sw.write(result, tmp_path / f"{name}.csv").read_text(encoding="utf-8")


def _cli_csv(tmp_path: Path, name: str, args: list[str]) -> str:
    out = tmp_path / f"{name}.csv"
    assert main(["sweep", *args, "--out", str(out)]) == 0
    return out.read_text(encoding="utf-8")


@pytest.mark.slow
def test_local_and_local_cluster_give_identical_tables(tmp_path, cluster, concave, coupling):
    """The done criterion: both sweeps locally and through a LocalCluster, identical tables
    (the local runs through the API, the cluster runs through the command line)."""
    address = cluster.scheduler_address
    local = _csv(tmp_path, "cam-local", sw.sweep(concave, {"R3": R3_GRID}, {"v_peak": V_PEAK}))
    cam = ["concave-cam", "--vary", f"R3={R3_GRID}", "--output", f"v_peak={V_PEAK}"]
    assert _cli_csv(tmp_path, "cam-dask", [*cam, "--scheduler", address]) == local
    assert len(local.splitlines()) == 22
    pool = sw.sweep(coupling, {"c1": C1_GRID}, {"phi2_steady": PHI2}, mode="processes")
    local = _csv(tmp_path, "c1-local", pool)
    cpl = ["advance-coupling", "--vary", f"c1={C1_GRID}", "--output", f"phi2_steady={PHI2}"]
    assert _cli_csv(tmp_path, "c1-dask", [*cpl, "--scheduler", address]) == local
    assert len(local.splitlines()) == 11 and pool.failed == 0


def test_an_unreachable_scheduler_is_a_clear_error(concave):
    pytest.importorskip("dask.distributed")
    with pytest.raises(workbook.WorkbookError, match="cannot reach the Dask scheduler"):
        sw.sweep(
            concave,
            {"R3": "40mm,50mm"},
            {"h22": "h(22)"},
            scheduler="tcp://127.0.0.1:9",
            connect_timeout=1.0,
        )


# -- numerical built-ins over a swept input: the interval and mpmath forms see each case ---------
FEATURES = """
[inputs]
a = "1"

[arguments]
x = { unit = "" }

[definitions]
"f(x)" = "exp(-((x - a)/0.01)^2)"
b = "2*a"
r = "root(x^2 - b, x, 0, 10)"
m = "maximum(f(x) + 0.5*exp(-((x - 5)/0.5)^2), x, 0, 10)"
w = "argmax(2*f(x) + exp(-((x - 5)/0.5)^2), x, 0, 10)"
q = "integral(f(x), x, 0, 10)"
"""


def test_numerical_builtins_over_a_swept_input_agree_with_serial(sheet_from):
    """A narrow peak centred at the swept input: the vectorised sweep's interval enclosures,
    feature search and mpmath check read each case's value of a (they read the sheet's a = 1:
    the maximum at a = 7.3 was 0.5, its argmax 5, and every integral 0, silently)."""
    sheet = sheet_from(FEATURES)
    cases = {"a": [1.0, 2.5, 7.3, 9.0]}
    outs = {k: k for k in "rmwq"}
    vector = sw.sweep(sheet, cases, outs, mode="vector")
    serial = sw.sweep(sheet, cases, outs, mode="serial")
    assert vector.mode == "vector" and vector.failed == 0
    pd.testing.assert_frame_equal(vector.table, serial.table, check_exact=False, rtol=1e-9)
    t = vector.table
    a = t["a"].to_numpy()
    assert t["r"].to_numpy() == pytest.approx(np.sqrt(2 * a), rel=1e-9)
    assert t["m"].to_numpy() == pytest.approx(np.ones(4), rel=1e-9)
    assert t["w"].to_numpy() == pytest.approx(a, abs=1e-6)
    assert t["q"].to_numpy() == pytest.approx(np.full(4, 0.01 * math.sqrt(math.pi)), rel=1e-9)


def _vectorisable_outputs(sheet, name: str) -> dict:
    """The scalar definitions that depend on input ``name``, are numbers and that a
    vectorised sweep of it computes."""
    from workbook.errors import WorkbookError
    from workbook.language import expr as ex
    from workbook.language.uses import dependencies
    from workbook.sweep.grid import as_varies
    from workbook.sweep.outputs import as_outputs, type_output
    from workbook.sweep.vector import vector_blockers

    spec, keep = sheet.spec, {}
    varies = as_varies(sheet, {name: [str(sheet.values[name])]})
    for n, d in spec.definitions.items():
        if d.is_function or name not in dependencies(spec, ex.Name(n)):
            continue
        out = as_outputs(sheet, {n: n})
        try:
            type_output(sheet, out[0])
        except WorkbookError:  # a text or a condition
            continue
        if not vector_blockers(sheet, out, varies):
            keep[n] = n
    return keep


@pytest.mark.slow
@pytest.mark.parametrize("template", workbook.list_templates())
def test_vector_sweeps_of_every_input_agree_with_serial(template):
    """Every template, every number input at 0.97, 1 and 1.03 times its value: the vectorised
    sweep of every output it reaches equals the serial sweep (fresh sheets, one per case)."""
    sheet = workbook.load(template)
    compared = 0
    for name, spec in sheet.spec.inputs.items():
        if spec.options:
            continue
        outs = _vectorisable_outputs(sheet, name)
        if not outs:
            continue
        q = sheet.values[name]
        values = [f"{float(q.magnitude) * k!r} {q.units:~}" for k in (0.97, 1.0, 1.03)]
        vector = sw.sweep(sheet, {name: values}, outs, mode="vector")
        serial = sw.sweep(sheet, {name: values}, outs, mode="serial")
        assert vector.mode == "vector"
        assert list(vector.table["error"]) == list(serial.table["error"]), name
        pd.testing.assert_frame_equal(
            vector.table, serial.table, check_exact=False, rtol=1e-9, atol=1e-12
        )
        compared += len(outs)
    assert compared > 0
