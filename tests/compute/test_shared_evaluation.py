"""Definitions computed once per evaluation: nested calls, and sub-expressions shared by
the columns of a table (workbook.language.subtrees, workbook.engine.numeric)."""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import pytest

from workbook.compute.excel import ExcelPrinter
from workbook.facade import Sheet
from workbook.numerics.registry import REGISTRY
from workbook.sweep import sweep

LEVELS = 40
# Without sharing, f40 is 2^40 calls of f0: a run that never ends. The bound below only turns
# such a hang into a failure; it is far above the time taken (timings are in benchmarks/).
HANG_SECONDS = 60.0


def _deep(sheet_from, levels: int = LEVELS) -> Sheet:
    """f_i(x) = (f_{i-1}(x) + f_{i-1}(x))/2: inlined, 2^levels calls of f0."""
    lines = [
        "[sheet]",
        'name = "deep"',
        "[inputs]",
        'a = "2 mm"',
        "[arguments]",
        'x = { unit = "mm" }',
        "[definitions]",
        '"f0(x)" = "x + a"',
    ]
    lines += [f'"f{i}(x)" = "(f{i - 1}(x) + f{i - 1}(x))/2"' for i in range(1, levels + 1)]
    lines += [
        f'top = "f{levels}(a)"',
        "[[tables]]",
        'name = "t"',
        'range = "x := 0, 1 .. 4"',
        f'columns = {{ f{levels} = "mm", f3 = "mm" }}',
    ]
    return sheet_from("\n".join(lines) + "\n", name="deep")


def _timed(fn):
    start = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - start


def test_nested_calls_are_computed_once(sheet_from):
    sheet = _deep(sheet_from)
    x = np.linspace(0.0, 10.0, 1001)
    got, seconds = _timed(lambda: sheet.evaluate(f"f{LEVELS}", x))
    assert np.array_equal(got.to("mm").magnitude, x + 2.0)  # (y + y)/2 is exact
    assert seconds < HANG_SECONDS
    assert sheet.evaluate("top").to("mm").magnitude == 4.0


def test_nested_calls_in_the_workbook_and_a_sweep(sheet_from, tmp_path):
    sheet = _deep(sheet_from)
    _, seconds = _timed(lambda: sheet.write_xlsx(tmp_path / "deep.xlsx"))
    assert seconds < HANG_SECONDS
    import openpyxl

    ws = openpyxl.load_workbook(tmp_path / "deep.xlsx")["Listing"]
    deep, shallow = ws["B2"], ws["C3"]
    assert "longer than Excel's limit" in deep.comment.text  # numbers, said so
    assert [ws.cell(r, 2).value for r in range(3, 8)] == [2, 3, 4, 5, 6]
    assert str(shallow.value).startswith("=")  # f3 stays a live formula
    for mode in ("vector", "serial"):
        result, seconds = _timed(
            lambda mode=mode: sweep(sheet, {"a": "1 mm..3 mm:21"}, {"top": "top"}, mode=mode)
        )
        assert seconds < HANG_SECONDS, mode
        assert result.table["top [mm]"].tolist() == pytest.approx(np.linspace(2, 6, 21))


def test_a_shallow_formula_against_the_formulas_package(sheet_from):
    formulas = pytest.importorskip("formulas")
    sheet = _deep(sheet_from)
    text = ExcelPrinter(sheet.typer, {"a": "2"}).formula(
        sheet.typer.function("f3").body, {"x": "7"}
    )
    assert float(formulas.Parser().ast(text)[1].compile()()) == 9.0


SHARED = """
[sheet]
name = "shared"

[inputs]
R = "3 mm"
p30 = "30 deg"
p60 = "60 deg"

[arguments]
x = { unit = "rad" }
y = { unit = "rad" }
phi = { unit = "deg" }

[definitions]
"f(x, y)" = "R*sin(x) + 2*R*cos(y)"
"g(y, x)" = "R*sin(x) + 2*R*cos(y)"
"h(phi)" = { pieces = ["R*sin(phi)^2 if phi <= p30", "R*cos(phi) if phi <= p60", "R otherwise"] }
"v(phi)" = { pieces = ["R*sin(phi) if phi <= p30", "-R*cos(phi) if phi <= p60", "2*R otherwise"] }
"w(phi)" = { pieces = ["R*sin(phi)^2 if phi < p30", "R otherwise"] }

[[tables]]
name = "t"
range = "phi := 0, 5 .. 90"
columns = { h = "mm", v = "mm", w = "mm" }
"""


@pytest.fixture
def shared(sheet_from) -> Sheet:
    return sheet_from(SHARED, name="shared")


def test_sharing_keeps_arguments_apart(shared):
    """The same sub-expression of other arguments (f(a, b) and g(b, a)) is not reused."""
    a, b = np.linspace(0, 1, 7), np.linspace(2, 3, 7)
    f, g = shared.evaluate(["f", "g"], x=a, y=b)
    assert f.to("mm").magnitude == pytest.approx(3 * np.sin(a) + 6 * np.cos(b), rel=1e-15)
    assert g.to("mm").magnitude == pytest.approx(3 * np.sin(a) + 6 * np.cos(b), rel=1e-15)
    f2, g2 = shared.evaluate(["f", "g"], a, b)  # positional: f(x=a, y=b), g(y=a, x=b)
    assert g2.to("mm").magnitude == pytest.approx(3 * np.sin(b) + 6 * np.cos(a), rel=1e-15)
    assert f2.to("mm").magnitude == pytest.approx(f.to("mm").magnitude, rel=0)


def test_pieces_shared_by_columns_give_the_values_of_each_alone(shared):
    phi = np.linspace(0.0, 90.0, 91)
    together = shared.evaluate(["h", "v", "w"], phi=phi)
    alone = [shared.evaluate(n, phi=phi) for n in ("h", "v", "w")]
    for t, a in zip(together, alone):
        assert np.array_equal(t.magnitude, a.magnitude)
    r = np.radians(phi)
    expect_h = np.where(phi <= 30, 3 * np.sin(r) ** 2, np.where(phi <= 60, 3 * np.cos(r), 3))
    assert together[0].to("mm").magnitude == pytest.approx(expect_h, rel=1e-15)
    table = shared.table_data("t")
    at = table.columns[0].values
    for col, name in zip(table.columns[1:], ("h", "v", "w")):
        assert np.array_equal(col.values, shared.evaluate(name, phi=at).to("mm").magnitude)


def test_an_evaluation_computes_a_shared_subtree_once(shared, monkeypatch):
    """Counted: sin(phi) is computed once for h, v and w at the same angles."""
    calls = []
    real = np.sin

    def counting(x, *args, **kwargs):
        calls.append(np.size(x))
        return real(x, *args, **kwargs)

    monkeypatch.setitem(REGISTRY, "sin", dataclasses.replace(REGISTRY["sin"], numpy=counting))
    fresh = Sheet(shared.full_spec)  # compiled with the counting sin
    phi = np.linspace(0.0, 25.0, 6)  # the first piece everywhere
    fresh.evaluate(["h", "v", "w"], phi=phi)
    assert len(calls) == 2  # h and v share their pieces; w's conditions differ
    calls.clear()
    for n in ("h", "v", "w"):
        fresh.evaluate(n, phi=phi)
    assert len(calls) == 3
