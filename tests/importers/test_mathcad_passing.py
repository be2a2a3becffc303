"""Mathcad's untyped functions called from functions, vectorised calls of the worksheet's
functions, and a matrix of names given a matrix of values of different units."""

from __future__ import annotations

import pytest
from helpers.mathcad_xml import (
    apply,
    call,
    check_sheet,
    define,
    evaluate,
    function,
    ident,
    import_sheet,
    local,
    math_region,
    matrix,
    program,
    real,
    shown,
    united,
)


def _vectorize(body: str) -> str:
    return apply("vectorize", body)


@pytest.mark.slow
def test_an_argument_takes_the_unit_passed_on_by_another_function(tmp_path, capsys):
    """g(z, k) := 1 + k*z is called only by h(z, k) := 2*g(z, k), and h(2 m, K) with
    K := 3/m: g's z is a length and its k per length (from h's call, whose arguments are
    h's own), so h(2 m, K) = 2*(1 + 6) = 14, never g typed as of plain numbers and h
    refused."""
    text = import_sheet(
        tmp_path,
        capsys,
        "passed",
        function(1, "g", ["z", "k"], apply("plus", real(1), apply("mult", ident("k"), ident("z")))),
        function(2, "h", ["z", "k"], apply("mult", real(2), call("g", ident("z"), ident("k")))),
        define(3, ident("K"), apply("div", real(3), ident("m"))),
        evaluate(4, call("h", apply("mult", real(2), ident("m")), ident("K")), real(14)),
    )
    assert "region 1:" not in text and "region 2:" not in text
    result = check_sheet(tmp_path, capsys, "passed")
    assert (result["printed"], result["reproduced"], result["failed"]) == (1, 1, 0), result


@pytest.mark.slow
def test_a_vectorised_call_of_a_function_of_the_worksheet(tmp_path, capsys):
    """c := 2, v := [1; 2; 3]*c (a vector computed, its length 3 known from the engine),
    f(x, a) := x^2 + a: ->(f(v, 1)) = [5; 17; 37], f called once per element (Mathcad's
    vectorize applies the worksheet's functions element by element)."""
    v = apply("mult", matrix(real(1), real(2), real(3)), ident("c"))
    f = apply("plus", apply("pow", ident("x"), real(2)), ident("a"))
    text = import_sheet(
        tmp_path,
        capsys,
        "vecf",
        define(1, ident("c"), real(2)),
        define(2, ident("v"), v),
        function(3, "f", ["x", "a"], f),
        evaluate(4, _vectorize(call("f", ident("v"), real(1))), matrix(*map(real, (5, 17, 37)))),
    )
    assert "f(v[0], 1)" in text
    result = check_sheet(tmp_path, capsys, "vecf")
    assert (result["printed"], result["reproduced"], result["failed"]) == (3, 3, 0), result


@pytest.mark.slow
def test_names_given_a_solve_blocks_unknowns_of_different_units(tmp_path, capsys):
    """e := 0, k := 0/m; Given e + 1 = 3, k*(2 m) = 8; [e1; k1] := Find(e, k): e1 = 2 and
    k1 = 4/m are two definitions (the matrix [2; 4/m] has no one unit), so
    e1 + k1*(1 m) = 6 is computed."""
    find = f"<ml:apply><ml:Find/>{ident('e')}{ident('k')}</ml:apply>"
    two_m = apply("mult", real(2), ident("m"))
    one_m = apply("mult", real(1), ident("m"))
    text = import_sheet(
        tmp_path,
        capsys,
        "parts",
        define(1, ident("e"), real(0)),
        define(2, ident("k"), apply("div", real(0), ident("m"))),
        math_region(3, ident("Given")),
        math_region(4, apply("equal", apply("plus", ident("e"), real(1)), real(3))),
        math_region(5, apply("equal", apply("mult", ident("k"), two_m), real(8))),
        define(6, matrix(ident("e", "1"), ident("k", "1")), find),
        evaluate(7, apply("plus", ident("e", "1"), apply("mult", ident("k", "1"), one_m)), real(6)),
        # the same block's values shown: [2; 4/m], a matrix of two units, compared by name
        define(8, ident("e"), real(0)),
        math_region(9, ident("Given")),
        math_region(10, apply("equal", apply("plus", ident("e"), real(1)), real(3))),
        math_region(11, apply("equal", apply("mult", ident("k"), two_m), real(8))),
        define(
            12,
            matrix(ident("e", "2"), ident("k", "2")),
            shown(find, matrix(real(2), united(4, ("m", -1)))),
        ),
    )
    assert "region 7" not in text.split("[inputs]")[0]
    result = check_sheet(tmp_path, capsys, "parts")
    assert (result["printed"], result["reproduced"], result["failed"]) == (3, 3, 0), result


