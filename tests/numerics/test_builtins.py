"""The registry of built-in functions, and built-ins that bind a variable (sum)."""

from __future__ import annotations

import re

import mpmath
import numpy as np
import pytest
from helpers.docs import DOC, documented

from workbook import WorkbookError
from workbook.compute.excel import ExcelPrinter
from workbook.engine.analysis import typed_text
from workbook.engine.numeric import Evaluator
from workbook.functions.entry import Builtin, register
from workbook.language import typed as ty
from workbook.language.visitor import UnhandledNode
from workbook.numerics import symbolic
from workbook.numerics.registry import REGISTRY
from workbook.numerics.symbolic import SympyConverter

SHEET = """
[sheet]
name = "sums"

[inputs]
R = "2 mm"
n = "5"

[arguments]
x = { unit = "deg" }
s = { unit = "mm" }

[definitions]
"f(x)" = { expr = "sum(R*sin(I*x)/I, I, 1, 5)", unit = "mm" }
"g(x)" = { expr = "sum(R*sin(I*x)/I, I, 1, n)", unit = "mm" }
total = "sum(I^2, I, -2, 4)"
empty = "sum(I, I, 3, 2)"
"""


def _fourier(x_deg: float, terms: int) -> float:
    """2 mm * sum sin(k x)/k, by mpmath."""
    x = mpmath.radians(x_deg)
    return float(mpmath.nsum(lambda k: 2 * mpmath.sin(k * x) / k, [1, terms]))


def test_every_entry_is_complete():
    for name, b in REGISTRY.items():
        assert b.name == name
        assert callable(b.unit_rule) and callable(b.numpy)
        assert callable(b.excel) and callable(b.sympy)
        assert b.doc


def test_the_reference_lists_every_builtin():
    assert sorted(documented(DOC.read_text(encoding="utf-8"))) == sorted(REGISTRY)


def test_a_name_is_registered_once():
    with pytest.raises(ValueError, match="registered twice"):
        register(REGISTRY["sin"])


def test_sum_against_mpmath(sheet_from):
    sheet = sheet_from(SHEET)
    x = np.array([0.0, 10.0, 33.0, 90.0, 200.0])
    got = sheet.evaluate("f", x).to("mm").magnitude
    assert got == pytest.approx([_fourier(v, 5) for v in x], rel=1e-14, abs=1e-15)
    # bounds from an input, and with n changed
    assert sheet.evaluate("g", x).to("mm").magnitude == pytest.approx(got, rel=1e-15)
    more = sheet.with_inputs(n=8).evaluate("g", 33.0).to("mm").magnitude
    assert more == pytest.approx(_fourier(33.0, 8), rel=1e-14)
    assert sheet.evaluate("total").magnitude == sum(i * i for i in range(-2, 5))
    assert sheet.evaluate("empty").magnitude == 0


@pytest.mark.slow
def test_sum_excel_formula_against_the_formulas_package(sheet_from):
    formulas = pytest.importorskip("formulas")
    sheet = sheet_from(SHEET)
    printer = ExcelPrinter(sheet.typer, {"R": "2", "n": "5"})
    text = printer.formula(sheet.typer.function("f").body, {"x": "33"})
    value = formulas.Parser().ast(text)[1].compile()()
    assert float(value) == pytest.approx(_fourier(33.0, 5), rel=1e-13)
    total = printer.formula(sheet.typer.scalar("total"), {})
    assert float(formulas.Parser().ast(total)[1].compile()()) == 35.0
    # bounds that follow an input: guarded terms up to MAX_LIVE_TERMS, #N/A past them
    live = printer.formula(sheet.typer.function("g").body, {"x": "33"})
    value = formulas.Parser().ast(live)[1].compile()()
    assert float(value) == pytest.approx(_fourier(33.0, 5), rel=1e-13)
    many = ExcelPrinter(sheet.typer, {"R": "2", "n": "40"}).formula(
        sheet.typer.function("g").body, {"x": "33"}
    )
    assert str(formulas.Parser().ast(many)[1].compile()()).startswith("#N/A")


def test_sum_in_sympy(sheet_from):
    sheet = sheet_from(SHEET)
    expr = symbolic.to_sympy(sheet, "f")
    fn = symbolic.lambdify(sheet, expr, "x")
    assert fn(33.0) == pytest.approx(_fourier(33.0, 5), rel=1e-13)
    assert symbolic.to_sympy(sheet, "total") == 35


