"""Built-ins of texts, as Mathcad names them: ``concat(S1, S2, ...)`` joins texts and
``num2str(x)`` writes a number as a text (15 significant digits, ``1e-05`` for small ones);
``strlen`` and ``substr`` count and cut a text by position; ``strupper``, ``strlower`` and
``strtrim`` are Excel's UPPER, LOWER and TRIM."""

from __future__ import annotations

import re

import numpy as np

from ..errors import DomainError, NotLive, NotSymbolic, TemplateError
from ..language import typed as ty
from ..language.expr import PREC
from ..limits import check_text_length
from .entry import Builtin, UnitContext, register


def _no_sympy(name: str):
    why = f"{name}() gives a text, which has no derivative"

    def convert(sp, *args):
        raise NotSymbolic(why)

    convert.refusal = why  # read by workbook.numerics.symbolic.refusal, without SymPy
    return convert


def _concat_unit(ctx: UnitContext, name: str, args: tuple) -> ty.T:
    for k, a in enumerate(args, 1):
        if not a.text or a.shape is not None:
            raise TemplateError(
                f"concat(): argument {k} is not a text; num2str(x) writes a number as one"
            )
    return ty.TFunc(ctx.dimensionless, func=name, args=tuple(args), text=True)


def _concat(*texts):
    if all(isinstance(t, str) for t in texts):
        check_text_length(sum(len(t) for t in texts), "concat()")
        return "".join(texts)
    return np.frompyfunc(lambda *parts: "".join(parts), len(texts), 1)(*texts)


def _num2str_unit(ctx: UnitContext, name: str, args: tuple) -> ty.T:
    (x,) = args
    if getattr(x, "kind", None) == "choice":  # a word, typed as a plain number
        raise TemplateError(f"num2str(x): '{x.name}' is a choice, not a number")
    if x.text or x.boolean or x.shape is not None:
        raise TemplateError("num2str(x): x must be a number")
    x = ctx.plain(x, "num2str(x): x (a value with a unit: divide it by the unit to write)")
    return ty.TFunc(ctx.dimensionless, func=name, args=(x,), text=True)


def number_text(x: float) -> str:
    """A number as num2str writes it: 15 significant digits, no trailing zeros."""
    return f"{float(x):.15g}"


def _num2str(x):
    if not np.all(np.isfinite(np.asarray(x, dtype=float))):  # never the text "inf" or "nan"
        raise DomainError("num2str(x): x is not a finite number, and has no text")
    if np.ndim(x) == 0:
        return number_text(x)
    return np.frompyfunc(number_text, 1, 1)(np.asarray(x, dtype=float))


def _concat_excel(args: list[str]) -> tuple[str, int]:
    return f"CONCATENATE({', '.join(args)})", PREC["atom"]


def _num2str_excel(args: list[str]) -> tuple[str, int]:
    raise NotLive("num2str: Excel writes numbers as texts with its own digits")


register(
    Builtin(
        "concat",
        (1, None),
        _concat_unit,
        _concat,
        _concat_excel,
        _no_sympy("concat"),
        doc="concat(S1, S2, ...): the texts joined (Mathcad's concat)",
        texts=True,
        mathcad=("concat",),
    )
)
register(
    Builtin(
        "num2str",
        1,
        _num2str_unit,
        _num2str,
        _num2str_excel,
        _no_sympy("num2str"),
        doc="num2str(x): the number x as a text, 15 significant digits (Mathcad's num2str)",
        texts=True,
        mathcad=("num2str",),
    )
)


def _text_arg(name: str, t, k: int):
    if not t.text or t.shape is not None:
        raise TemplateError(f"{name}(): argument {k} is not a text")


def _strlen_unit(ctx: UnitContext, name: str, args: tuple) -> ty.T:
    (s,) = args
    _text_arg(name, s, 1)
    return ty.TFunc(ctx.dimensionless, func=name, args=(s,))


def _substr_unit(ctx: UnitContext, name: str, args: tuple) -> ty.T:
    s, m, n = args
    _text_arg(name, s, 1)
    for k, a in ((2, m), (3, n)):
        if a.text or a.boolean or a.shape is not None:
            raise TemplateError(f"substr(S, m, n): argument {k} must be a number")
    m = ctx.plain(m, "substr(S, m, n): m (a position: a plain number)")
    n = ctx.plain(n, "substr(S, m, n): n (a count of characters: a plain number)")
    return ty.TFunc(ctx.dimensionless, func=name, args=(s, m, n), text=True)


