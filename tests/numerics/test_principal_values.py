"""A non-integrable interior singularity is refused, never given its principal value (a
symmetric rule's nodes cancel across it); integrable singularities are still integrated.
Exact values from mpmath at 50 digits."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

from workbook.functions.numerical import NumericsError

mpmath.mp.dps = 50


def _value(sheet_from, expr: str):
    s = sheet_from(f'[definitions]\ny = "{expr}"\n')
    v = s.evaluate("y").magnitude
    return float(v), max(float(np.max(r.error)) for _, r in s.evaluator.records)


@pytest.mark.parametrize(
    "expr, at",
    [
        ("integral(1/(x - 0.5), x, 0, 1)", "0.5"),  # the pole at the middle: was 0
        ("integral(1/(x - 0.5)^3, x, 0, 1)", "0.5"),  # was 5.9e-15
        ("integral(x/(x^2 - 0.25), x, -1, 1)", "-0.5"),  # odd about 0: was 3.5e-17
        ("integral(tan(x), x, -2, 2)", "-1.5708"),  # odd, two poles: was 1.5e-16
        ("integral(1/(x - 0.3), x, 0, 1)", "0.3"),
        ("integral(1/x^3, x, -1, 1)", "0"),
    ],
)
def test_a_principal_value_is_not_an_integral(sheet_from, expr, at):
    with pytest.raises(
        NumericsError, match=f"singular at x = {at}, inside the interval.*principal"
    ):
        _value(sheet_from, expr)


@pytest.mark.parametrize(
    "expr, exact",
    [
        ("integral(1/sqrt(abs(x - 0.5)), x, 0, 1)", lambda: 4 * mpmath.sqrt(0.5)),
        ("integral(ln(abs(x - 0.5)), x, 0, 1)", lambda: -1 - mpmath.log(2)),
        (
            "integral(ln(abs(x - 0.3)), x, 0, 1)",
            lambda: mpmath.quad(lambda x: mpmath.log(abs(x - mpmath.mpf(0.3))), [0, 0.3, 1]),
        ),
        ("integral(x^-0.99, x, 0, 1)", lambda: mpmath.mpf(100)),
        (
            "integral(1/sqrt(abs(x - 0.3)), x, 0, 1)",
            lambda: 2 * mpmath.sqrt(0.3) + 2 * mpmath.sqrt(0.7),
        ),
        ("integral(1/sqrt(1 - x^2), x, -1, 1)", lambda: mpmath.pi),
        ("integral(x/sqrt(abs(x^2 - 0.25)), x, -1, 1)", lambda: mpmath.mpf(0)),
    ],
)
def test_integrable_singularities_are_integrated(sheet_from, expr, exact):
    v, est = _value(sheet_from, expr)
    want = float(exact())
    assert abs(v - want) <= max(10 * est, 1e-15), (v, want, est)
    assert abs(v - want) <= 1e-7 * max(abs(want), 1.0)
