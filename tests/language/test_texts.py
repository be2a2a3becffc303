"""concat and num2str: texts joined and numbers written, their Excel form recalculated by the
`formulas` package, and what they refuse."""

from __future__ import annotations

import re

import pytest

from workbook import WorkbookError
from workbook.functions.texts import number_text

SHEET = r"""
[inputs]
n = "3"
L = "2 m"
mark = { value = "B", options = ["A", "B"] }

[arguments]
phi = { unit = "" }

[definitions]
label = "concat(\"n = \", num2str(n), \" bolts\")"
quoted = "concat(\"it's \", \"5 < 6 & 7\", \", x\")"
joined = "concat(\"grade \", \"B\")"
same = "1 if concat(\"A\", \"B\") == \"AB\" otherwise 0"
"tag(phi)" = "concat(\"phi=\", num2str(phi))"
#BAD

[[tables]]
name = "tags"
range = "phi := 0, 0.25 .. 1"
columns = { "tag(phi)" = "" }
"""


def test_texts_joined_and_numbers_written(sheet):
    assert sheet.evaluate("label") == "n = 3 bolts"
    assert sheet.evaluate("quoted") == "it's 5 < 6 & 7, x"
    assert float(sheet.evaluate("same").magnitude) == 1.0
    assert list(sheet.table("tags")["tag(phi)"]) == [
        "phi=0",
        "phi=0.25",
        "phi=0.5",
        "phi=0.75",
        "phi=1",
    ]


@pytest.mark.parametrize(
    "x, text",
    [(3.0, "3"), (0.1 + 0.2, "0.3"), (1 / 3, "0.333333333333333"), (-2.5e-5, "-2.5e-05"),
     (1.5e20, "1.5e+20"), (123456789012345.6, "123456789012346")],
)  # fmt: skip
def test_num2str_writes_15_significant_digits(x, text):
    assert number_text(x) == text


def test_concat_is_live_in_excel(sheet, tmp_path):
    formulas = pytest.importorskip("formulas")
    from workbook.compute.excel import ExcelPrinter

    printer = ExcelPrinter(sheet.typer, {"n": "3"})
    for name in ("quoted", "joined"):
        text = printer.formula(sheet.typer.scalar(name), {})
        assert text.startswith("=CONCATENATE(")
        assert formulas.Parser().ast(text)[1].compile()() == sheet.evaluate(name)


def test_num2str_is_written_as_its_value_with_a_comment(sheet, tmp_path):
    import openpyxl

    book = openpyxl.load_workbook(sheet.write_xlsx(tmp_path / "txt.xlsx"))
    cells = [c for ws in book.worksheets for r in ws.iter_rows() for c in r]
    label = next(c for c in cells if c.value == "n = 3 bolts")
    assert "Excel writes numbers as texts with its own digits" in label.comment.text


@pytest.mark.parametrize(
    "line, message",
    [
        ('bad = "concat(\\"a\\", n)"', "concat(): argument 2 is not a text"),
        ('bad = "num2str(\\"a\\")"', "num2str(x): x must be a number"),
        ('bad = "num2str(mark)"', "num2str(x): 'mark' is a choice, not a number"),
        ('bad = "num2str(L)"', "divide it by the unit"),
        ('bad = "num2str(n) + 1"', "text"),
    ],
)
def test_refused_at_load(sheet_from, line, message):
    with pytest.raises(WorkbookError, match=re.escape(message)):
        sheet_from(SHEET.replace("#BAD", line))


def test_a_caret_inside_a_text_is_a_caret(sheet_from):
    """`^` is the power operator outside texts only: "As (in^2)" keeps its `^`."""
    sheet = sheet_from(
        '[inputs]\nx = "3"\n[definitions]\n'
        'label = "concat(\\"As (in^2) = \\", num2str(x^2))"\n'
        "unit_text = \"'m^2' if x^2 > 4 otherwise 'mm^2'\"\n"
    )
    assert sheet.evaluate("label") == "As (in^2) = 9"
    assert sheet.evaluate("unit_text") == "m^2"
