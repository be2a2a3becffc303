"""Programs: a function body written as a few statements, as Mathcad's program regions.

One statement a line; a block is the lines indented under its header (as in Python).
The text is split into statements here and every expression goes through
:func:`workbook.expr.parse`, so nothing is ever evaluated by Python::

    a := x^2                      # a local (Mathcad's a <- x^2; '←' is read too)
    v := [0, 0, 0]                # a local vector; v[i] := ... sets an element
    w[i] := i^2                   # w not given: it is made, and grown, by its elements
    for i in 1 .. n               # Mathcad's range form: first[, second] .. last
        a := a + i
        break if a > 100          # any simple statement may end in 'if CONDITION'
    while a > 1
        a := a/2
    if a > 10                     # block form: if / else if / otherwise (or else)
        return a
    else if a > 5
        return 2*a
    "small" if a < 0              # one-line form, as Mathcad's 'value if condition'
    a otherwise

The value of a program is the value of the ``return`` that ends it or, without one, of the
last value line it executed (an expression line, or the value of a one-line ``if`` /
``otherwise``). Assignments and loops are not values. A program that ends without a value is
an error, never a silent 0; so is a loop that runs more than :data:`MAX_STEPS` statements.

Typing (:func:`type_program`) and running (:func:`compile_program`) take the expression
back end as callbacks, so the same statements serve every back end.
"""

from __future__ import annotations

import io
import re
import tokenize
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import expr as ex
from . import runtime as rt
from .errors import LimitError, TemplateError
from .typed import RUNTIME, is_runtime

#: Statements one call of a program may execute (a `while` that never ends stops here).
MAX_STEPS = 1_000_000
#: Longest program text and deepest block nesting.
MAX_PROGRAM_TEXT = 100_000
MAX_BLOCK_DEPTH = 50


# -- statements (E is ex.Node after parsing, a typed node after typing) -----------------------
@dataclass(frozen=True)
class Stmt:
    line: int  # line within the program text, from 1


@dataclass(frozen=True)
class Assign(Stmt):
    name: str
    value: Any


@dataclass(frozen=True)
class SetItem(Stmt):
    """``v[i] := EXPR`` or ``M[i, j] := EXPR``: an element of a local vector or matrix."""

    name: str
    indices: tuple
    value: Any
    origin: int = 0
    grow: Any = None  # (rows, columns) the local is made or grown to (zeros), if it is


@dataclass(frozen=True)
class Value(Stmt):
    value: Any


@dataclass(frozen=True)
class Return(Stmt):
    value: Any


@dataclass(frozen=True)
class Break(Stmt):
    pass


@dataclass(frozen=True)
class Continue(Stmt):
    pass


@dataclass(frozen=True)
class If(Stmt):
    branches: tuple[tuple[Any, tuple[Stmt, ...]], ...]  # (condition, block)
    otherwise: tuple[Stmt, ...] | None


@dataclass(frozen=True)
class For(Stmt):
    var: str
    first: Any
    second: Any  # None: step 1 (or -1)
    last: Any
    body: tuple[Stmt, ...]


@dataclass(frozen=True)
class While(Stmt):
    condition: Any
    body: tuple[Stmt, ...]


@dataclass(frozen=True)
class Program:
    body: tuple[Stmt, ...]
    text: str


# -- parsing ----------------------------------------------------------------------------------
@dataclass
class _Line:
    number: int
    indent: int
    text: str