def _characters(s) -> str:
    """The text, checked to count as Excel counts it (a character beyond U+FFFF is two for
    Excel, one here: refused, never another count)."""
    if not isinstance(s, str):
        raise DomainError("strlen/substr: the argument is not a text")
    if any(ord(ch) > 0xFFFF for ch in s):
        raise DomainError("strlen/substr: a character beyond U+FFFF, which Excel counts as two")
    return s


def _whole(x, what: str) -> int:
    v = float(x)
    if not np.isfinite(v) or v != int(v) or v < 0:
        raise DomainError(f"substr(S, m, n): {what} must be a whole number at least 0, got {v!r}")
    return int(v)


def _strlen_one(s) -> float:
    return float(len(_characters(s)))


def _substr_one(s, m, n) -> str:
    start = _whole(m, "m")
    return _characters(s)[start : start + _whole(n, "n")]


def _strlen(s):
    if isinstance(s, str):
        return _strlen_one(s)
    return np.frompyfunc(_strlen_one, 1, 1)(s).astype(float)


def _substr(s, m, n):
    if isinstance(s, str) and np.ndim(m) == 0 and np.ndim(n) == 0:
        return _substr_one(s, m, n)
    return np.frompyfunc(_substr_one, 3, 1)(s, m, n)


def _strlen_excel(args: list[str]) -> tuple[str, int]:
    return f"LEN({args[0]})", PREC["atom"]


def _substr_excel(args: list[str]) -> tuple[str, int]:
    return f"MID({args[0]}, ({args[1]}) + 1, {args[2]})", PREC["atom"]


register(
    Builtin(
        "strlen",
        1,
        _strlen_unit,
        _strlen,
        _strlen_excel,
        _no_sympy("strlen"),
        doc="strlen(S): the number of characters of the text S (Mathcad's strlen, Excel's LEN)",
        texts=True,
        mathcad=("strlen",),
    )
)
register(
    Builtin(
        "substr",
        3,
        _substr_unit,
        _substr,
        _substr_excel,
        _no_sympy("substr"),
        doc="substr(S, m, n): at most n characters of S from position m, the first 0 "
        "(Mathcad's substr; Excel's MID(S, m + 1, n))",
        texts=True,
        mathcad=("substr",),
    )
)


def _text_of_text_unit(ctx: UnitContext, name: str, args: tuple) -> ty.T:
    (s,) = args
    _text_arg(name, s, 1)
    return ty.TFunc(ctx.dimensionless, func=name, args=(s,), text=True)


def _ascii_letters(s) -> str:
    """The text, checked to hold no letter beyond ASCII (Excel's case of those is its own:
    ``ß``, ``ǅ``, dotted and dotless i)."""
    if not isinstance(s, str):
        raise DomainError("strupper/strlower: the argument is not a text")
    if any(ord(ch) > 127 and ch.isalpha() for ch in s):
        raise DomainError(
            "strupper/strlower: a letter beyond ASCII, whose case Excel may change otherwise"
        )
    return s


def _elementwise(one):
    def apply(s):
        if isinstance(s, str):
            return one(s)
        return np.frompyfunc(one, 1, 1)(s)

    return apply


def _trim_one(s) -> str:
    if not isinstance(s, str):
        raise DomainError("strtrim: the argument is not a text")
    return re.sub(" +", " ", s).strip(" ")


def _excel_of(function: str):
    def excel(args: list[str]) -> tuple[str, int]:
        return f"{function}({args[0]})", PREC["atom"]

    return excel


register(
    Builtin(
        "strupper",
        1,
        _text_of_text_unit,
        _elementwise(lambda s: _ascii_letters(s).upper()),
        _excel_of("UPPER"),
        _no_sympy("strupper"),
        doc="strupper(S): the text S in capitals (Excel's UPPER; a letter beyond ASCII is an "
        "error)",
        texts=True,
    )
)
register(
    Builtin(
        "strlower",
        1,
        _text_of_text_unit,
        _elementwise(lambda s: _ascii_letters(s).lower()),
        _excel_of("LOWER"),
        _no_sympy("strlower"),
        doc="strlower(S): the text S in small letters (Excel's LOWER; a letter beyond ASCII is "
        "an error)",
        texts=True,
    )
)
register(
    Builtin(
        "strtrim",
        1,
        _text_of_text_unit,
        _elementwise(_trim_one),
        _excel_of("TRIM"),
        _no_sympy("strtrim"),
        doc="strtrim(S): S without spaces at its ends, each run of spaces inside it one space "
        "(Excel's TRIM: the space only, not tabs or non-breaking spaces)",
        texts=True,
    )
)
