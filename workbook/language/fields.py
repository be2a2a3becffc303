"""Typed, checked access to one TOML table of a template.

A misspelt key (``postive = true``, ``unti = "mm"``) would otherwise be ignored and the sheet
computed without it; a value of the wrong type (``tolerance = "abc"``, ``options = 5``) would
surface as a Python exception. :class:`Fields` refuses both with a message that names the
table, the key, and the nearest known keys. :func:`find_line` and :func:`value_line` find
where in the text a key or a value is written, for messages that name the line.
"""

from __future__ import annotations

import functools
import math
import re
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


def find_line(text: str, key: str, section: str | None = None) -> int | None:
    """Line number (1-based) where ``key = ...`` is written, optionally inside [section]."""
    plain = key and "=" not in key and key == key.strip() and key[0] not in _QUOTES
    if plain and key[-1] not in _QUOTES:  # the index holds every line such a key matches
        for number, in_section in _key_lines(text).get(key, ()):
            if section is None or (
                in_section is not None
                and (in_section == section or in_section.startswith(section + "."))
            ):
                return number
        return None
    return scan_for_line(text, key, section)


_QUOTES = "\"'"


@functools.lru_cache(maxsize=4)
def _key_lines(text: str) -> dict[str, list[tuple[int, str | None]]]:
    """Each key a line may be written for (``KEY =``, ``"KEY" =``), with the line number and
    the section the line is in: one pass over a template, so that finding the lines of its
    definitions is linear (a scan per key took minutes for 30,000 definitions).

    A line matches :func:`scan_for_line`'s pattern for a key without ``=``, quotes or outer
    blanks exactly when the text before its first ``=``, stripped, is the key with an
    optional quote on either side."""
    index: dict[str, list[tuple[int, str | None]]] = {}
    current: str | None = None
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        header = stripped.startswith("[")
        if header:
            current = stripped.strip("[]").strip()
        head, eq, _ = line.partition("=")
        if not eq or not head.strip():
            continue
        head = head.strip()
        keys = {head}
        opens, closes = head[0] in _QUOTES, head[-1] in _QUOTES
        if opens:
            keys.add(head[1:])
        if closes:
            keys.add(head[:-1])
        if opens and closes and len(head) > 1:
            keys.add(head[1:-1])
        for k in keys:  # a section header is a key's line only when no section is asked
            index.setdefault(k, []).append((number, None if header else current))
    return index


def scan_for_line(text: str, key: str, section: str | None) -> int | None:
    """The line of ``key = ...`` in ``[section]`` of the worksheet text (any section when
    None), or None."""
    pattern = re.compile(r'^\s*["\']?' + re.escape(key) + r'["\']?\s*=')
    in_section = section is None
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if section is not None and stripped.startswith("["):
            name = stripped.strip("[]").strip()
            in_section = name == section or name.startswith(section + ".")
            continue
        if in_section and pattern.match(line):
            return number
    return None
