"""Nested integrals whose inner integrand is singular, or has a kink, at a bound that is the
outer variable: against mpmath at 50 digits."""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest

from workbook.numerics.estimates import estimate_findings

HEAD = "[sheet]\ntolerance = 1e-10\n[definitions]\n"

mpmath.mp.dps = 50


def _outer_error(s, name: str) -> float:
    return float(np.max([r.error for _, r in s.evaluator.records if r.notes.get("in") == name][-1]))


@pytest.mark.slow
def test_an_inner_integrand_singular_at_the_variable_bound_is_integrated(sheet_from):
    s = sheet_from(
        HEAD + 'n1 = "integral(integral(1/sqrt(x - y), y, 0, x), x, 0, 1)"\n'
        'n3 = "integral(integral(ln(x - y), y, 0, x), x, 0, 1)"\n',
    )
    # refused before: the outer tanh-sinh's nodes at x = 2e-323, whose inner interval holds
    # 4 doubles; QAGS takes the piece where an inner integral is refused at a node
    n1 = s.evaluate("n1").magnitude
    assert abs(n1 - 4 / 3) <= _outer_error(s, "n1")
    assert abs(n1 - 4 / 3) < 1e-7
    n3 = s.evaluate("n3").magnitude
    assert abs(n3 + 0.75) <= max(_outer_error(s, "n3"), 1e-15)
    # the nodes of the inner integrals beside their singular end are doubles: n1's estimate
    # is above the tolerance, and warned of
    assert "estimate n1" in [f.topic for f in estimate_findings(s)]


LOAD = mpmath.mpf(0.3)


def _moment(t):
    return mpmath.mpf(0.7) * t if t < LOAD else LOAD * (1 - t)


def _inner(s):
    return mpmath.quad(_moment, [0, LOAD, s] if s > LOAD else [0, s])


@pytest.mark.slow
def test_a_beam_by_double_integration_of_a_piecewise_moment(sheet_from):
    s = sheet_from(
        HEAD
        + 'b1 = "integral(integral(0.7*t if t < 0.3 otherwise 0.3*(1 - t), t, 0, s), s, 0, 1)"\n'
        'b3 = "integral(integral((0.7*t if t < 0.3 otherwise 0.3*(1 - t))*(s - t), t, 0, s),'
        ' s, 0, 1)"\n',
    )
    exact = {
        "b1": mpmath.quad(_inner, [0, 0.3, 1]),
        "b3": mpmath.quad(
            lambda s: mpmath.quad(
                lambda t: _moment(t) * (s - t), [0, mpmath.mpf(0.3), s] if s > 0.3 else [0, s]
            ),
            [0, 0.3, 1],
        ),
    }
    for name, want in exact.items():
        v = s.evaluate(name).magnitude
        err = abs(v - float(want))
        # the kink of the outer integrand where the bound crosses the load is a break point,
        # and the spot check's inner integral is split there too: the estimate was 3.7e-6
        # relative (warned) for an error of 1.4e-11 (5.8e-6 for 1.5e-10)
        assert err <= 1e-10 * abs(float(want)), (name, v, want)
        assert err <= max(_outer_error(s, name), 1e-17), (name, err)
    assert not [f for f in estimate_findings(s) if f.topic.startswith("estimate")]


def _counting_spot_checks(monkeypatch) -> list[int]:
    """The evaluations of integrands each rounding spot check makes, recorded as it runs."""
    from workbook.numerics import mpform, rounding

    counts: list[int] = []
    spend, check = mpform.spend_evaluation, rounding.discrepancy

    def counted(*args, **kwargs):
        calls = [0]

        def spending():
            calls[0] += 1
            spend()

        monkeypatch.setattr(mpform, "spend_evaluation", spending)
        try:
            return check(*args, **kwargs)
        finally:
            monkeypatch.setattr(mpform, "spend_evaluation", spend)
            counts.append(calls[0])

    monkeypatch.setattr(rounding, "discrepancy", counted)
    return counts


def _nested(depth: int, leaf: str) -> str:
    """integral(integral(...(leaf in u1)..., u1, 0, s1)..., s_depth, 0, y): depth integrals."""
    body = leaf
    for k in range(1, depth + 1):
        body = f"integral({body}, u{k}, 0, u{k + 1})"
    return body.replace(f"u{depth + 1}", "y")


@pytest.mark.slow
def test_a_nested_integral_is_spot_checked_within_its_bound(sheet_from, monkeypatch):
    """The spot check of an integral's own rounding evaluates its integrand in mpmath; an
    integral inside it costs hundreds of evaluations at each point checked, so the check stops
    at INNER_EVALUATIONS in all (nested twice, it is left out, not run for minutes)."""
    from workbook.numerics.rounding import INNER_EVALUATIONS

    counts = _counting_spot_checks(monkeypatch)
    plain = "".join(f"{v} = {{ unit = '' }}\n" for v in ("y", "u1", "u2"))
    s = sheet_from(
        f"[arguments]\n{plain}[definitions]\n"
        f'"g(y)" = "{_nested(1, "y*cos(u1)")}"\nK = "integral(g(y), y, 0, 1)"\n'
        f'"h(y)" = "{_nested(2, "exp(u1/2)")}"\nJ = "integral(h(y), y, 0, 1)"\n',
        name="nested",
    )
    # K = int_0^1 y sin(y) dy = sin 1 - cos 1; J = 8 (e^(1/2) - 1) - 5
    assert s.evaluate("K").magnitude == pytest.approx(math.sin(1) - math.cos(1), rel=1e-12)
    assert s.evaluate("J").magnitude == pytest.approx(8 * math.expm1(0.5) - 5, rel=1e-12)
    assert counts and max(counts) <= INNER_EVALUATIONS + 1
    assert any(0 < n <= INNER_EVALUATIONS for n in counts)  # K's, with one inner integral
    assert INNER_EVALUATIONS + 1 in counts  # J's, with two: stopped, and left out
