"""root, integral, maximum/argmax, sum/product and diff in worksheets, against scipy/mpmath."""

import re

import mpmath
import numpy as np
import pytest
from helpers.paths import DATA as TEST_DATA
from helpers.recalc import cell_values, formula_values, recalculate, soffice
from scipy.optimize import brentq

import workbook
from workbook.errors import TemplateError, UnitError, WorkbookError
from workbook.functions.numerical import NumericsError

PIPE = TEST_DATA / "pipe-flow.toml"
EPS, D = 0.05e-3, 0.1


@pytest.fixture(scope="module")
def pipe():
    return workbook.load(PIPE)


def colebrook(f, re):
    return 1 / np.sqrt(f) + 2 * np.log10(EPS / (3.7 * D) + 2.51 / (re * np.sqrt(f)))


@pytest.mark.parametrize("name", ["friction", "friction_guess"])
def test_colebrook_over_a_range_matches_brentq(pipe, name):
    re = np.geomspace(4000, 1e8, 40)
    got = pipe.evaluate(name, re).magnitude
    want = [brentq(colebrook, 0.005, 0.1, args=(r,), xtol=1e-16, rtol=1e-15) for r in re]
    assert np.max(np.abs(got - want) / want) < 1e-9  # the sheet's tolerance is 1e-10


def test_flow_rate_of_the_power_law_profile_matches_the_beta_function(pipe):
    R = np.array([10.0, 50.0, 120.0])  # mm
    got = pipe.evaluate("Q", R).to("m^3/s").magnitude
    for q, r in zip(got, R / 1000):
        exact = 2 * mpmath.pi * r**2 * 2 * mpmath.beta(2, mpmath.mpf(8) / 7)
        assert q == pytest.approx(float(exact), rel=1e-12)


def test_tables_of_roots_and_integrals(pipe):
    assert len(pipe.table("moody")) > 50
    q = pipe.table("flow").iloc[:, 1].to_numpy()
    assert np.all(np.diff(q) > 0)


EXTREMA = """
[inputs]
A = "10 mm"
omega = "100 1/s"
[arguments]
x = { unit = "" }
c = { unit = "" }
i = { unit = "" }
t = { unit = "s" }
[definitions]
peak = "maximum(sin(x) + 0.1*x, x, 0, 10)"
at = "argmax(sin(x) + 0.1*x, x, 0, 10)"
low = "minimum(sin(x) + 0.1*x, x, 0, 10)"
at_low = "argmin(sin(x) + 0.1*x, x, 0, 10)"
"kinked(c)" = "integral(abs(x - c)*exp(x), x, 0, 2)"
"pieces(c)" = "integral(step(x, c), x, 0, 2)"
"step(x, c)" = ["x^2 if x <= c", "1 - x otherwise"]
best = "argmin(kinked(c), c, -1, 3)"
basel = "sum(1/i^2, i, 1, 10)"
fact = "product(i, i, 1, 5)"
"s(t)" = { expr = "A*sin(omega*t)*exp(-omega*t/10)", unit = "mm" }
"v(t)" = { expr = "diff(s(t), t)", unit = "m/s" }
"a(t)" = { expr = "diff(s(t), t, 2)", unit = "m/s^2" }
"""


@pytest.fixture(scope="module")
def ext(load_text):
    return load_text(EXTREMA, name="ext")


def test_global_maximum_and_where_against_mpmath(ext):
    x = mpmath.findroot(lambda x: mpmath.cos(x) + mpmath.mpf("0.1"), 7.9)
    assert ext.evaluate("at").magnitude == pytest.approx(float(x), rel=1e-7)
    assert ext.evaluate("peak").magnitude == pytest.approx(float(mpmath.sin(x) + x / 10), rel=1e-13)
    x = mpmath.findroot(lambda x: mpmath.cos(x) + mpmath.mpf("0.1"), 4.6)
    assert ext.evaluate("at_low").magnitude == pytest.approx(float(x), rel=1e-7)
    assert ext.evaluate("low").magnitude == pytest.approx(float(mpmath.sin(x) + x / 10), rel=1e-13)


def test_integrals_split_at_kinks_against_mpmath(ext):
    c = np.array([-0.5, 0.3, 1.0, 1.7, 2.5])
    got = ext.evaluate("kinked", c).magnitude
    for v, ci in zip(got, c):
        pts = [0, ci, 2] if 0 < ci < 2 else [0, 2]
        want = mpmath.quad(lambda x, ci=ci: abs(x - ci) * mpmath.exp(x), pts)
        assert v == pytest.approx(float(want), rel=1e-13)
    got = ext.evaluate("pieces", c).magnitude
    for v, ci in zip(got, c):
        k = min(max(ci, 0), 2)
        want = k**3 / 3 + ((1 - 2) ** 2 - (1 - k) ** 2) / 2 * -1
        assert v == pytest.approx(want, rel=1e-12, abs=1e-14)


def test_minimum_of_an_integral(ext):
    # d/dc of integral |x - c| e^x over [0, 2] is 2 e^c - 1 - e^2: zero at ln((1 + e^2) / 2)
    want = float(mpmath.log((1 + mpmath.e**2) / 2))
    assert ext.evaluate("best").magnitude == pytest.approx(want, rel=1e-7)