def test_the_sheet_with_sums_is_written(sheet_from, tmp_path):
    sheet = sheet_from(SHEET)
    sheet.write_xlsx(tmp_path / "sums.xlsx")
    assert (tmp_path / "sums.xlsx").stat().st_size > 0


@pytest.mark.parametrize(
    "expr, message",
    [
        ("sum(I, 2*I, 1, 3)", "must be the name of the variable"),
        ("sum(I, R, 1, 3)", "already an input"),
        ("sum(I, I, 1)", "takes 1 argument (a vector) or 4 (EXPR, I, A, B), got 3"),
        ("sum(s, s, 1, 3)", "must be a plain number"),
        ("sum(I, I, R, 3)", "needs a dimensionless argument"),
        ("sum(I*R, I, 1, 3) + 1", "cannot add"),
    ],
)
def test_sum_errors_at_load(sheet_from, expr, message):
    text = SHEET + f'bad = "{expr}"\n'
    with pytest.raises(WorkbookError, match=re.escape(message)):
        sheet_from(text)


@pytest.mark.parametrize(
    "value, message", [("2.5", "must be an integer"), ("2000000", "limit 1000000")]
)
def test_sum_bounds_checked_when_evaluated(sheet_from, value, message):
    sheet = sheet_from(SHEET).with_inputs(n=float(value))
    with pytest.raises(WorkbookError, match=message):
        sheet.evaluate("g", 1.0)


@pytest.fixture
def at_entry():
    """A test-only built-in at(EXPR, VAR, A): EXPR with VAR = A (A in VAR's unit)."""

    def unit_rule(ctx, name, args):
        body, var, a = args
        a = ctx.convert(a, var.unit, "at(): the value")
        return ty.TFunc(body.unit, func=name, args=(body, var, a))

    entry = Builtin(
        "at",
        3,
        unit_rule,
        lambda fn, a: fn(a),
        lambda body, args, consts: (body(args[0]), 9),
        lambda sp, body, var, a: body.subs(var, a),
        doc="EXPR at VAR = A",
        binds=(0, 1),
    )
    register(entry)
    yield entry
    del REGISTRY["at"]


def test_a_binding_builtin_types_its_variable_in_the_declared_unit(sheet_from, at_entry):
    text = SHEET.replace('n = "5"', 'n = "5"\nquarter = "90 deg"')
    text += 'up = { expr = "at(R*sin(x), x, quarter)", unit = "mm" }\n'
    sheet = sheet_from(text)
    # x is declared in degrees: at x = 90 deg, sin(x) = 1 (the hook got EXPR as a callable)
    assert sheet.evaluate("up").to("mm").magnitude == pytest.approx(2.0, rel=1e-15)
    formulas = pytest.importorskip("formulas")
    printer = ExcelPrinter(sheet.typer, {"R": "2", "quarter": "90"})
    formula = printer.formula(sheet.typer.scalar("up"), {})
    assert float(formulas.Parser().ast(formula)[1].compile()()) == pytest.approx(2.0, rel=1e-15)
    assert float(symbolic.to_sympy(sheet, "up")) == pytest.approx(2.0, rel=1e-15)
    bad = SHEET + 'wrong = "at(R*sin(x), x, R)"\n'
    with pytest.raises(WorkbookError, match="at\\(\\): the value"):
        sheet_from(bad)


class TOdd(ty.T):
    """A node kind no back end knows."""


@pytest.mark.parametrize("backend", ["numpy", "excel", "sympy", "text"])
def test_an_unknown_node_is_refused_by_every_back_end(sheet_from, backend):
    sheet = sheet_from(SHEET)
    node = TOdd(sheet.typer.dimensionless)
    evaluator = Evaluator(sheet.typer, sheet.scalar_value, sheet.describe_call)
    run = {
        "numpy": lambda: evaluator.compile(node),
        "excel": lambda: ExcelPrinter(sheet.typer).print(node, {}),
        "sympy": lambda: SympyConverter(sheet).convert(node),
        "text": lambda: typed_text(node),
    }[backend]
    with pytest.raises(UnhandledNode, match="TOdd"):
        run()


def test_typed_nodes_are_frozen(sheet_from):
    node = sheet_from(SHEET).typer.scalar("total")
    with pytest.raises(AttributeError):
        node.unit = None
