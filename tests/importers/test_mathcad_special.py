"""Mathcad's special functions, factorial, counting functions and decompositions as the importer
translates them: each worksheet stores the value mpmath computes at 50 digits (no worksheet of
../shared calls any of them), and the check reproduces it; those Mathcad computes with signs of
its own solver (qr, svd) and the fits it gives as its own bookkeeping are refused with the
reason."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
from helpers.mathcad_xml import (
    apply,
    array_cells,
    call,
    check_sheet,
    define,
    ident,
    import_sheet,
    index,
    matrix,
    prime_package,
    prime_region,
    prime_result,
    real,
    shown,
)

from workbook.cli import main


def _f(x) -> float:
    with mpmath.workdps(50):
        return float(x)


CALLS = [
    # (Mathcad's call, the language's, mpmath's value)
    (call("Γ", real(4.5)), "gamma(4.5)", _f(mpmath.gamma(4.5))),
    (call("erf", real(0.3)), "erf(0.3)", _f(mpmath.erf(0.3))),
    (call("erfc", real(1.2)), "erfc(1.2)", _f(mpmath.erfc(1.2))),
    (call("J0", real(2.5)), "bessel_j(0, 2.5)", _f(mpmath.besselj(0, 2.5))),
    (call("J1", real(2.5)), "bessel_j(1, 2.5)", _f(mpmath.besselj(1, 2.5))),
    (call("Jn", real(3), real(2.5)), "bessel_j(3, 2.5)", _f(mpmath.besselj(3, 2.5))),
    (call("Y0", real(0.7)), "bessel_y(0, 0.7)", _f(mpmath.bessely(0, 0.7))),
    (call("Y1", real(0.7)), "bessel_y(1, 0.7)", _f(mpmath.bessely(1, 0.7))),
    (call("Yn", real(2), real(0.7)), "bessel_y(2, 0.7)", _f(mpmath.bessely(2, 0.7))),
    (call("I0", real(1.5)), "bessel_i(0, 1.5)", _f(mpmath.besseli(0, 1.5))),
    (call("I1", real(1.5)), "bessel_i(1, 1.5)", _f(mpmath.besseli(1, 1.5))),
    (call("In", real(2), real(1.5)), "bessel_i(2, 1.5)", _f(mpmath.besseli(2, 1.5))),
    (call("K0", real(1.5)), "bessel_k(0, 1.5)", _f(mpmath.besselk(0, 1.5))),
    (call("K1", real(1.5)), "bessel_k(1, 1.5)", _f(mpmath.besselk(1, 1.5))),
    (call("Kn", real(2), real(1.5)), "bessel_k(2, 1.5)", _f(mpmath.besselk(2, 1.5))),
    (call("combin", real(10), real(3)), "combin(10, 3)", 120.0),
    (call("permut", real(10), real(3)), "permut(10, 3)", 720.0),
    (apply("factorial", real(7)), "factorial(7)", 5040.0),
]


@pytest.mark.slow
def test_each_call_is_the_languages_and_reproduces_mpmath(tmp_path, capsys):
    regions = [
        define(k + 1, ident(f"v{k}"), shown(mathcad, real(repr(value))))
        for k, (mathcad, _, value) in enumerate(CALLS)
    ]
    text = import_sheet(tmp_path, capsys, "special", *regions)
    for k, (_, language, _) in enumerate(CALLS):
        assert f'v{k} = {{ expr = "{language}"' in text, language
    result = check_sheet(tmp_path, capsys, "special")
    assert (result["printed"], result["reproduced"]) == (len(CALLS), len(CALLS)), result


@pytest.mark.slow
def test_a_worksheets_own_j1_is_its_own(tmp_path, capsys):
    """J1 defined by the worksheet (a variable, as in the corpora) is not Mathcad's Bessel J1."""
    text = import_sheet(
        tmp_path,
        capsys,
        "own",
        define(1, ident("J1"), real(4)),
        define(2, ident("y"), shown(apply("mult", ident("J1"), real(2)), real(8))),
    )
    assert "bessel" not in text
    assert check_sheet(tmp_path, capsys, "own")["reproduced"] == 1


@pytest.mark.slow
def test_the_factorial_of_a_sum_and_the_incomplete_gamma(tmp_path, capsys):
    text = import_sheet(
        tmp_path,
        capsys,
        "fact",
        define(1, ident("n"), real(3)),
        define(
            2, ident("f"), shown(apply("factorial", apply("plus", ident("n"), real(1))), real(24))
        ),
        define(3, ident("g"), shown(call("Γ", real(2), real(1)), real(0.7357588823428847))),
    )
    assert 'expr = "factorial(n + 1)"' in text
    assert "Γ() with 2 arguments" in text  # Mathcad's incomplete gamma: not translated
    result = check_sheet(tmp_path, capsys, "fact")
    assert (result["reproduced"], result["not_computable"]) == (1, 1), result


@pytest.mark.slow
def test_cholesky_is_the_languages(tmp_path, capsys):
    a = np.array([[4.0, 12.0, -16.0], [12.0, 37.0, -43.0], [-16.0, -43.0, 98.0]])
    with mpmath.workdps(50):
        want = np.array(mpmath.cholesky(mpmath.matrix(a.tolist())).tolist(), dtype=float)
    text = import_sheet(
        tmp_path,
        capsys,
        "chol",
        define(1, ident("A"), array_cells(a)),
        define(2, ident("L"), shown(call("cholesky", ident("A")), array_cells(want))),
    )
    assert '"cholesky(A)"' in text
    result = check_sheet(tmp_path, capsys, "chol")
    assert (result["printed"], result["reproduced"]) == (9, 9), result