def parse(text: str, *, what: str = "program") -> Program:
    """Parse program text into statements (raises TemplateError naming the line)."""
    if not isinstance(text, str):
        raise TemplateError(f"{what}: a program is text (a multi-line string)")
    if len(text) > MAX_PROGRAM_TEXT:
        raise LimitError(f"{what}: program is {len(text)} characters (limit {MAX_PROGRAM_TEXT})")
    lines = []
    for number, raw in enumerate(text.splitlines(), start=1):
        body = _strip_comment(raw, what, number).rstrip()
        if not body.strip():
            continue
        if "\t" in body[: len(body) - len(body.lstrip())]:
            raise TemplateError(f"{what}, line {number}: indent with spaces, not tabs")
        lines.append(_Line(number, len(body) - len(body.lstrip()), body.strip()))
    if not lines:
        raise TemplateError(f"{what}: empty program")
    block, rest = _block(lines, 0, lines[0].indent, what, 0)
    if rest != len(lines):  # pragma: no cover - _block consumes everything at top level
        raise TemplateError(f"{what}, line {lines[rest].number}: unexpected indent")
    _check_loops(block, False, what)
    return Program(block, text)


def _check_loops(block: tuple[Stmt, ...], inside: bool, what: str) -> None:
    """'break' and 'continue' only inside a loop."""
    for s in block:
        if isinstance(s, (Break, Continue)) and not inside:
            word = "break" if isinstance(s, Break) else "continue"
            raise TemplateError(f"{what}, line {s.line}: '{word}' outside a loop")
        if isinstance(s, If):
            for _, b in s.branches:
                _check_loops(b, inside, what)
            if s.otherwise:
                _check_loops(s.otherwise, inside, what)
        elif isinstance(s, (For, While)):
            _check_loops(s.body, True, what)


def _strip_comment(raw: str, what: str, number: int) -> str:
    """The line without a trailing ``# comment`` (a '#' inside a string stays)."""
    if "#" not in raw:
        return raw
    quote = None
    for i, ch in enumerate(raw):
        if quote:
            if ch == quote:
                quote = None
        elif ch in "\"'":
            quote = ch
        elif ch == "#":
            return raw[:i]
    return raw


def _block(lines: list[_Line], i: int, indent: int, what: str, depth: int):
    if depth > MAX_BLOCK_DEPTH:
        raise LimitError(f"{what}: blocks nested more than {MAX_BLOCK_DEPTH} deep")
    out: list[Stmt] = []
    while i < len(lines):
        ln = lines[i]
        if ln.indent < indent:
            break
        if ln.indent > indent:
            raise TemplateError(f"{what}, line {ln.number}: unexpected indent")
        where = f"{what}, line {ln.number}"
        head, tail = _keyword(ln.text)
        i += 1
        if head in ("if", "for", "while", "else", "otherwise", "else if"):
            is_header = head != "otherwise" or not tail
            if head == "otherwise" and tail:
                raise TemplateError(f"{where}: write 'VALUE otherwise' or 'otherwise' alone")
        else:
            is_header = False
        if is_header:
            body, i = _body(lines, i, ln, what, depth)
            cond_text = tail.removesuffix(":").strip()
            if head == "if":
                out.append(If(ln.number, ((_expr(cond_text, where), body),), None))
            elif head in ("else if", "else", "otherwise"):
                prev = out[-1] if out else None
                if not isinstance(prev, If) or prev.otherwise is not None:
                    raise TemplateError(f"{where}: '{head}' without an 'if' before it")
                if head == "else if":
                    branches = (*prev.branches, (_expr(cond_text, where), body))
                    out[-1] = If(prev.line, branches, None)
                else:
                    if cond_text:
                        raise TemplateError(f"{where}: '{head}' takes no condition")
                    out[-1] = If(prev.line, prev.branches, body)
            elif head == "for":
                out.append(_for(cond_text, body, ln.number, where))
            else:
                out.append(While(ln.number, _expr(cond_text, where), body))
            continue
        if i < len(lines) and lines[i].indent > indent:
            raise TemplateError(
                f"{what}, line {lines[i].number}: unexpected indent (only if, else if, "
                "otherwise, for and while take an indented block)"
            )
        stmt = _simple(ln, where, out)
        if stmt is not None:
            out.append(stmt)
    return tuple(out), i


