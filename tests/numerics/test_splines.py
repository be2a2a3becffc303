"""Mathcad's spline pair (lspline, pspline, cspline(vx, vy) and interp) against splines built
independently: SymPy solves the conditions of each piecewise cubic exactly (continuity of the
value, slope and curvature, and the end conditions), in rationals."""

from __future__ import annotations

import re
from fractions import Fraction

import numpy as np
import pytest
import sympy

from workbook import WorkbookError

XS = ["0", "0.5", "1.1", "2", "3.2", "4"]
YS = ["1", "2.5", "1.7", "0.3", "-0.4", "0.2"]

SHEET = f"""
[inputs]
L = "1 m"

[arguments]
t = {{ unit = "s" }}

[definitions]
X = "[{", ".join(XS)}]*1 s"
Y = "[{", ".join(YS)}]*L"
N = "lspline(X, Y)"
P = "pspline(X, Y)"
C = "cspline(X, Y)"
"n(t)" = {{ expr = "interp(N, X, Y, t)", unit = "m" }}
"p(t)" = {{ expr = "interp(P, X, Y, t)", unit = "m" }}
"c(t)" = {{ expr = "interp(C, X, Y, t)", unit = "m" }}
"direct(t)" = {{ expr = "cspline(X, Y, t)", unit = "m" }}
"straight(t)" = {{ expr = "linterp(X, Y, t)", unit = "m" }}
"""


def _exact_spline(ends: str):
    """The piecewise cubic's coefficients, exactly: s_i(x) = a + b u + c u^2 + d u^3 with
    u = x - x_i on [x_i, x_(i+1)]."""
    xs = [sympy.Rational(Fraction(v)) for v in XS]
    ys = [sympy.Rational(Fraction(v)) for v in YS]
    n = len(xs) - 1
    co = sympy.symbols(f"c0:{4 * n}")
    piece = [co[4 * i : 4 * i + 4] for i in range(n)]

    def value(i, u, k=0):
        u_ = sympy.Symbol("u")
        a, b, c, d = piece[i]
        return sympy.diff(a + b * u_ + c * u_**2 + d * u_**3, u_, k).subs(u_, u)

    eqs = []
    for i in range(n):
        h = xs[i + 1] - xs[i]
        eqs += [value(i, 0) - ys[i], value(i, h) - ys[i + 1]]
        if i < n - 1:
            eqs += [value(i, h, 1) - value(i + 1, 0, 1), value(i, h, 2) - value(i + 1, 0, 2)]
    last = xs[-1] - xs[-2]
    if ends == "linear":
        eqs += [value(0, 0, 2), value(n - 1, last, 2)]
    elif ends == "parabolic":
        eqs += [piece[0][3], piece[n - 1][3]]  # no cubic term in the end intervals
    else:
        eqs += [piece[0][3] - piece[1][3], piece[n - 2][3] - piece[n - 1][3]]
    solution = sympy.solve(eqs, co, rational=True)
    return xs, [[solution[c] for c in p] for p in piece]


def _exact(ends: str, x: float) -> tuple[float, float]:
    """(value at x, second derivative at x) of the exact spline."""
    xs, pieces = _exact_spline(ends)
    xr = sympy.Rational(Fraction(x))
    i = max(k for k in range(len(pieces)) if xs[k] <= xr)
    a, b, c, d = pieces[i]
    u = xr - xs[i]
    return float(a + b * u + c * u**2 + d * u**3), float(2 * c + 6 * d * u)


@pytest.mark.slow
@pytest.mark.parametrize(
    "ends, vector, function", [("linear", "N", "n"), ("parabolic", "P", "p"), ("cubic", "C", "c")]
)
def test_spline_against_the_exact_one(sheet, ends, vector, function):
    ms = sheet.evaluate(vector)
    assert str(ms.units) == "meter / second ** 2"
    got = np.asarray(ms.magnitude, dtype=float).ravel()
    want = [_exact(ends, float(x))[1] for x in XS[:-1]] + [_exact_spline_end(ends)]
    assert got == pytest.approx(want, rel=1e-13, abs=1e-13)
    for x in (0.0, 0.25, 1.1, 1.5, 2.7, 3.99, 4.0):
        value = sheet.evaluate(function, x).to("m").magnitude
        assert value == pytest.approx(_exact(ends, x)[0], rel=1e-14, abs=1e-14), x


def _exact_spline_end(ends: str) -> float:
    xs, pieces = _exact_spline(ends)
    a, b, c, d = pieces[-1]
    u = xs[-1] - xs[-2]
    return float(2 * c + 6 * d * u)


def test_cubic_ends_are_cspline_of_three_arguments(sheet):
    x = np.linspace(0, 4, 41)
    got, direct = sheet.evaluate("c", x).magnitude, sheet.evaluate("direct", x).magnitude
    assert got == pytest.approx(direct, rel=1e-14, abs=1e-15)  # SciPy's not-a-knot spline


def test_linterp_reads_vectors_of_the_sheet_by_name(sheet):
    assert sheet.evaluate("straight", 1.5).to("m").magnitude == pytest.approx(
        1.7 + (0.3 - 1.7) * (1.5 - 1.1) / (2 - 1.1), rel=1e-15
    )


@pytest.mark.parametrize(
    "line, message",
    [
        ('bad = "interp(Y, X, Y, 1 s)"', "interp(vs, vx, vy, x): vs (a spline of vx, vy)"),
        ('bad = "interp(N, X, [1, 2]*L, 1 s)"', "have 6, 6 and 2 points"),
        ('bad = "lspline(X, [1, 2]*L)"', "vx has 6 points and vy 2"),
        ('bad = "lspline(X, 3)"', "argument 2 must be a column of a [data] table"),
        ('bad = "interp(N, X, Y, 1 m)"', "interp(vs, vx, vy, x): x"),
    ],
)
def test_spline_errors_at_load(sheet_from, line, message):
    with pytest.raises(WorkbookError, match=re.escape(message)):
        sheet_from(SHEET + line + "\n")


def test_outside_the_points_is_an_error(sheet):
    with pytest.raises(WorkbookError, match=r"x = 4.5 is outside the data \[0, 4\]"):
        sheet.evaluate("n", 4.5)


def test_written_as_values(sheet, tmp_path):
    import openpyxl

    path = sheet.write_xlsx(tmp_path / "spl.xlsx")
    assert openpyxl.load_workbook(path)  # the spline's values are numbers, with a comment
