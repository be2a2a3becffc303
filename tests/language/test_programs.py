"""Programs (function bodies as statements) and text values: parsing, typing, running, and
the live nested IF they become in the workbook (recalculated by the formulas package)."""

from __future__ import annotations

import math
import re

import numpy as np
import openpyxl
import pytest

import workbook
from workbook.program.run import MAX_STEPS

HEAD = '[inputs]\nf_d = "235 MPa"\n[arguments]\nx = { unit = "" }\ns = { unit = "MPa" }\n'


def prog(name: str, body: str) -> str:
    return f'"{name}" = {{ program = """\n{body}\n""" }}\n'


def test_loops_against_python(sheet_from):
    sheet = sheet_from(
        HEAD
        + "[definitions]\n"
        + prog(
            "collatz(x)",
            "n := 0\nwhile x != 1\n"
            "    x := x/2 if x - 2*floor(x/2) == 0 otherwise 3*x + 1\n"
            "    n := n + 1\nn",
        )
        + prog(
            "primes(x)",
            "count := 1\nfor k in 3 .. x\n    p := 1\n    for d in 2 .. k - 1\n"
            "        p := 0 if k - d*floor(k/d) == 0 otherwise p\n"
            "        break if p == 0\n    count := count + p\ncount",
        )
        + prog(
            "odd_sum(x)",
            "acc := 0\nfor k in 1 .. x\n"
            "    continue if k - 2*floor(k/2) == 0\n    acc := acc + k\nacc",
        )
    )

    def collatz(n):
        steps = 0
        while n != 1:
            n = n // 2 if n % 2 == 0 else 3 * n + 1
            steps += 1
        return steps

    xs = [1, 6, 27, 97]
    np.testing.assert_array_equal(sheet.evaluate("collatz", xs).magnitude, [collatz(x) for x in xs])
    primes = sum(1 for k in range(2, 101) if all(k % d for d in range(2, k)))
    assert sheet.evaluate("primes", 100).magnitude == primes
    assert sheet.evaluate("odd_sum", 9).magnitude == 1 + 3 + 5 + 7 + 9


def test_if_branches_returns_and_units(sheet_from):
    sheet = sheet_from(
        HEAD
        + "[definitions]\n"
        + prog("check(s)", '"OK" if s <= f_d\n"not OK" otherwise')
        + prog(
            "cap(s)",
            "limit := 0.9*f_d\nif s < 0\n    return 0\n"
            "else if s > limit\n    return limit\notherwise\n    s",
        )
    )
    assert sheet.evaluate("check", 200) == "OK"
    assert list(sheet.evaluate("check", [100, 300])) == ["OK", "not OK"]
    np.testing.assert_allclose(
        sheet.evaluate("cap", [-5, 100, 300]).to("MPa").magnitude, [0, 100, 0.9 * 235]
    )


@pytest.mark.parametrize(
    "body, message",
    [
        ("if x > 0\n    x", "no value"),  # ends without a value for x <= 0
        ("x + f_d", "cannot add"),
        ("a := s\na := x\na", "cannot be converted"),
        ('"OK" if x > 0\n1 otherwise', "a number here, text in another branch"),
        ("break", "'break' outside a loop"),
        ("for k in 1 .. 3\nk", "needs an indented block"),
        ("a = 1\na", "':='"),
        ("x\n    x", "unexpected indent"),
        ("f_d := 1\nf_d", "a name of the sheet"),
        ("if x\n    return 1\n0 otherwise", "a condition must be a comparison"),
    ],
)
def test_program_errors_at_load(sheet_from, body, message):
    text = HEAD + "[definitions]\n" + prog("g(x, s)", body)
    if message == "no value":
        sheet = sheet_from(text, name="p")
        with pytest.raises(workbook.WorkbookError, match="ended without a value"):
            sheet.evaluate("g", -1, 1)
        return
    with pytest.raises(workbook.WorkbookError, match=message) as info:
        sheet_from(text, name="p")
    assert "p.toml" in str(info.value)


@pytest.mark.slow
def test_a_while_that_never_ends_is_stopped_by_the_step_limit(sheet_from):
    sheet = sheet_from(HEAD + "[definitions]\n" + prog("loop(x)", "while x > 0\n    x := x + 1\nx"))
    with pytest.raises(workbook.WorkbookError, match=r"ran 1,000,000 statements") as info:
        sheet.evaluate("loop", 1)
    assert "in 'loop'" in str(info.value) and "limit exceeded" in str(info.value)
    assert MAX_STEPS == 1_000_000


