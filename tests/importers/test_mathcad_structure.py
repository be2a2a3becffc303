"""A file Mathcad did not write is refused with exit 2 and a message naming the file and the
line: an XInclude element (never followed), an element where Mathcad writes a definition's
side or an operator's operand (a tree missing a part is never translated by guessing)."""

from __future__ import annotations

import pytest
from helpers.mathcad_xml import (
    define,
    evaluate,
    ident,
    prime_package,
    prime_region,
    prime_result,
    real,
    worksheet,
)

from workbook.cli import main

XI = 'xmlns:xi="http://www.w3.org/2001/XInclude"'
INCLUDE = f'<xi:include {XI} href="/etc/passwd" parse="text"/>'


def _import(path, capsys) -> tuple[int, str]:
    code = main(["import", str(path), "--out", str(path.parent)])
    return code, capsys.readouterr().err


@pytest.mark.slow
@pytest.mark.parametrize("where", ["regions", "math"])
def test_an_xinclude_in_an_xmcd_is_refused(tmp_path, capsys, where):
    sheet = worksheet(define(1, ident("x"), real(2)), evaluate(2, ident("x"), real(2)))
    if where == "regions":
        sheet = sheet.replace("<regions>", "<regions>" + INCLUDE)
    else:
        sheet = sheet.replace("<ml:real>2</ml:real></ml:define>", INCLUDE + "</ml:define>")
    src = tmp_path / "inc.xmcd"
    src.write_text(sheet, encoding="utf-8")
    code, err = _import(src, capsys)
    assert code == 2
    assert "inc.xmcd: line" in err and "XInclude element (<include>)" in err
    assert not (tmp_path / "inc.toml").exists()


@pytest.mark.slow
def test_an_xinclude_in_an_mcdx_is_refused(tmp_path, capsys):
    body = f"<ml:define><ml:id>x</ml:id>{INCLUDE}</ml:define>"
    src = prime_package(tmp_path / "inc.mcdx", prime_region(1, 1, body), prime_result(1))
    code, err = _import(src, capsys)
    assert code == 2
    assert "of mathcad/worksheet.xml: an XInclude element" in err


@pytest.mark.slow
def test_an_element_of_another_kind_in_an_mcdx_definition_is_refused(tmp_path, capsys):
    """Prime's reader reads only Mathcad's namespaces: a definition whose right side is an
    element of another one has one side, and the file is refused (was an IndexError)."""
    body = '<ml:define><ml:id>x</ml:id><foo:bar xmlns:foo="urn:other"/></ml:define>'
    src = prime_package(tmp_path / "odd.mcdx", prime_region(1, 1, body), prime_result(1))
    code, err = _import(src, capsys)
    assert code == 2
    assert "region 1: <define> with 1 elements inside" in err


@pytest.mark.slow
def test_an_operator_without_its_operands_is_refused(tmp_path, capsys):
    plus = '<ml:apply><ml:plus/><ml:real>1</ml:real><foo:bar xmlns:foo="urn:o"/></ml:apply>'
    src = tmp_path / "plus.xmcd"
    src.write_text(worksheet(define(1, ident("x"), plus)), encoding="utf-8")
    code, err = _import(src, capsys)
    # an element of another namespace stays an element (Mathcad 15's reader keeps it)
    # and is listed as not translated; the shape is Mathcad's: exit 0
    assert code == 0, err
    src.write_text(
        worksheet(define(1, ident("x"), "<ml:apply><ml:plus/><ml:real>1</ml:real></ml:apply>")),
        encoding="utf-8",
    )
    code, err = _import(src, capsys)
    assert code == 2
    assert "<apply> of <plus> with 1 operands, not 2" in err
