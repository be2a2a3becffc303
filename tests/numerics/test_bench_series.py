"""`workbook bench` covers sum and product: every term in mpmath at 32 digits, added by
fsum; checked against closed forms from mpmath at 50 digits (Hurwitz zeta, the product
formula of sinh)."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

from workbook.numerics import bench

SHEET = """
[sheet]
tolerance = 1e-10
[arguments]
i = { unit = "" }
[definitions]
zeta = "sum(1/i^2, i, 1, 10000)"
canc = "sum(1/i - 1/(i + 1e-9), i, 1, 10000)"
prod = "product(1 + 1/i^2, i, 1, 1000)"
v = "sum([1, 2, 3])"
"""


@pytest.mark.slow
def test_bench_compares_sums_and_products_with_mpmath(sheet_from):
    sheet = sheet_from(SHEET, name="s")
    lines = {line.what: line for line in bench.run(sheet, repeats=1)}
    assert set(lines) == {"zeta", "canc", "prod"}  # sum(v) of a vector has no estimate
    with mpmath.workdps(50):
        zeta = mpmath.zeta(2) - mpmath.zeta(2, 10001)
        canc = mpmath.fsum(1 / mpmath.mpf(i) - 1 / (i + mpmath.mpf(1e-9)) for i in range(1, 10001))
        prod = mpmath.fprod(1 + 1 / mpmath.mpf(i) ** 2 for i in range(1, 1001))
    for name, exact in (("zeta", zeta), ("canc", canc), ("prod", prod)):
        line = lines[name]
        assert line.reference == "mpmath" and line.checked == 1, line.text()
        value = sheet.evaluate(name).magnitude
        # the reference is right: the engine's difference from it is its difference from exact
        true = float(abs(value - exact) / abs(exact))
        assert np.isclose(line.difference, true, rtol=0.1, atol=1e-15), (line.text(), true)
    assert lines["zeta"].verdict == lines["prod"].verdict == "ok"
    assert lines["canc"].verdict == "beyond tolerance (estimated)"  # its cancellation: 4e-8
