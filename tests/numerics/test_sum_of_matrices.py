"""sum(EXPR, I, A, B) of a matrix EXPR is a matrix; the other built-ins that bind a variable
refuse an EXPR that is a vector or matrix (typed as a number, its value was a matrix that then
broadcast into nonsense: S + M of 2x2 matrices was a 2x2x2x2 array)."""

from __future__ import annotations

import numpy as np
import pytest

from workbook.errors import WorkbookError


def test_a_sum_of_matrices_is_a_matrix(sheet_from):
    text = '[definitions]\nM = "[[1, 2], [3, 4]]"\nS = "sum(M * i, i, 1, 3)"\nT = "S + M"\n'
    sheet = sheet_from(text)
    m = np.array([[1.0, 2.0], [3.0, 4.0]])
    assert np.array_equal(np.asarray(sheet.evaluate("S").magnitude, dtype=float), 6 * m)
    assert np.array_equal(np.asarray(sheet.evaluate("T").magnitude, dtype=float), 7 * m)


@pytest.mark.parametrize(
    "expr", ["product(M, i, 1, 2)", "integral(M * t, t, 0, 1)", "maximum(M * t, t, 0, 1)"]
)
def test_other_binders_refuse_a_matrix_expression(sheet_from, expr):
    text = f'[definitions]\nM = "[[1, 2], [3, 4]]"\nX = "{expr}"\n'
    with pytest.raises(WorkbookError, match="the expression is a 2x2 matrix"):
        sheet_from(text)
