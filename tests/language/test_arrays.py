"""Vectors and matrices of the worksheet language against scipy.linalg (an independent
implementation) and hand values: literals, units, indexing with the origin, operators, every
matrix built-in, and the errors (index out of range, singular, not square, mixed units)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sl
from helpers.paths import DATA

import workbook

RNG = np.random.default_rng(7)
A = RNG.normal(size=(4, 4))
S = A + A.T  # symmetric: real eigenvalues
B = RNG.normal(size=(4, 2))
V = RNG.normal(size=(4, 1))


def _lit(m: np.ndarray) -> str:
    if m.shape[1] == 1:
        return "[" + ", ".join(repr(float(x)) for x in m[:, 0]) + "]"
    return "[" + ", ".join("[" + ", ".join(repr(float(x)) for x in r) + "]" for r in m) + "]"


@pytest.fixture(scope="module")
def sheet(load_text):
    text = f"""
[inputs]
k = "3 kN/m"
F0 = "2 kN"

[arguments]
i = {{ unit = "" }}

[definitions]
A = "{_lit(A)}"
S = "{_lit(S)}"
B = "{_lit(B)}"
V = "{_lit(V)}"
K = "S*k"
f = "V*F0"
detA = "det(A)"
invA = "inverse(A)"
x = "lsolve(K, f)"
lam = "eigenvals(S)"
vecs = "eigenvecs(S)"
AB = "A*B"
AV = "A*V"
VV = "V*V"
At = "transpose(B)"
A3 = "A^3"
Am1 = "A^-1"
had = "vectorize(A*A)"
quot = "vectorize(A/(A + 10))"
sinA = "sin(A)"
sumAB = "A + 2*A - A"
shift = "A + 1"
aug = "augment(A, B)"
stk = "stack(A, transpose(B))"
sub = "submatrix(A, 1, 2, 0, 3)"
sizes = "rows(B)*10 + cols(B)"
n = "length(V) + last(V)"
big = "max(A)"
small = "min(A, -100)"
avg = "mean(A)"
total = "sum(A)"
nv = "norm(V)"
dv = "dot(V, V)"
c = "cross([1, 2, 3], [4, 5, 6])"
"el(i)" = "A[i, 3 - i]"
"vi(i)" = "V[i]*F0"

