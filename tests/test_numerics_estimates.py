"""Hard cases of the numerical built-ins, each against an exact reference (mpmath at 50
digits or a closed form): the value within its error estimate, or refused naming why."""

from pathlib import Path

import mpmath
import numpy as np
import pytest

import workbook
from workbook.numerics import NumericsError

mpmath.mp.dps = 50


def value(tmp_path: Path, expr: str, tolerance: float | None = None, extra: str = ""):
    """(value, largest error estimate of the built-ins) of EXPR in a sheet of its own."""
    head = f"[sheet]\ntolerance = {tolerance}\n" if tolerance else ""
    path = tmp_path / "s.toml"
    path.write_text(f'{head}[definitions]\n{extra}y = "{expr}"\n', encoding="utf-8")
    s = workbook.load(path)
    v = s.evaluate("y").magnitude
    estimates = [float(np.max(r.error)) for _, r in s.evaluator.records if r.error.size]
    return v, max(estimates, default=0.0)


def right(tmp_path, expr: str, exact, rel: float = 1e-9, **kw):
    """The value is within rel of the exact one and within its estimate (x 1.01)."""
    v, est = value(tmp_path, expr, **kw)
    v, exact = float(v), float(exact)
    assert abs(v - exact) <= rel * max(abs(exact), 1e-300), (v, exact)
    assert abs(v - exact) <= 1.01 * est + 1e-300, (v, exact, est)
    return v, est


# `* sign(x + 1)` (1 on the bracket) takes the interval extension away: the samples decide
@pytest.mark.parametrize("plain", ["", " * sign(x + 1)"])
@pytest.mark.parametrize(
    "expr, exact",
    [
        # a sample lands on the pole 0.5 (inf); the root 0.5 + 1e-8 is beside it
        ("root((1/(x - 0.5) - 1e8){}, x, 0.4, 0.6)", mpmath.mpf("0.5") + mpmath.mpf("1e-8")),
        # exp overflows past 709.78: the samples at 725 .. 800 are inf
        ("root((exp(x) - 1e300){}, x, 600, 800)", mpmath.log(mpmath.mpf("1e300"))),
        ("root((exp(x) - 1e300){}, x, 600)", mpmath.log(mpmath.mpf("1e300"))),
    ],
)
def test_an_infinite_sample_keeps_its_sign(tmp_path, expr, exact, plain):
    """An infinite sample (a pole hit exactly, overflow) was refused as "not a finite
    number" though the bracket changes sign at a root; brentq solves both."""
    right(tmp_path, expr.format(plain), exact)


@pytest.mark.parametrize("plain", ["", " * sign(x + 1)"])
def test_a_sign_change_at_an_infinite_sample_is_still_a_pole(tmp_path, plain):
    with pytest.raises(NumericsError, match="a pole, not a root"):
        value(tmp_path, f"root(1/(x - 0.5){plain}, x, 0.4, 0.6)")