def _body(lines, i, header: _Line, what, depth):
    if i >= len(lines) or lines[i].indent <= header.indent:
        raise TemplateError(
            f"{what}, line {header.number}: '{header.text}' needs an indented block under it"
        )
    return _block(lines, i, lines[i].indent, what, depth + 1)


_KEYWORDS = re.compile(r"^(else\s+if|if|for|while|else|otherwise)\b\s*(.*)$")


def _keyword(text: str) -> tuple[str | None, str]:
    m = _KEYWORDS.match(text)
    if not m:
        return None, text
    return re.sub(r"\s+", " ", m.group(1)), m.group(2)


_FOR = re.compile(r"^([A-Za-z][A-Za-z0-9_]*)\s+(?:in|∈)\s+(.+)$")


def _for(text: str, body, number: int, where: str) -> For:
    from .ranges import parse_range

    m = _FOR.match(text)
    if not m:
        raise TemplateError(f"{where}: write 'for i in FIRST .. LAST' (or FIRST, SECOND .. LAST)")
    rng = parse_range(f"{m.group(1)} := {m.group(2)}", what=where)
    return For(number, rng.var, rng.first, rng.second, rng.last, body)


def _simple(ln: _Line, where: str, out: list[Stmt]) -> Stmt | None:
    """A one-line statement; ``VALUE otherwise`` joins the ``if`` before it (returns None)."""
    text = ln.text.replace("←", ":=")
    marks = _top_keywords(text, where)
    ifs = [c for w, c in marks if w == "if"]
    others = [c for w, c in marks if w in ("else", "otherwise")]
    if others and not ifs:
        col = others[0]
        if text[col:].strip() != "otherwise":
            raise TemplateError(f"{where}: write 'VALUE otherwise' (nothing after otherwise)")
        prev = out[-1] if out else None
        if not isinstance(prev, If) or prev.otherwise is not None:
            raise TemplateError(f"{where}: 'otherwise' without an 'if' before it")
        out[-1] = If(prev.line, prev.branches, (_plain(text[:col].strip(), ln.number, where),))
        return None
    if ifs and not others:
        if len(ifs) > 1:
            raise TemplateError(f"{where}: more than one 'if' on a line")
        col = ifs[0]
        cond = _expr(text[col + 2 :].strip(), where)
        stmt = _plain(text[:col].strip(), ln.number, where)
        return If(ln.number, ((cond, (stmt,)),), None)
    return _plain(text, ln.number, where)  # an inline 'a if c otherwise b' is an expression


def _plain(text: str, number: int, where: str) -> Stmt:
    if not text:
        raise TemplateError(f"{where}: a statement is missing before 'if'/'otherwise'")
    word = text.split(None, 1)
    if word[0] == "return":
        if len(word) == 1:
            raise TemplateError(f"{where}: 'return' needs a value")
        return Return(number, _expr(word[1], where))
    if text == "break":
        return Break(number)
    if text == "continue":
        return Continue(number)
    if word[0] in ("break", "continue"):
        raise TemplateError(f"{where}: '{word[0]}' takes nothing after it (or 'if CONDITION')")
    if ":=" in text:
        name, _, value = text.partition(":=")
        name = name.strip()
        if "[" in name:
            target = _expr(name, where)
            if isinstance(target, ex.Index) and isinstance(target.target, ex.Name):
                return SetItem(number, target.target.id, target.indices, _expr(value, where))
        if not ex.is_identifier(name):
            raise TemplateError(
                f"{where}: cannot assign to {name!r} (a local is a plain name, or v[i], M[i, j])"
            )
        return Assign(number, name, _expr(value, where))
    if re.match(r"^[A-Za-z][A-Za-z0-9_]*\s*=[^=]", text):
        raise TemplateError(f"{where}: a local is given its value with ':=' (not '=')")
    return Value(number, _expr(text, where))


