"""The Excel back end: print a typed tree as a live Excel formula.

One method per node kind, in the style of SymPy's code printers. Function calls
are inlined (Excel has no user functions without macros); inputs and scalar
definitions are referred to by defined names.
"""

from __future__ import annotations

import re

from . import typecheck as tc

MAX_FORMULA = 8192  # Excel's limit on formula length

_CELL = re.compile(r"^[A-Za-z]{1,3}[0-9]+$")
_R1C1 = re.compile(r"^([Rr][0-9]*)?([Cc][0-9]*)?$")
# Excel function names that a defined name must not shadow (LibreOffice reads
# some of them without brackets), plus the boolean literals.
_RESERVED = {
    "pi",
    "e",
    "true",
    "false",
    "sin",
    "cos",
    "tan",
    "asin",
    "acos",
    "atan",
    "atan2",
    "sqrt",
    "exp",
    "ln",
    "log",
    "log10",
    "abs",
    "sign",
    "int",
    "min",
    "max",
    "if",
    "and",
    "or",
    "not",
    "na",
    "sum",
    "rand",
    "row",
    "column",
    "index",
    "degrees",
    "radians",
    "power",
    "mod",
}


class NotLive(Exception):
    """The expression cannot be a live Excel formula (a solver block, or too long)."""


def excel_name(name: str) -> str:
    """A defined name Excel and LibreOffice will not read as a cell reference or function."""
    if _CELL.match(name) or _R1C1.match(name) or name.lower() in _RESERVED or len(name) == 1:
        return name + "_"
    return name


def number(value: float) -> str:
    if value != value or value in (float("inf"), float("-inf")):
        raise NotLive(f"{value} cannot be written in a formula")
    if float(value).is_integer() and abs(value) < 1e15:
        return str(int(value))
    return repr(float(value)).replace("e", "E")


_FUNCS = {
    "sin": "SIN",
    "cos": "COS",
    "tan": "TAN",
    "asin": "ASIN",
    "acos": "ACOS",
    "atan": "ATAN",
    "sinh": "SINH",
    "cosh": "COSH",
    "tanh": "TANH",
    "sqrt": "SQRT",
    "exp": "EXP",
    "ln": "LN",
    "log10": "LOG10",
    "abs": "ABS",
    "sign": "SIGN",
    "min": "MIN",
    "max": "MAX",
}
_CMP = {"<": "<", "<=": "<=", ">": ">", ">=": ">=", "==": "=", "!=": "<>"}

ATOM, POW, MUL, ADD, CMP = 6, 4, 3, 2, 1


class ExcelPrinter:
    """Prints typed trees of one sheet; ``subst`` maps parameters to cell references."""

    def __init__(self, typer: tc.Typer, names: dict[str, str] | None = None):
        self.typer = typer
        self.names = names or {}
        # (table, column) -> absolute cell range, filled by the writer for max_over()/min_over()
        self.ranges: dict[tuple[str, str], str] = {}

    def formula(self, t: tc.T, subst: dict[str, str]) -> str:
        text = "=" + self.print(t, subst)
        if len(text) > MAX_FORMULA:
            raise NotLive(f"formula is {len(text)} characters long (Excel's limit {MAX_FORMULA})")
        return text

    def print(self, t: tc.T, subst: dict[str, str]) -> str:
        return self._p(t, subst)[0]

    def _wrap(self, t, subst, level: int) -> str:
        text, own = self._p(t, subst)
        return f"({text})" if own <= level else text

    def _p(self, t: tc.T, s: dict[str, str]) -> tuple[str, int]:
        method = getattr(self, "_print_" + type(t).__name__)
        return method(t, s)

    def _print_TConst(self, t, s):
        text = number(t.value)
        return text, (ADD if text.startswith("-") else ATOM)

    def _print_TText(self, t, s):
        return '"' + t.value.replace('"', '""') + '"', ATOM

    def _print_TParam(self, t, s):
        return s[t.name], ATOM

    def _print_TRef(self, t, s):
        if t.kind == "builtin":
            return "PI()", ATOM
        return self.names.get(t.name, excel_name(t.name)), ATOM

    def _print_TScale(self, t, s):
        if t.factor == 1.0:
            return self._p(t.child, s)
        return f"{self._wrap(t.child, s, MUL - 1)}*{number(t.factor)}", MUL

    def _print_TUnary(self, t, s):
        if t.op == "not":
            return f"NOT({self.print(t.child, s)})", ATOM
        # Excel's negation binds tighter than ^: -x^2 is (-x)^2 there, so bracket all but atoms.
        return "-" + self._wrap(t.child, s, ATOM - 1), ADD

    def _print_TBinary(self, t, s):
        if t.op == "^":
            return f"{self._wrap(t.left, s, POW)}^{self._wrap(t.right, s, POW)}", POW
        level = ADD if t.op in "+-" else MUL
        left = self._wrap(t.left, s, level - 1)
        right = self._wrap(t.right, s, level)  # a-(b-c), a/(b*c)
        return f"{left}{t.op}{right}", level

    def _print_TCompare(self, t, s):
        parts = [self._wrap(o, s, CMP) for o in t.operands]
        pairs = [f"{a}{_CMP[op]}{b}" for a, op, b in zip(parts, t.ops, parts[1:])]
        if len(pairs) == 1:
            return pairs[0], CMP
        return f"AND({', '.join(pairs)})", ATOM

    def _print_TLogic(self, t, s):
        return f"{t.op.upper()}({', '.join(self.print(v, s) for v in t.values)})", ATOM

    def _print_TFunc(self, t, s):
        args = [self.print(a, s) for a in t.args]
        if t.func == "atan2":  # Excel's ATAN2 takes (x, y)
            return f"ATAN2({args[1]}, {args[0]})", ATOM
        if t.func == "floor":
            return f"INT({args[0]})", ATOM
        if t.func == "ceil":
            return f"-INT(-({args[0]}))", ADD
        return f"{_FUNCS[t.func]}({', '.join(args)})", ATOM

    def _print_TCall(self, t, s):
        f = self.typer.function(t.name)
        inner = {p: self._wrap(a, s, ATOM - 1) for p, a in zip(f.params, t.args)}
        return self._p(f.body, inner)

    def _print_TBlock(self, t, s):
        raise NotLive(f"{t.name}() is a solver block ({t.ref}); its values are written as numbers")

    def _print_TAggregate(self, t, s):
        ref = self.ranges.get((t.table, t.column))
        if ref is None:
            raise NotLive(
                f"{t.func}_over({t.table}, {t.column}) needs the cell range of that column, "
                "which this writer does not register"
            )
        return f"{t.func.upper()}({ref})", ATOM

    def _print_TPiecewise(self, t, s):
        tail = "NA()"
        for cond, val in reversed(list(zip(t.conditions, t.values))):
            v = self.print(val, s)
            tail = v if cond is None else f"IF({self.print(cond, s)}, {v}, {tail})"
        return tail, ATOM