def test_text_values_conditions_and_comparisons(sheet_from):
    sheet = sheet_from(
        HEAD
        + "[definitions]\n"
        + 'u = "0.2*f_d/f_d + 0.6"\n'
        + 'verdict = "\\"OK\\" if u <= 1 otherwise \\"not OK\\""\n'
        + 'same = "1 if verdict == \\"OK\\" otherwise 0"\n'
        + 'grade = ["\\"A\\" if u < 0.5", "\\"B\\" otherwise"]\n'
    )
    assert sheet.evaluate("verdict") == "OK"
    assert sheet.evaluate("same").magnitude == 1
    assert sheet.evaluate("grade") == "B"
    for bad, message in [
        ('z = "verdict + 1"', "text is not a number"),
        ('z = "verdict < \\"b\\""', "compared with == or != only"),
        ('z = "1 if u < 1 otherwise \\"no\\""', "gives text on one side"),
    ]:
        with pytest.raises(workbook.WorkbookError, match=message):
            sheet_from(HEAD + "[definitions]\n" + 'verdict = "\\"OK\\""\nu = "1"\n' + bad + "\n")


def test_a_program_of_branches_is_a_live_nested_if(sheet_from, tmp_path):
    import formulas  # an independent Excel evaluator

    sheet = sheet_from(
        HEAD
        + "[definitions]\n"
        + prog(
            "cap(s)", "limit := 0.9*f_d\nif s < 0\n    return 0\ns if s <= limit\nlimit otherwise"
        )
        + prog("check(s)", '"OK" if s <= f_d\n"not OK" otherwise')
        + '\n[[tables]]\nname = "t"\nrange = "s := -50, 100 .. 350"\n'
        + 'columns = { cap = "MPa", check = "" }\n'
    )
    path = sheet.write_xlsx(tmp_path / "p.xlsx")
    model = formulas.ExcelModel().loads(str(path)).finish()
    solution = model.calculate()
    got = {}
    for key, value in solution.items():
        if "LISTING" in key.upper() and "!" in key and ":" not in key.split("!")[1]:
            got[key.split("!")[1].upper()] = value.value[0, 0]
    table = sheet.table("t")
    for i in range(len(table)):
        row = 3 + i
        assert float(got[f"B{row}"]) == pytest.approx(table.iloc[i, 1], rel=1e-12)
        assert got[f"C{row}"] == table.iloc[i, 2]
    assert not math.isnan(float(got["B3"]))


def test_programs_build_vectors_and_matrices_element_by_element(sheet_from):
    sheet = sheet_from(
        '[inputs]\nL = "2 m"\n[arguments]\nx = { unit = "" }\n[definitions]\n'
        + prog("powers(x)", "v := [0, 0, 0, 0]\nfor k in 0 .. 3\n    v[k] := x^k\nv")
        + prog(
            "grid(x)",
            "M := [[0, 0, 0], [0, 0, 0]]*L\nfor i in 0 .. 1\n    for j in 0 .. 2\n"
            "        M[i, j] := (i + 10*j + x)*L\nreturn M",
        )
        + 'table = "powers(3)"\n'
    )
    xs = np.array([0.5, 2.0, 3.0])
    got = sheet.evaluate("powers", xs).magnitude  # matrix axes first, then the argument's
    np.testing.assert_allclose(got[:, 0, :].T, np.vander(xs, 4, increasing=True))
    i, j = np.mgrid[0:2, 0:3]
    np.testing.assert_allclose(sheet.evaluate("grid", 1).to("m").magnitude, (i + 10 * j + 1) * 2.0)
    np.testing.assert_allclose(sheet.evaluate("table").magnitude[:, 0], [1, 3, 9, 27])
    for body, message in [
        ("v := [1, 2]\nv := 3\nv", "was a vector of 2, here it is given a number"),
        ("v := [1, 2]\nv[-1] := 1\nv", "element index -1 is out of range"),
        ("v := [1, 2]\nif x > 0\n    return v\n0 otherwise", "gives a number here"),
    ]:
        with pytest.raises(workbook.WorkbookError, match=message):
            sheet_from('[arguments]\nx = { unit = "" }\n[definitions]\n' + prog("f(x)", body))


