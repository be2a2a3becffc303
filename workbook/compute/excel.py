"""The Excel back end: print a typed tree as a live Excel formula.

One method per node kind, in the style of SymPy's code printers. Function calls
are inlined (Excel has no user functions without macros); inputs and scalar
definitions are referred to by defined names.
"""

from __future__ import annotations

import contextlib
import dataclasses
from collections.abc import Iterator
from typing import TYPE_CHECKING

import numpy as np

from ..errors import NotLive
from ..functions import complexes, excel_names
from ..functions.constants import CONSTANTS
from ..language import cellunit
from ..language import typed as ty
from ..language.expr import PREC
from ..language.visitor import Visitor
from ..numerics.registry import REGISTRY

if TYPE_CHECKING:
    from ..language.typecheck import Typer
    from ..language.typeddefs import TypedDefinitions

MAX_FORMULA = 8192  # Excel's limit on formula length


def excel_name(name: str) -> str:
    """A defined name Excel and LibreOffice will not read as a cell reference or function."""
    return excel_names.single(name)


def number(value: float) -> str:
    if value != value or value in (float("inf"), float("-inf")):
        raise NotLive(f"{value} cannot be written in a formula")
    if float(value).is_integer() and abs(value) < 1e15:
        return str(int(value))
    return repr(float(value)).replace("e", "E")


def cell_value(t: ty.T, magnitude) -> float | str:
    """The value a cell of ``t`` holds: a number, or for a complex value Excel's complex
    text (``3+4i``), which the IM* functions read."""
    if t.complex:
        return complexes.excel_text(complex(magnitude))
    return float(np.real(magnitude))  # a real element of a complex matrix


_CMP = {"<": "<", "<=": "<=", ">": ">", ">=": ">=", "==": "=", "!=": "<>"}

# Excel's precedence levels are the worksheet's (one table); only negation differs (below).
ATOM, POW, MUL, ADD, CMP = PREC["atom"], PREC["^"], PREC["*"], PREC["+"], PREC["cmp"]


@dataclasses.dataclass(frozen=True)
class PrintContext:
    """What the printer prints in, set for a block of formulas by :meth:`ExcelPrinter.context`
    (as SymPy's ``printer_context``) rather than attributes set and reset by the caller."""

    #: the writer's allocator of helper cells (a root's bisection steps) where the formula
    #: goes; a binding hook finds it as ``body.helpers``
    helpers: object = None


@dataclasses.dataclass(frozen=True)
class BoundBody:
    """EXPR of a built-in that binds a variable (``root(EXPR, x, a, b)``), as the entry's
    Excel hook receives it: ``body(text)`` prints EXPR with the variable replaced by
    ``text`` (a cell, a node array); ``tree(t)`` prints another typed tree in the call's scope
    (diff's derivative)."""

    printer: ExcelPrinter
    subst: dict
    typed: ty.T  # EXPR's typed tree
    var: str  # the variable it binds
    var_param: ty.T  # the variable as typed
    rest: tuple  # the other arguments, typed
    helpers: object  # the context's helper cells (None outside one)
    scope: tuple  # the printed values of the variables around the call

    @property
    def typer(self) -> Typer:
        """The typer of the sheet (for a tree built from EXPR: diff's derivative)."""
        return self.printer.typer

    @property
    def defs(self) -> TypedDefinitions:
        """The typed definitions of the sheet (what a tree built from EXPR reads)."""
        return self.printer.defs

    def __call__(self, value: str) -> str:
        return self.printer.print(self.typed, {**self.subst, self.var: value})

    def tree(self, tree: ty.T) -> tuple[str, int]:
        return self.printer.visit(tree, self.subst)


class Formula(str):
    """A printed formula (``=...``); ``array`` is true when it computes with vectors or
    matrices (the writer writes it as an array formula)."""

    array: bool = False