[[tables]]
name = "diag"
range = "i := 0 .. 3"
columns = {{ "A[i, i]" = "", "vi(i)" = "kN" }}
"""
    return load_text(text, name="m")


def _m(sheet, name, unit=""):
    q = sheet.evaluate(name)
    return np.asarray(q.to(unit).magnitude, dtype=float)


def test_literals_are_columns_and_rows(sheet):
    assert _m(sheet, "V").shape == (4, 1)
    assert _m(sheet, "A").shape == (4, 4)
    np.testing.assert_allclose(_m(sheet, "A"), A, rtol=0, atol=0)


def test_a_quantity_times_a_matrix_carries_the_unit(sheet):
    np.testing.assert_allclose(_m(sheet, "K", "N/m"), S * 3000, rtol=1e-15)


def test_linear_algebra_against_scipy(sheet):
    assert float(_m(sheet, "detA")) == pytest.approx(sl.det(A), rel=1e-12)
    np.testing.assert_allclose(_m(sheet, "invA"), sl.inv(A), rtol=1e-10, atol=1e-12)
    want = sl.solve(S * 3.0, V * 2.0)  # kN/m and kN: x in m
    np.testing.assert_allclose(_m(sheet, "x", "m"), want, rtol=1e-10)
    np.testing.assert_allclose(_m(sheet, "lam")[:, 0], sl.eigh(S, eigvals_only=True), rtol=1e-10)


def test_eigenvectors_belong_to_their_eigenvalues(sheet):
    lam, vecs = _m(sheet, "lam")[:, 0], _m(sheet, "vecs")
    np.testing.assert_allclose(S @ vecs, vecs * lam, atol=1e-10)
    np.testing.assert_allclose(np.linalg.norm(vecs, axis=0), 1.0, rtol=1e-12)
    big = vecs[np.argmax(np.abs(vecs), axis=0), range(4)]
    assert np.all(big > 0)


def test_products_powers_and_elementwise(sheet):
    np.testing.assert_allclose(_m(sheet, "AB"), A @ B, rtol=1e-12)
    np.testing.assert_allclose(_m(sheet, "AV"), A @ V, rtol=1e-12)
    assert float(_m(sheet, "VV")) == pytest.approx(float(V[:, 0] @ V[:, 0]), rel=1e-14)
    np.testing.assert_allclose(_m(sheet, "At"), B.T)
    np.testing.assert_allclose(_m(sheet, "A3"), A @ A @ A, rtol=1e-12)
    np.testing.assert_allclose(_m(sheet, "Am1"), sl.inv(A), rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(_m(sheet, "had"), A * A, rtol=1e-15)
    np.testing.assert_allclose(_m(sheet, "quot"), A / (A + 10), rtol=1e-15)
    np.testing.assert_allclose(_m(sheet, "sinA"), np.sin(A), rtol=1e-15)
    np.testing.assert_allclose(_m(sheet, "sumAB"), 2 * A, rtol=1e-14)
    np.testing.assert_allclose(_m(sheet, "shift"), A + 1, rtol=1e-15)


def test_joining_cutting_and_sizes(sheet):
    np.testing.assert_allclose(_m(sheet, "aug"), np.hstack([A, B]))
    np.testing.assert_allclose(_m(sheet, "stk"), np.vstack([A, B.T]))
    np.testing.assert_allclose(_m(sheet, "sub"), A[1:3, 0:4])
    assert float(_m(sheet, "sizes")) == 42
    assert float(_m(sheet, "n")) == 4 + 3


def test_reductions_and_vector_functions(sheet):
    assert float(_m(sheet, "big")) == A.max()
    assert float(_m(sheet, "small")) == -100
    assert float(_m(sheet, "avg")) == pytest.approx(A.mean(), rel=1e-14)
    assert float(_m(sheet, "total")) == pytest.approx(A.sum(), rel=1e-13)
    assert float(_m(sheet, "nv")) == pytest.approx(float(np.linalg.norm(V)), rel=1e-14)
    assert float(_m(sheet, "dv")) == pytest.approx(float(np.sum(V * V)), rel=1e-14)
    np.testing.assert_allclose(_m(sheet, "c")[:, 0], np.cross([1, 2, 3], [4, 5, 6]))


def test_indexing_over_a_range_and_in_tables(sheet):
    got = sheet.evaluate("el", [0, 1, 2, 3]).magnitude
    np.testing.assert_allclose(got, [A[i, 3 - i] for i in range(4)])
    t = sheet.table("diag")
    np.testing.assert_allclose(t.iloc[:, 1], np.diag(A))
    np.testing.assert_allclose(t.iloc[:, 2], V[:, 0] * 2)


def test_origin_one_counts_from_one(sheet_from):
    s = sheet_from(
        "[sheet]\norigin = 1\n"
        + '[definitions]\nv = "[10, 20, 30]"\nfirst = "v[1]"\nlast_i = "last(v)"\n'
        'm = "submatrix([[1, 2], [3, 4]], 2, 2, 1, 2)"\n',
        name="m",
    )
    assert s.evaluate("first").magnitude == 10
    assert s.evaluate("last_i").magnitude == 3
    np.testing.assert_allclose(s.evaluate("m").magnitude, [[3, 4]])
    with pytest.raises(workbook.WorkbookError, match=r"index 0 is out of range"):
        sheet_from("[sheet]\norigin = 1\n" + '[definitions]\nv = "[1, 2]"\nz = "v[0]"\n', name="m")


@pytest.mark.parametrize(
    "body, message",
    [
        (
            'v = "[1, 2, 3]"\nz = "v[3]"',
            r"v\[3\]: element index 3 is out of range \(3 elements: 0 .. 2",
        ),
        ('M = "[[1, 2, 3], [4, 5, 6]]"\nd = "det(M)"', r"det\(\) needs a square matrix, got a 2x3"),
        ('M = "[[1, 2], [3, 4]]"\nz = "M*[[1, 2, 3]]"', "cannot multiply a 2x2 matrix by a 1x3"),
        ('v = "[1, 2]"\nz = "v < 3"', "cannot compare a vector or matrix"),
        ('v = "[1, 2]"\nz = "v[1, 1]"', "column index 1 is out of range"),
        ('M = "[[1, 2], [3, 4]]"\nz = "M[1]"', r"write M\[i, j\]"),
        ('z = "[[1, 2], [3]]"', "rows of a matrix differ in length"),
        ('v = "[1, 2]"\nz = "sin(v, v)"', "takes 1 argument"),
        ('M = "[[1, 2], [3, 4]]"\nz = "M^0.5"', "constant integer"),
        ('v = "[1, 2]"\nz = "1/v"', "cannot divide by a vector"),
    ],
)
def test_shape_errors_at_load(sheet_from, body, message):
    with pytest.raises(workbook.WorkbookError, match=message) as info:
        sheet_from("[definitions]\n" + body + "\n", name="m")
    assert "m.toml" in str(info.value)


def test_mixed_dimensions_in_a_matrix_are_refused(sheet_from):
    with pytest.raises(workbook.WorkbookError, match="a matrix has one unit") as info:
        sheet_from('[inputs]\nL = "1 m"\nF = "2 N"\n[definitions]\nM = "[[L, F]]"\n', name="m")
    assert "in 'M'" in str(info.value) and "[length]" in str(info.value)
    # a bare 0 fits any unit, and convertible units are converted to the first element's
    s = sheet_from('[inputs]\nL = "1 m"\nd = "20 mm"\n[definitions]\nM = "[L, 0, d]"\n', name="m")
    np.testing.assert_allclose(s.evaluate("M").to("m").magnitude[:, 0], [1, 0, 0.02])


@pytest.mark.parametrize("expr", ["inverse(M)", "lsolve(M, [1, 2])"])
def test_a_singular_matrix_is_an_error_naming_the_definition(sheet_from, expr):
    s = sheet_from(f'[definitions]\nM = "[[1, 2], [2, 4]]"\nz = "{expr}"\n', name="m")
    with pytest.raises(workbook.WorkbookError, match="singular") as info:
        s.evaluate("z")
    assert "in 'z'" in str(info.value) and "m.toml" in str(info.value)


def test_a_computed_index_out_of_range_is_an_error(sheet_from):
    s = sheet_from(
        '[arguments]\ni = { unit = "" }\n[definitions]\nv = "[1, 2, 3]"\n"g(i)" = "v[i]"\n',
        name="m",
    )
    with pytest.raises(workbook.WorkbookError, match="element index 5 is out of range"):
        s.evaluate("g", [0, 5])
    with pytest.raises(workbook.WorkbookError, match="index 0.5 is not an integer"):
        s.evaluate("g", 0.5)


@pytest.mark.slow
def test_run_prints_matrices_and_texts(tmp_path, capsys):

    from workbook.cli import main

    data = DATA / "arrays.toml"
    assert main(["run", str(data), "--out", str(tmp_path / "a.xlsx")]) == 0
    out = capsys.readouterr().out
    assert "  K = [ 8  2 ] kN/m\n      [ 4  6 ]\n" in out  # aligned rows, not numpy's text
    assert 'verdict = "OK"' in out


def test_eigenparts_against_scipy(sheet_from):
    """Complex eigenvalues as rows (Re, Im), by modulus then imaginary part, against
    scipy.linalg.eigvals of the same matrices (a real, a complex and a mixed spectrum)."""
    from scipy.linalg import eigvals

    cases = {
        "A": [[0, 1], [-25, -6]],  # -3 +- 4i
        "B": [[2, 1, 0], [1, 3, 1], [0, 1, 4]],  # real
        "C": [[0, 1, 0, 0], [-400, -0.2, 5, 0], [0, 0, 0, 1], [3, 0, -9, -0.01]],
    }
    text = "[definitions]\n" + "".join(f'e{k} = "eigenparts({v})"\n' for k, v in cases.items())
    sheet = sheet_from(text, name="e")
    for k, m in cases.items():
        got = sheet.evaluate(f"e{k}").magnitude
        lam = eigvals(np.array(m, dtype=float))
        lam = lam[np.lexsort((lam.imag, np.abs(lam)))]
        assert got.shape == (len(m), 2)
        np.testing.assert_allclose(got[:, 0], lam.real, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(got[:, 1], lam.imag, rtol=1e-12, atol=1e-12)
        moduli = np.hypot(got[:, 0], got[:, 1])
        assert np.all(np.diff(moduli) >= -1e-12)


def test_a_formula_ending_in_an_array_constant_keeps_its_brace(sheet_from, tmp_path):
    """xlsxwriter takes a last '}' for the brace of {=...}: a matrix literal at the end of a
    formula would lose it (=a_*{1,0;0,1); the formula is bracketed instead."""
    import openpyxl

    sheet = sheet_from('[inputs]\na = "2"\n[definitions]\nM = "a*[[1, 2], [3, 4]]"\n', name="m")
    out = tmp_path / "m.xlsx"
    sheet.write_xlsx(out)
    ws = openpyxl.load_workbook(out)["Matrices"]
    formulas = [
        c.value.text if hasattr(c.value, "text") else c.value
        for row in ws.iter_rows()
        for c in row
        if c.data_type == "f" or hasattr(c.value, "text")
    ]
    assert formulas, "no formula written"
    for f in formulas:
        assert f.count("{") == f.count("}"), f