def test_a_vector_is_made_and_grown_by_its_elements(sheet_from):
    """Mathcad's v[i] <- ... on a vector not given, or beyond its length: the vector is made
    or grown, the gap filled with 0; its length is known at load (indices are numbers or the
    variables of loops over numbers, set on every pass), else it is refused with why."""
    sheet = sheet_from(
        '[arguments]\nx = { unit = "" }\n[definitions]\n'
        + prog("squares(x)", "for k in 0 .. 3\n    w[k] := x*k^2\nw")
        + prog("gap(x)", "w[3] := x\nw")
        + prog("longer(x)", "v := [x, 2*x]\nv[4] := 5\nv")
        + prog(
            "grid(x)", "for i in 0 .. 1\n    for j in 0 .. 2\n        M[i, j] := i + 10*j + x\nM"
        )
        + prog(
            "fib(x)", "f[0] := 0\nf[1] := 1\nfor k in 2 .. 9\n    f[k] := f[k-1] + f[k-2]\nf[9]*x"
        )
        + prog("count(x)", "for k in 0 .. 4\n    w[k] := k\nrows(w)*x")
    )
    np.testing.assert_allclose(sheet.evaluate("squares", 2).magnitude[:, 0], [0, 2, 8, 18])
    np.testing.assert_allclose(sheet.evaluate("gap", 7).magnitude[:, 0], [0, 0, 0, 7])
    np.testing.assert_allclose(sheet.evaluate("longer", 3).magnitude[:, 0], [3, 6, 0, 0, 5])
    i, j = np.mgrid[0:2, 0:3]
    np.testing.assert_allclose(sheet.evaluate("grid", 1).magnitude, i + 10 * j + 1)
    assert sheet.evaluate("fib", 1).magnitude == 34
    assert sheet.evaluate("count", 2).magnitude == 10
    # a length known only when the program runs: a run-time array (workbook.engine.runtime)
    late = sheet_from(
        '[arguments]\nx = { unit = "" }\n[definitions]\n'
        + prog("upto(x)", "for k in 0 .. x\n    w[k] := 1\nw")
        + prog("maybe(x)", "w[0] := 1\nif x > 0\n    w[3] := 2\nw")
        + prog("stopped(x)", "for k in 0 .. 3\n    w[k] := 1\n    break if k > x\nw")
    )
    np.testing.assert_allclose(late.evaluate("upto", 2).magnitude[:, 0], [1, 1, 1])
    np.testing.assert_allclose(late.evaluate("maybe", 1).magnitude[:, 0], [1, 0, 0, 2])
    np.testing.assert_allclose(late.evaluate("maybe", -1).magnitude[:, 0], [1])
    np.testing.assert_allclose(late.evaluate("stopped", 1).magnitude[:, 0], [1, 1, 1])
    for body, message in [
        ("w := [0]\nfor k in 0 .. 3\n    w[k] := rows(w)\nw", "'w' is used whole where the"),
    ]:
        with pytest.raises(workbook.WorkbookError, match=re.escape(message)):
            sheet_from('[arguments]\nx = { unit = "" }\n[definitions]\n' + prog("f(x)", body))


def test_a_for_loop_never_goes_beyond_its_last_value(sheet_from):
    """A loop runs as Mathcad's for: first, first + step, ... up to the last value, not beyond
    it; a range variable of a table ends with its last value (the paper's listings)."""
    sheet = sheet_from(
        HEAD
        + "[definitions]\n"
        + prog("odd(x)", "t := 0\nfor k in 1, 3 .. x\n    t := t + k\nt")
        + prog("down(x)", "t := 0\nfor k in x, x - 3 .. 0\n    t := 10*t + k\nt")
        + prog("tenths(x)", "n := 0\nfor k in 0, 0.1 .. x\n    n := n + 1\nn")
        + '\n[[tables]]\nname = "t"\nrange = "x := 1, 3 .. 10"\ncolumns = { odd = "" }\n'
    )
    assert sheet.evaluate("odd", 10).magnitude == 1 + 3 + 5 + 7 + 9
    assert sheet.evaluate("odd", 9).magnitude == 1 + 3 + 5 + 7 + 9
    assert sheet.evaluate("down", 10).magnitude == 10_741  # 10, 7, 4, 1
    assert sheet.evaluate("tenths", 1).magnitude == 11  # 1 is on the step, within rounding
    assert list(sheet.table("t").iloc[:, 0]) == [1, 3, 5, 7, 9, 10]


def test_a_local_whose_assignment_did_not_run_is_an_error_of_the_program(sheet_from, tmp_path):
    """`k := 1 if x == 4` then `k`: where the `if` is false, k has no value. The engine says
    so for that definition (not a crash), and the workbook's nested IF gives #N/A there."""
    sheet = sheet_from(
        HEAD + "[definitions]\n" + prog("f(x)", "k := 1 if x == 4\nk") + 'a = "f(4)"\nb = "f(3)"\n'
    )
    assert float(sheet.evaluate("a").magnitude) == 1
    with pytest.raises(workbook.WorkbookError, match="reads the local 'k' before any line"):
        sheet.evaluate("b")
    text = HEAD + "[definitions]\n" + prog("f(x)", "k := 1 if x == 4\nk") + 'a = "f(4)"\n'
    book = openpyxl.load_workbook(sheet_from(text).write_xlsx(tmp_path / "p.xlsx"))
    formulas = [c.value for ws in book for row in ws.iter_rows() for c in row]
    assert "=IF(4=4, (1), NA())" in formulas  # where k is unset, #N/A
