"""Excel's joins of texts (``&``, ``CONCATENATE``, ``CONCAT``) as the language's ``concat``.

Each piece keeps Excel's meaning or the formula is refused: a text is itself; a number is the
text Excel writes for it (General format: at most 15 significant digits, no exponent), which is
``num2str``'s text where the number is 0 or of size 0.0001 up to 1e15 — elsewhere (where Excel
writes ``1E-05`` or ``1E+15``) the piece is an error, never other digits; an empty cell is the
empty text. TRUE/FALSE (Excel writes ``TRUE``), a value whose kind (text or number) is not
known from the formula, and texts with line breaks (``CHAR(10)``) are refused."""

from __future__ import annotations

from .aggregates import AGGREGATES
from .criteria import FUNCTIONS as CRITERIA
from .formula_terms import FormulaProblem, Ref, text_problem
from .functions import EXCEL, EXCEL_VARIADIC

#: operators whose value is a number (their operands are numbers, or the sheet refuses them)
_NUMBER_OPS = {"+", "-", "*", "/", "^", "u-", "u+", "%"}
#: Excel functions (beyond EXCEL and AGGREGATES) whose value is a number
_NUMBER_FUNCTIONS = {"ROUND", "ABS", "MOD", "INT", "TRUNC", "LEN", *CRITERIA}
#: Excel's functions of a text: by position, as ``strlen`` and ``substr`` (the first 0), and
#: UPPER, LOWER, TRIM as ``strupper``, ``strlower``, ``strtrim``
TEXT_PARTS = ("LEN", "LEFT", "RIGHT", "MID", "UPPER", "LOWER", "TRIM")
#: at most this many pieces in one join
MAX_PIECES = 200


def join(ft, nodes: list) -> str:
    """``concat(...)`` of the pieces of the nodes (each an operand of ``&`` or an argument of
    CONCATENATE/CONCAT), translated by the formula translator ``ft``."""
    pieces: list[str] = []
    for node in nodes:
        _pieces(ft, node, pieces)
    if len(pieces) > MAX_PIECES:
        raise FormulaProblem(f"joins more than {MAX_PIECES} texts")
    if not pieces:
        return '""'
    return (
        pieces[0]
        if len(pieces) == 1 and pieces[0].startswith('"')
        else (f"concat({', '.join(pieces)})")
    )


def _pieces(ft, node, out: list[str]) -> None:
    kind, name, payload = node
    if kind == "op" and name == "&":
        for a in payload:
            _pieces(ft, a, out)
        return
    if kind == "fn" and name.upper() == "CONCATENATE":
        for a in payload:
            if a[0] == "leaf" and a[1] == "Range" and not ft.ref_of(a[2]).single:
                raise FormulaProblem("CONCATENATE of a range")
            _pieces(ft, a, out)
        return
    if kind == "fn" and name.upper() in ("_XLFN.CONCAT", "CONCAT"):
        for a in payload:
            if a[0] == "leaf" and a[1] == "Range" and not ft.is_name_formula(a[2]):
                ref = ft.ref_of(a[2])
                for r in range(ref.r1, ref.r2 + 1):
                    for c in range(ref.c1, ref.c2 + 1):
                        _cell_piece(ft, ref.sheet, r, c, out)
            else:
                _pieces(ft, a, out)
        return
    if kind == "leaf" and name == "String":
        if payload.name:
            out.append(ft.value(node))
        return
    if kind == "leaf" and name == "Number":
        if payload.name.upper() in ("TRUE", "FALSE"):
            raise FormulaProblem("joins TRUE/FALSE (Excel writes the word)")
        out.append(f'"{excel_number_text(float(payload.name))}"')
        return
    if kind == "leaf" and name == "Range" and not ft.is_name_formula(payload):
        ref = ft.ref_of(payload)
        if not ref.single:
            raise FormulaProblem("joins a range (Excel joins one cell of it, or spills)")
        _cell_piece(ft, ref.sheet, ref.r1, ref.c1, out, payload)
        return
    if (kind == "op" and name in ("=", "<>", "<", ">", "<=", ">=")) or (
        kind == "fn" and name.upper() in ("AND", "OR", "NOT", "TRUE", "FALSE")
    ):
        raise FormulaProblem("joins TRUE/FALSE (Excel writes the word)")
    if kind == "fn" and name.upper() == "CHAR":
        out.append(_char(ft, payload))
        return
    if kind == "fn" and name.upper() in TEXT_PARTS[1:]:
        out.append(ft.value(node))
        return
    if _is_number(node):
        out.append(number_piece(ft.value(node, 0)))
        return
    raise FormulaProblem("joins a value whose kind (a text or a number) the formula does not show")


