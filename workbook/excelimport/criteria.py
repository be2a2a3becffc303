"""Excel's functions of criteria: ``SUMIF``, ``SUMIFS``, ``COUNTIF``, ``COUNTIFS``,
``AVERAGEIF`` and ``AVERAGEIFS``, one rule for all.

A criterion is a comparison with a number (``"<0"``, ``">=2.5"``, ``3``, or a constant number
cell) or a text that never changes (``"DL"``, ``"<>DL"``, or a constant text cell, without a
pattern ``* ? ~``). Which cells of a criteria range match is Excel's rule:

- a comparison with a number is live on a cell that holds a number (a constant or a formula
  that gives a number): ``(X if X < 0 otherwise 0)``; a constant text never matches it, but
  ``<>`` matches every text; an empty cell, TRUE/FALSE and a text that reads as a number (which
  Excel compares as that number) are refused;
- a text matches a text equal to it without case, found here (the texts never change: constant
  cells, or plain references to them, ``=D63``); a number or an empty cell never equals a text
  and always differs from it;
- ``"<>"`` alone matches every cell that is not empty: a constant, or a formula that gives a
  number (one that gives a text may give the empty text: refused).

SUMIF adds the matching cells of the sum range that hold numbers (an empty cell, a text or
TRUE/FALSE adds nothing); a formula cell of the sum range that gives other than a number is
refused. AVERAGEIF divides that sum by the count of those cells (none: #DIV/0!, an error).
"""

from __future__ import annotations

import re

from .formula_terms import FormulaProblem, Ref

_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_OPS = {"<>": "!=", "=": "==", "": "==", "<": "<", ">": ">", "<=": "<=", ">=": ">="}

#: terms at most in one translation (each a cell that may match)
MAX_TERMS = 200

#: the functions of criteria this module translates (each cell's formula on its own: what a
#: criterion matches is found when the cell is translated)
FUNCTIONS = ("SUMIF", "SUMIFS", "COUNTIF", "COUNTIFS", "AVERAGEIF", "AVERAGEIFS")


def criteria_function(ft, upper: str, args) -> str:
    """The translation of ``upper`` (one of :data:`FUNCTIONS`) of the parsed ``args``."""
    n = len(args)
    if upper == "SUMIF" or upper == "AVERAGEIF":
        if n not in (2, 3):
            raise FormulaProblem(f"{upper} with {n} arguments")
        pairs = [(args[0], args[1])]
        values = args[2] if n == 3 else args[0]
    elif upper == "COUNTIF":
        if n != 2:
            raise FormulaProblem(f"COUNTIF with {n} arguments")
        pairs, values = [(args[0], args[1])], None
    elif upper == "COUNTIFS":
        if n < 2 or n % 2:
            raise FormulaProblem(f"COUNTIFS with {n} arguments")
        pairs, values = [(args[k], args[k + 1]) for k in range(0, n, 2)], None
    else:  # SUMIFS, AVERAGEIFS: the range of values first
        if n < 3 or n % 2 == 0:
            raise FormulaProblem(f"{upper} with {n} arguments")
        pairs, values = [(args[k], args[k + 1]) for k in range(1, n, 2)], args[0]
    refs = [_range(ft, upper, where) for where, _ in pairs]
    tests = [_criterion(ft, upper, crit) for _, crit in pairs]
    total = None if values is None else _range(ft, upper, values)
    shape = _shape(refs[0])
    if any(_shape(r) != shape for r in refs[1:]) or (total and _shape(total) != shape):
        raise FormulaProblem(f"{upper} whose ranges differ in size (#VALUE! in Excel)")
    sums, counts = [], []
    for dr in range(shape[0] + 1):
        for dc in range(shape[1] + 1):
            conditions = []
            for ref, test in zip(refs, tests):
                found = _matches(ft, upper, ref.sheet, ref.r1 + dr, ref.c1 + dc, test)
                if found is False:
                    conditions = None
                    break
                if found is not True:
                    conditions.append(found)
            if conditions is None:
                continue
            cond = " and ".join(dict.fromkeys(conditions))
            if total is None:
                counts.append(f"(1 if {cond} otherwise 0)" if cond else "1")
                continue
            name = _value(ft, upper, total.sheet, total.r1 + dr, total.c1 + dc)
            if name is None:
                continue  # no number: nothing added, nothing counted
            sums.append(f"({name} if {cond} otherwise 0)" if cond else name)
            counts.append(f"(1 if {cond} otherwise 0)" if cond else "1")
    if len(counts) > MAX_TERMS:
        raise FormulaProblem(f"{upper} over more than {MAX_TERMS} cells that may match")
    count = "(" + " + ".join(counts) + ")" if counts else "0"
    if total is None:
        return count
    total_text = "(" + " + ".join(sums) + ")" if sums else "0"
    if upper.startswith("AVERAGE"):
        return f"({total_text}/{count})" if counts else "(1/0)"  # of none: #DIV/0!
    return total_text


