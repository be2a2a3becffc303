"""eigenvec, rank, polyroots and polyrootparts against mpmath at 50 digits and SymPy's exact
rank, with their unit rules and errors."""

from __future__ import annotations

import re

import mpmath
import numpy as np
import pytest
import sympy

from workbook import WorkbookError

mp = mpmath.mp

SHEET = """
[inputs]
k = "2 N/m"
s = "1 s"

[definitions]
K = "[[4, -1, 0.5], [-1, 3, -2], [0.5, -2, 5]]*k"
A = "[[2, 1, 0], [0.5, 3, 1], [0, 1, 4]]"
lam = "eigenvals(K)"
v0 = "eigenvec(K, lam[0])"
v1 = "eigenvec(K, lam[1])"
v2 = "eigenvec(K, lam[2])"
lamA = "eigenvals(A)"
w2 = "eigenvec(A, lamA[2])"
full = "rank(K)"
deficient = "rank([[1, 2, 3], [2, 4, 6], [1, 0, 1]])"
one = "rank([[1e-3, 2e-3], [2e-3, 4e-3]]*k)"
zero = "rank([[0, 0], [0, 0]])"
roots = "polyroots([-6, 11, -6, 1])"
wide = "polyroots([0.3, -7.1, 2.25, 4, -1.5])"
parts = "polyrootparts([5, -2, 1])"
mixed = "polyrootparts([-1, 0, 0, 1])"
"""


def _mp_eig(rows):
    with mp.workdps(50):
        values, vectors = mpmath.eig(mpmath.matrix(rows))
    return values, vectors


@pytest.mark.parametrize("name, matrix, scale", [("K", "K", 2.0), ("A", "A", 1.0)])
def test_eigenvec_against_mpmath(sheet, name, matrix, scale):
    rows = {
        "K": [[4, -1, 0.5], [-1, 3, -2], [0.5, -2, 5]],
        "A": [[2, 1, 0], [0.5, 3, 1], [0, 1, 4]],
    }[matrix]
    values, vectors = _mp_eig(rows)
    order = sorted(range(3), key=lambda i: float(mpmath.re(values[i])))
    targets = ["v0", "v1", "v2"] if name == "K" else [None, None, "w2"]
    for position, target in enumerate(targets):
        if target is None:
            continue
        got = np.asarray(sheet.evaluate(target).magnitude, dtype=float).ravel()
        col = [mpmath.re(vectors[r, order[position]]) for r in range(3)]
        norm = mpmath.sqrt(sum(c * c for c in col))
        want = np.array([float(c / norm) for c in col])
        want *= np.sign(want[np.argmax(np.abs(want))])  # the largest component positive
        assert got == pytest.approx(want, abs=1e-14), target
        assert np.linalg.norm(got) == pytest.approx(1.0, abs=1e-15)


def test_eigenvec_of_a_value_that_is_not_an_eigenvalue(sheet_from):
    text = SHEET + 'bad = "eigenvec(K, 3*k)"\n'
    sheet = sheet_from(text)
    with pytest.raises(WorkbookError, match=r"z = 6 is not an eigenvalue of M \(the nearest is"):
        sheet.evaluate("bad")


@pytest.mark.parametrize(
    "line, message",
    [
        ('bad = "eigenvec(K, 3*s)"', "eigenvec(M, z): z and the elements of M"),
        ('bad = "eigenvec([[1, 2, 3]], 1)"', "needs a square matrix"),
        ('bad = "polyroots([[1, 2], [3, 4]])"', "must be a vector"),
        ('bad = "polyroots([3])"', "at least 2 coefficients"),
        ('bad = "rank(2)"', "must be a matrix"),
    ],
)
def test_shapes_and_units_are_checked_at_load(sheet_from, line, message):
    with pytest.raises(WorkbookError, match=re.escape(message)):
        sheet_from(SHEET + line + "\n")


def test_rank_against_sympy(sheet):
    exact = {
        "full": [[4, -1, sympy.Rational(1, 2)], [-1, 3, -2], [sympy.Rational(1, 2), -2, 5]],
        "deficient": [[1, 2, 3], [2, 4, 6], [1, 0, 1]],
        "one": [[1, 2], [2, 4]],
        "zero": [[0, 0], [0, 0]],
    }
    for name, rows in exact.items():
        assert sheet.evaluate(name).magnitude == sympy.Matrix(rows).rank(), name
        assert str(sheet.evaluate(name).units) == "dimensionless"


def _mp_roots(coefficients):
    with mp.workdps(50):
        return mpmath.polyroots(coefficients[::-1], maxsteps=200, extraprec=200)


@pytest.mark.parametrize(
    "name, coefficients", [("roots", [-6, 11, -6, 1]), ("wide", [0.3, -7.1, 2.25, 4, -1.5])]
)
def test_polyroots_against_mpmath(sheet, name, coefficients):
    want = sorted(float(mpmath.re(r)) for r in _mp_roots(coefficients))
    got = np.asarray(sheet.evaluate(name).magnitude, dtype=float).ravel()
    assert got == pytest.approx(want, rel=1e-13, abs=1e-14)


@pytest.mark.parametrize("name, coefficients", [("parts", [5, -2, 1]), ("mixed", [-1, 0, 0, 1])])
def test_polyrootparts_against_mpmath(sheet, name, coefficients):
    roots = [complex(r) for r in _mp_roots(coefficients)]
    big = max(abs(r) for r in roots)
    roots.sort(key=lambda r: (round(abs(r) / big, 10), r.imag, r.real))
    got = np.asarray(sheet.evaluate(name).magnitude, dtype=float)
    assert got.shape == (len(roots), 2)
    assert got[:, 0] == pytest.approx([r.real for r in roots], abs=1e-14)
    assert got[:, 1] == pytest.approx([r.imag for r in roots], abs=1e-14)


@pytest.mark.parametrize(
    "line, message",
    [
        ('bad = "polyroots([5, -2, 1])"', "complex roots"),
        ('bad = "polyroots([1, 2, 0])"', "the last coefficient (of the highest power) is 0"),
    ],
)
def test_polyroots_errors_when_computed(sheet_from, line, message):
    sheet = sheet_from(SHEET + line + "\n")
    with pytest.raises(WorkbookError, match=re.escape(message)):
        sheet.evaluate("bad")


def test_written_as_values_with_a_comment(sheet, tmp_path):
    import openpyxl

    path = sheet.write_xlsx(tmp_path / "eig.xlsx")
    book = openpyxl.load_workbook(path)
    comments = " ".join(
        c.comment.text for ws in book.worksheets for row in ws.iter_rows() for c in row if c.comment
    )
    assert "eigenvectors have no spreadsheet formula" in comments
    assert "the roots of a polynomial have no spreadsheet formula" in comments
