"""Random worksheets that mix prefixed units, ratios of them, percentages (alone and beside
units of a dimension), degrees, temperatures, text results of an inline condition, tables and
scalars: each written, its every formula cell recalculated from the inputs by the check's own
reader of Excel formulas (default test, few examples) and by LibreOffice (slow), and compared
with the engine to 1e-9 relative."""

from __future__ import annotations

import os

import pytest
from helpers.recalc import recalculate, soffice
from helpers.recalculated import differences, mismatches, xleval_recalculated
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

POWERS = ["W", "kW", "MW", "mW"]
LENGTHS = ["mm", "cm", "m", "km", "um"]
STRESSES = ["Pa", "kPa", "MPa", "GPa"]

# scalars over the names of every sheet (r, s, q: ratios of prefixed units; p a percentage;
# ang in degrees; rr a ratio declared "")
SCALARS = [
    "2*r",
    "r + s",
    "s + 1",
    "r*s",
    "r/s",
    "sqrt(q)*r",
    "r*p",
    "sin(ang)*r + cos(ang)*s",
    "s^2 - r",
    "(r - s)*(r + s)",
    "max(r, s)",
    "abs(r - 2*s)",
    "q/(1 + r)",
]
DECLARED = ["", "%", None]
# a percentage beside units of a dimension: its unit is the number it stands for (kW/% is kW)
WITH_PERCENT = ["P1/p", "P1*p", "L1*p/S1", "p*p*L1", "P1/(p*L1)", "S1*(100 % - p)"]


@st.composite
def sheets(draw):
    def value(lo=0.5, hi=5.0) -> str:
        return f"{draw(st.floats(lo, hi)):.3f}"

    powers, lengths = draw(st.permutations(POWERS)), draw(st.permutations(LENGTHS))
    stresses = draw(st.permutations(STRESSES))
    picks = draw(st.lists(st.sampled_from(SCALARS), min_size=3, max_size=6, unique=True))
    defs = []
    for i, expr in enumerate(picks):
        unit = draw(st.sampled_from(DECLARED))
        defs.append(
            f'y{i} = "{expr}"' if unit is None else f'y{i} = {{ expr = "{expr}", unit = "{unit}" }}'
        )
    threshold = value(0.1, 3.0)
    with_percent = draw(st.sampled_from(WITH_PERCENT))
    column = draw(st.sampled_from(["x*r", "x*s + r", "x*y0", "(x + s)*p", "x*P1/P2"]))
    return f"""
[inputs]
P1 = "{value()} {powers[0]}"
P2 = "{value()} {powers[1]}"
L1 = "{value()} {lengths[0]}"
L2 = "{value()} {lengths[1]}"
S1 = "{value()} {stresses[0]}"
S2 = "{value()} {stresses[1]}"
p = "{value(1, 99)} %"
ang = "{value(1, 89)} deg"
T1 = "{value(-20, 80)} degC"
dT = "{value(1, 30)} delta_degC"

[arguments]
x = {{ unit = "" }}

[definitions]
r = "P1/P2"
s = "L1/L2"
q = "S1/S2"
rr = {{ expr = "P1/P2", unit = "" }}
T2 = {{ expr = "T1 + dT*rr", unit = "degC" }}
T3 = {{ expr = "T2", unit = "K" }}
verdict = "\\"high\\" if r > {threshold} otherwise \\"low\\""
{chr(10).join(defs)}
w = "{with_percent}"
"f(x)" = "{column}"
"g(x)" = "x*s"
top = "max_over(T, f)"
top2 = "top*2 + r"

[[tables]]
name = "T"
range = "x := 0, 0.25 .. 1"
columns = ["x", "f", "g"]
"""


def _written(sheet_from, tmp_path, text: str):
    sheet = sheet_from(text, name="random")
    refusals: list = []
    out = sheet.write_xlsx(tmp_path / "random.xlsx", force=True, refusals=refusals)
    return out, refusals


@settings(
    max_examples=2,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(text=sheets())
def test_random_sheets_recalculate_to_the_engine(sheet_from, tmp_path, text):
    out, refusals = _written(sheet_from, tmp_path, text)
    assert refusals == [], f"{text}\n{[r.where + ': ' + r.disagreement for r in refusals]}"
    bad = mismatches(out, xleval_recalculated(out))  # a chain from the inputs
    assert not bad, f"{text}\n{bad[:5]}"


@pytest.mark.slow
@pytest.mark.skipif(soffice() is None and not os.environ.get("CI"), reason="no LibreOffice")
@settings(
    max_examples=6,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(text=sheets())
def test_random_sheets_recalculate_in_libreoffice(sheet_from, tmp_path, text):
    out, refusals = _written(sheet_from, tmp_path, text)
    assert refusals == [], f"{text}\n{[r.where + ': ' + r.disagreement for r in refusals]}"
    bad = differences(out, recalculate(out, tmp_path / "lo"))
    assert not bad, f"{text}\n{bad[:5]}"