class ExcelPrinter(Visitor):
    """Prints typed trees of one sheet; ``subst`` maps parameters to cell references.

    ``visit(t, subst)`` returns (text, precedence level); one ``visit_<Node>`` per node kind.
    """

    def __init__(self, typer: Typer, names: dict[str, str] | None = None):
        self.typer = typer
        self.defs = typer.defs  # the definitions' typed trees, read
        self.names = names or {}
        # (table, column) -> absolute cell range, filled by the writer for max_over()/min_over()
        self.ranges: dict[tuple[str, str], str] = {}
        self._context = PrintContext()
        self._array = False  # set while one formula is printed when it computes with arrays
        # (function, argument texts, helper cells) -> printed
        self._calls: dict[tuple, tuple[str, int]] = {}

    @contextlib.contextmanager
    def context(self, **changes) -> Iterator[ExcelPrinter]:
        """Print the formulas of the ``with`` block in a context with ``changes``
        (``helpers=...``); the previous context is back after it."""
        saved = self._context
        self._context = dataclasses.replace(saved, **changes)
        try:
            yield self
        finally:
            self._context = saved

    @property
    def helpers(self):
        """The helper-cell allocator of the current context (None outside one)."""
        return self._context.helpers

    def visit(self, t, *args):
        if ty.is_runtime(getattr(t, "shape", None)):
            raise NotLive("an array whose size is known only when its program runs")
        return super().visit(t, *args)

    def formula(self, t: ty.T, subst: dict[str, str]) -> Formula:
        """The live formula of ``t`` (NotLive when it has none); ``.array`` says whether it
        computes with arrays."""
        self._array = False
        text = "=" + self.print(t, subst)
        if text.endswith("}"):  # xlsxwriter drops a last "}" (it reads {=...} array braces)
            text = f"=({text[1:]})"
        if len(text) > MAX_FORMULA:
            raise NotLive(f"formula is {len(text)} characters long (Excel's limit {MAX_FORMULA})")
        out = Formula(text)
        out.array = self._array
        return out

    def print(self, t: ty.T, subst: dict[str, str]) -> str:
        return self.visit(t, subst)[0]

    def _wrap(self, t, subst, level: int) -> str:
        text, own = self.visit(t, subst)
        return f"({text})" if own <= level else text

    def visit_TConst(self, t, s):
        if t.complex:
            return complexes.constant(t.value), ATOM
        text = number(t.value)
        return text, (ADD if text.startswith("-") else ATOM)

    def visit_TText(self, t, s):
        return '"' + t.value.replace('"', '""') + '"', ATOM

    def visit_TParam(self, t, s):
        return s[t.name], ATOM

    def visit_TRef(self, t, s):
        if t.shape is not None:
            self._array = True
        if t.kind == "builtin":  # a constant: pi, e, g
            return CONSTANTS[t.name].excel, ATOM
        if t.kind in ("solve", "data"):
            raise NotLive(
                f"{t.name} is found by a [[solve]] block (scipy.optimize.root)"
                if t.kind == "solve"
                else f"{t.name} is a column of measured data"
            )
        read = cellunit.reading(self.typer.convert, t)  # the cell's number in t's unit
        if read is not t:
            return self.visit(read, s)
        return self.names.get(t.name, excel_name(t.name)), ATOM

    def visit_TScale(self, t, s):
        if t.factor == 1.0:
            return self.visit(t.child, s)
        if t.complex:
            return f"IMPRODUCT({self.print(t.child, s)}, {number(t.factor)})", ATOM
        return f"{self._wrap(t.child, s, MUL - 1)}*{number(t.factor)}", MUL

    def visit_TUnary(self, t, s):
        if t.op == "not":
            return f"NOT({self.print(t.child, s)})", ATOM
        if t.complex:
            return f"IMSUB(0, {self.print(t.child, s)})", ATOM
        # Excel's negation binds tighter than ^: -x^2 is (-x)^2 there, so bracket all but atoms.
        return "-" + self._wrap(t.child, s, ATOM - 1), ADD

    def visit_TBinary(self, t, s):
        if t.complex:
            return self._complex_binary(t, s), ATOM
        if t.shape is not None or t.left.shape is not None or t.right.shape is not None:
            self._array = True
            if t.op == "@":
                return f"MMULT({self.print(t.left, s)}, {self.print(t.right, s)})", ATOM
            if t.op == "@^":
                return _matrix_power(self.print(t.left, s), int(t.right.value)), ATOM
        if t.op == "^":
            return f"{self._wrap(t.left, s, POW)}^{self._wrap(t.right, s, POW)}", POW
        level = ADD if t.op in "+-" else MUL
        left = self._wrap(t.left, s, level - 1)
        right = self._wrap(t.right, s, level)  # a-(b-c), a/(b*c)
        return f"{left}{t.op}{right}", level

    def _complex_binary(self, t, s) -> str:
        """An operator over the complex plane: IMSUM, IMSUB, IMPRODUCT, IMDIV, IMPOWER."""
        if t.shape is not None or t.left.shape is not None or t.right.shape is not None:
            raise NotLive("a vector or matrix of complex values has no live formula here")
        left, right = self.print(t.left, s), self.print(t.right, s)
        if t.op == "^":
            return complexes.power(left, right, not t.right.complex)
        return f"{complexes.OPERATORS[t.op]}({left}, {right})"

    def visit_TCompare(self, t, s):
        if any(o.complex for o in t.operands):
            raise NotLive("a comparison of complex values has no live formula here")
        parts = [self._wrap(o, s, CMP) for o in t.operands]
        pairs = [f"{a}{_CMP[op]}{b}" for a, op, b in zip(parts, t.ops, parts[1:])]
        if len(pairs) == 1:
            return pairs[0], CMP
        return f"AND({', '.join(pairs)})", ATOM

    def visit_TLogic(self, t, s):
        return f"{t.op.upper()}({', '.join(self.print(v, s) for v in t.values)})", ATOM

    def visit_TFunc(self, t, s):
        entry = REGISTRY[t.func]
        bound = entry.binds is not None and len(t.args) > max(entry.binds)  # sum(EXPR, I, A, B)
        if not bound and any(a.complex for a in t.args):
            if entry.complex_excel is None or any(a.shape is not None for a in t.args):
                raise NotLive(f"{t.func}() of complex values has no live formula")
            return entry.complex_excel([self.print(a, s) for a in t.args])
        if bound and t.complex and entry.complex_excel is None:
            raise NotLive(f"{t.func}() of complex values has no live formula")
        if entry.arrays and not bound and any(a.shape is not None for a in t.args):
            self._array = True
            shapes = tuple(a.shape for a in t.args)
            return entry.excel([self.print(a, s) for a in t.args], shapes=shapes)
        if not entry.binds or len(t.args) <= max(entry.binds):
            return entry.excel([self.print(a, s) for a in t.args])
        expr_at, var_at = entry.binds
        body, var = t.args[expr_at], t.args[var_at].name
        rest = [a for i, a in enumerate(t.args) if i not in (expr_at, var_at)]
        consts = [a.value if isinstance(a, ty.TConst) else None for a in rest]

        printed = BoundBody(
            self, s, body, var, t.args[var_at], tuple(rest), self.helpers, tuple(s.values())
        )
        return entry.excel(printed, [self.print(a, s) for a in rest], consts)

    def visit_TCall(self, t, s):
        # Excel has no user functions: the body is inlined. A call met again with the same
        # arguments reuses its text, and a text beyond Excel's limit stops the printing at
        # once (NotLive: the writer writes the values as numbers), so nested calls such as
        # f_i(x) = (f_{i-1}(x) + f_{i-1}(x))/2 cost the limit, not 2^depth.
        f = self.defs.function(t.name)
        if t.name in self.defs.recursive:  # Excel has no recursion
            raise NotLive(f"{t.name.split('@')[0]}() calls itself; its values are numbers")
        if any(f.shapes) and isinstance(f.body, ty.TProgram):  # loops over a matrix: no formula
            raise NotLive(
                f"{t.name.split('@')[0]}() is called with a vector or matrix; "
                "its values are written as numbers"
            )
        inner = {p: self._wrap(a, s, ATOM - 1) for p, a in zip(f.params, t.args)}
        # the helper cells in the key: a body with a root prints references to the helper
        # block of its context (a table's row-wise steps), which another table cannot reuse
        key = (t.name, tuple(inner.values()), self.helpers)
        if key not in self._calls:
            text, level = self.visit(f.body, inner)
            if len(text) > MAX_FORMULA:
                raise NotLive(
                    f"{t.name}() inlined is longer than Excel's limit of {MAX_FORMULA} characters"
                )
            self._calls[key] = (text, level)
        return self._calls[key]

    def visit_TBlock(self, t, s):
        raise NotLive(f"{t.name}() is a solver block ({t.ref}); its values are written as numbers")

    def visit_TAggregate(self, t, s):
        read = cellunit.reading(self.typer.convert, t)  # the column's cells in t's unit
        if read is not t:
            return self.visit(read, s)
        ref = self.ranges.get((t.table, t.column))
        if ref is None:
            raise NotLive(
                f"{t.func}_over({t.table}, {t.column}) needs the cell range of that column, "
                "which this writer does not register"
            )
        return f"{t.func.upper()}({ref})", ATOM

    def visit_TPiecewise(self, t, s):
        tail = "NA()"
        for cond, val in reversed(list(zip(t.conditions, t.values))):
            v = self.print(val, s)
            tail = v if cond is None else f"IF({self.print(cond, s)}, {v}, {tail})"
        return tail, ATOM

    def visit_TMatrix(self, t, s):
        if t.complex:
            raise NotLive("a matrix of complex values is written as values")
        self._array = True
        if not all(isinstance(e, ty.TConst) for row in t.rows for e in row):
            raise NotLive("a matrix written with formulas inside an expression (name it)")
        rows = (",".join(number(e.value) for e in row) for row in t.rows)
        return "{" + ";".join(rows) + "}", ATOM

    def visit_TIndex(self, t, s):
        target = self.print(t.target, s)
        idx = [self._index(i, t.origin, s) for i in t.indices]
        if len(idx) == 1 and t.target.shape[1] == 1:
            return f"INDEX({target}, {idx[0]})", ATOM
        return f"INDEX({target}, {idx[0]}, {idx[1]})", ATOM

    def _index(self, i, origin: int, s) -> str:
        if isinstance(i, ty.TConst):
            return number(i.value + 1 - origin)
        shift = 1 - origin
        text = self._wrap(i, s, ADD)
        return text if shift == 0 else f"{text}+{shift}" if shift > 0 else f"{text}{shift}"

    def visit_TProgram(self, t, s):
        from ..program.excel import excel_value

        return excel_value(t.program, lambda e, sub: self.print(e, sub), s), ATOM

    def visit_TOde(self, t, s):
        raise NotLive(f"{t.name}() is the solution of ode '{t.ode}'; its values are numbers")


def _matrix_power(m: str, n: int) -> str:
    if n == 0:
        raise NotLive("M^0 (the identity) has no formula here")
    base = m if n > 0 else f"MINVERSE({m})"
    out = base
    for _ in range(abs(n) - 1):
        out = f"MMULT({out}, {base})"
    return out
