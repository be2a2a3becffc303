"""`workbook import` of Mathcad worksheets, checked against the results Mathcad stored."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from helpers.paths import SHARED

from workbook.cli import main

# Mathcad's own files are third-party: read from the shared folder beside the repository
DATA = SHARED / "mathcad"
pytestmark = pytest.mark.skipif(not DATA.is_dir(), reason=f"{DATA} is absent")


def _import(name: str, out: Path, capsys) -> tuple[Path, str]:
    assert main(["import", str(DATA / name), "--out", str(out)]) == 0
    line = capsys.readouterr().out
    return out / (Path(name).stem + ".toml"), line


def _check(path: Path, capsys) -> dict:
    main(["check", str(path), "--json"])
    return json.loads(capsys.readouterr().out)


@pytest.mark.slow
def test_wind_load_reproduces_every_stored_result(tmp_path, capsys):
    toml, line = _import("wind-load.xmcd", tmp_path, capsys)
    assert re.match(r"wrote .*wind-load.toml: \d+ definitions, 2 results", line)
    text = toml.read_text(encoding="utf-8")
    assert 'v_b = { value = "24 m / s"' in text  # subscript as _, Mathcad units as pint
    assert "rho = " in text  # Greek letters spelled out
    assert "# Vindlasten bliver beregnet" in text  # text regions as comments
    result = _check(toml, capsys)
    assert result["printed"] == 2
    assert result["reproduced"] == 2, result["failures"]


@pytest.mark.slow
def test_timber_beam_never_a_wrong_number(tmp_path, capsys):
    """Every stored result is reproduced or not computable; a not computable one belongs to
    a region the worksheet lists as not translated."""
    toml, _ = _import("timber-beam.xmcd", tmp_path, capsys)
    result = _check(toml, capsys)
    assert result["printed"] == 60
    assert result["failed"] == 0, result["failures"]
    assert result["reproduced"] + result["not_computable"] == 60
    text = toml.read_text(encoding="utf-8")
    untranslated = set(re.findall(r"^#   region (\S+):", text, re.M))
    csv = (tmp_path / "timber-beam.mathcad.csv").read_text(encoding="utf-8")
    for failure in result["failures"]:
        assert failure["error"]
        assert failure["name"] not in re.findall(r"^(\w+) = ", text, re.M)
    assert untranslated
    assert 'unit = "MPa"' in text  # a unit override becomes the display unit
    assert csv.count("\n") > 60


@pytest.mark.slow
def test_overwrite_needs_force(tmp_path, capsys):
    _import("wind-load.xmcd", tmp_path, capsys)
    assert main(["import", str(DATA / "wind-load.xmcd"), "--out", str(tmp_path)]) == 2
    assert "--force" in capsys.readouterr().err
    args = ["import", str(DATA / "wind-load.xmcd"), "--out", str(tmp_path), "--force"]
    assert main(args) == 0


@pytest.mark.slow
def test_reference_is_followed_relative_to_the_file(tmp_path, capsys):
    toml, _ = _import("frame/example.xmcd", tmp_path, capsys)
    text = toml.read_text(encoding="utf-8")
    assert "AddTrainInTable" in text  # a function of the referenced iSET_module.xmcd
    # S is a data table (a component): a matrix of the worksheet, never the unit S (siemens),
    # and L := max(S^T<1>) reads it (Mathcad's stored L is checked in the table's test)
    assert 'S = { expr = "[[0, 5, 10, 15, 20, 25, 30, 35, 40, 45, 50, 55, 60], ' in text
    assert 'L = { expr = "max(submatrix(transpose(S), 1, rows(transpose(S)), 1, 1))"' in text
    # the value WRITEPRN wrote is a definition of its own, its stored result compared
    assert 'written_1 = { expr = "[[0, 0]]"' in text
    assert 'WRITEPRN wrote this value to the file "last_EH.txt"' in text


@pytest.mark.slow
@pytest.mark.parametrize(
    "name, status",
    [
        # a solve block of sin(phi) = 2, which Mathcad could not solve either: a failing
        # value (exit 1), the workbook written
        ("circle-area-and-plots.xmcd", 1),
        ("wind-load.xmcd", 0),
        ("timber-beam.xmcd", 0),  # texts ("OK")
        ("lagrange-polynomial.xmcd", 0),  # vectors
    ],
)
def test_imported_worksheet_runs(name, status, tmp_path, capsys):
    toml, _ = _import(name, tmp_path, capsys)
    out = tmp_path / "out.xlsx"
    assert main(["run", str(toml), "--out", str(out)]) == status
    assert out.exists()


@pytest.mark.slow
@pytest.mark.parametrize("name", ["lagrange-polynomial.xmcd", "fermat-spiral.xmcd"])
def test_vectors_over_ranges_reproduce_every_stored_value(name, tmp_path, capsys):
    """t1[i] := ..., A[i, j] := f(i, j) over ranges, columns and a matrix Mathcad showed."""
    toml, _ = _import(name, tmp_path, capsys)
    result = _check(toml, capsys)
    assert result["failed"] == 0, result["failures"]
    assert result["reproduced"] == result["printed"], result["failures"]


@pytest.mark.slow
@pytest.mark.parametrize(
    "name",
    sorted(
        p.relative_to(DATA).as_posix()
        for p in (DATA.rglob("*.xmcd") if DATA.is_dir() else [])
        if p.name != "iSET_module.xmcd"  # a library that frame/example.xmcd references
    ),
)
def test_no_stored_result_is_reproduced_wrongly(name, tmp_path, capsys):
    """Every value Mathcad stored is reproduced or not computable (its region listed); a
    different number only where a solve block has several roots (flagged FAIL by check)."""
    toml, _ = _import(name, tmp_path, capsys)
    result = _check(toml, capsys)
    assert result["reproduced"] + result["not_computable"] + result["failed"] == result["printed"]
    # a solve block of several roots may reach another one than Mathcad's: flagged, and only
    # there (the values of solve blocks are in the .solve CSV files)
    from_solve = {
        line.split(",")[0]
        for csv in tmp_path.glob("*.mathcad.solve*.csv")
        for line in csv.read_text(encoding="utf-8").splitlines()
    }
    wrong = [f for f in result["failures"] if "error" not in f]
    assert all(f["name"] in from_solve for f in wrong), wrong


@pytest.mark.slow
def test_solve_blocks_reach_the_roots_mathcad_found(tmp_path, capsys):
    """parabola-ellipse: intersections by solve blocks with several roots, inequalities beside
    the equations, one equation in two unknowns; each root is the one Mathcad stored (within
    its TOL), from Mathcad's guesses and its solver (Levenberg-Marquardt, or the root nearest
    the guess where it used its conjugate-gradient solver)."""
    toml, _ = _import("parabola-ellipse.xmcd", tmp_path, capsys)
    text = toml.read_text(encoding="utf-8")
    assert 'method = "nearest"' in text and 'conditions = ["t_4 < 0.9"]' in text
    result = _check(toml, capsys)
    assert result["failed"] == 0, result["failures"]
    assert result["reproduced"] == result["printed"], result["failures"]


def _charts(xlsx: Path) -> list:
    import openpyxl

    book = openpyxl.load_workbook(xlsx)
    return [c for ws in book.worksheets for c in ws._charts]


@pytest.mark.slow
def test_plots_become_native_charts(tmp_path, capsys):
    """fermat-spiral: an X-Y plot of y(x) over the range x, two polar plots of r(phi) (x = r
    cos(phi), y = r sin(phi)), and one whose second trace uses a name Mathcad could not
    define (listed); `workbook run` draws each as a native chart."""
    toml, _ = _import("fermat-spiral.xmcd", tmp_path, capsys)
    text = toml.read_text(encoding="utf-8")
    charts = re.findall(r"^\[\[charts\]\]  # Mathcad's plot \(region (\d+)\)$", text, re.M)
    assert charts == ["10", "34", "37", "107"]
    assert '{ x = "x", y = "y(x)" }' in text
    assert '{ x = "r(phi) * cos(phi)", y = "r(phi) * sin(phi)" }' in text
    assert re.search(r"^#   region 107: a plot \(traces left out\): trace 2: uses x1", text, re.M)
    out = tmp_path / "out.xlsx"
    assert main(["run", str(toml), "--out", str(out)]) == 0
    assert len(_charts(out)) == 4


@pytest.mark.slow
def test_a_plot_item_that_is_not_gzip_or_too_large_is_listed(tmp_path, capsys):
    """A plot's binary item is untrusted: not gzip, or larger than the limit once unpacked
    (a bomb), is listed as not translated, never unpacked beyond the limit."""
    import base64
    import gzip

    from workbook.mathcad.plot import MAX_PLOT_BYTES

    src = (DATA / "fermat-spiral.xmcd").read_text(encoding="utf-8")
    bomb = base64.b64encode(gzip.compress(b"\0" * (MAX_PLOT_BYTES + 1))).decode()
    bad = re.sub(r'(<item item-id="5"[^>]*>)[^<]*', lambda m: m.group(1) + "bm90IGd6aXA=", src)
    bad = re.sub(r'(<item item-id="16"[^>]*>)[^<]*', lambda m: m.group(1) + bomb, bad)
    (tmp_path / "in").mkdir()
    path = tmp_path / "in" / "hostile.xmcd"
    path.write_text(bad, encoding="utf-8")
    assert main(["import", str(path), "--out", str(tmp_path)]) == 0
    text = (tmp_path / "hostile.toml").read_text(encoding="utf-8")
    assert "region 10: a plot: a plot whose binary item is not gzip" in text
    assert "a plot whose binary item is larger than" in text


@pytest.mark.slow
def test_plot_of_vectors_is_a_series_over_their_index(tmp_path, capsys):
    """points-and-lines: Y against X (two vectors of six points) is a series of markers over
    the index; a trace over a range variable beside it keeps its own range; a quick plot (a
    variable the worksheet does not define) is drawn over Mathcad's default -10 .. 10."""
    toml, _ = _import("points-and-lines.xmcd", tmp_path, capsys)
    text = toml.read_text(encoding="utf-8")
    chart = text[text.index('name = "plot_912"') :].split("\n\n")[0]
    assert 'range = "index := 0 .. 5"' in chart
    assert '{ x = "X[index]", y = "Y[index]", line = "none", marker = true }' in chart
    assert re.search(r'\{ x = "x_", y = "L34\(x_\)", range = "x_ := x3 \.\. x4" \}', chart)
    # a quick plot: t is not defined, Mathcad draws x1(t, ...) against y1(t, ...) from -10 to 10
    quick = text[text.index('name = "plot_919"') :].split("\n\n")[0]
    assert 'range = "t := -10, -9.9 .. 10"' in quick
    out = tmp_path / "out.xlsx"
    assert main(["run", str(toml), "--out", str(out)]) == 0
    assert len(_charts(out)) == text.count("[[charts]]")