def test_sum_and_product(ext):
    assert ext.evaluate("basel").magnitude == pytest.approx(sum(1 / i**2 for i in range(1, 11)))
    assert ext.evaluate("fact").magnitude == 120


def test_derivatives_against_mpmath(ext):
    A, w = 0.01, 100.0
    s = lambda t: A * mpmath.sin(w * t) * mpmath.exp(-w * t / 10)  # noqa: E731
    for t in (0.0, 0.004, 0.03):
        assert ext.evaluate("v", t).to("m/s").magnitude == pytest.approx(
            float(mpmath.diff(s, t)), rel=1e-12, abs=1e-15
        )
        assert ext.evaluate("a", t).to("m/s^2").magnitude == pytest.approx(
            float(mpmath.diff(s, t, 2)), rel=1e-12, abs=1e-12
        )


BASE = """
[inputs]
R = "50 mm"
T = "2 s"
[arguments]
r = { unit = "mm" }
"""


@pytest.mark.parametrize(
    "definition, message",
    [
        ('"integral(2*pi*r, r, 0, T)"', "the upper bound B is [time] (s), but the variable r"),
        ('"integral(2*pi*r, r, T, R)"', "the lower bound A is [time]"),
        ('"root(r - R, r, T)"', "the guess is [time]"),
        ('"root(r - R, r, 0, T)"', "the upper bound B is [time]"),
        ('"maximum(r, r, 0, T)"', "the upper bound B is [time]"),
        ('"argmin(r, r, T, R)"', "the lower bound A is [time]"),
    ],
)
def test_unit_mistakes_in_bounds_are_refused_at_load(sheet_from, definition, message):
    with pytest.raises(UnitError) as err:
        sheet_from(BASE + f"[definitions]\nbad = {definition}\n", name="s")
    text = str(err.value)
    assert message in text
    assert "s.toml:8" in text and "'bad'" in text


def test_bad_tolerance_is_refused_at_load(sheet_from):
    with pytest.raises(TemplateError, match="tolerance"):
        sheet_from(
            "[sheet]\ntolerance = 0.5\n" + BASE + '[definitions]\nq = "root(r - R, r, 0, R)"\n',
        )


@pytest.mark.parametrize(
    "expr, message",
    [
        ("root(x^2 + 1, x, -3, 3)", r"no sign change .* signs \+{9}"),
        ("root(x^2 - 1, x, -3, 3)", "more than one root"),
        ("root(x^2 + 1, x, 1)", "no sign change found searching from the guess"),
        ("integral(1/x, x, 0, 1)", "divergent"),
        ("argmax(0*x + 1, x, 0, 1)", "flat"),
        ("argmax(min(x, 0.5), x, 0, 1)", r"maximum 0.5 is reached all along x = 0.5 \.\. 1"),
        ("argmin(max(x, 0.5), x, 0, 1)", r"minimum 0.5 is reached all along x = 0 \.\. 0.5"),
    ],
)
def test_hard_cases_are_errors_naming_file_line_definition(sheet_from, expr, message):
    s = sheet_from(f'[arguments]\nx = {{ unit = "" }}\n[definitions]\nbad = "{expr}"\n', name="s")
    with pytest.raises(NumericsError, match=message) as err:
        s.evaluate("bad")
    assert "s.toml:4" in str(err.value) and "'bad'" in str(err.value)


def test_rows_are_named_in_errors(pipe, sheet_from):
    s = sheet_from(
        '[arguments]\nx = { unit = "" }\nc = { unit = "" }\n'
        '[definitions]\n"g(c)" = "root(x^2 - c, x, 0, 2)"\n',
    )
    with pytest.raises(WorkbookError, match=r"for c = -1"):
        s.evaluate("g", [1.0, -1.0])