def _cell_piece(ft, sheet: str, row: int, col: int, out: list[str], token=None) -> None:
    """One cell of a join: its text, the text of its number, or nothing when empty."""
    cell = ft.book.cell(sheet, row, col)
    value = None if cell is None else cell.value
    if value is None or value == "":
        if cell is not None and cell.formula is not None:
            raise FormulaProblem("joins a formula cell that shows the empty text")
        return  # an empty cell joins as the empty text
    if isinstance(value, bool):
        raise FormulaProblem("joins TRUE/FALSE (Excel writes the word)")
    if token is not None:
        name = ft.reference(token)
    else:
        ft.out.refs.append(Ref(sheet, row, col, row, col))
        name = ft.name_of(sheet, row, col)
    if isinstance(value, str):
        if value.startswith("#") and cell.formula is not None:
            raise FormulaProblem("joins a cell that shows an error value")
        out.append(name)
    elif isinstance(value, (int, float)):
        out.append(number_piece(name))
    else:
        raise FormulaProblem(f"joins a {type(value).__name__}")


def _is_number(node) -> bool:
    kind, name, payload = node
    if kind == "op":
        return name in _NUMBER_OPS
    if kind == "fn":
        upper = name.upper()
        return (
            upper in EXCEL
            or upper in AGGREGATES
            or upper in EXCEL_VARIADIC
            or (upper in _NUMBER_FUNCTIONS)
        )
    return False


def _char(ft, args) -> str:
    """``CHAR(n)`` of a number written in the formula, a printable ASCII character."""
    if len(args) != 1 or args[0][0] != "leaf" or args[0][1] != "Number":
        raise FormulaProblem("CHAR of other than a number written in the formula")
    n = float(args[0][2].name)
    if n != int(n) or not 32 <= n <= 126:
        raise FormulaProblem(f"CHAR({args[0][2].name}) (a line break or other than ASCII)")
    text = chr(int(n))
    problem = text_problem(text)
    if problem:
        raise FormulaProblem(problem)
    return f'"{text}"'


def number_piece(expr: str) -> str:
    """The text Excel writes for the number ``expr`` when it joins it, as the language
    computes it: ``num2str`` where that is Excel's text, an error elsewhere."""
    x = f"({expr})"
    return (
        f"num2str((0 if {x} == 0 otherwise ({x} if abs({x}) >= 0.0001 and abs({x}) < 1e15 "
        f"otherwise 1/0)))"
    )


def excel_number_text(x: float) -> str:
    """The text Excel writes for a number written in a join's formula (General format)."""
    if x == 0:
        return "0"
    if not 1e-4 <= abs(x) < 1e15:
        raise FormulaProblem(f"joins the number {x!r}, which Excel writes with an exponent")
    return f"{x:.15g}"


def text_part(ft, upper: str, args) -> str:
    """``LEN(s)``, ``LEFT(s[, n])``, ``RIGHT(s[, n])``, ``MID(s, k, n)``, ``UPPER(s)``,
    ``LOWER(s)`` and ``TRIM(s)`` of a text (of a number Excel takes the text it displays, which
    the formula does not show: refused), as ``strlen``, ``substr``, ``strupper``, ``strlower``
    and ``strtrim``: MID's first character is 1, substr's 0, and a position or count that is no
    whole number at least 0 is an error (Excel's #VALUE! below 1 or 0)."""
    from .kinds import kind

    arities = {"LEFT": (1, 2), "RIGHT": (1, 2), "MID": (3,)}
    if len(args) not in arities.get(upper, (1,)):
        raise FormulaProblem(f"{upper} with {len(args)} arguments")
    if kind(ft, args[0]) != "text":
        raise FormulaProblem(
            f"{upper} of other than a text (of a number, Excel's text of its display)"
        )
    s = ft.value(args[0], 0)
    if upper in ("LEN", "UPPER", "LOWER", "TRIM"):
        short = {"LEN": "len", "UPPER": "upper", "LOWER": "lower", "TRIM": "trim"}[upper]
        return f"str{short}({s})"
    n = ft.value(args[-1], 0) if len(args) > 1 else "1"
    if upper == "LEFT":
        return f"substr({s}, 0, {n})"
    if upper == "RIGHT":
        return f"substr({s}, max(strlen({s}) - ({n}), 0), {n})"
    return f"substr({s}, ({ft.value(args[1], 3)}) - 1, {n})"
