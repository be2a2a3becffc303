"""Texts beside numbers in cell formulas, with Excel's rules, where the language keeps one kind
of value per definition and compares a text only with a text.

What kind of value a part of a formula gives (a number, a text, an empty cell, TRUE/FALSE) is
read from the formula and from the cells it reads (a constant's own value, a formula cell's
cached value: its translation gives that kind or has no value). Then:

- a comparison of a number with a text is Excel's: never equal, and a number orders before
  any text (``=5<"a"`` is TRUE); it is written so that the number is still computed
  (``x*0 == 1`` is false, and an error of x stays an error);
- an empty cell (an input 0, as Excel reads it in arithmetic) equals ``""``: ``A4=""`` is
  ``A4 == 0``;
- texts compare without case in Excel: two texts that never change are compared here, and a
  computed text only with a text without letters (``""``, ``"-"``); else the cell is listed;
- ``IF(c, "", a-b)`` whose branches are a text and a number: the value has the kind of
  Excel's cached value (of every row of a filled-down column), and the other branch is an
  error value, so where the condition turns the other way the cell has no value, never a
  value of another kind.
"""

from __future__ import annotations

from .formula_terms import FormulaProblem, row_relative, text_problem

NUMBER_FUNCTIONS = {
    "ABS", "SQRT", "EXP", "LN", "LOG10", "LOG", "SIN", "COS", "TAN", "ASIN", "ACOS", "ATAN",
    "ATAN2", "SINH", "COSH", "TANH", "SIGN", "PI", "POWER", "RADIANS", "DEGREES", "INT",
    "TRUNC", "ROUND", "MOD", "MAX", "MIN", "SUM", "AVERAGE", "COUNT", "PRODUCT", "MEDIAN",
    "STDEV", "STDEVP", "VAR", "VARP", "SUMSQ", "_XLFN.STDEV.S", "_XLFN.STDEV.P",
    "_XLFN.VAR.S", "_XLFN.VAR.P", "CONVERT", "MATCH", "SUMIF", "COUNTIF", "MMULT", "SUMIFS",
    "COUNTIFS", "AVERAGEIF", "AVERAGEIFS", "LEN",
}  # fmt: skip
TEXT_FUNCTIONS = {
    "CONCATENATE", "CONCAT", "_XLFN.CONCAT", "CHAR", "LEFT", "RIGHT", "MID", "UPPER", "LOWER",
    "TRIM",
}  # fmt: skip
_ORDER = {"=", "<>", "<", "<=", ">", ">="}
#: the error value of each kind, in the language (a definition has one kind)
_ERROR = {"number": "1/0", "text": "num2str(1/0)"}


def cell_kind(cell) -> str | None:
    """The kind of a cell's value: a constant's own, a formula cell's cached one."""
    if cell is None or (cell.value is None and cell.formula is None):
        return "empty"
    v = cell.value
    if v is None:
        return None  # a formula whose cached value is empty: "" or nothing, unknown
    if isinstance(v, bool):
        return "bool"
    if isinstance(v, (int, float)):
        return "number"
    if isinstance(v, str):
        if cell.formula is not None and v.startswith("#"):
            return "error"
        return "text"
    return None


_DEPTH = 12  # formula cells followed, one reading another, to find what kind one gives


def _formula_kind(ft, cell, depth: int) -> str | None:
    """The kind a formula cell gives where Excel cached no value ("" is cached so): read from
    its formula."""
    key = (cell.sheet, cell.row, cell.col)
    memo = _memo(ft, "kinds")
    if key in memo:
        return memo[key]
    tree = getattr(ft.book, "trees", {}).get(key)
    if tree is None or depth > _DEPTH or cell.array is not None:
        return None
    memo[key] = None  # a formula that reads itself gives no kind
    try:
        memo[key] = kind(cell_reader(ft, cell.sheet), tree, depth + 1)
    except FormulaProblem:
        pass
    return memo[key]


def _memo(ft, what: str) -> dict:
    """What was found of the formula cells (their kinds, their texts), once per workbook."""
    memos = ft.book.__dict__.setdefault("kind_memos", {})
    return memos.setdefault(what, {})


def cell_reader(ft, sheet: str):
    """A translator of another cell's formula, to read its parts' kinds and texts."""
    # the translator's own class (cells.py imports this module)
    return type(ft)(ft.book, sheet, lambda *_: "x", ft.functions, ft.defined, seen=set())


def cell_kind_in(ft, cell, depth: int) -> str | None:
    found = cell_kind(cell)
    if found is None and cell is not None and cell.formula is not None:
        return _formula_kind(ft, cell, depth) or _empty_text(ft)
    return found


