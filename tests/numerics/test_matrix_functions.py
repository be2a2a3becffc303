"""Functions called with vectors and matrices against numpy: the body is typed once per
tuple of argument shapes; shape and unit mistakes are errors at load naming the call."""

from __future__ import annotations

import math

import numpy as np
import pytest
from helpers.paths import DATA

from workbook.errors import TemplateError, UnitError
from workbook.facade import Sheet
from workbook.language.template import load_spec

DATA = DATA / "matrix_functions.toml"
L, TH = 0.25, math.radians(35)
A = np.array([1.5, -2, 0.25]) * L
B = np.array([4, 6, -1]) * L
C = np.array([[1.5, -2], [3, 0.5]])


def _rot(a: float) -> np.ndarray:
    return np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])


@pytest.fixture(scope="module")
def sheet() -> Sheet:
    return Sheet(load_spec(DATA))


def _mm(q) -> np.ndarray:
    return np.asarray(q.to("mm").magnitude, dtype=float)


def test_distance_between_two_points(sheet):
    assert _mm(sheet.evaluate("d")) == pytest.approx(1e3 * np.linalg.norm(A - B), rel=1e-13)
    assert _mm(sheet.evaluate("d2")) == pytest.approx(1e3 * np.linalg.norm(A - B), rel=1e-13)
    # one typed body per tuple of shapes, shared by both calls
    assert [k for k in sheet.typer.functions if k.startswith("dist@")] == ["dist@3x1,3x1"]


def test_matrix_functions_return_vectors(sheet):
    np.testing.assert_allclose(_mm(sheet.evaluate("r"))[:, 0], 1e3 * _rot(TH) @ A[:2], rtol=1e-13)
    np.testing.assert_allclose(_mm(sheet.evaluate("m"))[:, 0], 1e3 * C @ B[:2], rtol=1e-13)
    assert _mm(sheet.evaluate("t")) == pytest.approx(1e3 * B.sum(), rel=1e-13)
    np.testing.assert_allclose(_mm(sheet.evaluate("m2"))[:, 0], 1e3 * C @ B[:2], rtol=1e-13)
    want = 1e3 * ((C @ B[:2])[1] + B[0])
    assert _mm(sheet.evaluate("last_y")) == pytest.approx(want, rel=1e-13)


def test_mag_is_mathcads_absolute_value(sheet):
    assert _mm(sheet.evaluate("mag_number")) == pytest.approx(1e3 * L, rel=1e-15)
    assert _mm(sheet.evaluate("mag_vector")) == pytest.approx(1e3 * np.linalg.norm(A), rel=1e-14)
    got = float(sheet.evaluate("mag_matrix").magnitude)
    assert got == pytest.approx(np.linalg.det(C), rel=1e-14)


def test_a_condition_on_a_vector_argument_is_one_number(sheet):
    assert float(sheet.evaluate("sd").magnitude) == (1 if A[1] > 0 else -1)


def test_table_columns_over_a_range_with_vector_arguments(sheet):
    cols = {c.text: c.values for c in sheet.table_data("walk").columns}
    i = np.arange(5.0)
    want = [np.linalg.norm(A - np.array([k, 1, 0]) * L) for k in i]
    np.testing.assert_allclose(cols["dist(A, [i, 1, 0]*L)"], 1e3 * np.array(want), rtol=1e-13)
    np.testing.assert_allclose(cols["total([i, 1]*L)"], 1e3 * (i + 1) * L, rtol=1e-13)
    want = [(_rot(k * TH) @ np.array([L, 0]))[1] for k in i]
    np.testing.assert_allclose(cols["rot(i*th, [1, 0]*L)[1]"], 1e3 * np.array(want), atol=1e-12)
    # a condition on a vector that varies over the range: row by row
    assert list(cols["side([i, i - 2, 0]*L)"]) == [1 if k - 2 > 0 else -1 for k in i]


def test_workbook_inlines_a_call_and_writes_a_program_as_values(sheet, tmp_path):
    """A call with a matrix argument is inlined as for numbers (an array formula over the
    named blocks); a program called with one is written as its values, with a comment."""
    import openpyxl

    wb = openpyxl.load_workbook(sheet.write_xlsx(tmp_path / "mf.xlsx"))

    def cell(name: str):
        key = name if name in wb.defined_names else name + "_"  # d_: d reads as a column
        ((title, ref),) = wb.defined_names[key].destinations
        return wb[title][ref.replace("$", "")]

    assert "SQRT(SUMSQ(" in cell("d").value.text
    assert "MMULT(C_" in cell("last_y").value.text
    assert cell("t").value == pytest.approx(1e3 * B.sum(), rel=1e-12)
    assert "called with a vector or matrix" in cell("t").comment.text


