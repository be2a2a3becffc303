"""The one reader of quantity and unit text: ``"45.5 mm"``, ``"104.6 1/s"``, ``"kg*m^2"``.

Every value a user types (template values, bounds and units, ``--set``, ``--vary``, cells of
``--inputs``, the unit column of a printed-values CSV) goes through :func:`split_quantity` or
:func:`check_unit_text` before pint sees it. pint evaluates its text as Python arithmetic with
Python integers (``9**9**9`` never returns) and reads a space as a product (``"45 5 mm"`` is
225 mm, ``"700 MPa MPa"`` is MPa^2); here a quantity is exactly one decimal number and a unit
made of names, ``* / ^`` (or ``**``), parentheses and small exponents. Anything else is an
:class:`~workbook.errors.InputError` that says what to write instead.
"""

from __future__ import annotations

import re

from ..errors import InputError, LimitError

MAX_QUANTITY_TEXT = 200  # characters of one value or unit text
MAX_UNIT_POWER = 12  # largest exponent in a unit (m^3, s^-2, ...)
MAX_UNIT_TOKENS = 40  # names, operators and exponents of one unit

_NUMBER = re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?")
_SPECIAL = re.compile(r"[+-]?(?:nan|inf|infinity)\b", re.IGNORECASE)
_TOKEN = re.compile(
    r"\s*(\*\*|[*/^()]|\d+(?:\.\d*)?(?:[eE][+-]?\d+)?|[-+]|[^\W\d][\w°µμΩ%]*|[°%Ω])"
)


#: typeset unit text read as written (W/(m²·K), as the report and the workbook show it)
_TYPESET = str.maketrans({"·": "*", "⋅": "*"})


def split_quantity(text: str, *, what: str = "value") -> tuple[float | int, str]:
    """Split ``"45.5 mm"`` into ``(45.5, "mm")``; the unit text is checked (may be empty).

    ``nan`` and ``inf`` are read as numbers: the caller refuses them naming the input.
    """
    original = text
    if len(text) > MAX_QUANTITY_TEXT:
        raise LimitError(
            f"{what}: value text is {len(text):,} characters long (limit {MAX_QUANTITY_TEXT})"
        )
    text = text.strip()
    if not text:
        raise InputError(f"{what}: empty value")
    if text[0] in "[({" or "," in text or ";" in text:
        _refuse_list(text, what)
    if re.search(r"(?<![\w.])[\d.]+(?:[eE][+-]?\d+)?[ij](?!\w)", text):
        raise InputError(
            f"{what}: {original!r} is a complex number, and a value is one real number and its "
            "unit: give the parts as two values (R, X) and define the complex one, R + X*1i"
        )
    m = _SPECIAL.match(text) or _NUMBER.match(text)
    if m is None:
        raise InputError(
            f"{what}: cannot read {original!r} as a quantity (it starts with no number; "
            "write one number, then its unit: '45.5 mm')"
        )
    literal = m.group(0)
    number = float(literal)
    if re.fullmatch(r"[+-]?\d{1,15}", literal):
        number = int(literal)  # shown as it was typed ("-5 mm", not "-5.0 mm")
    rest = text[m.end() :].strip()
    if rest.startswith(("**", "^")):
        raise InputError(
            f"{what}: {original!r}: write the number itself (like 1e6), not a power of it"
        )
    if rest.startswith("*"):
        rest = rest[1:].strip()  # "45*mm" reads as "45 mm"
    elif rest.startswith("/"):
        rest = "1" + rest  # "5/s" reads as "5 1/s"
    return number, check_unit_text(rest, what=what, quantity=original)


def _refuse_list(text: str, what: str) -> None:
    if re.match(r"^[+-]?\d+,\d+(?![\d,])", text):
        fixed = re.sub(r"^([+-]?\d+),(\d+)", r"\1.\2", text)
        raise InputError(
            f"{what}: {text!r} has a decimal comma; write a decimal point: {fixed!r} "
            "(no thousands separators)"
        )
    raise InputError(
        f"{what}: {text!r} is not one value (lists, brackets and commas are not accepted; "
        "write one number and its unit, like '45.5 mm')"
    )


