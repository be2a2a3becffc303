"""Read a report back: MathML to worksheet text, displayed numbers and units to values.

The tests compare what a report shows with the engine, so they read the HTML with lxml
and turn each piece of MathML back into text the engine parses: a formula back into an
expression, a number back into a float, a unit back into a pint unit.
"""

from __future__ import annotations

import re

from lxml import html as lxml_html

from workbook.outputs.report.mathml import GREEK

_LATIN = {v: k for k, v in GREEK.items()}
_OPS = {
    "\u2212": "-",
    "\u22c5": "*",
    "\u2062": "*",
    "\u2061": "",
    "\u00d7": "*",
    "\u2264": "<=",
    "\u2265": ">=",
    "\u2260": "!=",
    "=": "==",
    "..": "..",
}


def parse(text: str):
    """The report's HTML as an lxml tree."""
    return lxml_html.fromstring(text)


def _tag(el) -> str:
    return el.tag.split("}")[-1] if isinstance(el.tag, str) else ""


def _name(text: str) -> str:
    return _LATIN.get(text, text)


def to_text(el) -> str:
    """MathML back to worksheet text: ``<mfrac>`` as (a)/(b), R with subscript 3 as R3."""
    tag = _tag(el)
    kids = [k for k in el if _tag(k)]
    if el.get("data-call"):  # a built-in written as its registry entry says: its arguments
        args = {}
        for a in el.xpath(".//*[@data-arg]"):
            if a.xpath("ancestor::*[@data-call][1]")[0] is el:
                args[int(a.get("data-arg"))] = to_text(a)
        return f"{el.get('data-call')}({', '.join(args[i] for i in sorted(args))})"
    if tag == "mrow" and el.get("class") == "literal":  # 20 mm, a number with its unit
        number, _space, unit = kids
        top, slash, bottom = to_text(unit).replace("(", "").replace(")", "").partition("/")
        if "*" in bottom:  # the unit's denominator is shown without brackets: W/m·K
            bottom = f"({bottom})"
        return f"({to_text(number)} {top}{slash}{bottom})"
    if tag == "mrow" and el.get("class") == "over":  # max_over(table, column)
        head, _apply, col = kids
        func, label = (k.text_content() for k in head)
        return f"{func}_over({label.removeprefix('table ')}, {to_text(col)})"
    if tag in ("math", "mrow", "mtd"):
        return "".join(to_text(k) for k in kids)
    if tag == "mi":
        return _name(el.text_content())
    if tag == "mn":
        return el.text_content().replace("\u2212", "-")
    if tag == "mo":
        t = el.text_content()
        return _OPS.get(t, t)
    if tag == "mtext":
        t = el.text_content().replace("\u00a0", " ")
        if t.strip() in ("and", "or", "not"):
            return f" {t.strip()} "
        return t.replace("\u201c", '"').replace("\u201d", '"')
    if tag == "mspace":
        return " "
    if tag == "mfrac":
        return f"(({to_text(kids[0])})/({to_text(kids[1])}))"
    if tag == "msup":
        base, exp = kids
        if _tag(base) == "mi" and base.text_content() in ("sin", "cos", "tan", "sinh", "cosh"):
            return f"{base.text_content()}^{{{to_text(exp)}}}"  # sin²(x): fixed up below
        return f"({to_text(base)})^({to_text(exp)})"
    if tag == "msub" and el.get("class") == "index":  # M[i, j]
        base, sub = kids
        return f"{to_text(base)}[{to_text(sub)}]"
    if tag == "msub":
        base, sub = kids
        parts = (
            [to_text(k) for k in sub if _tag(k) in ("mi", "mn")]
            if _tag(sub) == "mrow"
            else [to_text(sub)]
        )
        head = to_text(base)
        if parts and parts[0].isdigit():
            head += parts.pop(0)
        return head + "".join("_" + p for p in parts)
    if tag == "munder":
        return "".join(to_text(k) for k in kids)
    if tag == "mtable":  # inside its brackets: [a, b], [c, d] -> [[a, b], [c, d]]
        rows = [", ".join(to_text(cell) for cell in row if _tag(cell)) for row in kids]
        return ", ".join(f"[{r}]" for r in rows)
    raise AssertionError(f"unexpected MathML element <{tag}>")


def formula_text(el) -> str:
    """A displayed formula as text the engine's parser reads."""
    text = to_text(el)
    # sin^{2}(x) -> sin(x)^2, the written form
    while True:
        m = re.search(r"(sin|cos|tan|sinh|cosh)\^\{([^{}]*)\}\(", text)
        if not m:
            break
        start = m.end() - 1
        depth, i = 0, start
        while True:
            depth += {"(": 1, ")": -1}.get(text[i], 0)
            if depth == 0:
                break
            i += 1
        text = (
            text[: m.start()]
            + m.group(1)
            + text[start : i + 1]
            + f"^({m.group(2)})"
            + text[i + 1 :]
        )
    return text


def number(text: str) -> float:
    """A displayed number (``−1.5×10−5``, ``1.5×10<sup>−5</sup>`` as text) as a float."""
    t = text.strip().replace("\u2212", "-").replace(" ", "").replace(",", "")
    m = re.fullmatch(r"(-?[0-9.]+(?:e[-+]?\d+)?)(?:\u00d710(-?\d+))?", t)
    assert m, f"not a displayed number: {text!r}"
    return float(m.group(1) + (f"e{m.group(2)}" if m.group(2) else ""))


def value_and_unit(el) -> tuple[float, str]:
    """A displayed quantity (``<mrow class='result'>``): its number and unit text."""
    unit_el = el.find_class("unit")
    unit = ""
    if unit_el:
        unit = to_text(unit_el[0]).replace("(", "").replace(")", "").replace("^", "**")
        unit_el[0].getparent().remove(unit_el[0])
    return number(el.text_content()), unit
