"""VBA's number types, its rounding to an integer (half to even), written in the language, and
the value it gives an Optional argument left out."""

from __future__ import annotations

from .vbaexpr import parse, strip
from .vbamembers import NotTranslated

INTEGER_TYPES = {"integer", "long", "byte", "longlong", "longptr"}
NUMBER_TYPES = INTEGER_TYPES | {"double", "single", "currency", "decimal"}


def bankers(text: str) -> str:
    """VBA's rounding to an integer (half to even) as an expression of the language."""
    f = f"floor({text} + 0.5)"
    # an odd f at a half goes down: mod keeps the sign of f, so mod(-1, 2) is -1, not 1
    return f"({f} - 1 if {f} == {text} + 0.5 and mod({f}, 2) != 0 otherwise {f})"


def default_text(p) -> str:
    """The value VBA gives an Optional argument left out."""
    if p.default is not None:
        node = strip(parse(p.default))
        if node[0] == "num":
            return node[1]
        if node[0] == "un" and node[1] == "-" and strip(node[2])[0] == "num":
            return "-" + strip(node[2])[1]
        if node[0] == "id" and node[1].lower() in ("true", "false"):
            return "-1" if node[1].lower() == "true" else "0"
        if node[0] == "str" and '"' not in node[1]:
            return f'"{node[1]}"'
        raise NotTranslated(f"the default {p.default!r} of {p.name}")
    if p.type.lower() in NUMBER_TYPES or p.type.lower() == "boolean":
        return "0"
    return "0"  # a Variant left out: tested with IsMissing (the flag), else Empty (0)
