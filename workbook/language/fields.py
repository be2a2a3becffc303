"""Typed, checked access to one TOML table of a template.

A misspelt key (``postive = true``, ``unti = "mm"``) would otherwise be ignored and the sheet
computed without it; a value of the wrong type (``tolerance = "abc"``, ``options = 5``) would
surface as a Python exception. :class:`Fields` refuses both with a message that names the
table, the key, and the nearest known keys.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

from ..errors import TemplateError


def nearest(name: str, known: Iterable[str], *, n: int = 3) -> str:
    """`` (did you mean a, b?)`` with the names of ``known`` closest to ``name``, or ``""``."""
    import difflib

    known = [k for k in known if isinstance(k, str)]
    cutoff = 0.6 if len(name) > 3 else 0.5  # R2 -> R1: one letter of two differs
    close = difflib.get_close_matches(name, known, n=n, cutoff=cutoff)
    if not close:  # a name differing only in case or underscores (ks -> k_s)
        squash = {k.lower().replace("_", ""): k for k in known}
        hit = squash.get(name.lower().replace("_", ""))
        close = [hit] if hit else []
    return f" (did you mean {', '.join(close)}?)" if close else ""


class Fields:
    """The keys of one template table (``what`` names it in messages: "input R1")."""

    def __init__(self, raw: dict, allowed: Iterable[str], what: str):
        if not isinstance(raw, dict):
            raise TemplateError(f"{what} must be a table {{ key = value, ... }}")
        self.raw, self.what = raw, what
        allowed = tuple(allowed)
        for key in raw:
            if key not in allowed:
                raise TemplateError(
                    f"unknown key '{key}' in {what}{nearest(key, allowed)} "
                    f"(keys: {', '.join(allowed)})"
                )

    def __contains__(self, key: str) -> bool:
        return key in self.raw

    def _type_error(self, key: str, expected: str):
        value = self.raw[key]
        shown = repr(value) if len(repr(value)) <= 60 else repr(value)[:57] + "..."
        return TemplateError(f"{self.what}: {key} must be {expected}, got {shown}")

    def required(self, key: str, example: str):
        if key not in self.raw:
            raise TemplateError(f"{self.what} needs {key} (e.g. {example})")
        return self.raw[key]

    def required_text(self, key: str, example: str) -> str:
        self.required(key, example)
        return self.text(key)

    def text(self, key: str, default: str | None = "") -> str | None:
        """A string (numbers are accepted and written as they are)."""
        if key not in self.raw:
            return default
        value = self.raw[key]
        if isinstance(value, bool) or not isinstance(value, (str, int, float)):
            raise self._type_error(key, "text in quotes")
        return str(value)

    def flag(self, key: str, default: bool = False) -> bool:
        if key not in self.raw:
            return default
        if not isinstance(self.raw[key], bool):
            raise self._type_error(key, "true or false")
        return self.raw[key]

    def number(self, key: str, default: float | None = None) -> float | None:
        """A finite number (not text, not a boolean)."""
        if key not in self.raw:
            return default
        value = self.raw[key]
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self._type_error(key, "a number (without quotes)")
        try:
            value = float(value)
        except OverflowError:
            raise self._type_error(key, "a number of at most about 1.8e308") from None
        if not math.isfinite(value):
            raise self._type_error(key, "a finite number")
        return value

    def texts(self, key: str) -> tuple[str, ...]:
        """A list of strings."""
        if key not in self.raw:
            return ()
        value = self.raw[key]
        if not isinstance(value, list) or not all(
            isinstance(v, (str, int, float)) and not isinstance(v, bool) for v in value
        ):
            raise self._type_error(key, 'a list of texts like ["a", "b"]')
        return tuple(str(v) for v in value)

    def table(self, key: str) -> dict:
        if key not in self.raw:
            return {}
        if not isinstance(self.raw[key], dict):
            raise self._type_error(key, "a table { key = value, ... }")
        return self.raw[key]

    def tables(self, key: str) -> list[dict]:
        """A list of tables (``series = [{ y = "h" }, ...]``)."""
        if key not in self.raw:
            return []
        value = self.raw[key]
        if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
            raise self._type_error(key, "a list of tables [{ ... }, ...]")
        return value


def value_line(text: str, value: str) -> int | None:
    """Line number (1-based) of the first line of ``text`` holding ``value``, or None."""
    for number, line in enumerate(text.splitlines(), start=1):
        if value in line:
            return number
    return None
