"""What the translators of cell formulas share: the refusal of a formula, a reference to a
cell or a range, and which texts the language's text literals hold."""

from __future__ import annotations

import re
from dataclasses import dataclass


class FormulaProblem(Exception):
    """A formula this translation does not take (the reason is the message)."""


def text_problem(text: str) -> str | None:
    """Why a text cannot be a text literal of the language (None when it can): a quote or a
    backslash."""
    if '"' in text or "\\" in text:
        return "a text with a quote or a backslash"
    return None


@dataclass
class Ref:
    """A cell or a rectangle of cells of a sheet (rows and columns from 1)."""

    sheet: str
    r1: int
    c1: int
    r2: int
    c2: int

    @property
    def single(self) -> bool:
        return self.r1 == self.r2 and self.c1 == self.c2


def row_relative(token) -> bool:
    """A reference whose row moves when the formula is filled down (``M183``, ``$M183``)."""
    source, end = getattr(token, "source", None), getattr(token, "end_match", None)
    text = source[:end] if isinstance(source, str) and isinstance(end, int) else str(token)
    text = text.split("!")[-1]  # the parser's name drops the $: its source keeps them
    m = re.match(r"\$?[A-Za-z]{1,3}(\$?)\d+$", text)
    return m is not None and not m.group(1)


def written_number(node) -> float | None:
    """The number written in the formula (TRUE 1, FALSE 0), else None."""
    if node[0] == "leaf" and node[1] == "Number":
        word = node[2].name.upper()
        return 1.0 if word == "TRUE" else 0.0 if word == "FALSE" else float(node[2].name)
    if node[0] == "op" and node[1] == "u-":
        inner = written_number(node[2][0])
        return None if inner is None else -inner
    return None


def holds_number(cell) -> bool:
    """Whether Excel counts the cell in SUM, AVERAGE, MIN, MAX, COUNT over a reference: a
    number, or an error value (which the function then gives); not empty, text, TRUE/FALSE."""
    if cell is None or cell.value is None or isinstance(cell.value, bool):
        return False
    if isinstance(cell.value, str):
        return cell.formula is not None and cell.value.startswith("#")
    return isinstance(cell.value, (int, float))