def _top_keywords(text: str, where: str) -> list[tuple[str, int]]:
    """(word, column) of 'if', 'else', 'otherwise' outside brackets and strings."""
    found, depth = [], 0
    try:
        for tok in tokenize.generate_tokens(io.StringIO(text).readline):
            if tok.type == tokenize.OP and tok.string in "([{":
                depth += 1
            elif tok.type == tokenize.OP and tok.string in ")]}":
                depth -= 1
            elif tok.type == tokenize.NAME and depth == 0:
                if tok.string in ("if", "else", "otherwise"):
                    found.append((tok.string, tok.start[1]))
    except (tokenize.TokenError, SyntaxError, IndentationError) as err:
        raise TemplateError(f"{where}: cannot read {text!r}: {err}") from None
    return found


def _expr(text: str, where: str) -> ex.Node:
    if not text.strip():
        raise TemplateError(f"{where}: an expression is missing")
    return ex.parse(text, what=where)


# -- helpers for the back ends ----------------------------------------------------------------
def walk(block: tuple[Stmt, ...]):
    """Every statement of a block, nested ones included, parents first."""
    for s in block:
        yield s
        if isinstance(s, If):
            for _, b in s.branches:
                yield from walk(b)
            if s.otherwise:
                yield from walk(s.otherwise)
        elif isinstance(s, (For, While)):
            yield from walk(s.body)


def expressions(block: tuple[Stmt, ...]):
    """Every expression of a block (conditions, values, loop bounds)."""
    for s in walk(block):
        if isinstance(s, (Assign, Value, Return)):
            yield s.value
        elif isinstance(s, SetItem):
            yield from s.indices
            yield s.value
        elif isinstance(s, If):
            for c, _ in s.branches:
                yield c
        elif isinstance(s, For):
            yield from (e for e in (s.first, s.second, s.last) if e is not None)
        elif isinstance(s, While):
            yield s.condition


def names(program: Program) -> set[str]:
    """Names the program refers to that it does not define itself (locals, loop variables)."""
    local = set()
    for s in walk(program.body):
        if isinstance(s, Assign):
            local.add(s.name)
        elif isinstance(s, For):
            local.add(s.var)
    found = set()
    for e in expressions(program.body):
        found |= ex.names(e)
    return found - local


def has_loops(program: Program) -> bool:
    return any(isinstance(s, (For, While)) for s in walk(program.body))


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
        # locals whose shape is known only when the program runs (workbook.runtime): grown
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
        from .errors import WorkbookError

        try:
            return self.t.type_expr(e, self.scope)
        except WorkbookError as err:
            err.message = f"{self.where(s)}: {err.message}"
            raise

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
                    elif any(v != int(v) or v < origin for v in values):
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
            elif isinstance(st, For):
                bounds = [_number(b) if b is not None else 0.0 for b in (st.first, st.last)]
                second = _number(st.second) if st.second is not None else None
                values = None
                if None not in bounds and (st.second is None or second is not None):
                    try:
                        values = [float(v) for v in _range_values(bounds[0], second, bounds[1])]
                    except TemplateError:
                        values = None
                stop = any(isinstance(x, (Break, Continue, Return)) for x in walk(st.body))
                inner = why or (
                    "it is set in a loop with break, continue or return" if stop else ""
                )
                visit(st.body, {**loops, st.var: values}, inner, at)

    visit(program.body, {}, "", None)
    return out


def _number(node) -> float | None:
    """A number written in the program (``3``, ``-1``), else None."""
    if isinstance(node, ex.Number):
        return float(node.value)
    if isinstance(node, ex.Unary) and node.op == "-" and isinstance(node.operand, ex.Number):
        return -float(node.operand.value)
    return None


def _range_values(first, second, last):
    from .ranges import range_values

    return range_values(first, second, last, what="loop")


