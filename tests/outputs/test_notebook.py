"""A Sheet in Jupyter: the report's rendering (inputs, formulas, tables, charts, checks),
and the tables as DataFrames."""

import pytest
from helpers.sheets import write_template

import workbook
from workbook.outputs import notebook


@pytest.mark.slow
def test_the_html_shows_inputs_definitions_and_tables(concave):
    text = concave._repr_html_()
    assert text == notebook.sheet_html(concave.computed())
    assert "1. Inputs</h2>" in text and "<tr data-name='R3'>" in text
    assert "radius of the concave flank" in text
    assert "2. Calculation</h2>" in text and "id='def-k'" in text
    assert "<mrow class='result' data-name='k'><mrow><mn>1.75</mn></mrow></mrow>" in text
    assert "id='def-h1'" in text and "<mfrac>" in text  # the functions, as formulas
    assert "Table flank_AB" in text and "105 rows" in text
    assert "Fig. 4. Lift and velocity of the follower</figcaption>" in text and "<svg" in text


def test_tables_are_dataframes_with_units_in_the_headers(concave):
    frames = notebook.tables(concave.computed())
    assert list(frames) == ["flank_AB", "nose_BB", "flank_BA", "curves"]
    df = frames["flank_AB"]
    assert list(df.columns) == ["phi [deg]", "h1 [mm]", "v1 [m/s]", "j1 [m/s^2]"]
    assert df["v1 [m/s]"].iloc[-1] == pytest.approx(3.152, abs=5e-4)  # the printed v1(22)
    inputs = notebook.inputs_frame(concave.with_inputs(R3="45 mm").computed())
    assert inputs.set_index("name").loc["R3", "value"] == 45.0
    assert inputs.set_index("name").loc["phi_n", "unit"] == "deg"


@pytest.mark.slow
def test_ipython_displays_it():
    formatters = pytest.importorskip("IPython.core.formatters")
    sheet = workbook.load("concave-cam")
    html = formatters.HTMLFormatter()(sheet)
    assert html and "1. Inputs</h2>" in html


def test_an_error_is_shown_not_raised(tmp_path):
    path = write_template(
        tmp_path,
        """
[sheet]
title = "a <b>bold</b> title"

[inputs]
x = { value = "-1", note = "choice <and> text" }
law = { value = "a", options = ["a", "b"] }

[arguments]
t = { unit = "" }

[definitions]
r = "sqrt(x)"
"f(t)" = "sqrt(t)"

[[tables]]
name = "bad"
range = "t := -2 .. 2"
columns = { f = "" }
""",
    )
    text = workbook.load(path)._repr_html_()
    assert "a &lt;b&gt;bold&lt;/b&gt; title" in text and "choice &lt;and&gt; text" in text
    assert "Table bad" in text and "not computed" in text and "not a finite number" in text
    assert "one of: a, b" in text