def _text(definitions: str, inputs: str = 'L = "2 m"\nT = "3 s"\n') -> str:
    return (
        f'[inputs]\n{inputs}\n[arguments]\nP = {{ unit = "m" }}\nQ = {{ unit = "m" }}\n'
        f"\n[definitions]\n{definitions}"
    )


def test_index_out_of_range_names_the_call_and_the_definition(sheet_from):
    with pytest.raises(TemplateError) as err:
        sheet_from(_text('"third(P)" = "P[2]"\ny = "third([1, 2]*L)"\n'))
    text = str(err.value)
    assert "in 'third'" in text and "third([1, 2] * L)" in text and "P a vector of 2" in text
    assert "index 2 is out of range" in text and "called in 'y'" in text


@pytest.mark.parametrize(
    "body, message",
    [
        ('"f(P, Q)" = "P + Q"\ny = "f([1, 2]*L, [1, 2, 3]*L)"', "cannot add a vector of 3"),
        ('"f(P)" = "det(P)"\ny = "f([1, 2]*L)"', "square"),
        ('"f(P)" = "P[0]"\ny = "f(L)"', "P is not a vector or matrix"),
        ('"f(P)" = "P[0]*nosuch"', "with numbers: P is not a vector or matrix.*with arrays:"),
    ],
)
def test_shape_mistakes_are_refused_at_load(sheet_from, body, message):
    with pytest.raises(TemplateError, match=message):
        sheet_from(_text(body + "\n"))


@pytest.mark.parametrize(
    "body, message",
    [
        ('"f(P)" = "norm(P)"\ny = "f([1, 2]*T)"', r"\[time\] \(s\) cannot be converted"),
        ('"f(P)" = "P + 1"\ny = "f([1, 2]*L)"', "cannot add dimensionless"),
        ('"f(P)" = "sin(P)"\ny = "f([1, 2]*L)"', "dimensionless argument"),
    ],
)
def test_unit_mistakes_are_refused_at_load(sheet_from, body, message):
    with pytest.raises(UnitError, match=message):
        sheet_from(_text(body + "\n"))


def test_a_condition_in_a_program_on_a_local_vector_is_one_number(sheet_from):
    sheet = sheet_from(
        _text(
            '"loc(P)" = { program = """\nv := [1, -2]*P\nw := 1 if v[1] > 0 otherwise -1\n'
            'w\n""" }\ny = "loc(L)"\n'
        )
    )
    assert np.ndim(sheet.evaluate("y").magnitude) == 0
    assert float(sheet.evaluate("y").magnitude) == -1


@pytest.mark.slow
def test_libreoffice_recalculation_reproduces_the_engine(sheet, tmp_path):
    from helpers.recalc import cell_values, recalculate, soffice

    if soffice() is None:
        pytest.skip("LibreOffice is not installed")
    path = sheet.write_xlsx(tmp_path / "mf.xlsx")
    written = cell_values(path)
    again = cell_values(recalculate(path, tmp_path / "out"))
    compared = 0
    for key, value in written.items():
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            assert again.get(key) == pytest.approx(value, rel=1e-9, abs=1e-12), key
            compared += 1
    assert compared >= 30
    twice = sheet.evaluate("twice").to("mm").magnitude
    assert twice == pytest.approx(2e3 * np.linalg.norm(A - B), rel=1e-13)


def test_a_function_of_vectors_only_is_not_evaluated_with_numbers(sheet_from):
    """x0(P) = P[0] is typed for the vectors it is called with: evaluated by name with a
    list (the points of a range, for a function of numbers) it is refused, never indexed."""
    from workbook.errors import InputError

    sheet = sheet_from(_text('"x0(P)" = "P[0]"\ny = "x0([3, 4]*L)"\n'))
    assert float(sheet.evaluate("y").to("m").magnitude) == 6
    with pytest.raises(InputError, match="takes vectors or matrices"):
        sheet.evaluate("x0", [1.0, 2.0, 3.0])


def test_a_function_of_vectors_no_formula_calls_is_checked_with_run_time_arrays(sheet_from):
    """A library function of vectors that the sheet does not call loads (its units are
    checked with its argument as an array of a size known when called)."""
    sheet = sheet_from(_text('"first(P)" = "P[0]*2"\n'))
    assert sheet.typer.function("first").body.unit == sheet.typer.spec.arguments["P"].unit
