"""The numerical engine (workbook.numerics) against scipy's scalar routines and mpmath."""

import mpmath
import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from workbook.functions.numerical import NumericsError, Tolerance
from workbook.numerics.extrema import extremum
from workbook.numerics.given import solve
from workbook.numerics.interpolate import interpolate
from workbook.numerics.quadrature import integrate
from workbook.numerics.roots import root_in, root_near
from workbook.numerics.series import reduce

TIGHT = Tolerance(rtol=1e-13)


def colebrook(f, re, rr):
    return 1 / np.sqrt(f) + 2 * np.log10(rr / 3.7 + 2.51 / (re * np.sqrt(f)))


def test_root_in_every_row_matches_brentq():
    re = np.geomspace(4e3, 1e8, 50)
    got = root_in(colebrook, 0.005, 0.1, (re, 1e-4), TIGHT)
    want = [brentq(colebrook, 0.005, 0.1, args=(r, 1e-4), xtol=1e-15, rtol=1e-15) for r in re]
    assert np.max(np.abs(got.value - want) / want) < 1e-12
    assert np.all(got.error >= np.abs(got.value - want))  # the estimate is a bound
    assert np.all(got.error < 1e-8 * got.value)


def test_root_near_guess_matches_mpmath():
    c = np.array([0.5, 1.0, 3.0])
    got = root_near(lambda x, c: np.cos(x) - c * x, 1.0, (c,), TIGHT)
    for x, ci in zip(got.value, c):
        ref = mpmath.findroot(lambda t, ci=ci: mpmath.cos(t) - ci * t, 1.0, tol=1e-30)
        assert x == pytest.approx(float(ref), rel=1e-13)


def test_root_without_sign_change_lists_samples():
    with pytest.raises(NumericsError, match=r"no sign change .* signs \+{9}"):
        root_in(lambda x: x**2 + 1, -3, 3, var="x")


def test_root_with_two_roots_is_refused():
    with pytest.raises(NumericsError, match="more than one root"):
        root_in(lambda x: x**2 - 1, -3, 3)


def test_root_near_searches_both_sides_of_the_guess():
    """The secant at the guess may point away from every root: (x+1) e^x = 2 from x = -3
    (the secant says left, where the function tends to -2) has its root on the right; of
    roots on both sides the nearer one is taken (x^3 - 3x from 0.9: sqrt 3, not 0); a side
    where the function has no value (log of a negative number) is not searched. Each against
    scipy's brentq in the bracket around it."""
    f = lambda x: (x + 1) * np.exp(x) - 2  # noqa: E731
    got = root_near(f, np.array([-3.0, -5.0, 4.0]), (), TIGHT)
    want = brentq(f, -3, 4, xtol=1e-15, rtol=1e-15)
    assert got.value == pytest.approx(want, rel=1e-13)
    got = root_near(lambda x: x**3 - 3 * x, 0.9, (), TIGHT)
    assert got.value == pytest.approx(brentq(lambda x: x**3 - 3 * x, 1, 2, xtol=1e-15), rel=1e-13)
    with np.errstate(invalid="ignore"):
        got = root_near(lambda x: np.log(x) - 1, 0.5, (), TIGHT)
    assert got.value == pytest.approx(np.e, rel=1e-13)


def test_root_near_without_bracket():
    with pytest.raises(NumericsError, match="no sign change found searching from the guess"):
        root_near(lambda x: x**2 + 1, 1.0)


def test_integral_matches_quad_and_splits_at_kinks():
    c = np.linspace(0.1, 0.9, 9)
    got = integrate(lambda x, c: np.abs(x - c) * np.exp(x), 0.0, 2.0, (c,), TIGHT, breaks=(c,))
    for v, e, ci in zip(got.value, got.error, c):
        want = quad(
            lambda x, ci=ci: abs(x - ci) * np.exp(x), 0, 2, points=[ci], epsabs=0, epsrel=1e-13
        )
        assert v == pytest.approx(want[0], rel=1e-12)
        assert e < 1e-10


def test_integral_reversed_bounds_and_mpmath():
    got = integrate(lambda x: 1 / (1 + x**2), 1.0, 0.0, (), TIGHT)
    assert float(got.value) == pytest.approx(-float(mpmath.pi / 4), rel=1e-14)


def test_divergent_integral_is_an_error():
    with pytest.raises(NumericsError, match="divergent"):
        integrate(lambda x: 1 / x, 0.0, 1.0)


def test_extremum_is_global_among_local_ones():
    c = np.array([0.0, 0.1, -0.5])
    got = extremum(lambda x, c: np.sin(x) + c * x, 0.0, 10.0, (c,), kind="max")
    for v, w, ci in zip(got.value, got.where, c):
        xs = np.linspace(0, 10, 200001)
        ys = np.sin(xs) + ci * xs
        assert v == pytest.approx(ys.max(), abs=1e-9)
        assert w == pytest.approx(xs[ys.argmax()], abs=1e-4)
    f = lambda x: mpmath.sin(x) + mpmath.mpf("0.1") * x  # noqa: E731
    ref = mpmath.findroot(lambda x: mpmath.diff(f, x), 7.95)
    assert got.where[1] == pytest.approx(float(ref), rel=1e-7)
    assert got.value[1] == pytest.approx(float(f(ref)), rel=1e-14)


