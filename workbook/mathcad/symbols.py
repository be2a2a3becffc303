"""What the translation's modules share: the untranslatable construct, the names of the
generated worksheet, and how a Mathcad element is named in messages."""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ..language import expr as ex

if TYPE_CHECKING:
    from .reader import MNode


class Untranslatable(Exception):
    """A construct the language cannot express (yet): the message says what and why."""


class Unknown(Exception):
    """What an expression needs is not known at import, or the engine refuses it."""


@dataclass(eq=False)
class Sym:
    """A name of the generated worksheet; its final identifier is chosen at the end."""

    kind: str  # var | func | param | unit | helper
    base: str  # preferred identifier
    mathcad: str  # the name as Mathcad shows it
    unit: str = ""  # params and range variables: their unit (pint text)
    broken: str = ""  # why it is not translated
    region: str = ""
    is_range: bool = False
    final: str = ""
    hint: ex.Node | None = None  # a bound variable: an expression in its unit
    hint_sym: Sym | None = None  # a bound variable: the parameter it stands for
    generated: bool = False  # a name of the translation's own (no Mathcad name)

    def token(self) -> str:
        return f"\x00{id(self)}"


WHAT = {  # Mathcad tag -> what it is, in messages
    "indexer": "an array index",
    "matcol": "a matrix column",
    "matrix": "a matrix",
    "summation": "a summation",
    "product": "a product (of a range)",
    "derivative": "a derivative",
    "integral": "an integral",
    "program": "a program",
    "Find": "a solve block (Given/Find)",
    "Maximize": "Maximize from a guess (the language's maximum takes an interval)",
    "Minimize": "Minimize from a guess (the language's minimum takes an interval)",
    "lambda": "a lambda function",
    "symEval": "a symbolic evaluation",
    "vectorize": "a vectorised expression",
    "range": "a range",
    "str": "a text",
}


def what(tag: str) -> str:
    """A Mathcad element as a message names it: ``a matrix``, ``Mathcad's <foo>``."""
    return WHAT.get(tag, f"Mathcad's <{tag}>")


def key(node: MNode) -> tuple[str, str]:
    """A Mathcad name and its literal subscript."""
    return node.text.strip(), node.attrs.get("subscript", "")


#: Elements of one matrix written in a worksheet (rows x columns).
MAX_MATRIX_ELEMENTS = 1_000_000


def whole_number(text: str, what: str) -> int:
    """An attribute that must be a whole number (a size, a power), as Mathcad writes it."""
    text = str(text).strip()
    if not re.fullmatch(r"[+-]?[0-9]{1,9}", text):
        raise Untranslatable(f"{what} is {text[:40]!r}, not a whole number")
    return int(text)


def matrix_size(node: MNode) -> tuple[int, int]:
    """(rows, columns) a matrix element declares: whole numbers, at least 0, at most
    :data:`MAX_MATRIX_ELEMENTS` elements."""
    rows = whole_number(node.attrs.get("rows", "0"), "a matrix's number of rows")
    cols = whole_number(node.attrs.get("cols", "0"), "a matrix's number of columns")
    if rows < 0 or cols < 0 or rows * cols > MAX_MATRIX_ELEMENTS:
        raise Untranslatable(f"a matrix of {rows} x {cols} elements")
    return rows, cols