def _grown_used_whole(program: Program, grown: dict, growing: set[str]) -> None:
    """A vector made or grown by its elements is used whole (rows(v), v itself) only after
    the statement that sets its last element: before, Mathcad's length is still growing."""
    for k, top in enumerate(program.body):
        for name in sorted(growing):
            g = grown[name]
            if not g.first <= k <= g.last:
                continue
            for st in walk((top,)):
                exprs = list(expressions((st,))) if not isinstance(st, (If, For, While)) else []
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


# -- running ----------------------------------------------------------------------------------
class _Break(Exception):
    pass


class _Continue(Exception):
    pass


class _Return(Exception):
    def __init__(self, value):
        self.value = value


class NoValue(Exception):
    """The program ended without a value (the numeric back end names the function)."""


_NONE = object()


def compile_program(
    typed: TypedProgram, compile_expr: Callable[[Any], Callable], name: str
) -> Callable[[dict], Any]:
    """A closure env -> value for scalar arguments (the back end loops over arrays)."""
    from .ranges import range_values

    steps = [0]

    def tick(s: Stmt):
        steps[0] += 1
        if steps[0] > MAX_STEPS:
            raise LimitError(
                f"the program of '{name}' ran {MAX_STEPS:,} statements without ending "
                f"(line {s.line}: a loop that never ends?)",
                definition=name,
            )

    def block(stmts):
        compiled = [stmt(s) for s in stmts]

        def run(env, last):
            for c in compiled:
                last = c(env, last)
            return last

        return run

    def stmt(s: Stmt):
        if isinstance(s, Assign):
            f, n = compile_expr(s.value), s.name

            def assign(env, last):
                tick(s)
                value = f(env)  # a matrix is copied: its elements may be set later
                if isinstance(value, np.ndarray) and value.dtype == object:
                    env[n] = value.copy()
                else:
                    env[n] = np.array(value, dtype=float) if np.ndim(value) else value
                env.setdefault(_OWNED, set()).add(n)
                return last

            return assign
        if isinstance(s, SetItem):
            from .matrix import element_index

            f, n, origin, grow = compile_expr(s.value), s.name, s.origin, s.grow
            idx = [compile_expr(i) for i in s.indices]
            if is_runtime(grow):
                what = f"program of '{name}', line {s.line}: {n}[...]"

                def set_runtime(env, last):
                    tick(s)
                    _own(env, n)
                    at = [i(env) for i in idx]
                    env[n] = rt.set_item(env.get(n), at, f(env), origin=origin, what=what)
                    return last

                return set_runtime

            def set_item(env, last):
                tick(s)
                _own(env, n)
                if grow is not None:  # made, or grown with zeros, to its length at load
                    old = env.get(n)
                    if old is None or np.shape(old)[:2] != tuple(grow):
                        target = np.zeros(grow)
                        if old is not None:
                            old = np.asarray(old, dtype=float).reshape(np.shape(old)[0], -1)
                            target[: old.shape[0], : old.shape[1]] = old
                        env[n] = target
                target = env[n]
                at = element_index(target.shape, [i(env) for i in idx], origin, f"{n}[...]")
                target[at] = f(env)
                return last

            return set_item
        if isinstance(s, Value):
            f = compile_expr(s.value)

            def value(env, last):
                tick(s)
                return _result(f(env))  # a local set after this line does not change it

            return value
        if isinstance(s, Return):
            f = compile_expr(s.value)

            def ret(env, last):
                tick(s)
                raise _Return(f(env))

            return ret
        if isinstance(s, Break):

            def brk(env, last):
                raise _Break

            return brk
        if isinstance(s, Continue):

            def cont(env, last):
                raise _Continue

            return cont
        if isinstance(s, If):
            branches = [(compile_expr(c), block(b)) for c, b in s.branches]
            other = block(s.otherwise) if s.otherwise is not None else None

            def if_(env, last):
                tick(s)
                for c, b in branches:
                    if bool(c(env)):
                        return b(env, last)
                return other(env, last) if other is not None else last

            return if_
        if isinstance(s, For):
            first, last_ = compile_expr(s.first), compile_expr(s.last)
            second = compile_expr(s.second) if s.second is not None else None
            body, var = block(s.body), s.var

            def for_(env, last):
                where = f"program of '{name}', line {s.line}"
                values = range_values(
                    rt.number(first(env), where),
                    rt.number(second(env), where) if second is not None else None,
                    rt.number(last_(env), where),
                    what=where,
                )
                for v in values:
                    tick(s)
                    env[var] = float(v)
                    try:
                        last = body(env, last)
                    except _Break:
                        break
                    except _Continue:
                        continue
                return last

            return for_
        if isinstance(s, While):
            cond, body = compile_expr(s.condition), block(s.body)

            def while_(env, last):
                while True:
                    tick(s)
                    if not bool(cond(env)):
                        return last
                    try:
                        last = body(env, last)
                    except _Break:
                        return last
                    except _Continue:
                        continue

            return while_
        raise TypeError(s)  # pragma: no cover

    main = block(typed.body)
    # a local made by its elements when the program runs is the number 0 until its first
    # element is set (Mathcad's start of a local): rows(v) is 0, so v[rows(v) + 1] appends
    made = {s.name for s in walk(typed.body) if isinstance(s, SetItem) and is_runtime(s.grow)}

    def run(env: dict):
        steps[0] = 0
        local = dict(env)
        for n in made:
            local.setdefault(n, 0.0)
        try:
            out = main(local, _NONE)
        except _Return as r:
            return _result(r.value)
        except (_Break, _Continue):
            raise TemplateError(f"'break'/'continue' outside a loop in '{name}'") from None
        if out is _NONE:
            raise NoValue(name)
        return _result(out)

    return run


