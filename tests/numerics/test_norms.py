"""Norms, condition numbers, trace, diagonal and singular values of matrices: the values Mathcad
Prime stored in matrix-functions.mcdx for M = [1, 0, 7; 9, 5, 8; 3, 4, 2] (written here, as
the worksheet states it), and mpmath at 50 digits."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
from helpers.sheets import definitions

from workbook.errors import WorkbookError

M = [[1, 0, 7], [9, 5, 8], [3, 4, 2]]
STORED = {  # matrix-functions.mcdx, regions 149 to 161
    "n1": 17.0,
    "n2": 14.841898441682646,
    "ni": 22.0,
    "ne": 15.7797338380595,
    "sv": [14.841898441682643, 5.0979132482619631, 1.6520687515879497],
}


def _value(sheet, name):
    return np.asarray(sheet.evaluate(name).magnitude, dtype=float).reshape(-1)


def test_mathcads_stored_values_and_mpmath(sheet_from):
    sheet = sheet_from(
        definitions({
            "M": str(M),
            "n1": "norm1(M)", "n2": "norm2(M)", "ni": "normi(M)", "ne": "norm(M)",
            "sv": "svds(M)", "c1": "cond1(M)", "c2": "cond2(M)", "ce": "conde(M)",
            "ci": "condi(M)", "t": "tr(M)", "d": "diag(M)", "D": "diag([1, 2])",
        })
    )  # fmt: skip
    for name, value in STORED.items():
        assert _value(sheet, name) == pytest.approx(value, rel=1e-14), name
    mpmath.mp.dps = 50
    m = mpmath.matrix(M)
    inv = m**-1
    svd = sorted(mpmath.svd_r(m, compute_uv=False), reverse=True)
    want = {
        "c1": mpmath.mnorm(m, 1) * mpmath.mnorm(inv, 1),
        "ci": mpmath.mnorm(m, mpmath.inf) * mpmath.mnorm(inv, mpmath.inf),
        "ce": mpmath.mnorm(m, "f") * mpmath.mnorm(inv, "f"),
        "c2": svd[0] / svd[-1],
        "n2": svd[0],
    }
    for name, value in want.items():
        assert _value(sheet, name)[0] == pytest.approx(float(value), rel=1e-13), name
    assert _value(sheet, "t")[0] == 8
    assert list(_value(sheet, "d")) == [1, 5, 2]
    assert list(_value(sheet, "D")) == [1, 0, 0, 2]


@pytest.mark.parametrize(
    "expr, message",
    [
        ("cond1([[1, 2], [2, 4]])", "singular"),
        ("tr([[1, 2, 3], [4, 5, 6]])", "square"),
        ("diag([[1, 2, 3], [4, 5, 6]])", "square"),
    ],
)
def test_refusals(sheet_from, expr, message):
    with pytest.raises(WorkbookError, match=message):
        sheet_from(definitions({"X": expr})).evaluate("X")
