"""Written workbooks recalculated by LibreOffice: no formula cell differs from the engine.

Every template and every worksheet under tests/data, and worksheets that hypothesis composes
of the numerical built-ins (integrals of integrals, roots of integrals, integrals of roots,
sums and extrema of them, functions of vectors). Slow: each starts LibreOffice."""

import os
from pathlib import Path

import pytest
from helpers.paths import DATA
from helpers.recalc import recalculate, soffice
from helpers.recalculated import differences
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import workbook

if soffice() is None and os.environ.get("CI"):
    raise RuntimeError("CI must run the LibreOffice recalculation tests: install libreoffice-calc")
pytestmark = [
    pytest.mark.skipif(soffice() is None, reason="LibreOffice is not installed"),
    pytest.mark.slow,
]

RELATIVE = 1e-9


SHEETS = [*workbook.list_templates(), *sorted(str(p) for p in DATA.glob("*.toml"))]


@pytest.mark.parametrize("name", SHEETS, ids=[Path(n).stem for n in SHEETS])
def test_every_sheet_recalculates_to_the_engine(tmp_path, name):
    sheet = workbook.load(name)
    out = sheet.write_xlsx(tmp_path / "sheet.xlsx")
    bad = differences(out, recalculate(out, tmp_path / "lo"))
    assert not bad, f"{len(bad)} formula cells differ, e.g. {bad[:5]}"


# -- worksheets composed of the numerical built-ins -------------------------------------------
LEAVES = ["y^2", "sin(y)", "exp(y/2)", "1/(1 + y^2)", "y*cos(y)"]


def _compose(draw, depth: int) -> str:
    """A function of y (text): a leaf, or a built-in over a composition one level down (its
    bound variables s1, u1, i1 at depth 1, s2, u2, i2 at depth 2: no capture)."""
    leaf = draw(st.sampled_from(LEAVES))
    if depth == 0:
        return leaf
    g = f"({_compose(draw, depth - 1)})"  # a function of y
    s, u, i = f"s{depth}", f"u{depth}", f"i{depth}"
    kind = draw(st.sampled_from(["integral", "nested", "root", "sum", "maximum", "vector"]))
    if kind == "integral":  # an integral up to y
        return f"integral({g.replace('y', s)}, {s}, 0, y)"
    if kind == "nested":  # an integral of an integral up to the outer variable
        return f"integral(integral({g.replace('y', u)}, {u}, 0, {s}), {s}, 0, y)"
    if kind == "root":  # u^3 + u = value: one root in [-100, 100] for |value| < 1e6
        return f"root({u}^3 + {u} - {g}, {u}, -100, 100)"
    if kind == "sum":
        return f"sum({g.replace('y', f'(y*{i}/4)')}, {i}, 1, 4)"
    if kind == "maximum":
        return f"maximum({g.replace('y', s)}*(1 + y - {s}), {s}, 0, 1)"
    return f"dot(v, v)*{g}"


@st.composite
def sheets(draw):
    exprs = [_compose(draw, draw(st.integers(1, 2))) for _ in range(4)]
    defs = "\n".join(
        f'"f{k}(y)" = "{e}"\nI{k} = "integral(f{k}(y), y, 0, 1)"\nR{k} = "f{k}(0.7)"'
        for k, e in enumerate(exprs)
    )
    columns = ", ".join(f'f{k} = ""' for k in range(len(exprs)))
    return f"""
[inputs]
a = "1.5"

[arguments]
y = {{ unit = "" }}
s1 = {{ unit = "" }}
u1 = {{ unit = "" }}
i1 = {{ unit = "" }}
s2 = {{ unit = "" }}
u2 = {{ unit = "" }}
i2 = {{ unit = "" }}

[definitions]
v = "[1, 2, a]"
{defs}

[[tables]]
name = "t"
range = "y := 0, 0.25 .. 1"
columns = {{ {columns} }}
"""


@settings(
    max_examples=4,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(text=sheets())
def test_composed_built_ins_recalculate_to_the_engine(sheet_from, tmp_path, text):
    sheet = sheet_from(text, name="composed")
    out = sheet.write_xlsx(tmp_path / "composed.xlsx", force=True)
    bad = differences(out, recalculate(out, tmp_path / "lo"))
    assert not bad, f"{text}\n{len(bad)} formula cells differ, e.g. {bad[:5]}"
