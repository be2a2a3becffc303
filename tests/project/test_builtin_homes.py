"""A built-in has one home, its registry entry: a new one needs its entry and its line in the
docs, nothing else (a throwaway entry is picked up by the typer, numpy, the Excel printer and
writer, SymPy and diff, MathML and the docs check), and no module lists built-ins but the
modules of entries and the importers' lists of what is the other product's own (checked
here)."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import mpmath
import numpy as np
import openpyxl
import pytest
from helpers.docs import DOC, documented
from helpers.paths import ROOT

import workbook
from workbook.compute.excel import ExcelPrinter
from workbook.functions.builtins import excel_call, plain_in
from workbook.functions.entry import Builtin, register
from workbook.functions.excel_functions import stored
from workbook.language import typed as ty
from workbook.mathcad.functions import MATHCAD_FUNCTIONS, OPERATOR_FUNCTIONS
from workbook.numerics import symbolic
from workbook.numerics.derivative import sympy_functions
from workbook.numerics.registry import REGISTRY
from workbook.outputs.report.mathml import MathML

PACKAGE = ROOT / "workbook"

# The modules of registry entries (matrix.py: what the matrix entries compute, by name); the
# Mathcad importer's lists of Mathcad's own (the functions it refuses and why, those that count
# from ORIGIN: Mathcad's names for the built-ins are the entries' ``mathcad`` field, Excel's
# and VBA's their ``excel_import`` and ``vba`` fields, checked against the registry below).
HOMES = {
    "functions/builtins.py",
    "functions/distributions.py",
    "functions/matrix.py",
    "functions/matrix_entries.py",
    "numerics/entries.py",
    "mathcad/functions.py",
}

# Lists of built-in names that are still kept elsewhere, each exactly as it is now, so that a
# new list, or a built-in added to one of these, fails: (module, the built-ins listed).
KNOWN_ELSEWHERE = {
    # the words of a sweep output's grammar ("max of X over Y"), not calls
    ("sweep/outputs.py", ("argmax", "argmin", "max", "mean", "min")),
    # Excel's unit names of CONVERT (minute, pint, quart, second), not calls
    ("excelimport/convert.py", ("min", "pt", "qt", "sec")),
}  # fmt: skip


def _listed_strings(node: ast.AST) -> list[str] | None:
    """The texts a literal collection (or ``"a b c".split()``) holds."""
    if isinstance(node, (ast.Set, ast.List, ast.Tuple)):
        elements = node.elts
    elif isinstance(node, ast.Dict):
        elements = [k for k in node.keys if k is not None] + list(node.values)
    elif (
        isinstance(node, ast.Call)
        and isinstance(node.func, ast.Attribute)
        and node.func.attr == "split"
        and isinstance(node.func.value, ast.Constant)
        and isinstance(node.func.value.value, str)
    ):
        return node.func.value.value.split()
    else:
        return None
    return [e.value for e in elements if isinstance(e, ast.Constant) and isinstance(e.value, str)]


def builtin_lists(package: Path = PACKAGE) -> set[tuple[str, tuple[str, ...]]]:
    """Every literal list of three or more built-in names outside the homes of built-ins."""
    found = set()
    for path in sorted(package.rglob("*.py")):
        module = path.relative_to(package).as_posix()
        if module in HOMES:
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            texts = _listed_strings(node)
            listed = tuple(sorted(set(texts or ()) & set(REGISTRY)))
            if len(listed) >= 3:
                found.add((module, listed))
    return found


@pytest.mark.slow
def test_no_module_lists_builtins_but_their_homes():
    assert builtin_lists() == KNOWN_ELSEWHERE


def test_the_scan_finds_a_list_of_builtins(tmp_path):
    (tmp_path / "elsewhere.py").write_text('TRIG = ("sin", "cos", "tan")\nOK = ("sin", "x")\n')
    (tmp_path / "split.py").write_text('NAMES = "exp ln sqrt other".split()\n')
    assert builtin_lists(tmp_path) == {
        ("elsewhere.py", ("cos", "sin", "tan")),
        ("split.py", ("exp", "ln", "sqrt")),
    }


def test_mathcad_names_map_onto_registry_entries():
    targets = {name for name, _ in MATHCAD_FUNCTIONS.values()} | set(OPERATOR_FUNCTIONS.values())
    # Mathcad functions the language has no built-in for yet: reported as not translated
    missing = {"find", "maximize", "minimize"}
    assert targets - set(REGISTRY) == missing
    for name, order in MATHCAD_FUNCTIONS.values():
        if order is not None and name in REGISTRY:
            REGISTRY[name].check_arity(len(order))  # argument orders fit the entry


def test_excel_and_vba_names_map_onto_registry_entries():
    from workbook.excelimport.functions import EXCEL, EXCEL_VARIADIC, VBA

    called = {
        name
        for text, _ in [*EXCEL.values(), *VBA.values()]
        for name in re.findall(r"([A-Za-z_][A-Za-z0-9_]*)\(", text)
    }
    called |= {name for name in EXCEL_VARIADIC.values() if name.isidentifier()}
    assert called and called <= set(REGISTRY)


def test_the_derivatives_names_are_read_from_the_registry():
    names = sympy_functions()
    assert names["log"] == "ln" and names["ceiling"] == "ceil" and names["Abs"] == "abs"
    assert names["Min"] == "min" and names["atan2"] == "atan2"
    assert set(names.values()) <= set(REGISTRY)


@pytest.fixture
def acotan():
    """A built-in the engine has never heard of: its entry alone."""
    import sympy  # noqa: F401 - the entry's SymPy hook is called with it

    entry = register(
        Builtin(
            "acotan",
            1,
            plain_in,
            lambda x: np.arctan(1 / x),
            excel_call(stored("ACOT")),
            lambda sp, x: sp.acot(x),
            doc="arc cotangent (a test's entry)",
        )
    )
    yield entry
    del REGISTRY["acotan"]


SHEET = """
[sheet]
name = "acotan"