@pytest.mark.slow
def test_names_given_a_program_of_values_of_different_units(tmp_path, capsys):
    """[X; n] := (j <- 3; X <- 2 m * j; [X; j]): X = 6 m and n = 3, each the program with
    its last line that name's element (X*n shown as 18 m: 18 in metres, the SI value
    Mathcad stores)."""
    body = program(
        local(ident("j"), real(3)),
        local(ident("X"), apply("mult", apply("mult", real(2), ident("m")), ident("j"))),
        f"<ml:return>{matrix(ident('X'), ident('j'))}</ml:return>",
    )
    text = import_sheet(
        tmp_path,
        capsys,
        "progparts",
        define(1, matrix(ident("X"), ident("n")), body),
        evaluate(2, apply("mult", ident("X"), ident("n")), united(18, ("m", 1))),
        evaluate(3, ident("n"), real(3)),
    )
    assert "region 2" not in text.split("[inputs]")[0]
    result = check_sheet(tmp_path, capsys, "progparts")
    assert (result["printed"], result["reproduced"], result["failed"]) == (2, 2, 0), result


def test_the_whole_matrix_shown_is_still_compared(tmp_path, capsys):
    """[a; b] := [1; 2] = [1; 2]: each name its element, and the value Mathcad shows
    compared element by element as before."""
    import_sheet(
        tmp_path,
        capsys,
        "shownparts",
        define(
            1,
            matrix(ident("a"), ident("b")),
            shown(matrix(real(1), real(2)), matrix(real(1), real(2))),
        ),
        evaluate(2, apply("plus", ident("a"), ident("b")), real(3)),
    )
    result = check_sheet(tmp_path, capsys, "shownparts")
    assert (result["printed"], result["reproduced"], result["failed"]) == (3, 3, 0), result


def _stored(z: complex) -> str:
    return f"<ml:complex>{real(z.real)}<ml:imag>{z.imag!r}</ml:imag></ml:complex>"


@pytest.mark.slow
def test_square_roots_of_negative_numbers_where_mathcad_stored_complex_values(tmp_path, capsys):
    """f(x) := sqrt(4 - x^2), x := 0 .. 3, f(x) = [2; sqrt(3); 0; sqrt(5) i] as Mathcad 15
    stores it (cmath's roots): f computes in complex numbers, every part reproduced; g, the
    same formula whose stored value is real, stays real (its root of a negative number is
    an error, never a number)."""
    import cmath

    body = call("sqrt", apply("minus", real(4), apply("pow", ident("x"), real(2))))
    rng = f"<ml:range>{real(0)}{real(3)}</ml:range>"
    text = import_sheet(
        tmp_path,
        capsys,
        "croots",
        function(1, "f", ["x"], body),
        function(2, "g", ["x"], body),
        define(3, ident("x"), rng),
        evaluate(
            4, call("f", ident("x")), matrix(*(_stored(cmath.sqrt(4 - v * v)) for v in range(4)))
        ),
        evaluate(5, call("g", real(1)), real(3**0.5)),
    )
    assert "sqrt(4 - x^2 + 0i)" in text and "sqrt(4 - x^2)" in text
    result = check_sheet(tmp_path, capsys, "croots")
    assert (result["printed"], result["reproduced"], result["failed"]) == (9, 9, 0), result


@pytest.mark.slow
def test_shape_tests_and_primes_norm_of_a_vector(tmp_path, capsys):
    """Prime: v := [3; 4; 12], M := [[1, 2], [3, 4]], a := 2: norm(v) = 13 (its length, as
    Prime stores it), IsArray(v) = 1, IsScalar(v) = 0, IsScalar(a) = 1, IsArray(a) = 0;
    norm(M), of a matrix, is not translated (never a guess of which norm)."""
    from helpers.mathcad_xml import prime_package, prime_region, prime_result

    from workbook.cli import main

    ns = 'xmlns:ml="http://schemas.mathsoft.com/math50"'

    def define_(lhs: str, rhs: str) -> str:
        return f"<ml:define {ns}>{lhs}{rhs}</ml:define>"

    def eval_(body: str) -> str:
        return f"<ml:eval {ns}>{body}</ml:eval>"

    regions = [
        define_(ident("v"), matrix(real(3), real(4), real(12))),
        define_(ident("M"), matrix(real(1), real(3), real(2), real(4), cols=2)),
        define_(ident("a"), real(2)),
        eval_(call("norm", ident("v"))),
        eval_(call("IsArray", ident("v"))),
        eval_(call("IsScalar", ident("v"))),
        eval_(call("IsScalar", ident("a"))),
        eval_(call("IsArray", ident("a"))),
        eval_(call("norm", ident("M"))),
    ]
    stored = [None, None, None, 13, 1, 0, 1, 0, 5.4649857042190426]
    src = prime_package(
        tmp_path / "shapes.mcdx",
        "".join(prime_region(k + 1, k + 1, r) for k, r in enumerate(regions)),
        "".join(prime_result(k + 1, real(v)) for k, v in enumerate(stored) if v is not None),
    )
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    capsys.readouterr()
    text = (tmp_path / "shapes.toml").read_text(encoding="utf-8")
    assert "norm() of something that is not a vector" in text
    result = check_sheet(tmp_path, capsys, "shapes")
    assert (result["printed"], result["reproduced"], result["failed"]) == (6, 5, 0), result


