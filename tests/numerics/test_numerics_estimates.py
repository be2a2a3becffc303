"""Hard cases of the numerical built-ins, each against an exact reference (mpmath at 50
digits or a closed form): the value within its error estimate, or refused naming why."""

import mpmath
import numpy as np
import pytest

import workbook
from workbook.functions.numerical import NumericsError

mpmath.mp.dps = 50


def value(sheet_from, expr: str, tolerance: float | None = None, extra: str = ""):
    """(value, largest error estimate of the built-ins) of EXPR in a sheet of its own."""
    head = f"[sheet]\ntolerance = {tolerance}\n" if tolerance else ""
    s = sheet_from(f'{head}[definitions]\n{extra}y = "{expr}"\n')
    v = s.evaluate("y").magnitude
    estimates = [float(np.max(r.error)) for _, r in s.evaluator.records if r.error.size]
    return v, max(estimates, default=0.0)


def right(sheet_from, expr: str, exact, rel: float = 1e-9, **kw):
    """The value is within rel of the exact one and within its estimate (x 1.01)."""
    v, est = value(sheet_from, expr, **kw)
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
def test_an_infinite_sample_keeps_its_sign(sheet_from, expr, exact, plain):
    """An infinite sample (a pole hit exactly, overflow) was refused as "not a finite
    number" though the bracket changes sign at a root; brentq solves both."""
    right(sheet_from, expr.format(plain), exact)


@pytest.mark.parametrize("plain", ["", " * sign(x + 1)"])
def test_a_sign_change_at_an_infinite_sample_is_still_a_pole(sheet_from, plain):
    with pytest.raises(NumericsError, match="a pole, not a root"):
        value(sheet_from, f"root(1/(x - 0.5){plain}, x, 0.4, 0.6)")


# -- linear algebra: estimates from the condition number --------------------------------------
def _estimate(s, name: str) -> float:
    return max(float(np.max(r.error)) for _, r in s.evaluator.records if r.notes["in"] == name)


HILBERT = (
    "["
    + ", ".join("[" + ", ".join(f"1/{i + j + 1}" for j in range(10)) + "]" for i in range(10))
    + "]"
)


def test_a_hilbert_system_carries_its_condition_in_its_estimate(sheet_from):
    """Hilbert 10x10 (condition 1.6e13): lsolve was 1.3e-4 off (relative) and silent; its
    estimate (condition x eps x |x|) now covers the error against the exact rational solution,
    and run/check warn of it, as of det."""
    s = sheet_from(
        "[definitions]\n"
        + f'H = "{HILBERT}"\nx = "lsolve(H, [1, 1, 1, 1, 1, 1, 1, 1, 1, 1])"\nd = "det(H)"\n',
    )
    x = np.ravel(s.evaluate("x").magnitude)
    h = mpmath.matrix(10, 10)
    for i in range(10):
        for j in range(10):
            h[i, j] = mpmath.mpf(1) / (i + j + 1)
    exact = mpmath.lu_solve(h, mpmath.matrix([1] * 10))
    error = max(abs(float(x[i] - exact[i])) for i in range(10))
    assert error > 1e-6 * max(abs(float(v)) for v in exact)  # the system is ill-conditioned
    assert error <= _estimate(s, "x")
    d = float(s.evaluate("d").magnitude)
    assert abs(d - float(mpmath.det(h))) <= _estimate(s, "d")
    warned = [f.topic for f in s.check().findings if f.verdict == "warning"]
    assert "estimate x" in warned and "estimate d" in warned


def test_a_well_conditioned_system_is_not_warned_of(sheet_from):
    s = sheet_from("[definitions]\n" + 'x = "lsolve([[4, 1], [1, 3]], [1, 2])"\n')
    x = np.ravel(s.evaluate("x").magnitude)
    assert abs(x[0] - 1 / 11) <= max(_estimate(s, "x"), 1e-16)
    assert not [f for f in s.check().findings if f.verdict == "warning"]


@pytest.mark.parametrize(
    "matrix, double",
    [
        # (lambda - 2)^2: rounding splits it into 2 +- 2e-8 (real) ...
        ("[[1, 1], [-1, 3]]", mpmath.mpf(2)),
        # ... or into a complex pair 0.2 +- 2.4e-9 i, which was refused as "complex"
        ("[[0.1, 0.1], [-0.1, 0.3]]", mpmath.mpf("0.2")),
    ],
)
def test_a_defective_matrix_is_named_not_called_complex(sheet_from, matrix, double):
    s = sheet_from("[definitions]\n" + f'A = "{matrix}"\nl = "eigenvals(A)"\n')
    lam = np.ravel(s.evaluate("l").magnitude)
    error = max(abs(float(v - double)) for v in lam)
    assert error <= _estimate(s, "l") <= 1e-6
    (warning,) = [f for f in s.check().findings if f.topic == "estimate l"]
    assert "defective" in warning.what and "complex" not in warning.what


