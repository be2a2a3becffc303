"""vary on a table: its columns at each value of one input (a family of curves)."""

from __future__ import annotations

import math

import numpy as np
import openpyxl
import pytest

import workbook
from workbook.cli import main

SPRING = """
[inputs]
k = { value = "2000 N/m", min = "1 N/m" }
m = "0.5 kg"
x0 = "10 mm"

[arguments]
t = { unit = "s" }

[definitions]
"x(t)" = { expr = "x0*cos(sqrt(k/m)*t)", unit = "mm" }

[[tables]]
name = "family"
sheet = "Family"
range = "t := 0, 0.01 .. 0.1"
vary = { k = ["1000 N/m", "4 kN/m"] }
columns = [{ expr = "x", unit = "mm" }, { expr = "x(t)/x0", unit = "", title = "ratio" }]

[[charts]]
name = "curves"
series = [{ table = "family", x = "t [s]", y = "x k=4 kN/m [mm]", name = "stiff" }]
"""


def spring(tmp_path, text: str = SPRING):
    path = tmp_path / "spring.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_each_column_at_each_value_against_numpy(tmp_path):
    df = workbook.load(spring(tmp_path)).table("family")
    t = np.arange(11) * 0.01
    assert list(df.columns) == [
        "t [s]",
        "x k=1000 N/m [mm]",
        "x k=4 kN/m [mm]",
        "ratio k=1000 N/m",
        "ratio k=4 kN/m",
    ]
    for k, text in ((1000.0, "1000 N/m"), (4000.0, "4 kN/m")):
        want = 10 * np.cos(math.sqrt(k / 0.5) * t)
        np.testing.assert_allclose(df[f"x k={text} [mm]"], want, rtol=1e-14, atol=1e-14)
        np.testing.assert_allclose(df[f"ratio k={text}"], want / 10, rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(df["t [s]"], t, rtol=1e-15)


@pytest.mark.slow
def test_the_workbook_holds_the_family_as_numbers_with_a_comment_and_a_chart(tmp_path):
    out = tmp_path / "spring.xlsx"
    assert main(["run", str(spring(tmp_path)), "--out", str(out)]) == 0
    ws = openpyxl.load_workbook(out)["Family"]
    header = [c.value for c in ws[2]]
    assert header[:3] == ["t [s]", "x k=1000 N/m [mm]", "x k=4 kN/m [mm]"]
    assert "k (1000 N/m, 4 kN/m)" in ws.cell(2, 1).comment.text
    assert ws.cell(3, 2).value == pytest.approx(10.0)
    assert not str(ws.cell(4, 2).value).startswith("=")
    charts = openpyxl.load_workbook(out)["Charts"]._charts
    assert len(charts) == 1


@pytest.mark.slow
@pytest.mark.parametrize(
    ("vary", "message"),
    [
        ('{ kk = ["1 N/m"] }', "'kk' is not an input (did you mean k?)"),
        ('{ k = ["1 m"] }', "vary.k"),
        ('{ k = ["0.5 N/m"] }', "vary.k"),
        ("{ k = [] }", "must be a list of values"),
        ('{ k = ["1 N/m"], m = ["1 kg"] }', "vary takes one input"),
    ],
)
def test_a_wrong_vary_is_refused_at_load_naming_the_table(tmp_path, capsys, vary, message):
    text = SPRING.replace('vary = { k = ["1000 N/m", "4 kN/m"] }', f"vary = {vary}")
    path = spring(tmp_path, text)
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert message in err and str(path) in err and "table family" in err
