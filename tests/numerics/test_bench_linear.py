"""`workbook bench` covers diff (mpmath.diff at 50 digits on EXPR's mpmath form, not SymPy's
formula), lsolve, inverse, det (mpmath's LU at 50 digits) and eigenvals, eigenvecs
(mpmath.eig at 50 digits): each reference checked against closed forms or mpmath directly,
and a refusal is its own line."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

from workbook.numerics import bench


def _hilbert(n: int) -> str:
    rows = ", ".join("[" + ", ".join(f"1/{i + j + 1}" for j in range(n)) + "]" for i in range(n))
    return f"[{rows}]"


SHEET = f"""
[sheet]
tolerance = 1e-10
[arguments]
x = {{ unit = "" }}
[definitions]
"f(x)" = "diff(sin(x)*exp(x), x)"
"g(x)" = "diff((exp(x) - 1 - x)/x^2, x)"
"k(x)" = "diff(x if x < 1 otherwise 2*x - 1, x)"
d1 = "f(0.7)"
dc = "g(0.001)"
kink = "k(1)"
H = "{_hilbert(10)}"
xs = "lsolve(H, [1, 1, 1, 1, 1, 1, 1, 1, 1, 1])"
A = "[[2, 1, 0], [1, 3, 1], [0, 1, 4]]"
ev = "eigenvals(A)"
evec = "eigenvecs(A)"
dt = "det(A)"
inv = "inverse(A)"
"""


def _lines(sheet_from):
    sheet = sheet_from(SHEET, name="la")
    return sheet, {line.what: line for line in bench.run(sheet, repeats=1)}


def _error(got, exact) -> float:
    got = np.ravel(np.asarray(got, dtype=float))
    exact = np.ravel(np.asarray([float(e) for e in exact]))
    return float(np.max(np.abs(got - exact)) / np.max(np.abs(exact)))


@pytest.mark.slow
def test_bench_lines_of_diff_and_linear_algebra_are_independent_and_right(sheet_from):
    sheet, lines = _lines(sheet_from)
    assert {"d1", "dc", "kink", "xs", "ev", "evec", "dt", "inv"} <= set(lines)
    assert lines["kink"].verdict.startswith("refused by the engine: diff(): the expression has")
    with mpmath.workdps(50):
        x = mpmath.mpf(0.7)
        d1 = [mpmath.exp(x) * (mpmath.sin(x) + mpmath.cos(x))]
        x = mpmath.mpf(0.001)
        dc = [mpmath.diff(lambda t: (mpmath.exp(t) - 1 - t) / t**2, x)]
        n = 10
        h = mpmath.matrix([[mpmath.mpf(1.0 / (i + j + 1)) for j in range(n)] for i in range(n)])
        xs = list(mpmath.lu_solve(h, mpmath.matrix([1] * n)))
        a = mpmath.matrix([[2, 1, 0], [1, 3, 1], [0, 1, 4]])
        ev = sorted(mpmath.eig(a)[0], key=lambda e: float(mpmath.re(e)))
        ev = [mpmath.re(e) for e in ev]
        dt = [mpmath.det(a)]
        inv = list(mpmath.inverse(a))
    for name, exact in (("d1", d1), ("dc", dc), ("xs", xs), ("ev", ev), ("dt", dt), ("inv", inv)):
        line = lines[name]
        assert line.reference == "mpmath" and line.checked >= 1, line.text()
        true = _error(sheet.evaluate(name).magnitude, exact)
        # the reference is right: the engine's difference from it is its difference from exact
        assert np.isclose(line.difference, true, rtol=0.1, atol=1e-15), (line.text(), true)
    for name in ("d1", "ev", "evec", "dt", "inv"):
        assert lines[name].verdict == "ok", lines[name].text()
    # a cancelling derivative and the Hilbert system (condition 1.6e13): off by more than
    # the tolerance, and their estimates say so
    assert lines["dc"].verdict == "beyond tolerance (estimated)", lines["dc"].text()
    assert lines["xs"].verdict == "beyond tolerance (estimated)", lines["xs"].text()
    assert lines["xs"].difference > 1e-6