# -- sums and products: the rounding of the additions and of EXPR itself ----------------------
def _warned(sheet_from, expr: str) -> bool:
    s = sheet_from(f'[definitions]\ny = "{expr}"\n')
    s.evaluate("y")
    return any(f.topic == "estimate y" for f in s.check().findings)


def test_a_sum_of_cancelling_terms_carries_their_rounding(sheet_from):
    """Each term is 1e-9/i^2 left of two numbers near 1/i: the sum was 4e-8 off (relative)
    with no estimate; EXPR checked in mpmath at log-spaced terms gives one that covers it."""
    expr = "sum(1/i - 1/(i + 1e-9), i, 1, 20000)"
    a, n = mpmath.mpf("1e-9"), 20000
    exact = mpmath.digamma(n + 1) - mpmath.digamma(1) - mpmath.digamma(n + 1 + a)
    exact += mpmath.digamma(1 + a)
    v, est = value(sheet_from, expr)
    error = abs(float(v) - float(exact))
    assert 1e-9 * float(exact) < error <= est
    assert _warned(sheet_from, expr)


def test_an_alternating_series_carries_the_cancellation_of_its_terms(sheet_from):
    """exp(-20) by its series: terms up to 4.3e7 leave 2.06e-9, computed as 4.99e-9 (142 %
    off) with no estimate; n eps sum |term| covers it, and run/check warn."""
    expr = "sum((-20)^i/product(k, k, 1, i), i, 0, 100)"
    exact = sum(mpmath.mpf(-20) ** i / mpmath.factorial(i) for i in range(101))
    v, est = value(sheet_from, expr)
    assert abs(float(v) - float(exact)) <= est
    assert _warned(sheet_from, expr)


def test_a_plain_sum_and_product_are_not_warned_of(sheet_from):
    right(sheet_from, "sum(1/i^2, i, 1, 1000)", mpmath.zeta(2) - mpmath.zeta(2, 1001), rel=1e-14)
    exact = mpmath.fprod(1 + mpmath.mpf(1) / i**2 for i in range(1, 1001))
    right(sheet_from, "product(1 + 1/i^2, i, 1, 1000)", exact, rel=1e-13)
    assert not _warned(sheet_from, "sum(1/i^2, i, 1, 1000)")


# -- diff: no derivative at a kink; the rounding of the derivative's formula -------------------
def _diff_sheet(sheet_from, body: str, at: str):
    return sheet_from(
        f'[arguments]\nx = {{ unit = "" }}\n[definitions]\n"f(x)" = "diff({body}, x)"\n'
        f'y = "f({at})"\n'
    )


@pytest.mark.parametrize(
    "body, at, slopes",
    [
        ("x if x < 1 otherwise 2*x - 1", "1", r"1 on the left and 2 on the right"),
        ("abs(x - 2)", "2", r"-1 on the left and 1 on the right"),
    ],
)
def test_a_derivative_at_a_kink_is_refused_with_both_slopes(sheet_from, body, at, slopes):
    """At the join the derivative's formula took one side's slope (2, and 0 for abs)."""
    with pytest.raises(NumericsError, match=f"kink at x = {at}: its derivative is {slopes}"):
        _diff_sheet(sheet_from, body, at).evaluate("y")


def test_a_derivative_beside_a_kink_is_its_sides_slope(sheet_from):
    assert float(_diff_sheet(sheet_from, "x if x < 1 otherwise 2*x - 1", "0.5").evaluate("y")) == 1


def test_a_derivative_formula_that_cancels_carries_its_rounding(sheet_from):
    """d/dx (exp(x) - 1 - x)/x^2 at 1e-3: SymPy's formula is a difference of terms near
    1e6 that leave 0.1667; it was 3e-7 off with no estimate; the formula evaluated again
    in mpmath gives the estimate, and run/check warn of it."""
    s = _diff_sheet(sheet_from, "(exp(x) - 1 - x)/x^2", "1e-3")
    v = float(s.evaluate("y").magnitude)
    exact = mpmath.diff(lambda x: (mpmath.exp(x) - 1 - x) / x**2, mpmath.mpf("1e-3"))
    error = abs(v - float(exact))
    assert error > 1e-8
    assert error <= _estimate(s, "y")
    assert any(f.topic == "estimate y" for f in s.check().findings)


def test_an_integrand_that_cancels_carries_its_rounding(sheet_from):
    """cos(1e-4 x) - 1 is 5e-9 left of two numbers near 1: each value is off by up to 1e-16,
    which no quadrature rule sees (its estimate was 2.4e-20 for an error near 1e-18); EXPR
    spot-checked in mpmath puts it in the estimate, and run/check warn (relative 3e-8)."""
    expr = "integral(cos(1e-4*x) - 1, x, 0, 1)"
    exact = mpmath.sin(mpmath.mpf("1e-4")) / mpmath.mpf("1e-4") - 1
    v, est = value(sheet_from, expr)
    assert abs(float(v) - float(exact)) <= est
    assert _warned(sheet_from, expr)
    assert not _warned(sheet_from, "integral(x^2, x, 0, 1)")