@pytest.mark.slow
def test_a_trace_with_a_gap_is_drawn_with_the_others(tmp_path, capsys):
    """parabola-ellipse, region 406: f(x) = x^3 + 4 sqrt(x^3) over a quick plot's -10 .. 10
    has no value below 0: Mathcad leaves a gap, and so does the chart (its rows below 0 fail,
    the others are drawn) beside the tangent and the normal. The workbook is written; run
    exits 1 for the solve block xc, for which Mathcad showed no value either."""
    toml, _ = _import("parabola-ellipse.xmcd", tmp_path, capsys)
    text = toml.read_text(encoding="utf-8")
    assert "region 406: a plot" not in text  # no trace left out
    chart = text[text.index('name = "plot_406"') :].split("\n\n")[0]
    assert "trace 1)" in chart and "trace 2)" in chart and "trace 3)" in chart
    out = tmp_path / "out.xlsx"
    assert main(["run", str(toml), "--out", str(out)]) == 1
    assert "xc have no value" in capsys.readouterr().err
    assert len(_charts(out)) == text.count("[[charts]]")


@pytest.mark.slow
def test_frame_library_programs_reproduce_every_stored_value(tmp_path, capsys):
    """frame/example.xmcd with its library: the train table TT (a nested array: one printed
    value per number of it), x.e(TT, 1, 3), I.Н := Uk(1, 0)/2 and E.Н(1) (through r_EH, a
    while loop over Uk) as Mathcad stored them."""
    toml, _ = _import("frame/example.xmcd", tmp_path, capsys)
    result = _check(toml, capsys)
    assert result["failed"] == 0, result["failures"]
    assert (result["printed"], result["reproduced"]) == (48, 48), result["failures"]
    text = toml.read_text(encoding="utf-8")
    assert '"result_875_2_1(index)" = { expr = "TT_7[index][2][1]"' in text
    # found in the one typing pass: a trace the engine cannot draw (a vector where a number
    # is wanted) and a function it refuses, each listed with the engine's reason
    assert "#   region 39: a plot: trace 1: the engine cannot draw it: column" in text
    assert "#   region 432: A_(...) := ...: the engine refuses it: " in text
