"""Mathcad's imaginary unit (``4i``, ``2j``: ``<ml:imag>``) as the language's complex numbers,
and results Mathcad stored as complex numbers compared part by part: the real parts and the
imaginary parts are printed values of ``Re(...)`` and ``Im(...)`` (computed here by Python's
complex arithmetic); a real result where Mathcad stored a complex one is never reproduced."""

from __future__ import annotations

import cmath

from helpers.mathcad_xml import (
    apply,
    check_sheet,
    define,
    evaluate,
    ident,
    import_sheet,
    matrix,
    prime_package,
    prime_region,
    prime_result,
    real,
)

from workbook.cli import main


def imag(v: float, symbol: str = "i") -> str:
    return f'<ml:imag symbol="{symbol}">{v!r}</ml:imag>'


def stored(z: complex) -> str:
    return f"<ml:complex>{real(z.real)}<ml:imag>{z.imag!r}</ml:imag></ml:complex>"


def test_imaginary_literals_and_complex_results(tmp_path, capsys):
    """Z := 3 + 4i, W := Z·(1 - 2j); Z = 3 + 4i, W = 11 - 2i, |Z| = 5, e^(iπ/2) = i, and a
    vector [Z; 2] = [3 + 4i; 2]: each part reproduced (11 printed values)."""
    z, w = 3 + 4j, (3 + 4j) * (1 - 2j)
    text = import_sheet(
        tmp_path,
        capsys,
        "cx",
        define(1, ident("Z"), apply("plus", real(3), imag(4.0))),
        define(2, ident("W"), apply("mult", ident("Z"), apply("minus", real(1), imag(2.0, "j")))),
        evaluate(3, ident("Z"), stored(z)),
        evaluate(4, ident("W"), stored(w)),
        evaluate(5, apply("absval", ident("Z")), real(abs(z))),
        evaluate(
            6,
            apply("pow", ident("e"), apply("div", apply("mult", imag(1.0), ident("π")), real(2))),
            stored(cmath.exp(1j * cmath.pi / 2)),
        ),
        evaluate(7, matrix(ident("Z"), real(2)), matrix(stored(z), real(2))),
    )
    assert '"3 + 4i"' in text
    result = check_sheet(tmp_path, capsys, "cx")
    assert (result["printed"], result["reproduced"]) == (11, 11), result["failures"]


def test_a_wrong_imaginary_part_fails_and_a_real_value_is_never_complex(tmp_path, capsys):
    """Z := 3 + 4i with 3 - 4i stored fails on its imaginary part; x := 2 with 2 + 1i stored
    (a sheet Mathcad computed otherwise) fails on its imaginary part, never reproduced."""
    import_sheet(
        tmp_path,
        capsys,
        "cxbad",
        define(1, ident("Z"), apply("plus", real(3), imag(4.0))),
        define(2, ident("x"), real(2)),
        evaluate(3, ident("Z"), stored(3 - 4j)),
        evaluate(4, ident("x"), stored(2 + 1j)),
    )
    result = check_sheet(tmp_path, capsys, "cxbad")
    assert (result["printed"], result["reproduced"], result["failed"]) == (4, 2, 2), result


def test_prime_imaginary_unit(tmp_path, capsys):
    """In Prime, 1i is the same element (namespace math50), its result stored the same way."""
    ns = 'xmlns:ml="http://schemas.mathsoft.com/math50"'
    body = f"<ml:eval {ns}>{apply('mult', real(2), imag(1.5))}</ml:eval>"
    src = prime_package(
        tmp_path / "prime-cx.mcdx", prime_region(1, 1, body), prime_result(1, stored(3j))
    )
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    capsys.readouterr()
    result = check_sheet(tmp_path, capsys, "prime-cx")
    assert (result["printed"], result["reproduced"]) == (2, 2), result["failures"]


def test_a_complex_result_not_translated_counts_each_number_once(tmp_path, capsys):
    """v = [1 + 2i; 3] shown for a name the sheet never defines: its two stored numbers are
    two values, not computable (each counted once, never compared)."""
    import_sheet(
        tmp_path,
        capsys,
        "cxlost",
        evaluate(1, ident("v"), matrix(stored(1 + 2j), real(3))),
    )
    result = check_sheet(tmp_path, capsys, "cxlost")
    assert (result["printed"], result["not_computable"]) == (2, 2), result


def test_a_complex_result_over_a_range(tmp_path, capsys):
    """x := 0 .. 2; x + 2i = [2i; 1 + 2i; 2 + 2i]: the real and imaginary parts at each x."""
    rng = "<ml:range><ml:real>0</ml:real><ml:real>2</ml:real></ml:range>"
    import_sheet(
        tmp_path,
        capsys,
        "cxrange",
        define(1, ident("x"), rng),
        evaluate(
            2,
            apply("plus", ident("x"), imag(2.0)),
            matrix(*(stored(complex(v, 2)) for v in range(3))),
        ),
    )
    result = check_sheet(tmp_path, capsys, "cxrange")
    assert (result["printed"], result["reproduced"]) == (6, 6), result["failures"]


def test_the_functions_of_complex_numbers(tmp_path, capsys):
    """Z := 3 + 4i; Re(Z) = 3, Im(Z) = 4, arg(Z) = atan2(4, 3) (Mathcad's names)."""
    from helpers.mathcad_xml import call

    z = 3 + 4j
    import_sheet(
        tmp_path,
        capsys,
        "cxfun",
        define(1, ident("Z"), apply("plus", real(3), imag(4.0))),
        evaluate(2, call("Re", ident("Z")), real(z.real)),
        evaluate(3, call("Im", ident("Z")), real(z.imag)),
        evaluate(4, call("arg", ident("Z")), real(cmath.phase(z))),
    )
    result = check_sheet(tmp_path, capsys, "cxfun")
    assert (result["printed"], result["reproduced"]) == (3, 3), result["failures"]