def check_unit_text(text: str, *, what: str = "unit", quantity: str | None = None) -> str:
    """Check a unit text (``"kg*m^2"``, ``"1/s"``, ``""``) and return it stripped.

    Refuses numbers other than exponents (``"5 mm"`` inside a unit, juxtaposed numbers), an
    exponent above :data:`MAX_UNIT_POWER`, a unit name written twice (``"MPa MPa"``), and any
    character that is not a name, ``* / ^ **``, a parenthesis or a space.
    """
    shown = quantity if quantity is not None else text
    if len(text) > MAX_QUANTITY_TEXT:
        raise LimitError(
            f"{what}: unit text is {len(text):,} characters long (limit {MAX_QUANTITY_TEXT})"
        )
    text = text.strip().translate(_TYPESET)
    if not text:
        return ""
    tokens, pos = [], 0
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if m is None or m.end() == pos:
            bad = text[pos:].strip()[:1]
            raise InputError(
                f"{what}: cannot read {shown!r}: unexpected {bad!r} (a unit is names with "
                "* / ^ and parentheses, like 'kg*m^2' or '1/s')"
            )
        tokens.append(m.group(1))
        pos = m.end()
        if len(tokens) > MAX_UNIT_TOKENS:
            raise LimitError(f"{what}: unit {shown!r} has more than {MAX_UNIT_TOKENS} parts")
    names: list[str] = []
    depth = 0
    for i, tok in enumerate(tokens):
        prev = tokens[i - 1] if i else None
        if tok in ("**", "^"):
            _exponent(tokens, i, shown, what)
        elif tok[0].isdigit():
            exponent = prev in ("**", "^") or (prev in ("-", "+", "(") and _after_power(tokens, i))
            exponent = exponent or _denominator_of_power(tokens, i)  # the 2 of m^(1/2)
            one_over = tok == "1" and i == 0 and len(tokens) > 1 and tokens[1] == "/"
            if not (exponent or one_over):
                raise InputError(
                    f"{what}: {shown!r} has a number where a unit should be (write one number, "
                    "then its unit: '45.5 mm'; a power is written m^2)"
                )
        elif tok in ("-", "+"):
            if not _after_power(tokens, i + 1):
                raise InputError(
                    f"{what}: cannot read {shown!r}: {tok!r} is allowed only in an exponent "
                    "(s^-1); a value is one number and its unit"
                )
        elif tok == "(":
            depth += 1
            if depth > 5:
                raise LimitError(f"{what}: unit {shown!r} nests parentheses too deeply")
        elif tok == ")":
            depth -= 1
            if depth < 0:
                raise InputError(f"{what}: unbalanced parentheses in {shown!r}")
        elif tok not in ("*", "/"):
            if tok == prev:  # "MPa MPa": pint reads a space as a product
                raise InputError(
                    f"{what}: unit {tok!r} is written twice in {shown!r} (a space between two "
                    f"units multiplies them); write it once, or {tok}^2 if the square is meant"
                )
            names.append(tok)
    if depth:
        raise InputError(f"{what}: unbalanced parentheses in {shown!r}")
    return text


def _after_power(tokens: list[str], i: int) -> bool:
    """True when token ``i`` is inside the exponent that follows a ``^`` or ``**``."""
    j = i - 1
    while j >= 0 and tokens[j] in ("-", "+", "("):
        j -= 1
    return j >= 0 and tokens[j] in ("**", "^")


def _denominator_of_power(tokens: list[str], i: int) -> bool:
    """True when token ``i`` is the ``b`` of a fractional power ``^(a/b)`` (m^(1/2))."""
    return (
        i >= 3
        and tokens[i - 1] == "/"
        and tokens[i - 2][0].isdigit()
        and tokens[i - 3] in ("(", "-", "+")
        and "(" in tokens[i - 4 : i - 2] + tokens[i - 3 : i - 2]
        and _after_power(tokens, i - 2)
        and i + 1 < len(tokens)
        and tokens[i + 1] == ")"
    )


def _exponent(tokens: list[str], i: int, shown: str, what: str) -> None:
    j, sign = i + 1, 1.0
    while j < len(tokens) and tokens[j] in ("(", "-", "+"):
        if tokens[j] == "-":
            sign = -sign
        j += 1
    if j >= len(tokens) or not tokens[j][0].isdigit():
        raise InputError(f"{what}: {shown!r}: a power needs a number (m^2, s^-1)")
    value = sign * float(tokens[j])
    if j + 2 < len(tokens) and tokens[j + 1] == "/" and _denominator_of_power(tokens, j + 2):
        if float(tokens[j + 2]) == 0:
            raise InputError(f"{what}: {shown!r}: a power divides by zero")
        value /= float(tokens[j + 2])
        j += 2
    k, opened = j + 1, tokens[i + 1 : j].count("(")
    while k < len(tokens) and tokens[k] == ")" and opened:  # m^(2)^2 is m^(2^2) to pint
        k, opened = k + 1, opened - 1
    if k < len(tokens) and tokens[k] in ("**", "^"):
        # kg^9**9**9 is kg to the power 9**(9**9): each power alone is small, pint would
        # compute the tower (minutes of CPU and unbounded memory)
        raise LimitError(
            f"{what}: {shown!r} raises a power to a power (write one power: m^2, s^-1)"
        )
    if abs(value) > MAX_UNIT_POWER:
        raise LimitError(
            f"{what}: power {value:g} in {shown!r} (a unit's power is at most "
            f"{MAX_UNIT_POWER} in magnitude)"
        )
