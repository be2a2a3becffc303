"""``workbook new``: a starter worksheet that runs as it is, sweeps, and gives a chart."""

import zipfile

import openpyxl
import pytest

import workbook
from workbook.cli import main
from workbook.scaffold import starter


@pytest.mark.slow
def test_new_run_and_open_a_workbook_with_a_chart(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["new", "throw"]) == 0
    assert "workbook run ./throw.toml" in capsys.readouterr().out
    text = (tmp_path / "throw.toml").read_text(encoding="utf-8")
    assert text.count("\n#") >= 10  # commented
    assert main(["run", "./throw.toml"]) == 0
    out = tmp_path / "reports" / "throw.xlsx"
    wb = openpyxl.load_workbook(out, data_only=True)
    assert {"Inputs", "Definitions", "Listing", "Charts", "About"} <= set(wb.sheetnames)
    assert "xl/charts/chart1.xml" in zipfile.ZipFile(out).namelist()
    # the starter's numbers are those of the projectile formulas
    sheet = workbook.load(tmp_path / "throw.toml")
    import math

    v0, a, y0, g = 20.0, math.radians(40), 1.5, 9.81
    vy = v0 * math.sin(a)
    t_f = (vy + math.sqrt(vy**2 + 2 * g * y0)) / g
    assert sheet.evaluate("range_flat").to("m").magnitude == pytest.approx(
        v0 * math.cos(a) * t_f, rel=1e-12
    )
    assert sheet.evaluate("height", 10).to("m").magnitude == pytest.approx(
        y0 + math.tan(a) * 10 - g * 100 / (2 * (v0 * math.cos(a)) ** 2), rel=1e-12
    )
    assert sheet.with_inputs(ground="wall", wall="20 m").evaluate("reach").to("m").magnitude == 20
    assert sheet.check().ok


@pytest.mark.slow
def test_the_starter_sweeps(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["new", "throw"]) == 0
    assert main(["sweep", "./throw.toml", "--vary", "alpha=10deg..80deg:8", "--out", "s.csv"]) == 0
    import pandas as pd

    t = pd.read_csv(tmp_path / "s.csv")
    assert list(t.columns) == ["alpha [deg]", "reach [m]", "top [m]", "error"]
    assert t["error"].isna().all()
    # the highest point: y0 + (v0 sin alpha)^2 / (2 g), on a 0.01 s grid
    import math

    top = 1.5 + (20 * math.sin(math.radians(30))) ** 2 / (2 * 9.81)
    assert t.loc[t["alpha [deg]"] == 30, "top [m]"].item() == pytest.approx(top, abs=1e-3)


@pytest.mark.slow
def test_new_refuses_to_overwrite_and_bad_names(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["new", "a"]) == 0
    assert main(["new", "a"]) == 2
    assert "exists; use --force" in capsys.readouterr().err
    assert main(["new", "a", "--force"]) == 0
    assert main(["new", "../x"]) == 2
    assert main(["new", "b", "--out", "b.txt"]) == 2
    assert main(["new", "b", "--out", "nodir/b.toml"]) == 2


def test_the_starter_is_the_same_text_for_any_name():
    text = starter("my-sheet", "./my-sheet.toml")
    assert 'title = "My sheet"' in text and "workbook run ./my-sheet.toml" in text