@pytest.mark.slow
@pytest.mark.parametrize(
    "name, reason",
    [
        ("qr", "signs are those of Mathcad's solver"),
        ("svd", "signs are those of Mathcad's solver"),
        ("regress", "Mathcad's own bookkeeping for interp"),
        ("genfit", "Mathcad's own nonlinear solver"),
    ],
)
def test_refused_with_the_reason(tmp_path, capsys, name, reason):
    cells = matrix(real(1), real(2), real(3), real(4), cols=2)
    text = import_sheet(
        tmp_path,
        capsys,
        name,
        define(1, ident("A"), cells),
        define(2, ident("B"), shown(call(name, ident("A")), cells)),
    )
    assert reason in text
    result = check_sheet(tmp_path, capsys, name)
    assert result["reproduced"] == 0 and result["not_computable"] == 4, result


@pytest.mark.slow
def test_prime_factorial_and_gamma(tmp_path, capsys):
    """In Prime, n! and Γ(x) are written as in Mathcad 15 (the namespace math50)."""
    body_f = (
        '<ml:eval xmlns:ml="http://schemas.mathsoft.com/math50">'
        f"{apply('factorial', real(5))}</ml:eval>"
    )
    body_g = (
        f'<ml:eval xmlns:ml="http://schemas.mathsoft.com/math50">{call("Γ", real(0.5))}</ml:eval>'
    )
    src = prime_package(
        tmp_path / "prime-special.mcdx",
        prime_region(1, 1, body_f) + prime_region(2, 2, body_g),
        prime_result(1, real(120)) + prime_result(2, real(repr(_f(mpmath.sqrt(mpmath.pi))))),
    )
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    capsys.readouterr()
    result = check_sheet(tmp_path, capsys, "prime-special")
    assert (result["printed"], result["reproduced"]) == (2, 2), result


@pytest.mark.slow
def test_prime_vector_sum(tmp_path, capsys):
    """Prime's vector sum Σv (Σ with empty placeholders for its variable and its upper bound)
    is the sum of v's elements."""
    ns = 'xmlns:ml="http://schemas.mathsoft.com/math50"'
    v = matrix(real(1.5), real(2), real(4))
    total = (
        "<ml:apply><ml:summation/><ml:lambda><ml:boundVars><ml:placeholder/></ml:boundVars>"
        f"{ident('v')}</ml:lambda><ml:upperBound><ml:placeholder/></ml:upperBound></ml:apply>"
    )
    regions = prime_region(1, 1, f"<ml:define {ns}>{ident('v')}{v}</ml:define>")
    regions += prime_region(2, 2, f"<ml:eval {ns}>{total}</ml:eval>")
    src = prime_package(tmp_path / "vector-sum.mcdx", regions, prime_result(2, real(7.5)))
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    capsys.readouterr()
    assert '"sum(v)"' in (tmp_path / "vector-sum.toml").read_text(encoding="utf-8")
    result = check_sheet(tmp_path, capsys, "vector-sum")
    assert (result["printed"], result["reproduced"]) == (1, 1), result


@pytest.mark.slow
def test_an_element_assignment_at_a_shifted_index(tmp_path, capsys):
    """Data[i + N] := d[i] over i := 0 .. 2 (N := 2, d a vector of 3) sets Data[2..4] and keeps
    Data[0], Data[1] of the vector before; E[j - 1] := j over j := 1 .. 2 is [1, 2]."""
    span = "<ml:range>" + real(0) + real(2) + "</ml:range>"
    shifted = index(ident("Data"), apply("plus", ident("i"), ident("N")))
    d = matrix(real(7), real(8), real(9))
    text = import_sheet(
        tmp_path,
        capsys,
        "shifted",
        define(1, ident("i"), span),
        define(2, ident("N"), real(2)),
        define(3, ident("d"), d),
        define(4, ident("Data"), matrix(real(1), real(2))),
        define(5, shifted, index(ident("d"), ident("i"))),
        define(6, ident("s"), shown(index(ident("Data"), real(4)), real(9))),
        define(7, ident("r"), shown(call("rows", ident("Data")), real(5))),
        define(8, ident("j"), "<ml:range>" + real(1) + real(2) + "</ml:range>"),
        define(9, index(ident("E"), apply("minus", ident("j"), real(1))), ident("j")),
        define(10, ident("t"), shown(index(ident("E"), real(1)), real(2))),
    )
    assert "Data_of(0), Data_of(1), Data_of(2)]" in text
    result = check_sheet(tmp_path, capsys, "shifted")
    assert (result["printed"], result["reproduced"]) == (3, 3), result


@pytest.mark.slow
def test_prime_math_inside_a_text_region_computes(tmp_path, capsys):
    """Prime computes a math region placed inside a text region, where the text stands: its
    definition is read by the regions after it."""
    ns = 'xmlns:ml="http://schemas.mathsoft.com/math50"'
    inner = prime_region(2, 1, f"<ml:define {ns}>{ident('w')}{real(3)}</ml:define>")
    text = (
        f'<region region-id="1"><text item-idref="none"><regions>{inner}</regions></text></region>'
    )
    shown_w = prime_region(3, 2, f"<ml:eval {ns}>{apply('mult', ident('w'), real(2))}</ml:eval>")
    src = prime_package(tmp_path / "inline.mcdx", text + shown_w, prime_result(2, real(6)))
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    capsys.readouterr()
    result = check_sheet(tmp_path, capsys, "inline")
    assert (result["printed"], result["reproduced"]) == (1, 1), result
