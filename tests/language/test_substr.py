"""strlen and substr: Mathcad's texts by position (the first 0); strupper, strlower and
strtrim: Excel's UPPER, LOWER and TRIM; their Excel forms computed again by the `formulas`
package, and what they refuse."""

from __future__ import annotations

import re

import pytest

from workbook import WorkbookError

SHEET = r"""
[inputs]
k = "2"
L = "2 m"

[definitions]
word = "\"abcdef\""
middle = "substr(word, k, 3)"
tail = "substr(word, 4, 10)"
beyond = "substr(word, 9, 1)"
size = "strlen(word)"
first = "concat(substr(word, 0, 1), \"-\")"
spaced = "\"  Load \tcase  2 \""
trimmed = "strtrim(spaced)"
capitals = "strupper(word)"
small = "strlower(\"AbC 1\")"
german = "strupper(\"Maß\")"
#BAD
"""


def test_positions_from_0_and_at_most_n_characters(sheet):
    assert sheet.evaluate("middle") == "cde"
    assert sheet.evaluate("tail") == "ef"
    assert sheet.evaluate("beyond") == ""
    assert sheet.evaluate("size").magnitude == 6
    assert sheet.evaluate("first") == "a-"


def test_excel_trim_upper_and_lower(sheet):
    assert sheet.evaluate("trimmed") == "Load \tcase 2"  # the space only, a tab kept
    assert sheet.evaluate("capitals") == "ABCDEF"
    assert sheet.evaluate("small") == "abc 1"
    with pytest.raises(WorkbookError, match="a letter beyond ASCII"):
        sheet.evaluate("german")  # Python writes MASS, which may not be what Excel writes


@pytest.mark.parametrize("k", [-1, 1.5])
def test_a_position_that_is_no_whole_number_at_least_0_is_an_error(sheet, k):
    with pytest.raises(WorkbookError, match="m must be a whole number at least 0"):
        sheet.with_inputs(k=k).evaluate("middle")


def test_excel_form_is_mid_and_len(sheet):
    formulas = pytest.importorskip("formulas")
    from workbook.compute.excel import ExcelPrinter

    printer = ExcelPrinter(sheet.typer, {"k": "2"})
    forms = [("middle", "=MID("), ("tail", "=MID("), ("size", "=LEN("), ("capitals", "=UPPER(")]
    assert printer.formula(sheet.typer.scalar("trimmed"), {}).startswith("=TRIM(")
    for what, start in forms:
        text = printer.formula(sheet.typer.scalar(what), {})
        assert text.startswith(start)
        fn = formulas.Parser().ast(text)[1].compile()
        value = fn(*[{"WORD": "abcdef", "K": 2}[name] for name in fn.inputs])
        expected = sheet.evaluate(what)
        assert (value if isinstance(expected, str) else float(value)) == (
            expected if isinstance(expected, str) else expected.magnitude
        )


@pytest.mark.parametrize(
    "line, message",
    [
        ('bad = "strlen(k)"', "strlen(): argument 1 is not a text"),
        ('bad = "substr(word, \\"a\\", 1)"', "substr(S, m, n): argument 2 must be a number"),
        ('bad = "substr(word, L, 1)"', "substr(S, m, n): m"),
    ],
)
def test_refused_at_load(sheet_from, line, message):
    with pytest.raises(WorkbookError, match=re.escape(message)):
        sheet_from(SHEET.replace("#BAD", line))
