"""Prime's solve blocks whose guess values are computed: a block that is a function's body
(``f(a) := Find(x)``) whose guesses read the function's parameters is listed with why (Prime
computes them from each call's arguments, the language's [[solve]] guesses are constants);
guesses that read the sheet's names are values before the block, as before."""

from __future__ import annotations

import pytest
from helpers.mathcad import check_json as _check
from helpers.mathcad import prime_ident as _id
from helpers.mathcad_xml import prime_package as _package
from helpers.mathcad_xml import prime_region as _region
from helpers.mathcad_xml import prime_result as _result
from helpers.mathcad_xml import prime_solve_block, real

from workbook.cli import main

REASON = "a solve block that is a function's body whose guess of x reads the function's parameter a"


def _apply(op: str, *args: str) -> str:
    return f"<ml:apply><ml:{op}/>{''.join(args)}</ml:apply>"


def _define(lhs: str, rhs: str) -> str:
    return f"<ml:define>{lhs}{rhs}</ml:define>"


def _find(*names: str) -> str:
    seq = "".join(_id(n) for n in names)
    keyword = '<ml:id labels="KEYWORD">find</ml:id>'
    return f"<ml:apply>{keyword}<ml:sequence>{seq}</ml:sequence></ml:apply>"


def _shown(rid: int, body: str) -> str:
    override = "<ml:unitOverride><ml:placeholder/></ml:unitOverride>"
    return _region(rid, rid, f"<ml:eval>{body}{override}</ml:eval>")


def _call(name: str, arg: float) -> str:
    return f"<ml:apply>{_id(name, 'FUNCTION')}<ml:sequence>{real(arg)}</ml:sequence></ml:apply>"


def _x_squared_is_4a() -> str:
    """The constraint x·x = 4·a."""
    return _apply("equal", _apply("mult", _id("x"), _id("x")), _apply("mult", real(4), _id("a")))


def _solve_function(guess: str) -> str:
    """f(a) := Find(x) with the guess value x := ``guess`` and the constraint x·x = 4·a."""
    lhs = f"<ml:function>{_id('f')}<ml:boundVars>{_id('a')}</ml:boundVars></ml:function>"
    return prime_solve_block(
        10, [_define(_id("x"), guess)], [_x_squared_is_4a()], _define(lhs, _find("x"))
    )


def _import(tmp_path, name: str, regions: str, results: str) -> str:
    src = _package(tmp_path / f"{name}.mcdx", regions, results)
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    return (tmp_path / f"{name}.toml").read_text(encoding="utf-8")


def _calls() -> tuple[str, str]:
    """f(1) = 2 and f(9) = 6 shown, as Prime stores them (from the guesses 1 and 9)."""
    regions = _shown(20, _call("f", 1)) + _shown(21, _call("f", 9))
    stored = "".join(_result(k) for k in (11, 12, 13)) + _result(20, real(2))
    return regions, stored + _result(21, real(6))


@pytest.mark.slow
def test_a_guess_of_the_functions_parameter_is_listed_with_why(tmp_path, capsys):
    """x := a in the block of f(a) := Find(x): Prime starts each call from its argument; the
    block, the function and its calls are listed with that reason, none computed."""
    regions, stored = _calls()
    text = _import(tmp_path, "guessed", _solve_function(_id("a")) + regions, stored)
    head = text.split("[sheet]")[0]
    assert f"region 13: f(...) := ...: {REASON}" in head, head
    assert f"region 20: an evaluation ( = ): uses f, which is not translated: {REASON}" in head
    assert "\n[[solve]]" not in text
    result = _check(tmp_path / "guessed.toml", capsys)
    assert (result["reproduced"], result["failed"], result["not_computable"]) == (0, 0, 2)


def test_the_parameter_is_read_even_where_the_sheet_has_the_name(tmp_path, capsys):
    """a := 100 before the block: Prime's guess of x is still the call's a, never the sheet's
    100 (from which the solver would start elsewhere): the same reason, not the sheet's a."""
    regions, stored = _calls()
    sheet_a = _region(1, 1, _define(_id("a"), real(100)))
    text = _import(tmp_path, "shadowed", sheet_a + _solve_function(_id("a")) + regions, stored)
    assert f"region 13: f(...) := ...: {REASON}" in text.split("[sheet]")[0], text
    result = _check(tmp_path / "shadowed.toml", capsys)
    assert (result["reproduced"], result["failed"], result["not_computable"]) == (0, 0, 2)


@pytest.mark.slow
def test_a_guess_of_the_sheets_names_is_the_value_before_the_block(tmp_path, capsys):
    """b := 3; a solve block not inside a function, x := b, x·x = 4·a with a := 1: its guess
    reads no parameter, so it is solved from 3 as before, Find(x) = 2 reproduced."""
    block = prime_solve_block(
        10, [_define(_id("x"), _id("b"))], [_x_squared_is_4a()], _define(_id("r"), _find("x"))
    )
    regions = (
        _region(1, 1, _define(_id("a"), real(1)))
        + _region(2, 2, _define(_id("b"), real(3)))
        + block
        + _shown(20, _id("r"))
    )
    stored = "".join(_result(k) for k in (1, 2, 11, 12, 13)) + _result(20, real(2))
    text = _import(tmp_path, "sheetguess", regions, stored)
    assert "\n[[solve]]" in text and "function's parameter" not in text, text
    result = _check(tmp_path / "sheetguess.toml", capsys)
    assert (result["printed"], result["reproduced"], result["failed"]) == (1, 1, 0), result