def test_flat_argmax_is_an_error():
    with pytest.raises(NumericsError, match="flat"):
        extremum(lambda x: 0 * x + 2.0, 0.0, 1.0, need_where=True)


def test_sum_and_product_match_python():
    n = np.array([0, 1, 5, 10])
    s = reduce(lambda i, n: 1 / (i + 1) ** 2, 0, n, (n,), kind="sum")
    assert s.value == pytest.approx([sum(1 / (i + 1) ** 2 for i in range(k + 1)) for k in n])
    p = reduce(lambda i: i, 1, n, kind="product")
    assert p.value == pytest.approx([1, 1, 120, 3628800])


def test_solve_circle_and_line():
    R, th = 2.0, 0.3

    def res(z):
        x, y = z
        return [(x**2 + y**2 - R**2) / R**2, (y - x * np.tan(th)) / R]

    got = solve(res, [1, 0.5], [1, 0.5], names="xy", equations=["x^2+y^2==R^2", "y==x*tan"])
    assert got.value == pytest.approx([R * np.cos(th), R * np.sin(th)], rel=1e-12)


def test_solve_not_converging_shows_residuals():
    with pytest.raises(NumericsError, match="residual"):
        solve(lambda z: [z[0] ** 2 + 1], [1.0], [1.0], names="x", equations=["x^2 + 1 == 0"])


def test_interpolation_linear_and_cubic():
    xs = np.linspace(0, 3, 7)
    ys = xs**3
    assert interpolate(xs, ys, 1.2) == pytest.approx(np.interp(1.2, xs, ys))
    assert interpolate(xs, ys, np.array([1.2, 2.9]), kind="cubic") == pytest.approx(
        [1.2**3, 2.9**3], rel=1e-12
    )
    with pytest.raises(NumericsError, match="outside the data"):
        interpolate(xs, ys, 3.5)


def test_integral_with_endpoint_singularity_goes_to_tanhsinh():
    R = np.linspace(0.01, 0.1, 7)
    got = integrate(lambda r, R: 2 * np.pi * r * (1 - r / R) ** (1 / 7), 0.0, R, (R,), TIGHT)
    for v, e, Ri in zip(got.value, got.error, R):
        mp = mpmath.quad(
            lambda r, Ri=Ri: 2 * mpmath.pi * r * (1 - r / Ri) ** (mpmath.mpf(1) / 7), [0, Ri]
        )
        assert v == pytest.approx(float(mp), rel=1e-12)
        assert e >= abs(v - float(mp))


def _profile_flow(p: float, R: np.ndarray) -> np.ndarray:
    """The integral of 2*pi*r*(1 - r/R)^p for r from 0 to R: 2*pi*R^2*B(2, p + 1) (mpmath)."""
    return np.array([float(2 * mpmath.pi * Ri**2 * mpmath.beta(2, p + 1)) for Ri in R])


def test_integral_takes_the_same_levels_in_any_unit():
    # tanh-sinh's error estimate depends on the size of the integral: the engine divides it
    # out, so the profile in mm (values near 10^6) takes as many evaluations as in m
    R = np.linspace(0.01, 10.0, 300)

    def flow(r, R):
        return 2 * np.pi * r * (1 - r / R) ** (1 / 7)

    in_m = integrate(flow, 0.0, R, (R,))
    in_mm = integrate(flow, 0.0, 1000 * R, (1000 * R,))
    want = _profile_flow(1 / 7, R)
    for got, scale in ((in_m, 1.0), (in_mm, 1e6)):
        assert np.max(np.abs(got.value / scale - want) / want) < 1e-10
        assert np.all(got.error >= np.abs(got.value - scale * want))
    assert in_m.evaluations == in_mm.evaluations


def test_large_table_of_singular_rows_skips_the_gauss_kronrod_pass():
    R = np.linspace(0.01, 1.0, 1000)
    widths = []

    def flow(r, R):
        widths.append(r.shape)
        return 2 * np.pi * r * (1 - r / R) ** (1 / 7)

    got = integrate(flow, 0.0, R, (R,))
    kronrod = [s for s in widths if s[-1] == 21]
    assert kronrod == [(32, 21)]  # the probe's rows only
    assert np.max(np.abs(got.value - _profile_flow(1 / 7, R)) / got.value) < 1e-10


def test_table_of_mixed_rows_is_integrated_row_by_row():
    R = np.linspace(0.01, 1.0, 1000)
    p = np.where(np.arange(R.size) % 2, 1 / 7, 2.0)  # every other row smooth
    got = integrate(lambda r, R, p: 2 * np.pi * r * (1 - r / R) ** p, 0.0, R, (R, p))
    want = np.where(p == 2.0, _profile_flow(2.0, R), _profile_flow(1 / 7, R))
    assert np.max(np.abs(got.value - want) / want) < 1e-10
    assert np.all(got.error >= np.abs(got.value - want))
