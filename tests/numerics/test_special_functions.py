"""The special functions (gamma, erf, erfc, the Bessel functions, factorial, combin, permut)
against mpmath at 50 digits, their Excel forms against the `formulas` package, their domains;
the decompositions (cholesky, qr, svd) against mpmath and their defining identities."""

from __future__ import annotations

import re

import mpmath
import numpy as np
import pytest
from helpers.sheets import definitions

from workbook import WorkbookError
from workbook.functions.special import NAMES

# name -> (mpmath reference, argument tuples, relative tolerance)
_X = [-2.7, -0.9, -0.05, 0.3, 1.0, 2.5, 6.1]
_POS = [0.05, 0.7, 1.0, 3.3, 9.5, 20.0]
CASES = {
    "gamma": (mpmath.gamma, [(x,) for x in _X + [0.5, 10.0, 25.5]], 1e-13),
    "erf": (mpmath.erf, [(x,) for x in _X], 1e-15),
    "erfc": (mpmath.erfc, [(x,) for x in _X + [4.5]], 1e-14),
    "factorial": (mpmath.factorial, [(n,) for n in (0, 1, 5, 12, 20, 30)], 1e-15),
    "combin": (mpmath.binomial, [(5, 2), (10, 0), (10, 10), (30, 14), (52, 5)], 1e-15),
    "permut": (mpmath.ff, [(5, 2), (10, 0), (10, 10), (20, 7)], 1e-15),
    "bessel_j": (mpmath.besselj, [(n, x) for n in (0, 1, 3) for x in _X], 1e-12),
    "bessel_y": (mpmath.bessely, [(n, x) for n in (0, 1, 4) for x in _POS], 1e-12),
    "bessel_i": (mpmath.besseli, [(n, x) for n in (0, 1, 2) for x in _X], 1e-13),
    "bessel_k": (mpmath.besselk, [(n, x) for n in (0, 1, 3) for x in _POS], 1e-13),
}


def test_every_special_function_is_tested_here():
    assert set(CASES) == NAMES


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(CASES))
def test_special_function_agrees_with_mpmath(sheet_from, name):
    reference, points, rel = CASES[name]
    defs = {f"v{k}": f"{name}({', '.join(map(str, p))})" for k, p in enumerate(points)}
    sheet = sheet_from(definitions(defs))
    with mpmath.workdps(50):
        for k, p in enumerate(points):
            want = float(reference(*(mpmath.mpf(str(a)) for a in p)))
            got = float(sheet.evaluate(f"v{k}").magnitude)
            assert got == pytest.approx(want, rel=rel, abs=1e-300), (name, p)


def test_mathcads_fixed_orders_are_the_general_ones(sheet_from):
    sheet = sheet_from(definitions({"a": "bessel_j(1, 2.5) - bessel_j(-1, 2.5)"}))
    # J_-1 = -J_1: a negative whole order is defined
    assert float(sheet.evaluate("a").magnitude) == pytest.approx(
        2 * float(mpmath.besselj(1, 2.5)), rel=1e-14
    )


@pytest.mark.parametrize(
    "text",
    [
        "gamma(-2)",
        "gamma(0)",
        "factorial(2.5)",
        "factorial(-1)",
        "combin(5, 6)",
        "combin(5.5, 2)",
        "permut(4, -1)",
        "bessel_j(1.5, 2)",
        "bessel_y(0, 0)",
        "bessel_k(1, -1)",
    ],
)
def test_outside_the_domain_is_an_error_not_a_number(sheet_from, text):
    with pytest.raises(WorkbookError, match="not a finite number"):
        sheet_from(f'[definitions]\nbad = "{text}"\n').evaluate("bad")


@pytest.mark.parametrize(
    "text, message",
    [
        ("gamma(L)", "needs a dimensionless argument"),
        ("bessel_j(1, L)", "needs a dimensionless argument"),
        ("erf(1, 2)", "takes 1 argument(s), got 2"),
    ],
)
def test_arguments_are_plain_numbers(sheet_from, text, message):
    text = f'[inputs]\nL = "1 m"\n\n[definitions]\nbad = "{text}"\n'
    with pytest.raises(WorkbookError, match=re.escape(message)):
        sheet_from(text)


