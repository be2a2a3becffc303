"""Prime's try / on error in a program: the language's `try` and `on error` blocks, checked
against the values Prime stores; a try block whose errors may not be Mathcad's is refused with
why, and so is Mathcad 15's on error."""

from __future__ import annotations

import pytest
from helpers.mathcad import check_json as _check
from helpers.mathcad import prime_ident as _id
from helpers.mathcad_xml import function, import_sheet, local, program, real
from helpers.mathcad_xml import ident as _ident15
from helpers.mathcad_xml import prime_package as _package
from helpers.mathcad_xml import prime_region as _region
from helpers.mathcad_xml import prime_result as _result

from workbook.cli import main
from workbook.errors import LimitError, TemplateError


def _block(*lines: str) -> str:
    return f"<ml:program>{''.join(lines)}</ml:program>"


def _local(name: str, value: str) -> str:
    return f"<ml:localDefine>{_id(name)}{value}</ml:localDefine>"


def _apply(op: str, *args: str) -> str:
    return f"<ml:apply><ml:{op}/>{''.join(args)}</ml:apply>"


def _try(body: str, handler: str) -> str:
    return f"<ml:tryCatch>{body}{handler}</ml:tryCatch>"


def _function(rid: int, name: str, body: str) -> str:
    lhs = f"<ml:function>{_id(name)}<ml:boundVars>{_id('x')}</ml:boundVars></ml:function>"
    return _region(rid, rid, f"<ml:define>{lhs}{body}</ml:define>")


def _call_shown(rid: int, name: str, arg: float) -> str:
    args = f"<ml:sequence><ml:real>{arg}</ml:real></ml:sequence>"
    call = f"<ml:apply>{_id(name, 'FUNCTION')}{args}</ml:apply>"
    return _region(
        rid, rid, f"<ml:eval>{call}<ml:unitOverride><ml:placeholder/></ml:unitOverride></ml:eval>"
    )


def _f_body() -> str:
    """f(x) := | v <- [1; 2; 3] / try: (r <- 10/x; r <- r + v[x]) on error: r <- -1 / r |"""
    v = f'<ml:matrix rows="3" cols="1">{real(1)}{real(2)}{real(3)}</ml:matrix>'
    element = f"<ml:apply><ml:indexer/>{_id('v')}{_id('x')}</ml:apply>"
    tried = _block(
        _local("r", _apply("div", "<ml:real>10</ml:real>", _id("x"))),
        _local("r", _apply("plus", _id("r"), element)),
    )
    caught = _block(_local("r", _apply("neg", "<ml:real>1</ml:real>")))
    return _block(_local("v", v), _try(tried, caught), _id("r"))


@pytest.mark.slow
def test_try_on_error_reproduces_prime(tmp_path, capsys):
    """f(2) = 10/2 + v[2] = 8; f(0) divides by zero and f(5) reads v beyond its length: both
    errors in the try block, so r is the on error block's -1, as Prime stored."""
    regions = _function(1, "f", _f_body()) + "".join(
        _call_shown(k + 2, "f", arg) for k, arg in enumerate((2, 0, 5))
    )
    results = _result(1) + "".join(_result(k + 2, real(v)) for k, v in enumerate((8, -1, -1)))
    src = _package(tmp_path / "tries.mcdx", regions, results)
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    text = (tmp_path / "tries.toml").read_text(encoding="utf-8")
    assert "try\n" in text and "on error\n" in text, text
    result = _check(tmp_path / "tries.toml", capsys)
    assert (result["printed"], result["reproduced"], result["failed"]) == (3, 3, 0), result


def test_a_wrong_catch_is_a_failure(tmp_path, capsys):
    """The same worksheet with f(0) stored as 5 (as if the try block had run through): the
    translation's -1 is a failure, not a pass (the test above can fail)."""
    regions = _function(1, "f", _f_body()) + _call_shown(2, "f", 0)
    src = _package(tmp_path / "wrong.mcdx", regions, _result(1) + _result(2, real(5)))
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    result = _check(tmp_path / "wrong.toml", capsys)
    assert (result["printed"], result["failed"]) == (1, 1), result


def test_a_try_block_whose_errors_may_not_be_mathcads_is_refused(tmp_path, capsys):
    """sqrt of a negative number is complex in Mathcad (no error) and an error of the engine:
    the region is listed with that reason, never translated with a catch Mathcad never took."""
    tried = _block(_local("r", f"<ml:apply>{_id('sqrt', 'FUNCTION')}{_id('x')}</ml:apply>"))
    caught = _block(_local("r", "<ml:real>0</ml:real>"))
    body = _block(_try(tried, caught), _id("r"))
    regions = _function(1, "g", body) + _call_shown(2, "g", 4)
    src = _package(tmp_path / "unsure.mcdx", regions, _result(1) + _result(2, real(2)))
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    text = (tmp_path / "unsure.toml").read_text(encoding="utf-8")
    assert "a try / on error whose try block calls sqrt()" in text, text
    assert "on error\n" not in text
    result = _check(tmp_path / "unsure.toml", capsys)
    assert (result["reproduced"], result["failed"], result["not_computable"]) == (0, 0, 1)


def test_mathcad_15_on_error_is_listed(tmp_path, capsys):
    """Mathcad 15's on error operator (no worksheet measured shows which operand is tried)."""
    lines = local(_ident15("r"), real(0)) + local(_ident15("r"), real(1))
    body = program(f"<ml:onError>{lines}</ml:onError>", _ident15("r"))
    text = import_sheet(tmp_path, capsys, "mc15", function(1, "h", ["x"], body))
    assert "Mathcad 15's on error in a program" in text, text


def _text(program_text: str) -> str:
    return (
        '[arguments]\nx = { unit = "" }\n[definitions]\n'
        f'"f(x)" = {{ program = """\n{program_text}""" }}\n'
    )


def test_the_on_error_block_runs_from_where_the_error_was(sheet_from):
    """What the try block set before its error stays set; a value line of the try block
    before the error is not the program's value."""
    sheet = sheet_from(
        _text("r := 1\ntry\n    r := 2\n    r\n    r := r + 1/x\non error\n    r := r * 10\nr\n")
    )
    assert sheet.evaluate("f", x=0.5).magnitude == pytest.approx(4.0)
    assert sheet.evaluate("f", x=0).magnitude == pytest.approx(20.0)


@pytest.mark.slow
def test_a_limit_is_no_error_the_program_catches(sheet_from):
    """A loop that never ends inside a try block stops the program, as it would outside."""
    sheet = sheet_from(_text("try\n    while x > 0\n        x := x + 1\non error\n    x := 0\nx\n"))
    with pytest.raises(LimitError):
        sheet.evaluate("f", x=1)


@pytest.mark.parametrize(
    "text, message",
    [
        ("try\n    r := 1/x\nr\n", "'try' without its 'on error' block"),
        ("r := 1\non error\n    r := 2\nr\n", "'on error' without a 'try' before it"),
        ("try 1/x\non error\n    r := 2\nr\n", "'try' takes nothing after it"),
    ],
)
def test_try_without_its_blocks_is_refused(sheet_from, text, message):
    with pytest.raises(TemplateError, match=message):
        sheet_from(_text(text))
