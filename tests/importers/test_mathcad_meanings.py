"""Where Mathcad's meaning is not the first one read: an n-th derivative's order, ORIGIN set
inside the worksheet, a chain of equations in a solve block. Each is translated with
Mathcad's meaning (checked against values computed here independently) or refused."""

from __future__ import annotations

import math

import pytest
from helpers.mathcad_xml import (
    apply,
    call,
    check_sheet,
    define,
    derivative,
    function,
    ident,
    import_sheet,
    index,
    math_region,
    matrix,
    real,
    shown,
)


@pytest.mark.slow
def test_the_second_derivative_is_not_the_first(tmp_path, capsys):
    """f(x) := x^3 sin(x); d2 := d²/dx² f(x) at x = 0.7 (Mathcad's degree 2), d1 the first:
    both against the derivatives written out by hand."""
    x = 0.7
    first = 3 * x**2 * math.sin(x) + x**3 * math.cos(x)
    second = 6 * x * math.sin(x) + 6 * x**2 * math.cos(x) - x**3 * math.sin(x)
    body = apply("mult", apply("pow", ident("x"), real(3)), call("sin", ident("x")))
    text = import_sheet(
        tmp_path,
        capsys,
        "nth",
        function(1, "f", ["x"], body),
        function(2, "d2", ["x"], derivative("x", call("f", ident("x")), real(2))),
        function(3, "d1", ["x"], derivative("x", call("f", ident("x")), "<ml:placeholder/>")),
        define(4, ident("a"), shown(call("d2", real(x)), real(second))),
        define(5, ident("b"), shown(call("d1", real(x)), real(first))),
    )
    assert "diff(f(x), x, 2)" in text and '"d1(x)" = { expr = "diff(f(x), x)"' in text
    result = check_sheet(tmp_path, capsys, "nth")
    assert result["reproduced"] == 2, result["failures"]


@pytest.mark.slow
def test_a_derivative_of_an_order_not_written_is_refused(tmp_path, capsys):
    """d^n/dx^n with n a name: refused with the reason, never read as the first."""
    text = import_sheet(
        tmp_path,
        capsys,
        "order",
        define(1, ident("n"), real(2)),
        function(2, "g", ["x"], derivative("x", apply("pow", ident("x"), real(3)), ident("n"))),
    )
    assert "a derivative whose order is not a whole number from 1 to 5 written in it" in text
    assert "diff(" not in text.split("[definitions]")[-1]


def _vector(*values) -> str:
    return matrix(*(real(v) for v in values))


@pytest.mark.slow
def test_origin_set_after_the_first_index_refuses_submatrix_and_last(tmp_path, capsys):
    """v := [10; 20; 30]; v[0] = 10 (ORIGIN 0, the worksheet's origin), then ORIGIN := 1:
    last(v) (Mathcad's 3) and submatrix(v, 1, 2, 1, 1) (Mathcad's [10; 20]) are refused, as
    the language counts from the worksheet's origin; ORIGIN read as a value is 1 there."""
    text = import_sheet(
        tmp_path,
        capsys,
        "origin",
        define(1, ident("v"), _vector(10, 20, 30)),
        define(2, ident("a"), shown(index(ident("v"), real(0)), real(10))),
        define(3, ident("ORIGIN"), real(1)),
        define(4, ident("n"), shown(call("last", ident("v")), real(3))),
        define(5, ident("o"), shown(ident("ORIGIN"), real(1))),
        define(
            6,
            ident("s"),
            call("submatrix", ident("v"), real(1), real(2), real(1), real(1)),
        ),
    )
    assert "last() where ORIGIN is 1, and the worksheet's origin" in text
    assert "submatrix() where ORIGIN is 1" in text
    result = check_sheet(tmp_path, capsys, "origin")
    assert (result["printed"], result["reproduced"], result["failed"]) == (3, 2, 0)


@pytest.mark.slow
def test_a_chain_of_equations_in_a_solve_block_is_two_equations(tmp_path, capsys):
    """Given x = y = 2 - z (stored (x = y) = 2 - z) and x + y + z = 3: Find(x, y, z) is
    (1, 1, 1), the solution of x = y, y = 2 - z and the sum (not of (x = y as 1 or 0) =
    2 - z)."""
    chain = apply(
        "equal",
        apply("equal", ident("x"), ident("y")),
        apply("minus", real(2), ident("z")),
    )
    total = apply(
        "equal", apply("plus", apply("plus", ident("x"), ident("y")), ident("z")), real(3)
    )
    find = f"<ml:apply><ml:Find/>{ident('x')}{ident('y')}{ident('z')}</ml:apply>"
    import_sheet(
        tmp_path,
        capsys,
        "chain",
        define(1, ident("x"), real(0.2)),
        define(2, ident("y"), real(0.5)),
        define(3, ident("z"), real(0.1)),
        math_region(4, ident("Given")),
        math_region(5, chain),
        math_region(6, total),
        define(7, ident("S"), shown(find, _vector(1, 1, 1))),
    )
    result = check_sheet(tmp_path, capsys, "chain")
    assert (result["printed"], result["reproduced"]) == (3, 3), result["failures"]


def test_a_range_whose_bounds_index_a_vector_at_origin_1(tmp_path, capsys):
    """ORIGIN 1; P := [9; 16]; x := P[1], P[1] + 1 .. 12; 2x = [18; 20; 22; 24]: the range's
    bounds are computed at import at the worksheet's origin (P[1] is 9, never 16)."""
    from helpers.mathcad_xml import evaluate, index, matrix, real

    first = index(ident("P"), real(1))
    rng = (
        f"<ml:range><ml:sequence>{first}{apply('plus', first, real(1))}</ml:sequence>"
        f"{real(12)}</ml:range>"
    )
    import_sheet(
        tmp_path,
        capsys,
        "rng1",
        define(1, ident("P"), matrix(real(9), real(16))),
        define(2, ident("x"), rng),
        evaluate(
            3, apply("mult", real(2), ident("x")), matrix(*(real(v) for v in (18, 20, 22, 24)))
        ),
        origin=1,
    )
    result = check_sheet(tmp_path, capsys, "rng1")
    assert (result["printed"], result["reproduced"]) == (4, 4), result["failures"]