def _empty_text(ft) -> str | None:
    """The kind of a formula cell without a cached value: Excel caches a value for every
    formula it computed, none for "" (as openpyxl reads it); in a workbook saved before Excel
    finished calculating, unknown."""
    return None if getattr(ft.book, "stale", True) else "text"


def _seen(ft) -> set:
    """The kinds of Excel's cached values of the cells the formula computes."""
    seen = set(ft.seen or ())
    if None in seen:
        seen.discard(None)
        seen.add(_empty_text(ft))
    return seen - {"error", None}


def kind(ft, node, depth: int = 0) -> str | None:
    """The kind of value ``node`` gives: "number", "text", "empty", "bool", or None."""
    what, name, payload = node
    if what == "leaf":
        if name == "Number":
            return "bool" if payload.name.upper() in ("TRUE", "FALSE") else "number"
        if name == "String":
            return "text"
        if name == "Range" and not ft.is_name_formula(payload):
            ref = ft.ref_of(payload)
            if not ref.single:
                return None

            key = (ref.sheet, ref.r1, ref.c1)
            if key in ft.moving and row_relative(payload):  # each row of a filled-down column
                kinds = {
                    cell_kind_in(ft, ft.book.cell(ref.sheet, ref.r1 + k, ref.c1), depth)
                    for k in range(ft.rows)
                }
                if len(kinds) > 1:
                    kinds.discard("error")
            else:
                kinds = {cell_kind_in(ft, ft.book.cell(*key), depth)}
            return kinds.pop() if len(kinds) == 1 and "error" not in kinds else None
        return None
    if what == "op":
        if name in ("+", "-", "*", "/", "^", "u-", "u+", "%"):
            return "number"
        if name == "&":
            return "text"
        return "bool" if name in _ORDER else None
    upper = name.upper()
    if upper == "IF" and len(payload) == 3:
        a, b = kind(ft, payload[1], depth), kind(ft, payload[2], depth)
        if a == b:
            return a
        seen = _seen(ft)
        if id(node) in ft.tails and len(seen) == 1 and seen <= {"number", "text"}:
            return seen.pop()  # its value is of the kind Excel's cached value is
        return None
    if upper in ("ISBLANK", "ISNUMBER", "ISTEXT", "ISNONTEXT", "ISLOGICAL", "ISERROR", "ISERR"):
        return "bool"
    if upper in NUMBER_FUNCTIONS:
        return "number"
    if upper in TEXT_FUNCTIONS:
        return "text"
    return None


def static_text(ft, node) -> str | None:
    """A text written in the formula, or held by a constant text cell (a definition that
    never changes); None otherwise."""
    what, name, payload = node
    if what == "leaf" and name == "String":
        return payload.name
    if what == "leaf" and name == "Range" and not ft.is_name_formula(payload):
        ref = ft.ref_of(payload)
        if ref.single and (ref.sheet, ref.r1, ref.c1) not in ft.moving:
            cell = ft.book.cell(ref.sheet, ref.r1, ref.c1)
            if cell is not None and cell.formula is None and isinstance(cell.value, str):
                problem = text_problem(cell.value)
                if problem:  # never a stand-in: the formula is listed
                    raise FormulaProblem(f"reads {cell.ref}: {problem}")
                return cell.value
    return None


def texts_of(ft, node, depth: int = 0) -> set[str] | None:
    """Every text ``node`` can give, where they are texts written in formulas or held by
    constant cells (``IF(G9>4000,"TURBULENT","LAMINAR")``, or a cell that holds such a
    formula); None where a text is computed otherwise."""
    what, name, payload = node
    if depth > _DEPTH:
        return None
    if what == "leaf" and name == "String":
        return {payload.name}
    if what == "leaf" and name == "Range" and not ft.is_name_formula(payload):
        ref = ft.ref_of(payload)
        if not ref.single:
            return None

        rows = ft.rows if (ref.sheet, ref.r1, ref.c1) in ft.moving and row_relative(payload) else 1
        if rows > 50:
            return None
        out: set[str] = set()
        for k in range(rows):
            cell = ft.book.cell(ref.sheet, ref.r1 + k, ref.c1)
            if cell is None or cell.formula is None:
                if cell is None or not isinstance(cell.value, str) or text_problem(cell.value):
                    return None
                out.add(cell.value)
                continue
            key = (cell.sheet, cell.row, cell.col)
            memo = _memo(ft, "texts")
            if key not in memo:
                tree = getattr(ft.book, "trees", {}).get(key)
                memo[key] = None
                if tree is not None and cell.array is None:
                    memo[key] = texts_of(cell_reader(ft, cell.sheet), tree, depth + 1)
            if memo[key] is None:
                return None
            out |= memo[key]
        return out
    if what == "fn" and name.upper() == "IF" and len(payload) == 3:
        out = set()
        for branch in payload[1:]:
            k = kind(ft, branch, depth)
            if k == "number":
                continue  # an error value where the IF gives a text (if_of_kinds)
            found = texts_of(ft, branch, depth + 1) if k == "text" else None
            if found is None:
                return None
            out |= found
        return out
    return None