[inputs]
a = "0.7"
L = "2 m"

[arguments]
x = { unit = "" }

[definitions]
"f(x)" = "L*acotan(x)"
"g(x)" = { expr = "diff(f(x), x)", unit = "m" }
y = "f(a)"
slope = "g(a)"
"""


def _acot(x):
    return float(mpmath.acot(mpmath.mpf(x)))


def test_a_new_builtin_needs_only_its_entry_and_its_docs_line(sheet_from, tmp_path, acotan):
    sheet = sheet_from(SHEET, name="acotan")  # the typer read the entry
    assert isinstance(sheet.typer.function("f").body, ty.T)
    # numpy
    assert sheet.evaluate("y").to("m").magnitude == pytest.approx(2 * _acot(0.7), rel=1e-15)
    # SymPy and diff: the derivative -L/(1 + x^2) read back through the derived names
    assert "acot" in sympy_functions() and sympy_functions()["acot"] == "acotan"
    want = -2 / (1 + 0.7**2)
    assert sheet.evaluate("slope").to("m").magnitude == pytest.approx(want, rel=1e-13)
    assert float(symbolic.to_sympy(sheet, "y")) == pytest.approx(2 * _acot(0.7), rel=1e-15)
    # the Excel printer, recalculated by the formulas package
    formulas = pytest.importorskip("formulas")
    printer = ExcelPrinter(sheet.typer, {"a": "0.7", "L": "2"})
    for name, value in (("y", 2 * _acot(0.7)), ("slope", want)):
        text = printer.formula(sheet.typer.scalar(name), {})
        assert name == "slope" or "_xlfn.ACOT(" in text  # the derivative has no acot left
        assert float(formulas.Parser().ast(text)[1].compile()()) == pytest.approx(value, rel=1e-12)
    # the writer: the newer function keeps its prefix (not taken for a classic one)
    out = tmp_path / "acotan.xlsx"
    sheet.write_xlsx(out)
    cells = [
        c.value
        for ws in openpyxl.load_workbook(out).worksheets
        for row in ws.iter_rows()
        for c in row
        if isinstance(c.value, str) and "ACOT(" in c.value
    ]
    assert cells and all("_xlfn.ACOT(" in c for c in cells)
    # MathML of the report
    assert "<mi>acotan</mi>" in MathML().box(workbook.language.expr.parse("acotan(x)")).xml
    # the docs check: the entry is missing from the reference until its line is written
    text = DOC.read_text(encoding="utf-8")
    assert sorted(documented(text)) != sorted(REGISTRY)
    text = text.replace("Built-in functions: `", "Built-in functions: `acotan ", 1)
    assert sorted(documented(text)) == sorted(REGISTRY)


@pytest.fixture
def stepped():
    """Built-ins the engine has never heard of, whose entries say where they are singular,
    jump, have a kink and take an angle."""
    entries = [
        register(
            Builtin(
                name,
                1,
                plain_in,
                np.floor,
                excel_call("INT"),
                lambda sp, x: sp.floor(x),
                doc="a test's entry",
                **fields,
            )
        )
        for name, fields in (
            ("stairs", {"jumps": lambda t: ty.TFunc(t.unit, func="cos", args=t.args)}),
            ("spike", {"singular": lambda t: (t.args[0],)}),
            ("vee", {"kinks": lambda t: ((t.args[0], None),)}),
            ("turn", {"angle": True}),
        )
    ]
    yield entries
    for entry in entries:
        del REGISTRY[entry.name]


def test_where_a_builtin_jumps_or_is_singular_is_read_from_its_entry(tmp_path, stepped):
    from workbook.engine.angle_slips import takes_angle
    from workbook.numerics.singular import singular_arguments
    from workbook.numerics.switches import switching

    (tmp_path / "s.toml").write_text(
        '[arguments]\nx = { unit = "" }\n\n[definitions]\n'
        '"f(x)" = "stairs(x) + spike(x - 1) + vee(x - 2) + turn(x)"\n',
        encoding="utf-8",
    )
    sheet = workbook.load(tmp_path / "s.toml")
    body = sheet.typer.function("f").body
    found = switching(body, "x")
    assert any(isinstance(t, ty.TFunc) and t.func == "cos" for t in found)  # stairs' jumps
    assert any(isinstance(t, ty.TBinary) and t.op == "-" for t in found)  # vee's kink, x - 2
    assert [t for t in singular_arguments(sheet.defs, body, "x") if isinstance(t, ty.TBinary)]
    assert takes_angle("turn") and not takes_angle("stairs")
