"""A TOML document built from values and comments, never from joined text.

Every key and every scalar value is written by tomli-w; arrays and inline tables are composed
of those pieces; a comment is one line whose control characters (a newline, DEL, a line
separator) are shown escaped, so nothing in it can end the comment. :meth:`Document.text`
reads the written text back and refuses it unless it is exactly the data it was built from.
"""

from __future__ import annotations

import sys
import unicodedata
from typing import Any

import tomli_w

from ..errors import WorkbookError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

#: Characters that end a line for some reader (str.splitlines), besides the C0/C1 controls.
_LINE_BREAKS = "\x85\u2028\u2029"


def one_line(text: str) -> str:
    """``text`` with every control character and line break shown as ``\\uXXXX``: safe in a
    comment of a TOML or CSV file (a tab stays)."""
    return "".join(
        f"\\u{ord(c):04X}"
        if (c != "\t" and unicodedata.category(c) in ("Cc", "Zl", "Zp")) or c in _LINE_BREAKS
        else c
        for c in str(text)
    )


def is_one_line(text: str) -> bool:
    return one_line(text) == text


def key_text(key: str) -> str:
    """A key as TOML writes it: bare when it can be, else a quoted string."""
    written = tomli_w.dumps({key: 0})
    return _escape_breaks(written[: -len(" = 0\n")])


def value_text(value: Any, *, multiline: bool = False) -> str:
    """A value on one line: a scalar as tomli-w writes it, a list as ``[a, b]``, a dict as an
    inline table ``{ k = v }``. ``multiline``: a string with newlines as a triple-quoted one."""
    if isinstance(value, dict):
        inner = ", ".join(
            f"{key_text(k)} = {value_text(v, multiline=multiline)}" for k, v in value.items()
        )
        return "{ " + inner + " }" if inner else "{}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(value_text(v) for v in value) + "]"
    written = tomli_w.dumps({"v": value}, multiline_strings=multiline)
    return _escape_breaks(written[len("v = ") : -1])


def _escape_breaks(text: str) -> str:
    # tomli-w leaves U+0085, U+2028 and U+2029 raw in strings (valid TOML); they are escaped
    # here so that every reader counts the lines of the document alike
    for c in _LINE_BREAKS:
        text = text.replace(c, f"\\u{ord(c):04X}")
    return text


class Document:
    """A TOML document: tables, arrays of tables, key = value lines and comments."""

    def __init__(self) -> None:
        self.lines: list[str] = []
        self.data: dict[str, Any] = {}
        self._table: dict[str, Any] = self.data

    def comment(self, text: str = "") -> None:
        """One comment line per line of ``text`` (an empty text: a bare ``#``)."""
        for line in str(text).split("\n") or [""]:
            self.lines.append(("# " + one_line(line)).rstrip())

    def blank(self) -> None:
        self.lines.append("")

    def table(self, name: str, comment: str | None = None) -> None:
        if name in self.data:
            raise WorkbookError(f"the table [{name}] is written twice")
        self._table = self.data[name] = {}
        self.lines.append(self._with_comment(f"[{key_text(name)}]", comment))

    def array_table(self, name: str, comment: str | None = None) -> None:
        self._table = {}
        self.data.setdefault(name, []).append(self._table)
        self.lines.append(self._with_comment(f"[[{key_text(name)}]]", comment))

    def pair(self, key: str, value: Any, comment: str | None = None, *, multiline=False) -> None:
        if key in self._table:
            raise WorkbookError(f"the key {key!r} is written twice in a table")
        self._table[key] = value
        line = f"{key_text(key)} = {value_text(value, multiline=multiline)}"
        self.lines.append(self._with_comment(line, comment))

    def array(self, key: str, items: list[Any], comments: list[str]) -> None:
        """``key = [`` one item a line, each with its comment, ``]``."""
        if key in self._table:
            raise WorkbookError(f"the key {key!r} is written twice in a table")
        self._table[key] = list(items)
        self.lines.append(f"{key_text(key)} = [")
        for item, comment in zip(items, comments, strict=True):
            self.lines.append(self._with_comment(f"  {value_text(item)},", comment))
        self.lines.append("]")

    @staticmethod
    def _with_comment(line: str, comment: str | None) -> str:
        return f"{line}  # {one_line(comment)}" if comment else line

    def text(self) -> str:
        """The document; it reads back as exactly the data written (else a bug: exit 3)."""
        text = "\n".join(self.lines) + "\n"
        try:
            back = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise RuntimeError(f"the generated TOML does not read back: {exc}") from None
        if back != _plain(self.data):
            raise RuntimeError("the generated TOML reads back as other data than was written")
        return text


def _plain(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value
