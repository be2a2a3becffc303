"""A function whose value is an element of an array of numbers and texts gives that element
when evaluated on its own: a text, or a number (a text element was an internal error)."""

from __future__ import annotations


def test_the_element_of_a_mixed_array_is_a_text_or_a_number(sheet_from):
    text = '[arguments]\nk = { unit = "" }\n\n[definitions]\nV = "[1, \'ok\']"\n"f(k)" = "V[k]"\n'
    sheet = sheet_from(text)
    assert sheet.evaluate("f", 1) == "ok"
    assert sheet.evaluate("f", 0).magnitude == 1.0
