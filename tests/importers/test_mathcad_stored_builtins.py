"""Built-ins against the values Mathcad Prime stored in public worksheets (../shared, read with
its own lister; skipped when absent): the distributions of statistics-functions.mcdx, the
eigenvectors (equal up to their sign, a convention) and rank of matrix-functions.mcdx."""

from __future__ import annotations

import json
import re
import subprocess
import sys

import numpy as np
import pytest
from helpers.paths import SHARED
from helpers.sheets import definitions

PRIME = SHARED / "mathcad-prime"
pytestmark = pytest.mark.skipif(not PRIME.is_dir(), reason="../shared/mathcad-prime is absent")


def _items(name: str) -> list[dict]:
    out = subprocess.run(
        [sys.executable, str(PRIME / "mcdx_results.py"), "--json", str(PRIME / name)],
        capture_output=True,
        text=True,
        check=True,
        timeout=120,
    )
    return json.loads(out.stdout)["items"]


def _number(value: dict) -> float:
    return float(value["real"])


def _matrix(value: dict) -> np.ndarray:
    """A stored matrix (column-major)."""
    flat = [float(e["real"]) for e in value["elements"]]
    return np.array(flat).reshape(value["cols"], value["rows"]).T


def _evaluate(sheet_from, values: dict[str, str]) -> dict[str, np.ndarray]:
    sheet = sheet_from(definitions(values))
    return {k: np.asarray(sheet.evaluate(k).magnitude, dtype=float) for k in values}


# the stored expression -> the same in the language, with {a} (the alpha defined above it in
# the worksheet) and {nu} (its stored nu)
DISTRIBUTIONS = {
    "p := |qt(α/2, ν)| =": "abs(qt({a}/2, {nu}))",
    "pt(1-α, ν) =": "pt(1 - {a}, {nu})",
    "z_t := qnorm(1-α/2, 0, 1) =": "qnorm(1 - {a}/2, 0, 1)",
    "z_L := qnorm(α, 0, 1) =": "qnorm({a}, 0, 1)",
    "z_R := qnorm(1-α, 0, 1) =": "qnorm(1 - {a}, 0, 1)",
}


def test_distributions_reproduce_mathcads_stored_values(sheet_from):
    alpha = nu = None
    definitions, stored = {}, {}
    for item in _items("statistics-functions.mcdx"):
        text = item["text"]
        if m := re.fullmatch(r"α := ([0-9.]+)", text):
            alpha = m.group(1)
        if text == "ν := N-1 =":
            nu = f"{_number(item['value']):g}"
        if text in DISTRIBUTIONS:
            name = f"r{item['region']}"
            definitions[name] = DISTRIBUTIONS[text].format(a=alpha, nu=nu)
            stored[name] = _number(item["value"])
    assert len(definitions) == len(DISTRIBUTIONS)
    got = _evaluate(sheet_from, definitions)
    for name, value in stored.items():
        assert float(got[name]) == pytest.approx(value, rel=1e-14), definitions[name]


def _language_matrix(text: str) -> str:
    """Mathcad's ``[3, 2; 1, 0]`` as the language's ``[[3, 2], [1, 0]]``."""
    rows = text.strip("[]").split(";")
    return "[" + ", ".join("[" + r.strip() + "]" for r in rows) + "]"


def _same_up_to_sign(got: np.ndarray, want: np.ndarray) -> bool:
    """An eigenvector's sign is a convention: Mathcad's is not documented."""
    return np.allclose(got, want, rtol=0, atol=1e-13) or np.allclose(got, -want, rtol=0, atol=1e-13)


def test_eigenvec_and_rank_reproduce_mathcads_stored_values(sheet_from):
    items = {item["text"]: item for item in _items("matrix-functions.mcdx")}
    m = next(t for t in items if t.startswith("M := ["))
    definitions = {
        "M": _language_matrix(m.split(":= ", 1)[1]),
        "e0": "eigenvec(M, eigenvals(M)[3])",  # Mathcad's e is descending: e[0] the largest
        "r": "rank(M)",
    }
    got = _evaluate(sheet_from, definitions)
    largest = _matrix(items["e := eigenvals(M) ="]["value"])[0, 0]
    assert largest == pytest.approx(np.linalg.eigvalsh(got["M"]).max(), rel=1e-14)
    want = _matrix(items["eigenvec(M, e[0]) ="]["value"])
    assert _same_up_to_sign(got["e0"], want)
    assert float(got["r"]) == _number(items["rank(M) ="]["value"])


def test_eigenvec_of_a_covariance_matrix_reproduces_mathcads(sheet_from):
    """Principal axes (matrix-functions.mcdx): T = augment of eigenvec(S1, V[j])."""
    items = {item["text"]: item for item in _items("matrix-functions.mcdx")}
    s1 = _matrix(items["S1 := X^T*X/(rows(D)-1) ="]["value"])
    values = _matrix(items["V := reverse(sort(eigenvals(S1))) ="]["value"])[:, 0]
    axes = _matrix(items["T := augment(x[0], x[1], x[2]) ="]["value"])
    rows = ", ".join("[" + ", ".join(repr(float(x)) for x in row) + "]" for row in s1)
    definitions = {"S": f"[{rows}]"}
    for j, v in enumerate(values):
        definitions[f"x{j}"] = f"eigenvec(S, {float(v)!r})"
    got = _evaluate(sheet_from, definitions)
    for j in range(3):
        assert _same_up_to_sign(got[f"x{j}"][:, 0], axes[:, j]), j
