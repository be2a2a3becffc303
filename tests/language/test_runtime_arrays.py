"""Arrays whose size is known only when the program runs (workbook.engine.runtime): growth, nested
arrays, Mathcad's rules on shapes, and the errors that replace a guess."""

from __future__ import annotations

import numpy as np
import openpyxl
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from workbook.engine import runtime as rt
from workbook.errors import InputError, WorkbookError
from workbook.functions.matrix import size

SHEET = '''
[sheet]
name = "grow"
origin = 1

[inputs]
L = "2 m"

[arguments]
n = { unit = "" }
x = { unit = "m" }
T = { unit = "" }
v = { unit = "" }
t = { unit = "" }

[definitions]
"appended(n)" = { program = """
for i in 1 .. n
    l[rows(l) + 1] := i^2
l
""" }
"grown(x)" = { program = """
r := 0
r[rows(r) + 1] := x
r[rows(r) + 1] := 2*x
r
""" }
"table(n)" = { program = """
T := 1
for k in 1 .. n
    T[rows(T) + 1] := [k, [0, 30] + 10*k, [60, 0]]
T
""" }
"at(T, n, t)" = { program = """
for i in 1 .. rows(T)
    if T[i][1] == n
        ind := i
        break
linterp(T[ind][2], T[ind][3], t)
""" }
"set_first(v)" = { program = """
v[1] := 99
v[1]
""" }
"same(n)" = { program = """
a[rows(a) + 1] := n
b[rows(b) + 1] := n
1 if a == b otherwise 0
""" }
"selfdot(n)" = { program = """
a[rows(a) + 1] := n
a[rows(a) + 1] := 1
a*a
""" }
"bad_sum(n)" = { program = """
a[rows(a) + 1] := n
a + [1, 2]
""" }
"bad_order(n)" = { program = """
a[rows(a) + 1] := n
1 if a < 2 otherwise 0
""" }
"flipped(n)" = { program = """
v[rows(v) + 1] := n
v[rows(v) + 1] := 2*n
transpose(v)
""" }
"sorted(n)" = { program = """
M[1, 1] := 3
M[1, 2] := 30
M[2, 1] := n
M[2, 2] := 10*n
csort(M, 1)
""" }
three = "appended(3)"
lengths = "grown(L)"
trains = "table(3)"
where = "at(trains, 2, 15)"
base = "[5, 6]"
first = "set_first(base)"
after = "base[1]"
equal = "same(4)"
dotted = "selfdot(3)"
sum_error = "bad_sum(1)"
order_error = "bad_order(1)"
ordered = "sorted(1)"
row = "flipped(3)"
'''


@pytest.fixture(scope="module")
def sheet(load_text):
    return load_text(SHEET, name="grow")


def value(sheet, name):
    return rt.value(sheet.scalar_value(name, "definition"))


def test_a_vector_grown_at_run_time_indices(sheet):
    assert value(sheet, "three").ravel().tolist() == [1.0, 4.0, 9.0]


def test_a_number_grown_into_a_vector_keeps_its_unit(sheet):
    q = sheet.evaluate(["lengths"])[0]
    assert q.to("mm").magnitude.ravel().tolist() == [2000.0, 4000.0]


def test_a_nested_array_of_trains(sheet):
    trains = value(sheet, "trains")
    assert trains.shape == (3, 1) and trains.dtype == object
    second = rt.value(trains[1, 0])
    assert rt.value(second[0, 0]) == 2.0
    assert rt.value(second[1, 0]).ravel().tolist() == [20.0, 50.0]


def test_linterp_in_a_nested_element(sheet_from):
    s = _changed(sheet_from, 'where = "at(trains, 2, 15)"', 'where = "at(trains, 2, 35)"')
    assert rt.value(s.scalar_value("where", "definition")) == pytest.approx(30.0, rel=1e-15)


def test_linterp_outside_the_data_is_an_error_naming_it(sheet):
    with pytest.raises(WorkbookError, match="outside the data"):
        sheet.scalar_value("where", "definition")


def test_an_argument_array_is_not_changed_by_the_program(sheet):
    assert value(sheet, "first") == 99.0
    assert value(sheet, "after") == 5.0


def test_whole_array_equality(sheet):
    assert value(sheet, "equal") == 1.0


def test_vector_times_vector_is_the_dot_product(sheet):
    assert value(sheet, "dotted") == 10.0


def test_shape_mistakes_are_errors_when_they_run(sheet):
    with pytest.raises(WorkbookError, match="cannot add or subtract a vector of 1 and a vector"):
        sheet.scalar_value("sum_error", "definition")
    with pytest.raises(WorkbookError, match="cannot order"):
        sheet.scalar_value("order_error", "definition")


def test_csort_sorts_rows_by_a_column(sheet):
    assert value(sheet, "ordered").tolist() == [[1.0, 10.0], [3.0, 30.0]]


def _changed(sheet_from, old: str, new: str):
    return sheet_from(SHEET.replace(old, new), name="grow")


def test_units_are_still_checked_at_load(sheet_from):
    with pytest.raises(WorkbookError, match="cannot add"):
        _changed(sheet_from, 'three = "appended(3)"', 'three = "appended(3) + L"')


