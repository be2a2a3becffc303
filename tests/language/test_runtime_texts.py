"""Arrays that hold texts beside numbers (a table of loads and their kinds): indexing gives the
element, a text compares with a text, and every other use of a text is an error naming it,
never a number."""

from __future__ import annotations

import pytest

import workbook

HEAD = """
[inputs]
L = "2 mm"

[arguments]
m = { plain = true }
u = { unit = "m" }

[definitions]
loads = '[[1.5, "D"], [2, "L"], [4, "D"]]'
lengths = '[[L, "D"], [3 mm, "L"]]'
"""


def test_a_program_picks_the_numbers_of_one_kind(sheet_from):
    s = sheet_from(
        HEAD
        + '''"dead(m)" = { program = """
t := 0
for i in 0 .. rows(m) - 1
    k := m[i, 1]
    if k == "D"
        t := t + m[i, 0]
t
""" }
total = "dead(loads)"
kind = "loads[1, 1]"
same = '1 if loads[2, 1] == "D" otherwise 0'
other = '1 if loads[1, 1] != "D" otherwise 0'
'''
    )
    assert s.evaluate("total").magnitude == 5.5
    assert s.evaluate("kind") == "L"
    assert s.evaluate("same").magnitude == 1
    assert s.evaluate("other").magnitude == 1


def test_the_numbers_keep_their_unit_and_the_texts_stay_texts(sheet_from):
    s = sheet_from(
        HEAD
        + '''"pick(u)" = { program = """
u[0, 0]
""" }
"kindof(u)" = { program = """
u[1, 1]
""" }
inmetres = "pick(lengths)"
kind = "kindof(lengths)"
'''
    )
    assert s.evaluate("inmetres").to("mm").magnitude == pytest.approx(2.0)
    assert s.evaluate("kind") == "L"


@pytest.mark.parametrize(
    "expr, message",
    [
        ("loads[0, 1] + 1", "arithmetic on the text 'D'"),
        ("-loads[0, 1]", "arithmetic on the text 'D'"),
        ("2*loads[1, 1]", "arithmetic on the text 'L'"),
        ("sin(loads[1, 1])", "the text 'L' where a number is wanted"),
        ("1 if loads[0, 1] < 1 otherwise 0", "cannot compare the text 'D' with a number"),
        ('1 if loads[0, 0] == "D" otherwise 0', "cannot compare a number with the text 'D'"),
        ("1 if loads[0, 1] > loads[1, 1] otherwise 0", "text is compared with == or != only"),
        ("loads*2", "arithmetic on a 3x2 matrix holding text (the text 'D')"),
        ("max(loads)", "holding text (the text 'D') where a number is wanted"),
    ],
)
def test_any_other_use_of_a_text_is_an_error_naming_it(sheet_from, expr, message):
    s = sheet_from(HEAD + f"out = '{expr}'\n")
    with pytest.raises(
        workbook.WorkbookError, match=message.replace("(", r"\(").replace(")", r"\)")
    ):
        s.evaluate("out")


def test_a_text_in_a_loop_bound_is_an_error(sheet_from):
    s = sheet_from(
        HEAD
        + '''"f(m)" = { program = """
j := 0
for i in 0 .. m[0, 1]
    j := i
j
""" }
out = "f(loads)"
'''
    )
    with pytest.raises(workbook.WorkbookError, match="the text 'D' where a number is wanted"):
        s.evaluate("out")


def test_the_workbook_shows_the_texts(sheet_from, tmp_path):
    import openpyxl

    s = sheet_from(
        HEAD
        + '''"kind(m)" = { program = """
m[0, 1]
""" }
out = "kind(loads)"
'''
    )
    target = tmp_path / "texts.xlsx"
    s.write_xlsx(target)
    wb = openpyxl.load_workbook(target)
    shown = {c.value for ws in wb for row in ws.iter_rows() for c in row}
    assert '[[1.5, "D"], [2, "L"], [4, "D"]]' in shown
    assert "D" in shown


def test_a_division_by_zero_of_an_element_is_not_a_finite_number(sheet_from):
    s = sheet_from(
        HEAD
        + '''"first(m)" = { program = """
m[0, 0]
""" }
out = "first(loads)/0"
'''
    )
    with pytest.raises(workbook.WorkbookError, match="not a finite number"):
        s.evaluate("out")


def test_a_condition_over_a_range_gives_elements_of_run_time_arrays(sheet_from):
    sheet = sheet_from(
        """
[arguments]
m = { plain = true }
i = { plain = true }

[definitions]
loads = '[[1.5, "D"], [2, "L"], [4, "D"]]'
"el(m, i)" = { program = \"\"\"
m[i, 0]
\"\"\" }
"g(i)" = "el(loads, i) if i > 0 otherwise 0"
"h(i)" = 'el(loads, i) if loads[i, 1] == "D" otherwise 0'

[[tables]]
name = "t"
range = "i := 0 .. 2"
columns = [{ expr = "g(i)" }, { expr = "h(i)" }]
""",
        name="table",
    )
    table = sheet.table("t")
    assert list(table["g(i)"]) == [0.0, 2.0, 4.0]
    assert list(table["h(i)"]) == [1.5, 0.0, 4.0]