def never_a_number(ft, node) -> bool:
    """Whether ``node`` gives a text that Excel never reads as a number in arithmetic (a text
    without a digit, ``""``, ``"-"``, ``"LAMINAR"``: ``=""*2`` is #VALUE!); a text with a digit
    may be one (``"5"``, ``"1e3"``, ``"50%"``, a date), by rules of Excel's own."""
    try:
        if kind(ft, node) != "text":
            return False
        texts = texts_of(ft, node)
    except FormulaProblem:
        return False
    return texts is not None and not any(ch.isdigit() for t in texts for ch in t)


def _caseless(text: str | None) -> bool:
    return text is not None and text.lower() == text.upper()


def compared(ft, op: str, args) -> str | None:
    """The condition of a comparison that involves a text, by Excel's rules; None where the
    plain comparison of the language is Excel's (numbers, or a text without letters)."""
    ka, kb = kind(ft, args[0]), kind(ft, args[1])
    if "text" not in (ka, kb):
        return None
    truths = {"1 == 1": True, "1 == 0": False}
    if ka == kb == "text":
        sa, sb = static_text(ft, args[0]), static_text(ft, args[1])
        if op not in ("=", "<>"):
            raise FormulaProblem("an ordering of texts (Excel orders them by rules of its own)")
        if sa is not None and sb is not None:
            for a in args:
                ft.value(a, 3)  # the cells it reads are read
            same = sa.casefold() == sb.casefold()
            return next(t for t, v in truths.items() if v == (same == (op == "=")))
        if _caseless(sa) or _caseless(sb):
            return None
        for known, node in ((sb, args[0]), (sa, args[1])):
            found = None if known is None else texts_of(ft, node)
            if found is None:
                continue
            matches = sorted(t for t in found if t.casefold() == known.casefold())
            if any(text_problem(t) for t in matches + [known]):
                break
            x = ft.value(node, 3)
            if not matches:  # no text it gives equals the other, with case or without
                return f'{x} {"==" if op == "=" else "!="} "{known}"'
            same = " or ".join(f'{x} == "{t}"' for t in matches)
            return same if op == "=" else f"not ({same})"
        raise FormulaProblem("a comparison of texts (Excel's = does not tell case apart)")
    text_first = ka == "text"
    other, ko = (args[1], kb) if text_first else (args[0], ka)
    text = static_text(ft, args[0] if text_first else args[1])
    if ko is None:
        if _caseless(text):
            return None  # the language compares it (and refuses a number beside a text)
        raise FormulaProblem("a comparison of a text with a value of unknown kind")
    if ko == "bool":
        raise FormulaProblem("a comparison of TRUE/FALSE with a text")
    x = ft.value(other, 4)
    if ko == "empty":
        if op not in ("=", "<>") or text is None:
            raise FormulaProblem("a comparison of an empty cell with a text")
        if text == "":
            return f"{x} == 0" if op == "=" else f"{x} != 0"
        return f"{x}*0 == 1" if op == "=" else f"{x}*0 == 0"
    if ko != "number":
        return None
    number_first = not text_first
    truth = {
        "=": False,
        "<>": True,
        "<": number_first,
        "<=": number_first,
        ">": not number_first,
        ">=": not number_first,
    }[op]
    if not text_first or text is None:
        ft.value(args[0] if text_first else args[1], 3)  # the text's cells are read
    return f"{x}*0 == 0" if truth else f"{x}*0 == 1"


def if_of_kinds(ft, node) -> str:
    """``IF(c, a, b)``; where a and b are of two kinds, the one of Excel's cached value(s),
    the other branch an error value."""
    _, name, args = node
    if len(args) != 3:
        raise FormulaProblem("IF without a value for FALSE")
    tail = id(node) in ft.tails
    if tail:
        ft.tails.update((id(args[1]), id(args[2])))
    ka, kb = kind(ft, args[1]), kind(ft, args[2])
    mixed = ka != kb and {ka, kb} <= {"number", "text"}
    if not mixed:
        return ft.function(name, args)
    seen = _seen(ft)
    if not tail or len(seen) != 1 or not seen <= {"number", "text"}:
        raise FormulaProblem(
            "IF whose value is a text on one side and a number on the other (a definition of "
            "the language has one kind of value)"
        )
    (want,) = seen
    cond = ft.condition(args[0])
    a = ft.value(args[1], 1) if ka == want else _ERROR[want]
    b = ft.value(args[2], 1) if kb == want else _ERROR[want]
    return f"({a} if {cond} otherwise {b})"