def test_static_shapes_keep_their_load_errors(sheet_from):
    with pytest.raises(WorkbookError, match="cannot add a vector of 3 to a vector of 2"):
        _changed(sheet_from, 'three = "appended(3)"', 'three = "[1, 2] + [1, 2, 3]"')


def test_the_workbook_shows_values_and_nested_arrays_as_text(sheet, tmp_path):
    out = tmp_path / "grow.xlsx"
    sheet.write_xlsx(out)
    wb = openpyxl.load_workbook(out)
    cells = {
        c.value: (ws.title, c.row, c.column)
        for ws in wb
        for row in ws.iter_rows()
        for c in row
        if isinstance(c.value, str)
    }
    title, row, _ = cells["trains"]
    shown = wb[title].cell(row + 1, 2).value
    assert shown == "[[1, [10, 40], [60, 0]], [2, [20, 50], [60, 0]], [3, [30, 60], [60, 0]]]"
    assert wb[title].cell(row + 1, 2).data_type == "s"
    title, row, _ = cells["three"]
    assert [wb[title].cell(row + 1 + i, 2).value for i in range(3)] == [1, 4, 9]


# -- the run-time operations themselves ----------------------------------------------------------
def test_set_item_grows_with_zeros_and_nests():
    v = rt.set_item(0.0, [3], 7.0, origin=1, what="v")
    assert v.ravel().tolist() == [0.0, 0.0, 7.0]
    w = rt.set_item(v, [2], np.array([[1.0], [2.0]]), origin=1, what="v")
    assert w.dtype == object and rt.value(w[2, 0]) == 7.0
    assert v.dtype == float  # the original is not changed


def test_index_errors_name_the_index():
    v = np.array([[1.0], [2.0]])
    with pytest.raises(InputError, match="element index 3 is out of range"):
        rt.index(v, [3], origin=1, what="v[3]")
    with pytest.raises(InputError, match="cannot be indexed"):
        rt.index(2.0, [1], origin=1, what="x[1]")
    with pytest.raises(InputError, match="not an integer"):
        rt.index(v, [1.5], origin=1, what="v[1.5]")


def test_sizes_of_a_number_are_zero_as_mathcad():
    assert size("rows", 5.0) == 0.0
    assert size("last", np.zeros((4, 1)), origin=1) == 4.0


def test_matrix_rules_when_running():
    a = np.array([[1.0, 2.0], [3.0, 4.0]])
    assert np.allclose(rt.binary("^", a, -1.0, "a^-1"), np.linalg.inv(a))
    assert rt.binary("*", a, np.array([[1.0], [1.0]]), "a*v").ravel().tolist() == [3.0, 7.0]
    with pytest.raises(InputError, match="cannot divide"):
        rt.binary("/", 1.0, a, "1/a")


# -- a model: a run-time vector against a Python list -------------------------------------------
@pytest.mark.slow
@given(
    st.lists(
        st.tuples(st.integers(min_value=1, max_value=12), st.floats(-1e6, 1e6)),
        min_size=1,
        max_size=30,
    )
)
@settings(max_examples=200, deadline=None)
def test_set_item_matches_a_list_model(steps):
    """v[i] := x in any order (origin 1) is a list that grows with zeros to reach i."""
    model: list[float] = []
    v = 0.0  # Mathcad's start of a local
    for i, x in steps:
        v = rt.set_item(v, [i], x, origin=1, what="v")
        model += [0.0] * (i - len(model))
        model[i - 1] = x
        assert size("rows", v) == len(model)
    assert v.ravel().tolist() == model
    for i, x in enumerate(model, start=1):
        assert rt.index(v, [i], origin=1, what="v") == x
    with pytest.raises(InputError, match="out of range"):
        rt.index(v, [len(model) + 1], origin=1, what="v")


def test_a_table_column_of_run_time_values_is_a_number_a_row(sheet_from):
    text = '''
[sheet]
name = "col"
origin = 1

[arguments]
n = { unit = "" }

[definitions]
"grown(n)" = { program = """
for i in 1 .. n
    v[rows(v) + 1] := i
v
""" }
"total(n)" = { program = """
g := grown(n)
s := 0
for i in 1 .. rows(g)
    s := s + g[i]
s + 0*g[1]
""" }
"whole(n)" = "grown(n)"

[[tables]]
name = "sums"
range = "n := 1 .. 5"
columns = { "total(n)" = "" }

[[tables]]
name = "arrays"
range = "n := 1 .. 3"
columns = { "whole(n)" = "" }
'''
    sheet = sheet_from(text, name="col")
    assert sheet.table("sums")["total(n)"].tolist() == [1.0, 3.0, 6.0, 10.0, 15.0]
    with pytest.raises(WorkbookError, match="whole.*a vector of 1 where a number is wanted"):
        sheet.table("arrays")


def test_the_report_shows_a_nested_array_in_brackets(sheet, tmp_path):
    html = sheet.report(tmp_path / "grow.html").read_text(encoding="utf-8")
    assert "<p class='error'>error:" not in html  # no section failed
    assert "not computed: " in html  # 'where' reads outside its data
    start = html.index("data-name='trains'")
    # the column of 3 trains, and in each train its column and its two vectors
    assert html.count("<mtable>", start, html.index("</div>", start)) == 1 + 3 * 3


def test_transpose_of_a_run_time_vector_is_a_row(sheet):
    assert value(sheet, "row").tolist() == [[3.0, 6.0]]