def _result(value):
    """A program's value: an array is the program's own copy."""
    if isinstance(value, np.ndarray):
        return value.copy() if value.dtype == object else np.array(value)
    return value


#: Where a program run keeps the names of the locals it made (an argument's array is copied
#: before its first element is set); not a valid name, so no local can meet it.
_OWNED = "#owned"


def _own(env: dict, name: str) -> None:
    """Before the first element of ``name`` is set in this run: an array the run did not
    make (an argument's, the caller's) is replaced by a copy of it."""
    owned = env.setdefault(_OWNED, set())
    if name not in owned and isinstance(env.get(name), np.ndarray):
        env[name] = env[name].copy()
    owned.add(name)


# -- a live spreadsheet formula ---------------------------------------------------------------
def excel_value(typed: TypedProgram, printed: Callable[[Any, dict], str], subst: dict) -> str:
    """A program without loops as one nested IF: locals are replaced by their formulas and
    each branch carries the statements after it. A loop has no formula (NotLive)."""
    from .errors import NotLive

    if typed.loops:
        raise NotLive("a program with a loop is written as values")

    def run(stmts: list[Stmt], s: dict, last: str | None) -> str:
        for k, st in enumerate(stmts):
            if isinstance(st, SetItem):  # pragma: no cover - typed as a loop (values)
                raise NotLive("a program that sets elements is written as values")
            if isinstance(st, Assign):
                s = {**s, st.name: f"({printed(st.value, s)})"}
            elif isinstance(st, Value):
                last = printed(st.value, s)
            elif isinstance(st, Return):
                return printed(st.value, s)
            elif isinstance(st, If):
                rest = list(stmts[k + 1 :])
                tail = run(list(st.otherwise or ()) + rest, s, last)
                for cond, block in reversed(st.branches):
                    tail = f"IF({printed(cond, s)}, {run(list(block) + rest, s, last)}, {tail})"
                return tail
            else:  # pragma: no cover - loops were refused above
                raise NotLive("a loop is written as values")
        return last if last is not None else "NA()"

    return run(list(typed.body), dict(subst), None)