def test_gamma_is_the_factorial_shifted(sheet_from):
    sheet = sheet_from(definitions({"a": "gamma(7)", "b": "factorial(6)", "c": "combin(6, 2) * 2"}))
    assert float(sheet.evaluate("a").magnitude) == float(sheet.evaluate("b").magnitude) == 720
    assert float(sheet.evaluate("c").magnitude) == 30


EXCEL_CASES = {
    "c_gamma": ("gamma(x)", "GAMMA("),
    "c_erf": ("erf(x)", "ERF("),
    "c_erfc": ("erfc(x)", "ERFC("),
    "c_fact": ("factorial(n)", "FACT("),
    "c_combin": ("combin(n, k)", "COMBIN("),
    "c_permut": ("permut(n, k)", "PERMUT("),
    "c_j": ("bessel_j(k, x)", "BESSELJ("),
    "c_y": ("bessel_y(k, x)", "BESSELY("),
    "c_i": ("bessel_i(k, x)", "BESSELI("),
    "c_k": ("bessel_k(k, x)", "BESSELK("),
}


def _workbook(sheet_from, tmp_path):
    text = '[inputs]\nx = "1.7"\nn = "7"\nk = "2"\n\n[definitions]\n'
    text += "".join(f'{k} = "{v}"\n' for k, (v, _) in EXCEL_CASES.items())
    sheet = sheet_from(text, name="special")
    return sheet, sheet.write_xlsx(tmp_path / "special.xlsx")


def _cells_of(cells, function: str) -> list:
    pattern = re.compile(rf"(?<![A-Z]){re.escape(function)}")
    found = [key for key, (f, _) in cells.items() if pattern.search(f)]
    assert len(found) == 1, (function, found)
    return found[0]


def test_excel_forms_are_excels_functions(sheet_from):
    """Each call is printed as Excel's function (GAMMA with its prefix, BESSELJ x first)."""
    from workbook.compute.excel import ExcelPrinter

    text = '[inputs]\nx = "1.7"\nn = "7"\nk = "2"\n\n[definitions]\n'
    text += "".join(f'{k} = "{v}"\n' for k, (v, _) in EXCEL_CASES.items())
    sheet = sheet_from(text)
    printer = ExcelPrinter(sheet.typer, {"x": "x_", "n": "n_", "k": "k_"})
    printed = {name: printer.formula(sheet.typer.scalar(name), {}) for name in EXCEL_CASES}
    assert printed["c_gamma"] == "=_xlfn.GAMMA(x_)"
    assert printed["c_j"] == "=BESSELJ(x_, k_)"
    assert printed["c_combin"] == "=COMBIN(n_, k_)"
    for name, (_, function) in EXCEL_CASES.items():
        assert function in printed[name], (name, printed[name])


@pytest.mark.slow
def test_excel_forms_agree_with_the_formulas_package(sheet_from, tmp_path):
    """Every live formula recalculated by `formulas` (which has no COMBIN: checked by
    LibreOffice below) agrees with the engine."""
    formulas = pytest.importorskip("formulas")
    from helpers.recalc import formula_values

    sheet, path = _workbook(sheet_from, tmp_path)
    cells = formula_values(path)
    solution = formulas.ExcelModel().loads(str(path)).finish().calculate()
    recalculated = {}
    for key, ranges in solution.items():
        book_sheet, _, cell = key.rpartition("!")
        if ":" in cell or "]" not in book_sheet:
            continue
        recalculated[(book_sheet.split("]", 1)[1].strip("'").upper(), cell)] = ranges.value[0, 0]
    for name, (_, function) in EXCEL_CASES.items():
        key = _cells_of(cells, function)
        if function == "COMBIN(":
            continue
        got = recalculated[(key[0].upper(), key[1])]
        engine = float(sheet.evaluate(name).magnitude)
        assert float(got) == pytest.approx(engine, rel=1e-12), (name, cells[key][0])


@pytest.mark.slow
def test_libreoffice_recalculates_the_special_functions(sheet_from, tmp_path):
    from helpers.recalc import cell_values, formula_values, recalculate, soffice

    if soffice() is None:
        pytest.skip("LibreOffice is not installed")
    sheet, path = _workbook(sheet_from, tmp_path)
    cells = formula_values(path)
    values = cell_values(recalculate(path, tmp_path / "out"))
    for name, (_, function) in EXCEL_CASES.items():
        key = _cells_of(cells, function)
        engine = float(sheet.evaluate(name).magnitude)
        # LibreOffice's Bessel functions are series of its own (BESSELK(1.7, 2): 2.2e-8)
        rel = 1e-7 if function.startswith("BESSEL") else 1e-12
        assert float(values[key]) == pytest.approx(engine, rel=rel), (name, cells[key][0])


