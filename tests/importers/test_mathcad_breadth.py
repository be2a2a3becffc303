"""Mathcad constructs beyond the basics: vectorize of an expression."""

from __future__ import annotations

import pytest
from helpers.mathcad_xml import apply as _apply
from helpers.mathcad_xml import check_sheet as _check
from helpers.mathcad_xml import define as _define
from helpers.mathcad_xml import evaluate as _eval
from helpers.mathcad_xml import ident as _id
from helpers.mathcad_xml import import_sheet as _import
from helpers.mathcad_xml import index as _index
from helpers.mathcad_xml import matrix as _matrix
from helpers.mathcad_xml import real as _real


def _vectorize(body: str) -> str:
    return _apply("vectorize", body)


@pytest.mark.slow
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


@pytest.mark.slow
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


def _range_def(rid: int, name: str, first: int, last: int) -> str:
    return _define(rid, _id(name), f"<ml:range>{_real(first)}{_real(last)}</ml:range>")


def _shown(body: str, result: str) -> str:
    return f"<ml:eval>{body}<ml:result>{result}</ml:result></ml:eval>"


@pytest.mark.slow
def test_element_definition_shown_is_the_whole_vector(tmp_path, capsys):
    """i := 0 .. 2, v[i] := i^2 = [0; 1; 4] (Mathcad shows the vector it built), then
    v[i] := 10 + i over the same range (every element again) = [10; 11; 12]; j := 0 .. 1,
    v[j] := 5 = [5; 5; 12] (Mathcad keeps v[2], never a vector of two or a 0 there);
    M := [[1, 2], [3, 4]], M[j, j] := 9 = [[9, 2], [3, 9]] (a diagonal, the rest kept)."""
    square = _apply("pow", _id("i"), _real(2))
    text = _import(
        tmp_path,
        capsys,
        "elements",
        _range_def(1, "i", 0, 2),
        _define(2, _index(_id("v"), _id("i")), _shown(square, _matrix(*map(_real, (0, 1, 4))))),
        _define(
            3,
            _index(_id("v"), _id("i")),
            _shown(_apply("plus", _real(10), _id("i")), _matrix(*map(_real, (10, 11, 12)))),
        ),
        _range_def(4, "j", 0, 1),
        _define(5, _index(_id("v"), _id("j")), _shown(_real(5), _matrix(*map(_real, (5, 5, 12))))),
        _define(6, _id("M"), _matrix(*map(_real, (1, 3, 2, 4)), cols=2)),
        _define(
            7,
            _index(_id("M"), _id("j"), _id("j")),
            _shown(_real(9), _matrix(*map(_real, (9, 3, 2, 9)), cols=2)),
        ),
    )
    assert "region 5" not in text.split("[sheet]")[0]  # nothing listed
    result = _check(tmp_path, capsys, "elements")
    assert (result["printed"], result["reproduced"], result["failed"]) == (13, 13, 0), result


@pytest.mark.slow
def test_sum_over_a_range_variable(tmp_path, capsys):
    """i := 1 .. 4: Σ_i i^2 = 30 (Mathcad's sum over a range variable, without bounds);
    k := 0, 0.5 .. 2 (not of whole steps) is listed."""

    def range_sum(var: str) -> str:
        lam = (
            f"<ml:lambda><ml:boundVars>{_id(var)}</ml:boundVars>"
            f"{_apply('pow', _id(var), _real(2))}</ml:lambda>"
        )
        return f"<ml:apply><ml:summation/>{lam}</ml:apply>"

    halves = f"<ml:range><ml:sequence>{_real(0)}{_real(0.5)}</ml:sequence>{_real(2)}</ml:range>"
    text = _import(
        tmp_path,
        capsys,
        "sums",
        _range_def(1, "i", 1, 4),
        _eval(2, range_sum("i"), _real(30)),
        _define(3, _id("k"), halves),
        _eval(4, range_sum("k"), _real(7.5)),
    )
    assert "not of whole steps of 1" in text
    result = _check(tmp_path, capsys, "sums")
    assert (result["printed"], result["reproduced"], result["failed"]) == (2, 1, 0), result
