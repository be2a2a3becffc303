"""The translator's trees printed with the language's precedence read back as the same tree:
Mathcad's (-1)^2, stored as a literal -1 under the power, must not become -(1^2)."""

from __future__ import annotations

import json

import pytest
from helpers.mathcad import bare_worksheet as _worksheet
from helpers.mathcad import region as _region
from helpers.mathcad_xml import apply as _apply
from helpers.mathcad_xml import evaluate as _eval
from helpers.mathcad_xml import ident as _id
from helpers.mathcad_xml import real as _real
from hypothesis import given, settings
from hypothesis import strategies as st

from workbook.cli import main
from workbook.language import expr as ex

NAMES = st.sampled_from(["x", "y", "a_1", "L", "phi"])
NUMBERS = st.floats(min_value=-1e6, max_value=1e6, allow_nan=False, allow_infinity=False)


def _leaves() -> st.SearchStrategy[ex.Node]:
    return st.one_of(NUMBERS.map(ex.Number), NAMES.map(ex.Name))


def _extend(children: st.SearchStrategy[ex.Node]) -> st.SearchStrategy[ex.Node]:
    two = st.tuples(children, children)
    elements = children.filter(lambda t: not isinstance(t, ex.Matrix))
    return st.one_of(
        st.tuples(st.sampled_from(["-", "+", "not"]), children).map(lambda t: ex.Unary(*t)),
        st.tuples(st.sampled_from(["+", "-", "*", "/", "^"]), children, children).map(
            lambda t: ex.Binary(*t)
        ),
        st.tuples(st.sampled_from(["<", "<=", "==", "!="]), two).map(
            lambda t: ex.Compare((t[0],), t[1])
        ),
        st.tuples(st.sampled_from(["and", "or"]), two).map(lambda t: ex.Logic(*t)),
        st.tuples(NAMES, st.lists(children, min_size=1, max_size=3)).map(
            lambda t: ex.Call(t[0], tuple(t[1]))
        ),
        # a column of arrays only is refused by the translator ([[a], [b]] reads by rows)
        st.lists(elements, min_size=1, max_size=3).map(
            lambda xs: ex.Matrix(tuple((x,) for x in xs))
        ),
        st.lists(st.tuples(elements, elements), min_size=1, max_size=2).map(
            lambda rows: ex.Matrix(tuple(rows))
        ),
        st.tuples(children, children).map(lambda t: ex.Index(t[0], (t[1],))),
        st.tuples(children, children, children).map(lambda t: ex.IfElse(*t)),
    )


TREES = st.recursive(_leaves(), _extend, max_leaves=25)


def _canonical(tree: ex.Node) -> ex.Node:
    """The tree as the parser builds it: a negative number is a minus applied to a number."""
    if isinstance(tree, ex.Number) and tree.value < 0:
        return ex.Unary("-", ex.Number(-tree.value))
    if isinstance(tree, ex.Number):
        return ex.Number(abs(tree.value))  # -0.0 reads as 0
    return ex.map_children(tree, _canonical)


@pytest.mark.slow
@settings(max_examples=400, deadline=None)
@given(TREES)
def test_printed_tree_parses_back_to_itself(tree):
    assert ex.parse(ex.to_text(tree)) == _canonical(tree)


def test_unary_minus_under_a_power_keeps_its_brackets():
    minus_one = ex.Unary("-", ex.Number(1.0))
    assert ex.to_text(ex.Binary("^", minus_one, ex.Name("i"))) == "(-1)^i"
    assert ex.to_text(ex.Binary("^", ex.Number(-1.0), ex.Name("i"))) == "(-1)^i"
    assert ex.to_text(ex.Unary("-", ex.Binary("^", ex.Number(1.0), ex.Name("i")))) == "-1^i"


@pytest.mark.slow
def test_a_negative_literal_under_a_power_is_powered_with_its_sign(tmp_path, capsys):
    """Mathcad stores (-1)^2 as a literal -1 under the power, = 1 and (-2)^3 = -8, and
    -(2^2) = -4 as a minus applied to the power."""
    src = tmp_path / "signs.xmcd"
    src.write_text(
        _worksheet(
            _region(1, _id("a") + _apply("pow", _real(-1), _real(2))),
            _region(2, _id("b") + _apply("pow", _real(-2), _real(3))),
            _region(3, _id("c") + _apply("neg", _apply("pow", _real(2), _real(2)))),
            _eval(4, _id("a"), _real(1)),
            _eval(5, _id("b"), _real(-8)),
            _eval(6, _id("c"), _real(-4)),
        ),
        encoding="utf-8",
    )
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    text = (tmp_path / "signs.toml").read_text(encoding="utf-8")
    assert '"(-1)^2"' in text and '"(-2)^3"' in text and '"-2^2"' in text
    capsys.readouterr()
    main(["check", str(tmp_path / "signs.toml"), "--json"])
    result = json.loads(capsys.readouterr().out)
    assert (result["printed"], result["reproduced"]) == (3, 3), result["failures"]