@pytest.mark.slow
def test_loading_a_sheet_with_numerical_builtins_imports_no_scipy():
    import subprocess
    import sys

    code = (
        f"import sys, workbook; s = workbook.load({str(PIPE)!r}); "
        "heavy = ('scipy.optimize', 'scipy.integrate', 'sympy', 'mpmath'); "
        "print(sorted(m for m in heavy if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


PUMP = "Q,H\n0,32.0\n10,31.2\n20,29.5\n30,26.4\n40,21.8\n50,15.9\n"
DATA = """
[data.pump]
file = "pump.csv"
columns = { Q = "m^3/h", H = "m" }
[inputs]
T = "2 s"
[arguments]
q = { unit = "L/s" }
[definitions]
"""


def test_interpolation_against_scipy_and_numpy(sheet_from, tmp_path):
    from scipy.interpolate import make_interp_spline

    (tmp_path / "pump.csv").write_text(PUMP)
    s = sheet_from(DATA + '"lin(q)" = "linterp(Q, H, q)"\n"cub(q)" = "cspline(Q, H, q)"\n')
    q = np.linspace(0.0, 50 / 3.6, 23)  # L/s, the data's whole range
    qh = q * 3.6  # m^3/h
    xs = np.array([0, 10, 20, 30, 40, 50.0])
    ys = np.array([32.0, 31.2, 29.5, 26.4, 21.8, 15.9])
    assert s.evaluate("lin", q).to("m").magnitude == pytest.approx(np.interp(qh, xs, ys), rel=1e-13)
    spline = make_interp_spline(xs, ys, k=3)  # not-a-knot ends
    assert s.evaluate("cub", q).to("m").magnitude == pytest.approx(spline(qh), rel=1e-12)
    with pytest.raises(NumericsError, match="outside the data"):
        s.evaluate("lin", 20.0)


@pytest.mark.parametrize(
    "csv, definition, error, message",
    [
        (PUMP, '"linterp(Q, H, T)"', UnitError, "x is [time] (s), but the data column Q"),
        (PUMP, '"linterp(Q, eta, T)"', TemplateError, "must be a column of a [data] table"),
        (PUMP, '"Q + 1 m"', UnitError, "cannot add [length] (m) to"),  # Q: a vector
        (PUMP.replace("20,29.5", "5,29.5"), '"linterp(Q, H, 0)"', NumericsError, "increasing"),
        (
            PUMP.replace("31.2", "high"),
            '"linterp(Q, H, 0)"',
            TemplateError,
            "'high' is not a number",
        ),
    ],
)
def test_data_mistakes_are_refused_at_load(sheet_from, tmp_path, csv, definition, error, message):
    (tmp_path / "pump.csv").write_text(csv)
    with pytest.raises(error, match=re.escape(message)) as err:
        sheet_from(DATA + f"bad = {definition}\n", name="s")
    assert "s.toml" in str(err.value)


SOLVE = """
[inputs]
R = "2 m"
theta = "0.3"
T = "1 s"
[[solve]]
unknowns = { x = "1 m", y = "50 cm" }
equations = [EQUATIONS]
[definitions]
d = { expr = "sqrt(x^2 + y^2)", unit = "mm" }
"""


def test_given_find_against_the_closed_form(sheet_from, tmp_path):
    s = sheet_from(SOLVE.replace("EQUATIONS", '"x^2 + y^2 == R^2", "y == x*tan(theta)"'))
    assert s.evaluate("x").to("m").magnitude == pytest.approx(2 * np.cos(0.3), rel=1e-13)
    assert s.evaluate("y").to("m").magnitude == pytest.approx(2 * np.sin(0.3), rel=1e-13)
    assert s.evaluate("d").to("mm").magnitude == pytest.approx(2000, rel=1e-13)
    s.write_xlsx(tmp_path / "s.xlsx")  # what uses x and y is written as numbers


@pytest.mark.parametrize(
    "equations, error, message",
    [
        ('"x^2 + y^2 == R", "y == x*tan(theta)"', UnitError, "the left side is [length] ** 2"),
        ('"x == T", "y == x"', UnitError, "the right side [time] (s)"),
        ('"x + y == R"', TemplateError, "2 unknown(s) and 1 equation(s)"),
        ('"x + y == R", "2*x"', TemplateError, "an equation is written LEFT == RIGHT"),
    ],
)
def test_given_find_mistakes_are_refused_at_load(sheet_from, equations, error, message):
    with pytest.raises(error, match=re.escape(message)) as err:
        sheet_from(SOLVE.replace("EQUATIONS", equations), name="s")
    assert "s.toml:8" in str(err.value) and "solve x, y" in str(err.value)


def test_given_find_with_a_side_that_is_zero(sheet_from):
    """`EXPR == 0` (common in Mathcad's solve blocks): a residual relative to sides that move
    with x would be a step of +-1 there; a linear system is solved exactly."""
    eqs = '"x + 2*y - R == 0", "x - y == 0"'
    s = sheet_from(SOLVE.replace("EQUATIONS", eqs))
    assert s.evaluate("x").to("m").magnitude == pytest.approx(2 / 3, rel=1e-12)
    assert s.evaluate("y").to("m").magnitude == pytest.approx(2 / 3, rel=1e-12)


def test_given_find_by_levenberg_marquardt(sheet_from):
    """The method Mathcad's Find uses: the same closed form; an unknown method is refused."""
    text = SOLVE.replace("EQUATIONS", '"x^2 + y^2 == R^2", "y == x*tan(theta)"')
    s = sheet_from(text.replace("[definitions]", 'method = "levenberg-marquardt"\n[definitions]'))
    assert s.spec.solves[0].method == "levenberg-marquardt"
    assert s.evaluate("x").to("m").magnitude == pytest.approx(2 * np.cos(0.3), rel=1e-12)
    with pytest.raises(TemplateError, match="one of hybrid, levenberg-marquardt, nearest"):
        sheet_from(text.replace("[definitions]", 'method = "newton"\n[definitions]'))


def test_given_find_conditions_are_checked_at_the_root(sheet_from):
    """Mathcad's inequalities beside the equations: the root found must meet them."""
    text = SOLVE.replace("EQUATIONS", '"x^2 + y^2 == R^2", "y == x*tan(theta)"')
    met = text.replace("[definitions]", 'conditions = ["x > 0 m"]\n[definitions]')
    s = sheet_from(met.replace('"x > 0 m"', '"x > 0"'))
    assert s.evaluate("x").to("m").magnitude == pytest.approx(2 * np.cos(0.3), rel=1e-12)
    s = sheet_from(met.replace('"x > 0 m"', '"x < 0"'))
    with pytest.raises(NumericsError, match="does not meet the condition 'x < 0'"):
        s.evaluate("x")
    with pytest.raises(TemplateError, match="a condition is written LEFT < RIGHT"):
        sheet_from(met.replace('"x > 0 m"', '"x == 0"'))


def test_given_find_levenberg_marquardt_honours_the_conditions(sheet_from):
    """Levenberg-Marquardt solves with the conditions (Mathcad's Find): x^2 = 4 from the guess
    -1 reaches -2, but with x > 1 the guess is first moved to meet it and the root is 2 (the
    hybrid method reaches -2 and reports the condition unmet)."""
    text = """
[[solve]]
unknowns = { x = "-1" }
equations = ["x^2 == 4"]
method = "levenberg-marquardt"
"""
    assert sheet_from(text).evaluate("x").magnitude == pytest.approx(-2, rel=1e-9)
    cond = text + 'conditions = ["x > 1"]\n'
    assert sheet_from(cond).evaluate("x").magnitude == pytest.approx(2, rel=1e-9)
    hybrid = cond.replace('method = "levenberg-marquardt"', "")
    with pytest.raises(NumericsError, match="does not meet the condition 'x > 1'"):
        sheet_from(hybrid).evaluate("x")


def test_given_find_fewer_equations_than_unknowns(sheet_from):
    """One equation in two unknowns (Mathcad's Find of an underdetermined block): the point
    on the circle that MINPACK's Levenberg-Marquardt reaches from (1 m, 1 m), as scipy's
    leastsq with the residuals padded to two (Mathcad's answer in the worksheets measured);
    the hybrid method refuses it."""
    from scipy.optimize import leastsq

    text = SOLVE.replace("EQUATIONS", '"x^2 + y^2 == R^2"').replace('"50 cm"', '"1 m"')
    lm = text.replace("[definitions]", 'method = "levenberg-marquardt"\n[definitions]')
    s = sheet_from(lm)
    x, y = s.evaluate("x").to("m").magnitude, s.evaluate("y").to("m").magnitude
    want = leastsq(lambda z: [z[0] ** 2 + z[1] ** 2 - 4, 0.0], [1.0, 1.0], xtol=1e-14)[0]
    assert (x, y) == pytest.approx(tuple(want), rel=1e-9)
    assert x**2 + y**2 == pytest.approx(4, rel=1e-9)
    with pytest.raises(TemplateError, match=re.escape('(or fewer, with method = "levenberg')):
        sheet_from(text)


def test_given_find_nearest_root_meeting_the_conditions(sheet_from):
    """`nearest`: of the roots of sin(phi) = 1/2 (pi/6 and 5 pi/6, plus 2 pi k) with phi < 0,
    the one nearest the guess 0 is 5 pi/6 - 2 pi."""
    text = """
[[solve]]
unknowns = { phi = "0" }
equations = ["sin(phi) == 0.5"]
method = "nearest"
conditions = ["phi < 0"]
"""
    s = sheet_from(text)
    assert s.evaluate("phi").magnitude == pytest.approx(5 * np.pi / 6 - 2 * np.pi, rel=1e-9)
    s = sheet_from(text.replace("phi < 0", "phi > 1"))
    assert s.evaluate("phi").magnitude == pytest.approx(5 * np.pi / 6, rel=1e-9)


def test_given_find_not_converging_shows_residuals(sheet_from):
    s = sheet_from(SOLVE.replace("EQUATIONS", '"x^2 + R^2 == 0", "y == x"'))
    with pytest.raises(NumericsError, match=r"did not converge.*x\^2 \+ R\^2 == 0: residual"):
        s.evaluate("d")


def test_rows_are_solved_in_chunks_with_the_same_results(pipe, sheet_from, monkeypatch):
    from workbook.numerics import entries

    re_ = np.geomspace(4000, 1e8, 40)
    R = np.linspace(10, 100, 23)
    whole = pipe.with_inputs().evaluate("friction", re_).magnitude, pipe.evaluate("Q", R).magnitude
    monkeypatch.setattr(entries, "CHUNK", 7)
    chunked = pipe.with_inputs()
    assert np.array_equal(chunked.evaluate("friction", re_).magnitude, whole[0])
    assert np.array_equal(chunked.evaluate("Q", R).magnitude, whole[1])
    s = sheet_from(
        '[arguments]\nx = { unit = "" }\nc = { unit = "" }\n'
        '[definitions]\n"g(c)" = "root(x^2 - c, x, 0, 2)"\n',
    )
    with pytest.raises(NumericsError, match=r"for c = -1\)"):
        s.evaluate("g", [1.0] * 10 + [-1.0])


ALL = TEST_DATA / "numerical-builtins.toml"


@pytest.mark.slow
def test_every_builtin_runs_from_a_plain_template(tmp_path, capsys):
    """root (both forms), integral, diff, sum, product, maximum, argmax, Given/Find and data
    interpolation in one template, through the command line; values against closed forms."""
    from workbook.cli import main

    assert main(["run", str(ALL), "--out", str(tmp_path / "all.xlsx")]) == 0
    s = workbook.load(ALL)
    R, u_max = 0.05, 2.0
    beta = float(mpmath.beta(2, mpmath.mpf(8) / 7))
    assert s.evaluate("flow").to("m^3/s").magnitude == pytest.approx(
        2 * np.pi * R**2 * u_max * beta
    )
    half = 50 * (1 - 2.0**-7)  # (1 - r/R)^(1/7) = 1/2
    assert s.evaluate("r_half").to("mm").magnitude == pytest.approx(half, rel=1e-12)
    assert s.evaluate("r_near").to("mm").magnitude == pytest.approx(half, rel=1e-12)
    # s = A sin(wt) exp(-wt/10): v is largest at t = 0 (A w); s is largest where tan(wt) = 10
    assert s.evaluate("v_peak").to("m/s").magnitude == pytest.approx(1.0, rel=1e-12)
    assert s.evaluate("t_peak").to("s").magnitude == pytest.approx(np.arctan(10) / 100, rel=1e-7)
    assert s.evaluate("basel").magnitude == pytest.approx(sum(1 / k**2 for k in range(1, 101)))
    assert s.evaluate("fact").magnitude == 720
    assert s.evaluate("dist").to("m").magnitude == pytest.approx(2.0, rel=1e-12)
    capsys.readouterr()
    assert main(["bench", str(ALL)]) == 0
    out = capsys.readouterr().out
    for name in ("flow", "r_half", "r_near", "v_peak", "t_peak"):
        line = next(x for x in out.splitlines() if x.startswith(name + " "))
        assert line.endswith("ok"), line


def test_bounds_of_a_plain_argument_are_in_its_declared_unit(sheet_from):
    """phi is a plain number of degrees (Mathcad's phi*deg): a bound of 120 deg is 120, not
    2.09 (radians), and a plain 120 is taken as degrees, as range bounds are."""
    s = sheet_from(
        '[inputs]\nphi_max = "120 deg"\n'
        '[arguments]\nphi = { unit = "deg", plain = true }\npsi = { unit = "deg" }\n'
        '[definitions]\ndeg = "pi/180"\n'
        'top = "argmax(sin(phi*deg), phi, 0, phi_max)"\n'
        'top2 = "argmax(sin(phi*deg), phi, 0, 120)"\n'
        'top3 = { expr = "argmax(sin(psi), psi, 0, phi_max)", unit = "deg" }\n'
        'area = "integral(sin(phi*deg), phi, 0, phi_max)"\n',
    )
    for name in ("top", "top2", "top3"):
        assert s.evaluate(name).magnitude == pytest.approx(90.0, rel=1e-7)
    want = (1 - np.cos(np.radians(120))) * 180 / np.pi  # per degree of phi
    assert s.evaluate("area").magnitude == pytest.approx(want, rel=1e-13)
    with pytest.raises(UnitError, match=r"the upper bound B is \[length\]"):
        sheet_from(
            '[inputs]\nL = "1 m"\n[arguments]\nphi = { unit = "deg", plain = true }\n'
            '[definitions]\nbad = "integral(phi, phi, 0, L)"\n',
        )


# -- diff: the unit at load, the derivative (SymPy) at first use ---------------------------------
HEAVY_CODE = (
    "import sys, workbook\n{body}\n"
    "heavy = ('sympy', 'mpmath', 'scipy.optimize', 'scipy.integrate')\n"
    "print(','.join(m for m in heavy if m in sys.modules) or '-')"
)


def _heavy_imports(body: str, *argv: str) -> str:
    import subprocess
    import sys

    code = HEAVY_CODE.format(body=body)
    done = subprocess.run(
        [sys.executable, "-c", code, *argv], capture_output=True, text=True, check=True
    )
    return done.stdout.splitlines()[-1]


@pytest.mark.slow
def test_loading_every_template_imports_no_sympy_mpmath_or_scipy_solvers():
    # reducer-profile calls diff: its derivatives are found when first evaluated
    body = "for name in workbook.list_templates():\n    workbook.load(name)"
    assert _heavy_imports(body) == "-"


@pytest.mark.slow
def test_cold_start_of_concave_cam_imports_no_sympy_mpmath_or_scipy_solvers(tmp_path):
    body = (
        "from workbook.cli import main\n"
        "assert main(['run', 'concave-cam', '--out', sys.argv[1]]) == 0"
    )
    assert _heavy_imports(body, str(tmp_path / "cc.xlsx")) == "-"


@pytest.mark.slow
def test_a_derivative_is_found_at_first_use(tmp_path):
    path = tmp_path / "d.toml"
    path.write_text(EXTREMA, encoding="utf-8")
    body = (
        f"s = workbook.load({str(path)!r})\n"
        "assert s.typer.function('v').body.unit is not None\n"
        "print(','.join(m for m in ('sympy',) if m in sys.modules) or '-')\n"
        "print(s.evaluate('v', 0.0))"
    )
    import subprocess
    import sys

    code = HEAVY_CODE.format(body=body)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    before, value, after = out.stdout.splitlines()
    assert before == "-" and "sympy" in after.split(",")
    assert value == "1.0 meter / second"  # A*omega = 10 mm * 100/s


DIFF = """
[inputs]
A = "10 mm"
omega = "100 1/s"
[arguments]
x = {{ unit = "" }}
y = {{ unit = "" }}
t = {{ unit = "s" }}
[definitions]
"s(t)" = {{ expr = "A*sin(omega*t)", unit = "mm" }}
{line}
"""


@pytest.mark.parametrize(
    "line, message",
    [
        ('"d(t)" = "diff(s(t), t, 11)"', "the order N must be a whole number from 1 to 10"),
        ('"d(t)" = "diff(s(t), t, 1.5)"', "the order N must be a whole number"),
        ('d = "diff(x^2, x)"', "the derivative is a function of x, which is not an argument"),
        ('"d(x)" = "diff(root(x*y - 1, y, 0.1, 10), x)"', "root() is solved numerically"),
        ('"d(x)" = "diff(maximum(x*y, y, 0, 1), x)"', "maximum() is solved numerically"),
        ('"d(x)" = "diff(x > 1, x)"', "a comparison cannot be used as a number"),
        ('"d(t)" = "diff(s(t), omega)"', "already an input"),
    ],
)
def test_diff_errors_without_sympy_come_at_load(sheet_from, line, message):
    with pytest.raises(TemplateError, match=re.escape(message)) as err:
        sheet_from(DIFF.format(line=line), name="d")
    assert err.value.line == 11 and err.value.definition == "d"
    assert "d.toml" in str(err.value)


@pytest.mark.slow
def test_a_derivative_sympy_cannot_write_back_is_an_error_at_first_use(tmp_path):
    from workbook.cli import main

    path = tmp_path / "d.toml"
    path.write_text(DIFF.format(line='"d(x)" = "diff(sign(x)*x^2, x, 2)"'), encoding="utf-8")
    s = workbook.load(path)  # the second derivative holds DiracDelta: found when first used
    with pytest.raises(TemplateError, match="the derivative contains DiracDelta") as err:
        s.evaluate("d", 1.0)
    assert (err.value.line, err.value.definition) == (11, "d")
    assert str(err.value).startswith(f"{path}:11, in 'd'")
    table = DIFF.format(line='"d(x)" = "diff(sign(x)*x^2, x, 2)"') + (
        '[[tables]]\nname = "t"\nrange = "x := 1, 2 .. 3"\ncolumns = { d = "" }\n'
    )
    path.write_text(table, encoding="utf-8")
    assert main(["run", str(path), "--out", str(tmp_path / "d.xlsx")]) == 2


def test_a_derivative_inside_another_function_call(sheet_from):
    # diff's variable is the enclosing one: z(u) = v(2*u) is s'(t) at t = 2*u
    lines = '"v(t)" = { expr = "diff(s(t), t)", unit = "m/s" }\n"z(t)" = "v(2*t)"'
    s = sheet_from(DIFF.format(line=lines))
    t = np.array([0.0, 0.003, 0.02])
    want = 0.01 * 100 * np.cos(100 * 2 * t)
    assert np.allclose(s.evaluate("z", t).to("m/s").magnitude, want, rtol=1e-13, atol=1e-16)


# -- a root in a table column: live, one bisection chain per table row ---------------------------
ROOT_TABLE = """
[inputs]
eps = "0.05 mm"
D = "100 mm"
[arguments]
Re = { unit = "" }
f = { unit = "" }
[definitions]
"colebrook(f, Re)" = "1/sqrt(f) + 2*log10(eps/(3.7*D) + 2.51/(Re*sqrt(f)))"
"friction(Re)" = "root(colebrook(f, Re), f, 0.005, 0.1)"
"friction_guess(Re)" = "root(colebrook(f, Re), f, 0.02)"
[[tables]]
name = "moody"
range = "Re := 4000, 24000 .. 104000"
columns = { friction = "", friction_guess = "" }
"""


def _root_table(sheet_from, tmp_path):
    import openpyxl

    s = sheet_from(ROOT_TABLE)
    path = s.write_xlsx(tmp_path / "m.xlsx")
    wb = openpyxl.load_workbook(path)
    ws = next(w for w in wb.worksheets if w.title not in ("Inputs", "Definitions"))
    return s, path, wb, ws


@pytest.mark.slow
def test_a_root_in_a_table_column_is_live_as_bisection_steps(sheet_from, tmp_path):
    s, path, wb, ws = _root_table(sheet_from, tmp_path)
    heads = [c.value for c in ws[2]]
    live, guess = heads.index("friction") + 1, heads.index("friction_guess") + 1
    re_values = [ws.cell(r, 1).value for r in range(3, 9)]
    assert re_values == [4000 + 20000 * i for i in range(6)]
    for r in range(3, 9):
        formula = ws.cell(r, live).value
        assert formula.startswith("=IF('Solver rows'!$B$" + str(r)), formula
        assert isinstance(ws.cell(r, guess).value, float)  # from a guess: a number
    assert "Solver rows" in wb.sheetnames
    assert "from a guess" in ws.cell(2, guess).comment.text
    stated = re.search(r"by ([0-9.e+-]+) ", ws.cell(2, live).comment.text)
    assert stated and float(stated.group(1)) < 1e-10
    # the cached value of every step cell is what the formulas compute (the same steps)
    from workbook.numerics.excelforms import bisection

    steps = wb["Solver rows"]
    f = lambda x, i: colebrook(x, np.array(re_values)[i.astype(int)])  # noqa: E731
    want = bisection(f, np.full(6, 0.005), np.full(6, 0.1), np.arange(6.0))
    cached = openpyxl_values(path)["Solver rows"]
    assert steps.cell(3, 2).value.startswith("=1/SQRT((0.005))")
    for r in range(6):
        assert cached[(r + 3, 2)] == pytest.approx(want["fa"][r], rel=1e-12)
        assert cached[(r + 3, 2 + 2 + 3 * 60)] == pytest.approx(want["lo"][60][r], rel=1e-12)


def openpyxl_values(path) -> dict:
    import openpyxl

    wb = openpyxl.load_workbook(path, data_only=True)
    return {
        ws.title: {(c.row, c.column): c.value for row in ws.iter_rows() for c in row}
        for ws in wb.worksheets
    }


def test_a_root_in_a_long_table_column_is_a_number_with_the_limit(sheet_from, tmp_path):
    import openpyxl

    long = ROOT_TABLE.replace("Re := 4000, 24000 .. 104000", "Re := 4000, 4100 .. 104000")
    s = sheet_from(long)
    path = s.write_xlsx(tmp_path / "m.xlsx")
    ws = next(w for w in openpyxl.load_workbook(path).worksheets if w.title != "Inputs")
    heads = [c.value for c in ws[2]]
    col = heads.index("friction") + 1
    assert isinstance(ws.cell(3, col).value, float)
    text = ws.cell(2, col).comment.text
    assert "up to 100,000 cells" in text and "1,001 rows" in text


@pytest.mark.slow
@pytest.mark.skipif(soffice() is None, reason="LibreOffice is not installed")
def test_a_live_root_column_follows_an_input_change_in_libreoffice(sheet_from, tmp_path):
    s, path, wb, ws = _root_table(sheet_from, tmp_path)
    heads = [c.value for c in ws[2]]
    col = heads.index("friction") + 1
    stated = float(re.search(r"by ([0-9.e+-]+) ", ws.cell(2, col).comment.text).group(1))
    # unchanged inputs: LibreOffice computes every formula cell to its cached value (f near
    # the root is rounding noise, 1e-14 beside terms near 7, computed a little differently)
    before = formula_values(path)
    again = cell_values(recalculate(path, tmp_path / "lo0"))
    bad = [
        (k, v, again.get(k))
        for k, (_, v) in before.items()
        if isinstance(v, float) and again.get(k) != pytest.approx(v, rel=1e-12, abs=1e-12)
    ]
    assert not bad, bad[:5]
    # eps 0.05 mm -> 0.5 mm: the column follows
    row = next(r for r in wb["Inputs"].iter_rows() if r[0].value == "eps")
    row[1].value = 0.5
    wb.save(tmp_path / "edited.xlsx")
    got = cell_values(recalculate(tmp_path / "edited.xlsx", tmp_path / "lo1"))
    re_values = np.array([4000.0 + 20000 * i for i in range(6)])
    want = s.with_inputs(eps="0.5 mm").evaluate("friction", re_values).magnitude
    old = s.evaluate("friction", re_values).magnitude
    for i, r in enumerate(range(3, 9)):
        value = got[(ws.title, f"{ws.cell(r, col).column_letter}{r}")]
        assert value == pytest.approx(want[i], rel=1e-9, abs=10 * stated)
        assert value != pytest.approx(old[i], rel=1e-3)


def test_a_loaded_sheet_with_diff_pickles():
    # as one without diff does (before evaluating: compiled closures do not pickle)
    import pickle

    s = workbook.load("reducer-profile")
    again = pickle.loads(pickle.dumps(s))
    assert again.evaluate("dx_t", 1, 10.0) == s.evaluate("dx_t", 1, 10.0)


# -- extrema: live as samples and golden-section steps ---------------------------------------
EXTREMA_LIVE = """
[inputs]
c = "0.1"
[arguments]
x = { unit = "" }
k = { unit = "" }
[definitions]
peak = "maximum(sin(x) + c*x, x, 0, 10)"
at = "argmax(sin(x) + c*x, x, 0, 10)"
low = "minimum(sin(x) + c*x, x, 0, 10)"
at_low = "argmin(sin(x) + c*x, x, 0, 10)"
"top(k)" = "maximum(sin(x) + (k + c)*x, x, 0, 10)"
"where(k)" = "argmax(sin(x) + (k + c)*x, x, 0, 10)"
[[tables]]
name = "t"
range = "k := 0, 0.05 .. 0.3"
columns = { top = "", where = "" }
"""
STATED = r"differs from the engine's value by ([0-9.e+-]+) "


def _extrema_book(sheet_from, tmp_path):
    import openpyxl

    s = sheet_from(EXTREMA_LIVE)
    path = s.write_xlsx(tmp_path / "e.xlsx")
    wb = openpyxl.load_workbook(path)
    return s, path, wb


def _cells(wb):
    """{name: (sheet, cell, stated difference)} of the scalar results and the table rows."""
    out = {}
    res = wb["Results"]
    for row in res.iter_rows(min_row=2, max_row=5):
        out[row[0].value] = ("Results", row[1].coordinate, row[1].comment.text)
    ws = wb["Listing"]
    heads = {c.value: c for c in ws[2]}
    for name in ("top", "where"):
        head = heads[name]
        for r in range(3, 10):
            cell = ws.cell(r, head.column)
            out[(name, r - 3)] = ("Listing", cell.coordinate, head.comment.text)
    return out


@pytest.mark.slow
def test_extrema_are_live_where_close_to_the_engine(sheet_from, tmp_path):
    s, path, wb = _extrema_book(sheet_from, tmp_path)
    for key, (sheet_name, ref, comment) in _cells(wb).items():
        cell = wb[sheet_name][ref].value
        name = key if isinstance(key, str) else key[0]
        if name in ("at", "at_low", "where"):  # flat there: found to 1e-6 only, a number
            assert isinstance(cell, float), (key, cell)
            assert "more than 1e-09" in comment, comment
            continue
        steps = "'Solver steps'" if sheet_name == "Results" else "'Solver rows'"
        assert cell.startswith("=IF(") and steps + "!" in cell, (key, cell)
        assert float(re.search(STATED, comment).group(1)) < 1e-9 * 2, (key, comment)


@pytest.mark.slow
@pytest.mark.skipif(soffice() is None, reason="LibreOffice is not installed")
def test_live_extrema_follow_an_input_change_in_libreoffice(sheet_from, tmp_path):
    s, path, wb = _extrema_book(sheet_from, tmp_path)
    cells = {
        k: v for k, v in _cells(wb).items() if isinstance(wb[v[0]][v[1]].value, str)
    }  # the live ones
    assert {"peak", "low", ("top", 0)} <= set(cells)
    row = next(r for r in wb["Inputs"].iter_rows() if r[0].value == "c")
    row[1].value = -0.05  # the global maximum moves to the first peak
    wb.save(tmp_path / "edited.xlsx")
    got = cell_values(recalculate(tmp_path / "edited.xlsx", tmp_path / "lo"))
    new, k = s.with_inputs(c="-0.05"), 0.05 * np.arange(7)
    want = {name: new.evaluate(name).magnitude for name in ("peak", "low")}
    want.update({("top", i): v for i, v in enumerate(new.evaluate("top", k).magnitude)})
    for key, (sheet_name, ref, comment) in cells.items():
        stated = float(re.search(STATED, comment).group(1))
        value = got[(sheet_name, ref)]
        assert value == pytest.approx(want[key], rel=1e-9, abs=10 * stated), key
    old = s.evaluate("peak").magnitude
    assert got[cells["peak"][:2]] != pytest.approx(old, rel=1e-2)  # it followed the edit


@pytest.mark.slow
@pytest.mark.parametrize("name", workbook.list_templates())
def test_bench_of_every_template_is_an_answer_not_a_crash(name, capsys):
    """`workbook bench` on each installed template: a table (0) or "nothing to time" (2),
    never an internal error (a text definition among the targets was one)."""
    from workbook.cli import main

    assert main(["bench", name, "--quick"]) in (0, 2)


LIVE_FORMS = """
[inputs]
R = "50 mm"
u_max = "2 m/s"
eps = "0.05 mm"
D = "100 mm"
[arguments]
r = { unit = "mm" }
Re = { unit = "" }
f = { unit = "" }
[definitions]
"u(r)" = { expr = "u_max*(1 - (r/R)^2)", unit = "m/s" }
Q = { expr = "integral(2*pi*r*u(r), r, 0, R)", unit = "L/s" }
"colebrook(f, Re)" = "1/sqrt(f) + 2*log10(eps/(3.7*D) + 2.51/(Re*sqrt(f)))"
"friction(Re)" = "root(colebrook(f, Re), f, 0.005, 0.1)"
[[tables]]
name = "moody"
range = "Re := 4000, 104000 .. 1004000"
columns = { friction = "" }
"""


def test_the_checks_sheet_lists_each_live_form_and_its_difference(sheet_from, tmp_path):
    """An integral's Gauss-Legendre sum and a column of bisection chains: on the Checks sheet,
    where each is, the engine's value, the live cell and their difference."""
    import openpyxl

    s = sheet_from(LIVE_FORMS)
    out = s.write_xlsx(tmp_path / "pipe.xlsx")
    ws = openpyxl.load_workbook(out)["Checks"]
    rows = [[c.value for c in row] for row in ws.iter_rows()]
    start = next(i for i, r in enumerate(rows) if r[0] == "Live forms of numerical built-ins")
    lines = {r[1]: r for r in rows[start + 2 :] if r[0] and r[0].startswith("'")}
    q = lines["Q"]
    assert q[2] == "integral()" and q[5] == f"={q[0]}"
    assert q[4] == pytest.approx(s.evaluate("Q").to("L/s").magnitude, rel=1e-12)
    column = next(r for what, r in lines.items() if what.startswith("table moody: friction"))
    assert column[2] == "root()" and ":" in column[0]
    assert 0 <= column[6] < 1e-9