def _shape(ref: Ref) -> tuple[int, int]:
    return (ref.r2 - ref.r1, ref.c2 - ref.c1)


def _range(ft, upper: str, node) -> Ref:
    if node[0] != "leaf" or node[1] != "Range" or ft.is_name_formula(node[2]):
        raise FormulaProblem(f"{upper} of other than cell ranges")
    return ft.ref_of(node[2])


def _criterion(ft, upper: str, node) -> tuple:
    """("number", op, text of the number) or ("text", op, folded text), op "==" or "!=" for a
    text."""
    kind, name, payload = node
    if kind == "leaf" and name == "Number":
        if payload.name.upper() in ("TRUE", "FALSE"):
            raise FormulaProblem(f"{upper} whose criterion is TRUE/FALSE")
        return ("number", "==", repr(float(payload.name)))
    if kind == "op" and name == "u-" and payload[0][0] == "leaf" and payload[0][1] == "Number":
        return ("number", "==", repr(-float(payload[0][2].name)))
    if kind == "leaf" and name == "String":
        return _written(upper, payload.name)
    if kind == "leaf" and name == "Range" and not ft.is_name_formula(payload):
        ref = ft.ref_of(payload)
        if not ref.single:
            raise FormulaProblem(f"{upper} whose criterion is a range")
        cell = ft.book.cell(ref.sheet, ref.r1, ref.c1)
        value = None if cell is None else cell.value
        if cell is not None and cell.formula is not None:
            from .kinds import cell_kind_in

            if cell_kind_in(ft, cell, 0) != "number":
                raise FormulaProblem(f"{upper} whose criterion is a formula that gives no number")
            ft.out.refs.append(Ref(ref.sheet, ref.r1, ref.c1, ref.r1, ref.c1))
            return ("number", "==", ft.name_of(ref.sheet, ref.r1, ref.c1))
        if cell is None or value is None:
            raise FormulaProblem(f"{upper} whose criterion is an empty cell")
        if isinstance(value, bool):
            raise FormulaProblem(f"{upper} whose criterion is TRUE/FALSE")
        if isinstance(value, (int, float)):
            ft.out.refs.append(Ref(ref.sheet, ref.r1, ref.c1, ref.r1, ref.c1))
            return ("number", "==", ft.name_of(ref.sheet, ref.r1, ref.c1))
        if isinstance(value, str):
            if value.strip() != value or re.match(r"[=<>]", value):
                raise FormulaProblem(f"{upper} whose criterion {value!r} is an operator or spaced")
            return _written(upper, value)
    raise FormulaProblem(f"{upper} whose criterion is other than a number, a text or a cell")


