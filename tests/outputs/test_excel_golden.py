"""The Excel back end against an independent Excel evaluator (the `formulas` package).

One worksheet holds the expressions where an Excel printer goes wrong (precedence of
negation and powers, left-associative division and subtraction, chained comparisons,
min/max, ATAN2's argument order, unit factors, piecewise -> IF, inlined functions,
names Excel would read as cells). Its workbook is written, every formula cell is
recalculated by `formulas` (no LibreOffice needed) and compared with the engine's numpy
value at a tight tolerance.
"""

from __future__ import annotations

import math
import re

import formulas
import pytest
from helpers.recalc import formula_values

from workbook.functions.distributions import NAMES as DISTRIBUTIONS
from workbook.functions.special import NAMES as SPECIAL
from workbook.numerics.registry import REGISTRY

REL = 1e-13

# (name, worksheet expression, unit shown or None)
CASES = [
    ("neg_sq", "-x^2", None),  # Excel reads -x^2 as (-x)^2
    ("neg_sq_sum", "a - x^2", None),
    ("pow_neg", "2^-1", None),
    ("pow_neg_input", "x^-a", None),
    ("pow_chain", "x^a^b", None),  # Excel's ^ is left-associative, the worksheet's right
    ("pow_of_neg", "(-x)^a", None),
    ("pow_of_sum", "(a + b)^0.5", None),
    ("pow_of_product", "(a*b)^2", None),
    ("div_chain", "a/b/c", None),
    ("div_of_product", "a/(b*c)", None),
    ("sub_nest", "a-(b-c)", None),
    ("sub_neg", "a - -b", None),
    ("mul_of_neg", "a*-b", None),
    ("min_max", "min(a, b, -x) + max(a, -x)", None),
    ("min_neg", "-min(a, b)", None),
    ("atan2_order", "atan2(a, b)", None),  # x first in both: ATAN2(a, b)
    ("atan2_quadrant", "atan2(-a, -b)", None),
    ("unit_sum", "R1 + L2", "mm"),  # a factor 1000 on the metre input
    ("unit_product", "omega*R1", "m/s"),
    ("unit_angle", "sin(alpha) + cos(2*alpha)", None),  # degrees -> radians
    ("mangled", "R1/RC + C3*k", "mm"),  # R1, RC, C3, k are cells or too short for Excel
    ("builtin_pi", "pi*a", None),
    ("inline_neg", "sq(-x)", None),  # sq(u) = u^2: the argument keeps its brackets
    ("inline_diff", "sq(a - b) + cube(-a)", None),
    ("inline_nested", "sq(sq(a) - x)", None),
    ("floor_ceil", "floor(-x/2) + 10*ceil(-x/2)", None),
    ("round_trunc", "round(-x/4, 1) + 10*round(x/2) + 100*trunc(-x/2)", None),  # halves
    ("mod_signs", "mod(-x, a) + 10*mod(x, -a)", None),  # Excel's MOD takes the sign of y
    ("sign_abs", "sign(a - x) + abs(a - x)", None),
    ("exp_ln", "exp(-a) + ln(b) + log10(c)", None),
    ("hyperbolic", "sinh(a/b) + cosh(a/b) - tanh(a/b)", None),
    ("hyperbolic_reciprocal", "coth(a/b) + sech(a/b) - csch(-a/b)", None),
    ("inverse_hyperbolic", "asinh(-a/b) + acosh(b/a + 1) + atanh(a/c)", None),
    ("inverse_reciprocal", "asec(c/a) + acsc(-c/b) + acoth(c/a) + asech(a/c) + acsch(-b)", None),
    ("inverse_trig", "asin(a/c) + acos(a/c) + atan(b/c)", None),
    ("sqrt_of_sum", "sqrt(a + b + c)", None),
    # complex numbers: the parts and angle of IM* results are numbers
    ("complex_parts", "Re(polar(a, x/4)) + Im(conj(a - b*1i)) + arg(-a + x*1i)", None),
    ("tangent", "tan(a/c) - tan(-x/4)", None),
    ("reciprocal_trig", "2^sec(a/c) - csc(x/4)*cot(b/c)", None),  # 1/COS(...) under ^ and *
    ("sum_bound", "sum(u^2 - a*u, u, 1, 4)", None),  # unrolled: (1^2-a_*1)+...
    ("product_bound", "product(u + a, u, 1, 3)/x", None),
    ("pick_first", "pick(a)", None),
    ("pick_middle", "pick(b)", None),
    ("pick_last", "pick(c)", None),
    ("pick_chained", "window(b)", None),
    ("logic", "flag(b)", None),
    ("choice", "by_law(b)", None),
]

