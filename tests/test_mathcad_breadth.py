"""Mathcad constructs beyond the basics: vectorize of an expression."""

from __future__ import annotations

from test_mathcad_programs import _apply, _check, _define, _eval, _id, _import, _matrix, _real


def _vectorize(body: str) -> str:
    return _apply("vectorize", body)


def test_vectorize_of_an_expression_is_element_by_element(tmp_path, capsys):
    """v := [1; 4; 9], w := [2; 3; 4]: ->(v*w) = [2; 12; 36] (not the dot product 50),
    ->(sqrt(v) + [1; 1; 1]) = [2; 3; 4], ->(v/2) = [0.5; 2; 4.5]."""
    v = _matrix(_real(1), _real(4), _real(9))
    w = _matrix(_real(2), _real(3), _real(4))
    ones = _matrix(_real(1), _real(1), _real(1))
    sqrt_v = f"<ml:apply>{_id('sqrt')}{_id('v')}</ml:apply>"
    text = _import(
        tmp_path,
        capsys,
        "vec",
        _define(1, _id("v"), v),
        _define(2, _id("w"), w),
        _eval(3, _vectorize(_apply("mult", _id("v"), _id("w"))), _matrix(*map(_real, (2, 12, 36)))),
        _eval(4, _vectorize(_apply("plus", sqrt_v, ones)), _matrix(*map(_real, (2, 3, 4)))),
        _eval(
            5, _vectorize(_apply("div", _id("v"), _real(2))), _matrix(*map(_real, (0.5, 2, 4.5)))
        ),
    )
    assert "v[0] * w[0]" in text
    result = _check(tmp_path, capsys, "vec")
    assert (result["printed"], result["reproduced"]) == (9, 9), result["failures"]


def test_vectorize_that_cannot_be_element_by_element_is_listed(tmp_path, capsys):
    """->(max(v)) (a function of a vector) and ->(v*u) with vectors of 3 and 2 are listed,
    never computed otherwise than Mathcad."""
    v = _matrix(_real(1), _real(4), _real(9))
    u = _matrix(_real(1), _real(2))
    max_v = f"<ml:apply>{_id('max')}{_id('v')}</ml:apply>"
    text = _import(
        tmp_path,
        capsys,
        "vecbad",
        _define(1, _id("v"), v),
        _define(2, _id("u"), u),
        _eval(3, _vectorize(max_v), _real(9)),
        _eval(4, _vectorize(_apply("mult", _id("v"), _id("u"))), _real(1)),
    )
    assert "a vectorised call of max" in text
    assert "vectors of different lengths" in text
