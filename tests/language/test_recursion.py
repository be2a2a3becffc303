"""Functions that call themselves (Mathcad's recursion): typed with an assumed unit that must
agree with the body, run with their depth bounded, written as numbers in Excel."""

from __future__ import annotations

import openpyxl
import pytest

from workbook.errors import LimitError, WorkbookError

SHEET = '''
[sheet]
name = "rec"

[inputs]
L = "2 m"

[arguments]
n = { unit = "" }
x = { unit = "m" }

[definitions]
"fact(n)" = { program = """
1 if n <= 1
n*fact(n - 1) otherwise
""" }
"fib(n)" = ["n if n < 2", "fib(n - 1) + fib(n - 2) otherwise"]
"halve(x)" = { program = """
if x < 0.1*L
    return x
halve(x/2)
""" }
"depth(n)" = { program = """
0 if n <= 0
1 + depth(n - 1) otherwise
""" }
"endless(n)" = { program = """
endless(n + 1) + 1
""" }
f10 = "fact(10)"
fib20 = "fib(20)"
h = "halve(L)"
d500 = "depth(500)"
too_deep = "depth(5000)"
never = "endless(1)"
'''


def test_recursive_values(sheet_from):
    s = sheet_from(SHEET, name="rec")
    f10, fib20, h, d500 = s.evaluate(["f10", "fib20", "h", "d500"])
    assert f10.magnitude == 3628800.0
    assert fib20.magnitude == 6765.0
    assert h.to("m").magnitude == 0.125  # 2, 1, 0.5, 0.25, 0.125 m: the unit of x
    assert d500.magnitude == 500.0


@pytest.mark.slow
def test_a_recursion_too_deep_is_a_limit_naming_the_function(sheet_from):
    s = sheet_from(SHEET, name="rec")
    with pytest.raises(LimitError, match=r"depth\(\) called itself more than 1000 deep"):
        s.evaluate(["too_deep"])
    with pytest.raises(LimitError, match=r"endless\(\) called itself"):
        s.evaluate(["never"])
    assert s.evaluate(["d500"])[0].magnitude == 500.0  # the depth count starts again


def test_a_formula_calling_itself_without_a_condition_is_circular(sheet_from):
    text = SHEET.replace('f10 = "fact(10)"', '"loop(n)" = "loop(n) + 1"\nf10 = "fact(10)"')
    with pytest.raises(WorkbookError, match="circular definition: loop -> loop"):
        sheet_from(text, name="rec")


def test_a_unit_that_does_not_settle_asks_for_a_declared_unit(sheet_from):
    text = SHEET.replace(
        'f10 = "fact(10)"',
        '"grow(x)" = { program = """\nx if x > L\ngrow(x)*x otherwise\n""" }\nf10 = "fact(10)"',
    )
    with pytest.raises(WorkbookError, match=r"grow\(\) calls itself.*declare its unit"):
        sheet_from(text, name="rec")


def test_the_workbook_writes_recursive_values_as_numbers(sheet_from, tmp_path):
    s = sheet_from(
        SHEET.replace('too_deep = "depth(5000)"\nnever = "endless(1)"\n', ""), name="rec"
    )
    out = tmp_path / "rec.xlsx"
    s.write_xlsx(out)
    ws = openpyxl.load_workbook(out)["Results"]
    cells = {ws.cell(r, 1).value: ws.cell(r, 2) for r in range(1, ws.max_row + 1)}
    assert cells["f10"].value == 3628800
    assert "calls itself" in cells["f10"].comment.text


def test_mutual_recursion_is_typed_with_the_settled_unit(sheet_from):
    """even(x) calls odd(x) which calls even(x): odd is typed inside even's attempts and
    must be typed again with the unit that holds (metres here, not the first guess)."""
    text = SHEET.replace(
        'f10 = "fact(10)"',
        '"down(x)" = { program = """\nx if x < L\nacross(x - L) otherwise\n""" }\n'
        '"across(x)" = { program = """\nx if x < L\ndown(x - L) otherwise\n""" }\n'
        'left = "down(7.5*L)"\nf10 = "fact(10)"',
    )
    s = sheet_from(text, name="rec")
    assert s.evaluate(["left"])[0].to("m").magnitude == pytest.approx(1.0)  # 15 m - 7*2 m