# -- an ODE that blows up: the values before it ------------------------------------------------
TAN = """[arguments]
t = { unit = "s" }
[definitions]
a = "y(1.2 s)"
b = "y(1.9 s)"
[[ode]]
name = "tan"
time = "t := 0 .. 2 s"
rtol = 1e-8
atol = 1e-10
states = [{ name = "y", unit = "", initial = "0", derivative = "(1 + y^2)/(1 s)" }]
"""


def test_an_ode_that_blows_up_gives_its_values_before_the_blow_up(sheet_from):
    """y' = 1 + y^2 is tan t, which blows up at pi/2: every value was refused; y(1.2) is
    tan 1.2 now, y(1.9) is refused as past the blow-up, and check says the run stopped."""
    s = sheet_from(TAN, name="tan")
    assert float(s.evaluate("a").magnitude) == pytest.approx(float(mpmath.tan(1.2)), rel=1e-7)
    with pytest.raises(workbook.WorkbookError, match=r"y\(1\.9\) is at or past t = 1\.57"):
        s.evaluate("b")
    findings = [f for f in s.check().findings if f.topic == "ode tan"]
    assert findings[0].verdict == "fail" and "values before t = 1.57" in findings[0].note


def test_bench_goes_on_past_a_definition_the_engine_refuses(sheet_from):
    """A refused definition (a pole) stopped workbook bench; it is one line of its own now."""
    from workbook.numerics import bench

    sheet = sheet_from(
        '[definitions]\na = "root(x^2 - 2, x, 0, 2)"\nb = "root(1/(x - 0.3), x, 0, 1)"\n'
        'c = "integral(x^2, x, 0, 1)"\n',
        name="b",
    )
    lines = bench.run(sheet, repeats=1)
    verdicts = {line.what: line.verdict for line in lines}
    assert verdicts["a"] == verdicts["c"] == "ok"
    assert verdicts["b"].startswith("refused by the engine: root(): the function changes sign")


LOGISTIC = """[arguments]
t = { unit = "s" }
[definitions]
t_half = "root(y(t) - 0.5, t, 0 s, 10 s)"
[[ode]]
name = "logistic"
time = "t := 0 .. 10 s"
states = [{ name = "y", unit = "", initial = "0.01", derivative = "y*(1 - y)/(1 s)" }]
"""


def test_a_root_of_an_ode_state_carries_the_states_global_error(sheet_from):
    """y = 1/(1 + 99 e^-t) is 0.5 at t = ln 99; at the run's rtol 1e-6 the root was 1.1e-6
    off with an estimate of 1e-10 (the bracket's); the states' error over the slope is in it."""
    s = sheet_from(LOGISTIC, name="l")
    v = float(s.evaluate("t_half").magnitude)
    error = abs(v - float(mpmath.log(99)))
    assert 1e-8 < error <= _estimate(s, "t_half") <= 10 * error


def test_an_integral_of_an_ode_state_carries_the_states_global_error(sheet_from):
    """The integral of y = 1/(1 + 99 e^-t) over [0, 10] is 10 + ln((1 + 99 e^-10)/100); at
    the run's rtol 1e-6 it is 1.2e-6 off, which the quadrature's estimate (1e-14) missed."""
    s = sheet_from(
        LOGISTIC.replace("root(y(t) - 0.5, t, 0 s, 10 s)", "integral(y(t), t, 0 s, 10 s)"), name="l"
    )
    v = float(s.evaluate("t_half").magnitude)
    exact = 10 + mpmath.log((1 + 99 * mpmath.exp(-10)) / 100)
    error = abs(v - float(exact))
    assert 1e-8 < error <= _estimate(s, "t_half") <= 10 * error


@pytest.mark.parametrize(
    "expr, exact",
    [
        ("integral(x^-0.99, x, 0, 1)", mpmath.mpf(100)),
        (
            "integral(ln((x - 0.3)^2), x, 0, 1)",
            2 * (mpmath.mpf("0.7") * mpmath.log(mpmath.mpf("0.7")) - 1)
            + 2 * mpmath.mpf("0.3") * mpmath.log(mpmath.mpf("0.3")),
        ),
    ],
)
def test_quadpack_integrates_where_the_vectorised_rule_gives_up(sheet_from, expr, exact):
    """Both were refused at the refinement limit; QUADPACK's QAGS (extrapolation) takes the
    pieces tanh-sinh gives up on, its estimate the value's."""
    right(sheet_from, expr, exact, rel=1e-9)


@pytest.mark.parametrize("expr", ["integral(x^-1.01, x, 0, 1)", "integral(x^-1.5, x, 0, 1)"])
def test_a_divergent_integral_is_not_given_its_analytic_continuation(sheet_from, expr):
    """QAGS's extrapolation gives x^-1.01 on [0, 1] the value -100: refused, as before."""
    with pytest.raises(NumericsError, match="refinement limit"):
        value(sheet_from, expr)
