"""EXPR's own rounding in the estimates of root and of the extrema: spot-checked in mpmath
beside the result (numerics.rounding), each case against mpmath at 50 digits."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

HEAD = "[sheet]\ntolerance = 1e-10\n"

mpmath.mp.dps = 50


def _exp_m1_m(x):
    return mpmath.exp(x) - 1 - x


@pytest.mark.slow
def test_a_table_of_roots_of_a_cancelling_expression_has_honest_estimates(sheet_from):
    # 100 rows: beyond the rows the mpmath polish checks; each row's residual is the
    # difference of numbers near 1, its rounding over the slope x is the root's error
    s = sheet_from(
        HEAD + '[arguments]\nx = { unit = "" }\nc = { unit = "" }\n[definitions]\n'
        '"r(c)" = "root((exp(x) - 1 - x) - c, x, 1e-7, 1)"\n'
        '[[tables]]\nname = "t"\nrange = "c := 1e-10, 2e-10 .. 1e-8"\n'
        'columns = { "r(c)" = "" }\n',
    )
    table = s.spec.tables[0]
    cs = s.range_values(table.range, "t")
    s.column(table.columns[0], table.range.var, cs, "t")
    (res,) = [r for name, r in s.evaluator.records if name == "root"]
    ratios = []
    for c, v, e in zip(np.ravel(np.asarray(cs, float)), np.ravel(res.value), np.ravel(res.error)):
        exact = mpmath.findroot(lambda x, c=c: _exp_m1_m(x) - mpmath.mpf(c), mpmath.sqrt(2 * c))
        ratios.append(abs(float(exact) - v) / e)
    assert len(ratios) == 100
    assert max(ratios) <= 10, max(ratios)  # was 4.6e3: 89 rows off by more than 10 x
    # and the estimate says the rows are not known to the tolerance
    assert np.max(np.ravel(res.error) / np.ravel(res.value)) > 1e-8


def test_a_root_of_a_cancelling_expression_is_polished(sheet_from):
    s = sheet_from(HEAD + '[definitions]\ny = "root((exp(x) - 1 - x) - 1e-9, x, 1e-6, 1)"\n')
    v = s.evaluate("y").magnitude
    exact = mpmath.findroot(lambda x: _exp_m1_m(x) - mpmath.mpf(1e-9), 4.5e-5)
    (res,) = [r for _, r in s.evaluator.records]
    assert abs(v - float(exact)) <= max(float(res.error), 1e-20)
    assert abs(v - float(exact)) <= 1e-15 * float(exact)


def _flat_peak(x):
    return mpmath.cos(mpmath.mpf(1e-4) * x) - 1 + mpmath.mpf(1e-9) * mpmath.sin(x)


def test_the_place_of_a_cancelling_maximum_has_an_honest_estimate_and_is_warned(sheet_from):
    expr = "cos(1e-4*x) - 1 + 1e-9*sin(x)"
    s = sheet_from(
        HEAD + f'[definitions]\nm = "maximum({expr}, x, 0, 3)"\na = "argmax({expr}, x, 0, 3)"\n'
    )
    where = mpmath.findroot(lambda x: mpmath.diff(_flat_peak, x), 0.0995)
    top = _flat_peak(where)
    m, a = s.evaluate("m").magnitude, s.evaluate("a").magnitude
    est = {name: float(np.max(r.error)) for name, r in s.evaluator.records}
    assert abs(m - float(top)) <= est["maximum"]
    # the place is 4e-5 off (the flat peak's curvature is 1e-8, its rounding 1e-16): the
    # estimate, from the curvature, covers it (it was 1.8e-9)
    assert 1e-6 < abs(a - float(where)) <= est["argmax"]
    from workbook.numerics.estimates import estimate_findings

    warned = [f.topic for f in estimate_findings(s)]
    assert "estimate a" in warned, warned


def test_a_maximum_of_a_cancelling_expression_is_within_its_estimate(sheet_from):
    # (1 - cos x)/x^2 -> 1/2 at 0, computed as a difference of numbers near 1
    s = sheet_from(HEAD + '[definitions]\nm = "maximum((1 - cos(x))/x^2, x, 1e-5, 1e-3)"\n')
    m = s.evaluate("m").magnitude
    exact = max((1 - mpmath.cos(x)) / x**2 for x in (mpmath.mpf(1e-5), mpmath.mpf(1e-3)))
    (res,) = [r for _, r in s.evaluator.records]
    assert abs(m - float(exact)) <= float(np.max(res.error)), (m, exact, res.error)