@pytest.mark.slow
def test_elements_shown_one_row_per_value_of_a_range_above_origin(tmp_path, capsys):
    """i := 1 .. 2, v[i] := 10*i = [10; 20] (Prime shows a row per value of i; v itself is
    [0; 10; 20]): each row compared with v at that i, v[1] = 10 and v[2] = 20."""
    from helpers.mathcad_xml import index

    rng = f"<ml:range>{real(1)}{real(2)}</ml:range>"
    text = import_sheet(
        tmp_path,
        capsys,
        "rows",
        define(1, ident("i"), rng),
        define(
            2,
            index(ident("v"), ident("i")),
            shown(apply("mult", real(10), ident("i")), matrix(real(10), real(20))),
        ),
    )
    assert "v[2]" in text
    result = check_sheet(tmp_path, capsys, "rows")
    assert (result["printed"], result["reproduced"], result["failed"]) == (2, 2, 0), result


@pytest.mark.slow
def test_primes_eigenvalues_from_the_largest_down(tmp_path, capsys):
    """Prime: M := [[2, 1, 0], [1, 3, 1], [0, 1, 4]], eigenvals(M) = numpy's eigenvalues from
    the largest down (Prime's order); a Mathcad 15 worksheet's eigenvals(M) stays refused (its
    order is its solver's)."""
    import numpy as np
    from helpers.mathcad_xml import array_cells, prime_package, prime_region, prime_result

    from workbook.cli import main

    m = np.array([[2.0, 1.0, 0.0], [1.0, 3.0, 1.0], [0.0, 1.0, 4.0]])
    values = sorted(np.linalg.eigvalsh(m), reverse=True)
    ns = 'xmlns:ml="http://schemas.mathsoft.com/math50"'
    regions = prime_region(1, 1, f"<ml:define {ns}>{ident('M')}{array_cells(m)}</ml:define>")
    regions += prime_region(2, 2, f"<ml:eval {ns}>{call('eigenvals', ident('M'))}</ml:eval>")
    stored = prime_result(2, matrix(*(real(repr(float(v))) for v in values)))
    src = prime_package(tmp_path / "eig.mcdx", regions, stored)
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    capsys.readouterr()
    result = check_sheet(tmp_path, capsys, "eig")
    assert (result["printed"], result["reproduced"], result["failed"]) == (3, 3, 0), result
    text = import_sheet(
        tmp_path,
        capsys,
        "eig15",
        define(1, ident("M"), array_cells(m)),
        evaluate(2, call("eigenvals", ident("M")), matrix(*(real(repr(float(v))) for v in values))),
    )
    assert "eigenvals() is neither defined before nor a known built-in" in text


@pytest.mark.slow
def test_each_element_program_reads_the_names_before_the_matrix_gives_them(tmp_path, capsys):
    """X := 5 m; [X; n] := (j <- 2; [X*j; X/m]): X becomes 10 m and n is 5, the old X's
    (Mathcad computes the program once, then gives the names), never 10."""
    body = program(
        local(ident("j"), real(2)),
        matrix(apply("mult", ident("X"), ident("j")), apply("div", ident("X"), ident("m"))),
    )
    import_sheet(
        tmp_path,
        capsys,
        "reads",
        define(1, ident("X"), apply("mult", real(5), ident("m"))),
        define(2, matrix(ident("X"), ident("n")), body),
        evaluate(3, ident("n"), real(5)),
        evaluate(4, ident("X"), united(10, ("m", 1))),
    )
    result = check_sheet(tmp_path, capsys, "reads")
    assert (result["printed"], result["reproduced"], result["failed"]) == (2, 2, 0), result
