"""`workbook bench`'s reference is mpmath on the same typed tree: the mpmath form of EXPR
against mpmath at 50 digits written by hand, the fallback named where EXPR has no mpmath
form, and bench on every template and on the hard cases: every "ok" is a row whose reference
is mpmath, and every estimate is at least a tenth of the difference from it."""

import mpmath
import pytest
from helpers.sheets import HARD_SHEET

import workbook
from workbook.numerics import bench, mpref
from workbook.numerics.mpform import NoMpForm, NoValue, mp_form

MP = mpmath.mpf


FORMS = """
[arguments]
x = { unit = "" }
[definitions]
k = "3"
"f(x)" = "k*x^2 + atan2(x, 2)"
"p(x)" = { pieces = ["sqrt(x) if x > 0.5", "-x otherwise"] }
"a(x)" = "f(x) - p(x) + exp(-x)*ln(1 + x)/log10(2 + x) + tanh(x)*abs(x - 1) + max(x, 0.7)"
"""


def _a_by_hand(x):
    f = 3 * x**2 + mpmath.atan2(2, x)  # atan2(x, 2): x first
    p = mpmath.sqrt(x) if x > 0.5 else -x
    return (
        f
        - p
        + mpmath.exp(-x) * mpmath.log(1 + x) / mpmath.log10(2 + x)
        + mpmath.tanh(x) * abs(x - 1)
        + max(x, MP(0.7))  # the tree's constants are the doubles numpy computes with
    )


@pytest.mark.parametrize("x", [0.1, 0.5, 0.75, 2.5])
def test_the_mpmath_form_of_a_tree_is_its_formula_at_32_digits(sheet_from, x):
    """Sheet functions, a scalar definition, a piecewise value and the plain built-ins."""
    s = sheet_from(FORMS)
    ctx = mpref.context(32)
    form = mp_form(s.evaluator, ctx, s.typer.function("a").body)
    got = form({"x": x})
    with mpmath.workdps(50):
        want = _a_by_hand(MP(x))
        assert abs(got - want) <= MP("1e-29") * abs(want)


def test_no_real_value_and_no_form_are_said(sheet_from):
    s = sheet_from(
        '[arguments]\nx = { unit = "" }\n[definitions]\n'
        '"r(x)" = "sqrt(x - 1)"\n"m(x)" = "mod(x, 1)"\n',
    )
    ctx = mpref.context(32)
    with pytest.raises(NoValue):
        mp_form(s.evaluator, ctx, s.typer.function("r").body)({"x": 0.5})
    with pytest.raises(NoMpForm, match=r"mod\(\)"):
        mp_form(s.evaluator, ctx, s.typer.function("m").body)


def test_a_formula_without_an_mpmath_form_falls_back_and_says_so(sheet_from):
    s = sheet_from(
        '[definitions]\nsaw = "integral(pnorm(x, 0, 1), x, 0, 2.5)"\n'
        'sq = "integral(x^2, x, 0, 3)"\n',
    )
    lines = {line.what: line for line in bench.run(s, repeats=1)}
    assert lines["saw"].reference == "scipy (pnorm(): no mpmath form)"
    assert lines["saw"].verdict == "ok"  # against QUADPACK
    assert lines["sq"].reference == "mpmath" and lines["sq"].verdict == "ok"
    assert lines["sq"].difference <= 1e-15


def test_the_reference_of_each_call_is_compared_not_the_definition(sheet_from):
    """A definition that is the difference of an integral and its closed form is rounding
    noise; its error relative to itself says nothing. Each built-in call is compared with
    the reference's call of the same EXPR, relative to that call's size."""
    s = sheet_from('[definitions]\nd = "integral(sin(x), x, 0, 1) - (1 - cos(1))"\n')
    (line,) = bench.run(s, repeats=1)
    assert line.reference == "mpmath" and line.checked == 1
    assert line.difference <= 1e-15 and line.verdict == "ok"


def test_a_reference_that_cannot_answer_raises_what_bench_prints():
    """The reference's refusals are exceptions with the reason (bench prints them as "no
    reference: ..."), never a value: two roots where both ends have one sign, a pole."""
    ctx = mpref.context(60)
    with pytest.raises(mpref.Unconverged, match="2 sign changes"):
        mpref.root_in(ctx, lambda x: (x - MP("0.1")) * (x - MP("0.5")), 0, 1)
    with pytest.raises(mpref.Unconverged, match="a pole or a jump"):
        mpref.root_in(ctx, lambda x: 1 / (x - MP("0.3")), 0, 1)
    with pytest.raises(mpref.Unconverged, match="no sign change"):
        mpref.root_near(ctx, lambda x: x * x + 1, 0.5)


HARD = (
    HARD_SHEET
    + """near = "root(tan(x), x, 1.5)"
bump = "minimum(x^2 - 1/(1 + ((x - 0.61)/1e-5)^2), x, 0, 1)"
nested = "integral(integral(1/sqrt(t + 1e-3), t, 0, u), u, 0, 1)"
"""
)

#: the one formula of the templates without an mpmath form: data interpolation, whose
#: reference is QUADPACK in doubles (said on its line)
FALLBACK = "scipy (linterp(): no mpmath form)"


def _verdicts_are_honest(where: str, lines) -> None:
    for line in lines:
        assert line.verdict not in ("WRONG", "ESTIMATE LOW"), (where, line.text())
        assert not line.failed, (where, line.text())
        assert line.estimate >= line.difference / 10 or line.difference <= bench.ROUNDING, (
            where,
            line.text(),
        )
        if line.verdict == "ok":
            assert line.reference in ("mpmath", FALLBACK), (where, line.text())
            assert line.checked > 0


@pytest.mark.slow
def test_bench_of_the_hard_cases_against_mpmath(sheet_from):
    lines = bench.run(sheet_from(HARD), repeats=1)
    _verdicts_are_honest("hard cases", lines)
    ok = {line.what for line in lines if line.verdict == "ok"}
    assert {"peak", "wave", "narrow", "step", "lorentz", "sqrt2", "near", "bump"} <= ok


@pytest.mark.slow
@pytest.mark.parametrize("name", workbook.list_templates())
def test_bench_of_every_template_against_mpmath(name):
    lines = bench.run(workbook.load(name), repeats=1)
    _verdicts_are_honest(name, lines)