def _written(upper: str, text: str) -> tuple:
    """The criterion of a text as Excel reads it: an operator, then a number or a text."""
    m = re.fullmatch(r"(<>|<=|>=|=|<|>)?(.*)", text, re.S)
    op, rest = m.group(1) or "", m.group(2)
    if text == "<>":  # Excel's "not empty"
        return ("filled", "!=", "")
    if re.fullmatch(r"\s*" + _NUMBER + r"\s*", rest):
        return ("number", _OPS[op], repr(float(rest)))
    if not rest or re.search(r"[*?~]", rest) or rest.strip() != rest:
        raise FormulaProblem(f"{upper} whose criterion {text!r} is a pattern or an operator")
    if op not in ("", "=", "<>"):
        raise FormulaProblem(f"{upper} whose criterion {text!r} orders texts")
    if _reads_as_number(rest):
        raise FormulaProblem(f"{upper} whose criterion {text!r} reads as a number")
    return ("text", _OPS[op], rest.casefold())


def _reads_as_number(text: str) -> bool:
    """Whether Excel may read the text as a number: a number, or digits with the marks of a
    date, a time, a percentage, a currency or a fraction, or beside a month's name or am/pm
    (``W1``, ``E2`` are texts)."""
    try:
        float(text)
    except ValueError:
        pass
    else:
        return True
    if not re.search(r"\d", text):
        return False
    if re.fullmatch(r"[\d\s.,:/%$+\-()]+", text):
        return True
    months = r"jan|feb|mar|apr|may|jun|jul|aug|sep|oct|nov|dec|am|pm|a|p"
    return bool(re.search(rf"(?<![a-z])({months})[a-z]*(?![a-z])", text, re.I)) and bool(
        re.fullmatch(r"[\w\s.,:/%$+\-()]+", text)
    )


def _matches(ft, upper: str, sheet: str, row: int, col: int, test: tuple):
    """True or False where the cell's match never changes, else the condition (a text)."""
    what, op, rhs = test
    if what == "filled":  # "<>": a cell that is not empty
        cell = ft.book.cell(sheet, row, col)
        if cell is None or cell.formula is None:
            return cell is not None and cell.value is not None and cell.value != ""
        from .kinds import cell_kind_in

        if cell_kind_in(ft, cell, 0) != "number":  # a formula may give the empty text
            raise FormulaProblem(f'{upper} "<>" over a formula that gives no number')
        return True
    if what == "text":
        value = ft.constant_behind(sheet, row, col)
        same = isinstance(value, str) and value.casefold() == rhs
        return same if op == "==" else not same
    from .kinds import cell_kind_in

    cell = ft.book.cell(sheet, row, col)
    if cell is None or (cell.formula is None and (cell.value is None or cell.value == "")):
        raise FormulaProblem(f"{upper} over an empty cell")
    if cell.formula is None:
        value = cell.value
        if isinstance(value, bool):
            raise FormulaProblem(f"{upper} over a cell that holds TRUE/FALSE")
        if isinstance(value, str):
            if _reads_as_number(value.strip()):
                raise FormulaProblem(f"{upper} over a text that reads as a number")
            return op == "!="  # a text never equals a number and differs from it
    elif cell_kind_in(ft, cell, 0) != "number":
        raise FormulaProblem(f"{upper} over a formula that gives no number")
    ft.out.refs.append(Ref(sheet, row, col, row, col))
    return f"{ft.name_of(sheet, row, col)} {op} {rhs}"


def _value(ft, upper: str, sheet: str, row: int, col: int) -> str | None:
    """The name of a cell of the range of values, None where it adds nothing."""
    from .kinds import cell_kind_in

    cell = ft.book.cell(sheet, row, col)
    if cell is None or (cell.formula is None and not _number(cell.value)):
        return None  # empty, a text or TRUE/FALSE: not added, not counted
    if cell.formula is not None and cell_kind_in(ft, cell, 0) != "number":
        raise FormulaProblem(f"{upper} of a formula cell that gives no number")
    ft.out.refs.append(Ref(sheet, row, col, row, col))
    return ft.name_of(sheet, row, col)


def _number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)
