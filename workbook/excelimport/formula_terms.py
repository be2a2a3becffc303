"""What the translators of cell formulas share: the refusal of a formula, a reference to a
cell or a range, and which texts the language's text literals hold."""

from __future__ import annotations

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