TEMPLATE = (
    """
[inputs]
x = "3"
a = "2"
b = "3"
c = "5"
k = "0.25"
R1 = "20 mm"
RC = "4"
C3 = "7 mm"
L2 = "0.05 m"
omega = "104.6 1/s"
alpha = "30 deg"
law = { value = "harmonic", options = ["stepped", "harmonic"] }

[arguments]
u = { unit = "" }

[definitions]
"sq(u)" = "u^2"
"cube(u)" = "u^3"
"pick(u)" = ["1 if u <= a", "10 if u == b", "100 if u != b and u >= b"]
"window(u)" = ["u if a < u <= b < c", "-u otherwise"]
"flag(u)" = ["1 if (u > a and u < c) or not u > 0", "0 otherwise"]
"by_law(u)" = ["u if law == \\"harmonic\\"", "-u otherwise"]
"g(u)" = ["1 if u < -1", "-u^2 if -1 <= u <= 1", "2 otherwise"]
"""
    + "".join(
        f'{name} = {{ expr = "{text}", unit = "{unit}" }}\n' if unit else f'{name} = "{text}"\n'
        for name, text, unit in CASES
    )
    + """
[[tables]]
name = "functions"
range = "u := -2, -1.5 .. 2"
columns = { g = "", "sq(u - a)" = "", "-sq(u)" = "", "atan2(u, a)" = "", "(u + 3)^-2" = "" }

[[tables]]
name = "scalars"
range = "u := 1 .. 1"
columns = { """
    + ", ".join(f'"u*{name}" = "{unit or ""}"' for name, _, unit in CASES)
    + " }\n"
)


@pytest.fixture(scope="module")
def golden(load_text, tmp_path_factory):
    """The sheet, its formula cells {(sheet, cell): (formula, engine value)}, the values
    `formulas` computes {(SHEET, cell): value} and the Definitions rows {name: row}."""
    import openpyxl

    tmp = tmp_path_factory.mktemp("golden")
    sheet = load_text(TEMPLATE, name="golden")
    path = sheet.write_xlsx(tmp / "golden.xlsx")
    cells = formula_values(path)
    defs = openpyxl.load_workbook(path)["Definitions"]
    rows = {r[0].value: r[0].row for r in defs.iter_rows(min_row=2) if r[0].value}
    solution = formulas.ExcelModel().loads(str(path)).finish().calculate()
    recalculated = {}
    for key, ranges in solution.items():
        book_sheet, _, cell = key.rpartition("!")
        if ":" in cell or "]" not in book_sheet:  # ranges and defined names
            continue
        name = book_sheet.split("]", 1)[1].strip("'")
        recalculated[(name.upper(), cell.upper())] = ranges.value[0, 0]
    return sheet, cells, recalculated, rows


def _close(got, expected) -> bool:
    if isinstance(expected, str):
        return got == expected
    try:
        return math.isclose(float(got), expected, rel_tol=REL, abs_tol=1e-300)
    except (TypeError, ValueError):  # an Excel error value
        return False


def test_every_plain_builtin_is_printed_here():
    """Every built-in of one or two numbers (the registry) is called by some case (the
    distributions by tests/numerics/test_distributions.py)."""
    plain = {n for n, b in REGISTRY.items() if not (b.binds or b.arrays or b.data_args)}
    plain -= DISTRIBUTIONS | {n for n, b in REGISTRY.items() if b.texts}  # test_texts.py
    plain -= SPECIAL  # against mpmath and recalculated: tests/numerics/test_special_functions.py
    called = {n for _, text, _ in CASES for n in re.findall(r"([A-Za-z_]\w*)\(", text)}
    assert plain - called == set()


@pytest.mark.slow
def test_every_formula_cell_matches_the_formulas_package(golden):
    _, cells, recalculated, _ = golden
    assert len(cells) > 2 * len(CASES)
    bad = [
        (key, formula, cached, recalculated.get((key[0].upper(), key[1])))
        for key, (formula, cached) in cells.items()
        if not _close(recalculated.get((key[0].upper(), key[1])), cached)
    ]
    assert not bad, f"{len(bad)} of {len(cells)} formula cells differ, e.g. {bad[:5]}"


@pytest.mark.parametrize("name,text,unit", CASES, ids=[c[0] for c in CASES])
def test_definition_is_live_and_agrees_with_numpy(golden, name, text, unit):
    sheet, cells, recalculated, rows = golden
    cell = f"B{rows[name]}"
    formula, _ = cells[("Definitions", cell)]  # a KeyError: written as a number, not live
    print(f"{text:40} -> {formula}")
    engine = sheet.evaluate(name)
    engine = float((engine.to(unit) if unit else engine.to("")).magnitude)
    got = recalculated[("DEFINITIONS", cell)]
    assert _close(got, engine), f"{formula}: formulas gives {got}, numpy {engine}"
