"""lu, rref and geninv: against Mathcad Prime's stored results (../shared, skipped when absent),
against SciPy and SymPy, and their units and refusals."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
import scipy.linalg
import sympy
from helpers.paths import SHARED

from workbook.errors import WorkbookError
from workbook.functions.factorizations import geninv, lu, rref
from workbook.functions.matrix import SINGULAR_COND

PRIME = SHARED / "mathcad-prime"
needs_corpus = pytest.mark.skipif(not PRIME.is_dir(), reason=f"{PRIME} is absent")


def _stored(name: str) -> dict[str, np.ndarray]:
    """The matrices Prime stored in a worksheet, by the text of their region."""
    out = subprocess.run(
        [sys.executable, str(PRIME / "mcdx_results.py"), "--json", str(PRIME / name)],
        capture_output=True,
        text=True,
        check=True,
        timeout=120,
    )
    matrices = {}
    for item in json.loads(out.stdout)["items"]:
        value = item.get("value")
        if isinstance(value, dict) and "elements" in value:
            flat = [float(e["real"]) for e in value["elements"]]
            matrices[item["text"]] = np.array(flat).reshape(value["cols"], value["rows"]).T
    return matrices


@needs_corpus
def test_lu_rref_geninv_reproduce_mathcads_stored_values():
    """linear-systems-lab.mcdx: lu(N) (an 8x8 whose partial-pivoting LU has other pivots),
    rref(augment(N, w)) and geninv(M), each against the result Prime stored."""
    stored = _stored("linear-systems-lab.mcdx")
    n, w, m = stored["N ="], stored["w ="], stored["M ="]
    b = stored["B ="]
    got = lu(n)
    assert np.array_equal(got[:, :8], b[:, :8])  # the permutation: Mathcad's pivots
    assert np.allclose(got, b, rtol=1e-12, atol=1e-12 * np.abs(b).max())
    p, low, up = scipy.linalg.lu(n)
    assert not np.array_equal(p.T, b[:, :8])  # LAPACK's pivots are others
    ag = stored["Ag ="]
    assert np.allclose(rref(np.hstack([n, w])), ag, rtol=1e-12, atol=1e-12 * np.abs(ag).max())
    g = stored["geninv(M) ="]
    assert np.allclose(geninv(m, SINGULAR_COND), g, rtol=1e-12, atol=1e-12 * np.abs(g).max())


@pytest.mark.parametrize("seed", range(5))
def test_lu_is_a_factorization_with_scaled_pivots(seed):
    """P M = L U; the pivots are those of partial pivoting on M with each row divided by its
    largest element (SciPy's LU of that matrix). The last column holds each row's largest
    element, so that no two rows tie in the columns before it."""
    rng = np.random.default_rng(seed)
    m = rng.normal(size=(6, 6)) * np.exp(rng.normal(size=(6, 1)) * 3)
    m[:, -1] = rng.uniform(2, 5, size=6) * np.abs(m).max(axis=1)
    out = lu(m)
    p, low, up = out[:, :6], out[:, 6:12], out[:, 12:]
    assert np.allclose(p @ m, low @ up, rtol=0, atol=1e-12 * np.abs(m).max())
    assert np.allclose(np.diag(low), 1) and np.allclose(np.triu(low, 1), 0)
    assert np.allclose(np.tril(up, -1), 0)
    scaled = m / np.abs(m).max(axis=1, keepdims=True)
    ps, _, _ = scipy.linalg.lu(scaled)
    assert np.array_equal(p, ps.T)


def test_rref_against_sympy_exact():
    a = [[1, 2, -1, 3], [2, 4, 0, 2], [3, 6, -1, 5], [0, 0, 1, -2]]
    exact = np.array(sympy.Matrix(a).rref()[0].tolist(), dtype=float)
    assert np.allclose(rref(np.array(a, dtype=float)), exact, rtol=0, atol=1e-14)


def test_geninv_is_the_left_inverse():
    rng = np.random.default_rng(3)
    m = rng.normal(size=(7, 3))
    g = geninv(m, SINGULAR_COND)
    assert np.allclose(g @ m, np.eye(3), atol=1e-13)
    assert np.allclose(g, scipy.linalg.pinv(m), rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize(
    "expr, message",
    [
        ("lu([[1, 2], [2, 4]])", "singular"),
        ("lu([[1, 2], [3, 4]] * 1 m)", "divide the matrix by its unit"),
        ("lu([[1, 2, 3], [3, 4, 5]])", "square"),
        ("geninv([[1, 2, 3], [3, 4, 5]])", "at least as many rows as columns"),
        ("geninv([[1, 2], [2, 4], [3, 6]])", "dependent"),
    ],
)
def test_refusals(sheet_from, expr, message):
    sheet_text = f'[definitions]\nX = "{expr}"\n'
    with pytest.raises(WorkbookError, match=message):
        sheet_from(sheet_text).evaluate("X")


def test_units(sheet_from):
    text = (
        "[definitions]\n"
        'R = "rref([[1, 2, 5], [3, 4, 11]] * 1 kN)"\n'
        'G = "geninv([[2, 0], [0, 4], [0, 0]] * 1 m)"\n'
    )
    sheet = sheet_from(text)
    r, g = sheet.evaluate("R"), sheet.evaluate("G")
    assert str(r.units) == "dimensionless"
    assert np.allclose(r.magnitude, [[1, 0, 1], [0, 1, 2]])
    assert np.allclose(g.to("1/m").magnitude, [[0.5, 0, 0], [0, 0.25, 0]])