# -- decompositions -------------------------------------------------------------------------------
A = [[4.0, 12.0, -16.0], [12.0, 37.0, -43.0], [-16.0, -43.0, 98.0]]
B = [[1.0, 0.0, 7.0], [9.0, 5.0, 8.0], [3.0, 4.0, 2.0], [2.0, -1.0, 0.5]]


def _matrix(sheet, name):
    return np.asarray(sheet.evaluate(name).magnitude, dtype=float)


def test_cholesky_against_mpmath(sheet_from):
    sheet = sheet_from(definitions({"A": str(A), "L": "cholesky(A)"}))
    with mpmath.workdps(50):
        want = np.array(mpmath.cholesky(mpmath.matrix(A)).tolist(), dtype=float)
    assert _matrix(sheet, "L") == pytest.approx(want, rel=1e-14, abs=1e-14)
    assert np.allclose(want, [[2, 0, 0], [6, 1, 0], [-8, 5, 3]])


def test_cholesky_keeps_the_square_root_of_the_unit(sheet_from):
    text = '[definitions]\nA = "[[4, 2], [2, 3]] * 1 m^2"\nL = "cholesky(A)"\n'
    sheet = sheet_from(text)
    assert str(sheet.evaluate("L").units) == "meter"


@pytest.mark.parametrize(
    "text, message",
    [
        ("cholesky([[1, 2], [3, 4]])", "not symmetric"),
        ("cholesky([[1, 2], [2, 1]])", "not positive definite"),
    ],
)
def test_cholesky_refuses(sheet_from, text, message):
    with pytest.raises(WorkbookError, match=message):
        sheet_from(f'[definitions]\nbad = "{text}"\n').evaluate("bad")


def test_qr_is_q_times_r(sheet_from):
    sheet = sheet_from(definitions({"B": str(B), "QR": "qr(B)"}))
    qr = _matrix(sheet, "QR")
    assert qr.shape == (4, 7)
    q, r = qr[:, :4], qr[:, 4:]
    assert q @ q.T == pytest.approx(np.eye(4), abs=1e-14)
    assert q @ r == pytest.approx(np.array(B), rel=1e-13, abs=1e-13)
    assert np.allclose(np.tril(r, -1), 0, atol=1e-14)
    assert np.all(np.diag(r) >= 0)
    with mpmath.workdps(50):  # R^T R = B^T B, R's diagonal positive: R is the Cholesky factor
        gram = mpmath.matrix(B).T * mpmath.matrix(B)
        want = np.array(mpmath.cholesky(gram).T.tolist(), dtype=float)
    assert r[:3] == pytest.approx(want, rel=1e-13, abs=1e-13)


def test_svd_against_mpmath(sheet_from):
    sheet = sheet_from(definitions({"B": str(B), "UV": "svd(B)", "s": "svds(B)"}))
    uv = _matrix(sheet, "UV")
    assert uv.shape == (7, 3)
    u, v, s = uv[:4], uv[4:], _matrix(sheet, "s").reshape(-1)
    assert u @ np.diag(s) @ v.T == pytest.approx(np.array(B), rel=1e-13, abs=1e-13)
    assert v.T @ v == pytest.approx(np.eye(3), abs=1e-14)
    for j in range(3):
        assert u[np.argmax(np.abs(u[:, j])), j] > 0
    with mpmath.workdps(50):
        want = sorted(mpmath.svd_r(mpmath.matrix(B), compute_uv=False), reverse=True)
    assert s == pytest.approx([float(w) for w in want], rel=1e-14)


@pytest.mark.parametrize(
    "text, message",
    [
        ("qr([[1, 2], [3, 4]] * 1 m)", "one matrix of one unit"),
        ("svd([[1, 2, 3], [4, 5, 6]])", "at least as many rows as columns"),
    ],
)
def test_qr_and_svd_refuse(sheet_from, text, message):
    with pytest.raises(WorkbookError, match=message):
        sheet_from(f'[definitions]\nbad = "{text}"\n')
