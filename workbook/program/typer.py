"""Typing a program: every expression through the typer's callbacks; a local keeps the unit
of its first value."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ..errors import LimitError, TemplateError
from ..language import expr as ex
from ..language.typed import RUNTIME, is_runtime
from ..limits import MAX_ARRAY_ELEMENTS, count_text
from .statements import (
    Assign,
    Break,
    Continue,
    For,
    If,
    Program,
    Return,
    SetItem,
    Stmt,
    Try,
    Value,
    While,
    expressions,
    has_loops,
    walk,
)


# -- typing -----------------------------------------------------------------------------------
@dataclass
class ExprTyping:
    """What :func:`type_program` needs from the typer (all callbacks)."""

    type_expr: Callable[[Any, dict], Any]  # (expression, scope name -> unit) -> typed node
    convert: Callable[[Any, Any, str], Any]  # (typed, unit, where) -> typed in that unit
    is_boolean: Callable[[Any], bool]
    is_text: Callable[[Any], bool]
    is_zero: Callable[[Any], bool]  # a bare literal 0 (fits any unit)
    unit_of: Callable[[Any], Any]
    shape_of: Callable[[Any], Any] = lambda t: None  # (rows, columns) of a matrix, or None
    scope_entry: Callable[[Any, Any], Any] = lambda unit, shape: unit  # a local in the scope
    index: Callable[[Any, dict, tuple, str], Any] = None  # (index expr, scope, shape, word)
    origin: int = 0


@dataclass(frozen=True)
class TypedProgram:
    body: tuple[Stmt, ...]  # expressions are typed nodes
    unit: Any
    text: bool  # the program's value is text ("OK")
    loops: bool
    source: str
    shape: Any = None  # (rows, columns) when the program gives a vector or matrix

    def expressions(self) -> list:
        """Every typed expression of the program."""
        return list(expressions(self.body))


def type_program(
    program: Program, scope: dict, typing: ExprTyping, *, reserved=frozenset()
) -> TypedProgram:
    """Type every expression; locals keep the unit of their first value (a bare 0 waits for
    the next); every value the program can give must agree (numbers in one dimension, or text).
    """
    pending: dict[str, Any] = {}
    runtime: set[str] = set()
    grown = growth(program, typing.origin)
    for _ in range(4):
        state = _TypeState(dict(scope), dict(pending), typing, reserved, grown, set(runtime))
        body = state.block(program.body, top=True)
        if state.local_units == pending and state.runtime == runtime:
            break
        pending = dict(state.local_units)
        runtime = set(state.runtime)
    _grown_used_whole(program, grown, state.growing - state.runtime)
    if state.value_unit is None and not state.value_text:
        raise TemplateError("the program gives no value (no return and no value line)")
    unit = state.value_unit if not state.value_text else typing.unit_of(state.first_value)
    if unit is None:  # only bare zeros
        unit = typing.unit_of(state.first_value)
    loops = has_loops(program) or any(isinstance(s, SetItem) for s in walk(program.body))
    return TypedProgram(body, unit, state.value_text, loops, program.text, state.value_shape)


class _TypeState:
    def __init__(self, scope, hints, typing: ExprTyping, reserved, grown=None, runtime=()):
        self.grown: dict[str, _Growth] = grown or {}
        # locals whose shape is known only when the program runs (workbook.engine.runtime): grown
        # at indices not known at load, given arrays as elements, or given values of
        # different shapes where one is such an array
        self.runtime: set[str] = set(runtime)
        self.growing: set[str] = set()  # locals made or grown by their elements
        self.top = 0  # the top-level statement being typed
        self.scope = scope
        self.hints = hints  # units learned for locals in an earlier pass
        self.local_units: dict[str, Any] = {}
        self.t = typing
        self.reserved = reserved
        self.value_unit = None
        self.value_text = False
        self.first_value = None
        self.value_shape = _UNSET
        self.local_shapes: dict[str, Any] = {}

    def where(self, s: Stmt) -> str:
        return f"program line {s.line}"

    def expr(self, e, s: Stmt):
        from ..errors import WorkbookError

        try:
            return self.t.type_expr(e, self.scope)
        except WorkbookError as err:
            raise err.reworded(f"{self.where(s)}: {err.message}") from None

    def cond(self, e, s: Stmt):
        t = self.expr(e, s)
        if not self.t.is_boolean(t):
            raise TemplateError(f"{self.where(s)}: a condition must be a comparison")
        return t

    def number(self, e, s: Stmt, what: str):
        t = self.expr(e, s)
        if self.t.is_boolean(t) or self.t.is_text(t):
            raise TemplateError(f"{self.where(s)}: {what} must be a number")
        return t

    def value(self, e, s: Stmt):
        t = self.expr(e, s)
        if self.t.is_boolean(t):
            raise TemplateError(f"{self.where(s)}: the value is a comparison, not a number")
        shape = self.t.shape_of(t)
        if self.value_shape is _UNSET:
            self.value_shape = shape
        elif is_runtime(shape) or is_runtime(self.value_shape):
            self.value_shape = RUNTIME
        elif shape != self.value_shape:
            raise TemplateError(
                f"{self.where(s)}: the program gives {_shape_words(shape)} here and "
                f"{_shape_words(self.value_shape)} elsewhere"
            )
        if self.t.is_text(t):
            if self.first_value is not None and not self.value_text:
                raise TemplateError(f"{self.where(s)}: text here, a number in another branch")
            self.value_text, self.first_value = True, self.first_value or t
            return t
        if self.value_text:
            raise TemplateError(f"{self.where(s)}: a number here, text in another branch")
        if self.value_unit is None:
            if self.t.is_zero(t) and self.first_value is None:
                self.first_value = t
                return t  # a bare 0: its unit comes from another value, if any
            self.value_unit = self.t.unit_of(t)
            self.first_value = t
            return t
        return self.t.convert(t, self.value_unit, f"{self.where(s)}: the program's value")

    def assign(self, s: Assign):
        if s.name in self.reserved:
            raise TemplateError(
                f"{self.where(s)}: '{s.name}' is a name of the sheet; give the local another name"
            )
        t = self.number(s.value, s, f"the value of '{s.name}'")
        shape = self.t.shape_of(t)
        given = self.local_shapes.get(s.name)
        if (
            is_runtime(shape)
            or s.name in self.runtime
            or (
                # arrays of other sizes given to one local (Mathcad's and VBA's): its size is
                # the last one given, known when it runs
                shape is not None and given is not None and shape != given
            )
        ):
            # given a run-time array here, or elsewhere: it is one everywhere (next pass)
            self.runtime.add(s.name)
            shape = self.local_shapes[s.name] = RUNTIME
        elif s.name in self.local_shapes and is_runtime(self.local_shapes[s.name]):
            shape = RUNTIME
        if s.name in self.local_shapes and self.local_shapes[s.name] != shape:
            raise TemplateError(
                f"{self.where(s)}: '{s.name}' was {_shape_words(self.local_shapes[s.name])}, "
                f"here it is given {_shape_words(shape)}"
            )
        self.local_shapes[s.name] = shape
        unit = self.local_units.get(s.name) or self.hints.get(s.name)
        if unit is None:
            if self.t.is_zero(t):
                self.scope.setdefault(s.name, self.t.unit_of(t))
                return Assign(s.line, s.name, t)
            unit = self.t.unit_of(t)
            self.local_units[s.name] = unit
        else:
            self.local_units[s.name] = unit
        self.scope[s.name] = self.t.scope_entry(unit, shape)
        return Assign(s.line, s.name, self.t.convert(t, unit, f"{self.where(s)}: '{s.name}'"))

    def set_item(self, s: SetItem):
        for node in s.indices:
            constant_index(node, self.t.origin, f"{self.where(s)}: {s.name}[...]")
        shape = self.local_shapes.get(s.name)
        given = self.scope.get(s.name)
        if shape is None and isinstance(given, tuple) and s.name not in self.reserved:
            # an argument's vector: the program sets elements of its own copy (as Mathcad)
            shape = self.local_shapes[s.name] = given[1]
            self.local_units.setdefault(s.name, given[0])
        g = self.grown.get(s.name)
        reach = None
        if g is not None and not g.why and min(g.extent) >= 0:
            reach = (g.extent[0] + 1, g.extent[1] + 1 if len(g.extent) == 2 else 1)
            if float(reach[0]) * reach[1] > MAX_ARRAY_ELEMENTS:  # refused before it is made
                at = ", ".join(f"{e + self.t.origin:g}" for e in g.extent)
                raise LimitError(
                    f"{self.where(s)}: '{s.name}' set at index {at} would be an array of "
                    f"{count_text(float(reach[0]) * reach[1])} elements (limit "
                    f"{MAX_ARRAY_ELEMENTS:,} elements)"
                )
        if s.name in self.runtime or is_runtime(shape):
            return self.runtime_item(s)
        if shape is None and reach is None and s.name not in self.reserved:
            return self.runtime_item(s)  # grown at indices known only when it runs
        if shape is None or (reach is not None and (reach[0] > shape[0] or reach[1] > shape[1])):
            if s.name in self.reserved:
                raise TemplateError(
                    f"{self.where(s)}: '{s.name}' is a name of the sheet; give the local "
                    "another name"
                )
            if reach is None:
                why = g.why if g is not None and g.why else "its length is not known at load"
                raise TemplateError(
                    f"{self.where(s)}: '{s.name}' is made or grown by its elements, but {why}; "
                    f"give it its full length first (e.g. {s.name} := [0, 0, 0])"
                )
            shape = reach if shape is None else (max(shape[0], reach[0]), max(shape[1], reach[1]))
            self.local_shapes[s.name] = shape
            self.growing.add(s.name)
        if len(s.indices) == 1 and shape[1] != 1:
            raise TemplateError(f"{self.where(s)}: '{s.name}' is a matrix: write {s.name}[i, j]")
        words = ("row", "column") if len(s.indices) == 2 else ("element",)
        idx = tuple(self.t.index(i, self.scope, n, w) for i, n, w in zip(s.indices, shape, words))
        t = self.number(s.value, s, f"an element of '{s.name}'")
        if self.t.shape_of(t) is not None:  # an array as an element: a nested array
            return self.runtime_item(s)
        unit = self.local_units.get(s.name) or self.hints.get(s.name) or self.t.unit_of(t)
        value = self.t.convert(t, unit, f"{self.where(s)}: an element of '{s.name}'")
        if s.name in self.growing:
            self.local_units[s.name] = unit
            self.scope[s.name] = self.t.scope_entry(unit, shape)
            return SetItem(s.line, s.name, idx, value, self.t.origin, shape)
        return SetItem(s.line, s.name, idx, value, self.t.origin)

    def runtime_item(self, s: SetItem):
        """``v[i] := x`` on a local whose shape is known only when the program runs: made,
        grown (with zeros) or nested as in Mathcad, checked when it runs."""
        if s.name in self.reserved:
            raise TemplateError(
                f"{self.where(s)}: '{s.name}' is a name of the sheet; give the local another name"
            )
        if len(s.indices) > 2:
            raise TemplateError(f"{self.where(s)}: at most two indices, {s.name}[i, j]")
        self.runtime.add(s.name)
        t = self.number(s.value, s, f"an element of '{s.name}'")
        unit = self.local_units.get(s.name) or self.hints.get(s.name)
        if unit is None and not self.t.is_zero(t):
            unit = self.t.unit_of(t)
        if unit is not None:
            self.local_units[s.name] = unit
            value = self.t.convert(t, unit, f"{self.where(s)}: an element of '{s.name}'")
        else:  # only zeros so far: the unit comes from another element
            value = t
        self.local_shapes[s.name] = RUNTIME
        self.scope[s.name] = self.t.scope_entry(unit or self.t.unit_of(t), RUNTIME)
        words = ("row", "column") if len(s.indices) == 2 else ("element",)
        idx = tuple(self.t.index(i, self.scope, None, w) for i, w in zip(s.indices, words))
        return SetItem(s.line, s.name, idx, value, self.t.origin, RUNTIME)

    def block(self, block, top: bool = False):
        out = []
        for k, s in enumerate(block):
            if top:
                self.top = k
            out.append(self.stmt(s))
        return tuple(out)

    def stmt(self, s: Stmt) -> Stmt:
        if isinstance(s, Assign):
            return self.assign(s)
        if isinstance(s, SetItem):
            return self.set_item(s)
        if isinstance(s, Value):
            return Value(s.line, self.value(s.value, s))
        if isinstance(s, Return):
            return Return(s.line, self.value(s.value, s))
        if isinstance(s, (Break, Continue)):
            return s
        if isinstance(s, If):
            branches = tuple((self.cond(c, s), self.block(b)) for c, b in s.branches)
            other = self.block(s.otherwise) if s.otherwise is not None else None
            return If(s.line, branches, other)
        if isinstance(s, For):
            if s.var in self.reserved:
                raise TemplateError(f"{self.where(s)}: loop variable '{s.var}' is a sheet name")
            first = self.number(s.first, s, "a loop bound")
            unit = self.t.unit_of(first)
            conv = lambda e: self.t.convert(  # noqa: E731
                self.number(e, s, "a loop bound"), unit, f"{self.where(s)}: loop bounds"
            )
            second = conv(s.second) if s.second is not None else None
            last = conv(s.last)
            self.scope[s.var] = unit
            return For(s.line, s.var, first, second, last, self.block(s.body))
        if isinstance(s, While):
            return While(s.line, self.cond(s.condition, s), self.block(s.body))
        if isinstance(s, Try):
            return Try(s.line, self.block(s.body), self.block(s.handler))
        raise TypeError(s)  # pragma: no cover


_UNSET = object()


def _shape_words(shape) -> str:
    if shape is None:
        return "a number"
    if is_runtime(shape):
        return "a run-time array"
    r, c = shape
    return f"a {r}x{c} matrix" if c != 1 else f"a vector of {r}"


# -- vectors made and grown by their elements (Mathcad's v[i] <- ...) ------------------------
@dataclass
class _Growth:
    """What the element assignments of one local reach, found before typing."""

    extent: list[int]  # the largest row (and column) index, origin 0 (-1: none known)
    why: str = ""  # why the extent is not known at load ('' : it is)
    first: int = -1  # the top-level statement of the first element assignment
    last: int = -1  # ... and of the last
    last_line: int = 0  # the program line of the last


def growth(program: Program, origin: int) -> dict[str, _Growth]:
    """For each name assigned by element (``v[i] := ...``): the largest index its element
    assignments reach, known at load when every index is a number or the variable of a
    ``for`` over numbers, and every such assignment runs on every pass (not under ``if`` or
    ``while``, in no loop with ``break``, ``continue`` or ``return``); else why not."""
    out: dict[str, _Growth] = {}

    def index_values(node, loops: dict):
        if isinstance(node, ex.Name) and node.id in loops:
            return loops[node.id]
        v = _number(node)
        return None if v is None else [v]

    def visit(block, loops: dict, why: str, top: int | None) -> None:
        for k, st in enumerate(block):
            at = k if top is None else top
            if isinstance(st, SetItem):
                g = out.setdefault(st.name, _Growth([-1] * len(st.indices), first=at))
                g.last = max(g.last, at)
                g.last_line = max(g.last_line, st.line)
                if len(g.extent) != len(st.indices):
                    g.why = g.why or "it is set with one index and with two"
                    continue
                for d, node in enumerate(st.indices):
                    values = index_values(node, loops)
                    if values is None:
                        g.why = g.why or (
                            f"line {st.line}: its index {ex.to_text(node)} is known only when "
                            "the program runs (a number, or the variable of a for over numbers)"
                        )
                    elif any(not math.isfinite(v) or v != int(v) or v < origin for v in values):
                        g.why = g.why or f"line {st.line}: an index below the origin or not whole"
                    else:
                        g.extent[d] = max(g.extent[d], int(max(values)) - origin)
                if why:
                    g.why = g.why or f"line {st.line}: {why}"
            elif isinstance(st, If):
                for _, b in st.branches:
                    visit(b, loops, why or "it is set under an if", at)
                if st.otherwise is not None:
                    visit(st.otherwise, loops, why or "it is set under an if", at)
            elif isinstance(st, While):
                visit(st.body, loops, why or "it is set in a while loop", at)
            elif isinstance(st, Try):
                for b in (st.body, st.handler):
                    visit(b, loops, why or "it is set under a try or on error", at)
            elif isinstance(st, For):
                bounds = [_number(b) if b is not None else 0.0 for b in (st.first, st.last)]
                second = _number(st.second) if st.second is not None else None
                values = None
                if None not in bounds and (st.second is None or second is not None):
                    try:
                        values = [float(v) for v in _loop_values(bounds[0], second, bounds[1])]
                    except TemplateError:
                        values = None
                stop = any(isinstance(x, (Break, Continue, Return)) for x in walk(st.body))
                inner = why or (
                    "it is set in a loop with break, continue or return" if stop else ""
                )
                visit(st.body, {**loops, st.var: values}, inner, at)

    visit(program.body, {}, "", None)
    return out


_FOLD = {
    "+": lambda a, b: a + b,
    "-": lambda a, b: a - b,
    "*": lambda a, b: a * b,
    "/": lambda a, b: a / b if b else math.copysign(math.inf, a) if a else math.nan,
    "^": lambda a, b: a**b,
}


def _number(node) -> float | None:
    """A number written in the program (``3``, ``-1``, ``0/0``, ``2^40``: numbers and ``+ - *
    / ^``), else None; NaN or inf where the arithmetic has no finite value."""
    if isinstance(node, ex.Number):
        return float(node.value)
    if isinstance(node, ex.Unary) and node.op in "+-":
        v = _number(node.operand)
        return None if v is None else (-v if node.op == "-" else v)
    if isinstance(node, ex.Binary) and node.op in _FOLD:
        a, b = _number(node.left), _number(node.right)
        if a is None or b is None:
            return None
        try:
            v = _FOLD[node.op](a, b)
        except OverflowError:
            return math.inf
        except (ZeroDivisionError, ValueError):
            return math.nan
        return v if isinstance(v, float) else math.nan  # a complex power
    return None


def constant_index(node, origin: int, where: str) -> None:
    """Refuse at load an index written as numbers that is no element's: not a finite
    number, not whole, below the origin, or beyond any array."""
    v = _number(node)
    if v is None:
        return
    shown = ex.to_text(node)
    if shown.replace(" ", "") not in (f"{v:g}", str(v)):
        shown += f" = {v:g}"
    if not math.isfinite(v):
        raise TemplateError(f"{where}: the index {shown} is not a finite number")
    if v != int(v):
        raise TemplateError(f"{where}: the index {shown} is not a whole number")
    if v < origin:
        raise TemplateError(
            f"{where}: element index {shown} is out of range (below the origin {origin})"
        )
    if v - origin >= MAX_ARRAY_ELEMENTS:
        raise LimitError(
            f"{where}: the index {shown} is beyond any array (at most "
            f"{MAX_ARRAY_ELEMENTS:,} elements)"
        )


def _loop_values(first, second, last):
    from ..language.ranges import loop_values

    return loop_values(first, second, last, what="loop")


def _grown_used_whole(program: Program, grown: dict, growing: set[str]) -> None:
    """A vector made or grown by its elements is used whole (rows(v), v itself) only after
    the statement that sets its last element: before, Mathcad's length is still growing."""
    for k, top in enumerate(program.body):
        for name in sorted(growing):
            g = grown[name]
            if not g.first <= k <= g.last:
                continue
            for st in walk((top,)):
                compound = (If, For, While, Try)
                exprs = list(expressions((st,))) if not isinstance(st, compound) else []
                if isinstance(st, If):
                    exprs = [c for c, _ in st.branches]
                elif isinstance(st, For):
                    exprs = [e for e in (st.first, st.second, st.last) if e is not None]
                elif isinstance(st, While):
                    exprs = [st.condition]
                if any(_whole_uses(e, {name}) for e in exprs):
                    raise TemplateError(
                        f"program line {st.line}: '{name}' is used whole where the program is "
                        f"still setting its elements (its length grows until line "
                        f"{g.last_line}); use it after, or its elements {name}[i]"
                    )


def _whole_uses(node, names: set[str]) -> set[str]:
    """Names of ``names`` that ``node`` uses as a whole (not as v[...])."""
    found = set()
    skip = {id(n.target) for n in ex.walk(node) if isinstance(n, ex.Index)}
    for n in ex.walk(node):
        if isinstance(n, ex.Name) and n.id in names and id(n) not in skip:
            found.add(n.id)
    return found
