"""workbook.numerics.symbolic: the typed tree as SymPy, derivatives, exact numbers."""

import math

import mpmath
import numpy as np
import pytest
import sympy as sp

import workbook
from workbook.engine.analysis import true_pi_sheet
from workbook.errors import NotSymbolic
from workbook.numerics import symbolic


def test_exact_numbers():
    assert symbolic.exact_number(0.001) == sp.Rational(1, 1000)
    assert symbolic.exact_number(1.5) == sp.Rational(3, 2)
    assert symbolic.exact_number(math.pi / 180) == sp.pi / 180
    assert symbolic.exact_number(104.6) == sp.Rational(523, 5)
    assert symbolic.exact_number(3.0) == 3


def test_h1_is_the_engine_formula(concave):
    expr = symbolic.to_sympy(concave, "h1")
    phi = symbolic.symbol("phi")
    assert expr.free_symbols == {phi}
    f = symbolic.lambdify(concave, expr, "phi")
    x = np.linspace(0, 22, 23)
    assert np.allclose(f(x), concave.evaluate("h1", phi=x).to("mm").magnitude, rtol=0, atol=1e-13)


def test_piecewise_and_inputs_kept_as_symbols(concave):
    h = symbolic.to_sympy(concave, "h")
    assert isinstance(h, sp.Piecewise) and len(h.args) == 4  # three pieces and the nan 'no piece'
    kept = symbolic.to_sympy(concave, "h1", keep={"R1", "R3", "Rp", "k", "deg"})
    assert {s.name for s in kept.free_symbols} == {"R1", "R3", "Rp", "k", "deg", "phi"}
    body = concave.typer.function("h1").body
    assert symbolic.text(concave, body).startswith("-R1 - Rp + (R1 + R3)*(cos(deg*phi)")


def test_derivative_per_radian_is_v1_with_the_true_pi(concave):
    ref = true_pi_sheet(concave)
    d = symbolic.derivative(ref, "h1", "phi")
    f = symbolic.lambdify(ref, d * symbolic.per_radian(ref, "phi"), "phi")
    x = np.linspace(0, 22, 45)
    omega = 104.6
    v = ref.evaluate("v1", phi=x).to("mm/s").magnitude
    assert np.max(np.abs(omega * f(x) - v)) < 1e-9 * np.max(np.abs(v))
    assert symbolic.per_radian(concave, "phi") == pytest.approx(180 / math.pi, rel=1e-15)


def test_true_pi_option(concave):
    a = symbolic.to_sympy(concave, "deg")
    b = symbolic.to_sympy(concave, "deg", true_pi=True)
    assert a == sp.Rational(3142, 1000) / 180
    assert b == sp.pi / 180


def test_stable_lift_form_is_algebraically_formula_1():
    """The geometry sheet's hf (stable form) equals formula (1) to 60 digits."""
    g = workbook.load("concave-cam-geometry")
    stable = symbolic.to_sympy(g, "hf")
    phi = symbolic.symbol("phi")
    R1, R3, Rp = 20, 50, 10
    d, c = R1 + R3, R3 - Rp
    k = sp.Rational(d, c)
    x = phi * sp.pi / 180
    formula1 = d * (sp.cos(x) - 1 / k * sp.sqrt(1 - k**2 * sp.sin(x) ** 2)) - (R1 + Rp)
    for p in ("0.5", "3", "11.25", "18"):
        diff = (stable - formula1).evalf(60, subs={phi: sp.Rational(p)})
        assert abs(diff) < 1e-50
    # and numerically with mpmath at a small angle, where formula (1) cancels
    mpmath.mp.dps = 50
    xs = mpmath.mpf("1e-6") * mpmath.pi / 180
    ref = d * (mpmath.cos(xs) - mpmath.sqrt(1 - k**2 * mpmath.sin(xs) ** 2) / k) - (R1 + Rp)
    got = g.evaluate("hf", phi=1e-6).to("mm").magnitude
    assert abs(got - float(ref)) / float(ref) < 1e-15


def test_block_is_not_symbolic(tmp_path):
    with pytest.raises(NotSymbolic):
        symbolic.to_sympy(workbook.load("concave-cam"), "nothing_here")


def test_a_derivative_called_with_another_argument(sheet_from):
    # diff's variable stays the enclosing one: z(t) = v(2*t) is s'(2*t)
    sheet = sheet_from(
        '[inputs]\nA = "10 mm"\nomega = "100 1/s"\n[arguments]\nt = { unit = "s" }\n'
        "[definitions]\n"
        '"s(t)" = { expr = "A*sin(omega*t)^2", unit = "mm" }\n'
        '"v(t)" = { expr = "diff(s(t), t)", unit = "mm/s" }\n'
        '"z(t)" = "v(2*t)"\n',
        name="d",
    )
    t = symbolic.symbol("t")
    want = sp.diff(10 * sp.sin(100 * t) ** 2, t).subs(t, 2 * t)
    assert sp.simplify(symbolic.to_sympy(sheet, "z") - want) == 0
