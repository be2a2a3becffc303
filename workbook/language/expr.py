"""The expression language: a small tree parsed safely from worksheet text.

Text is parsed with ``ast.parse(mode="eval")`` and only a whitelist of node types
is turned into the engine's own nodes; nothing is ever evaluated by Python.
``^`` is the power operator (as in Mathcad and Excel).
"""

from __future__ import annotations

import ast
import math
import operator
import re
import warnings
from dataclasses import dataclass

from ..errors import LimitError, TemplateError
from .visitor import Visitor

MAX_TEXT = 20_000
MAX_DEPTH = 200

#: The comparison operators by their worksheet symbol, as Python's (the back ends and the
#: mpmath form compare with them)
COMPARE = {
    "<": operator.lt,
    "<=": operator.le,
    ">": operator.gt,
    ">=": operator.ge,
    "==": operator.eq,
    "!=": operator.ne,
}


@dataclass(frozen=True)
class Node:
    """Base of all expression nodes."""


@dataclass(frozen=True)
class Number(Node):
    value: float


@dataclass(frozen=True)
class Quantity(Node):
    """A number followed by a unit, ``20 mm`` or ``9.81 m/s^2``: ``unit`` is the unit text as
    written (read by :mod:`workbook.language.quantity`, the reader of inputs, when it is typed)."""

    value: float
    unit: str


@dataclass(frozen=True)
class Imaginary(Node):
    """A number followed by ``i`` or ``j`` (``4i``, ``2.5j``, as Mathcad writes it): ``value``
    times the imaginary unit. ``i`` and ``j`` alone stay names (range variables)."""

    value: float


@dataclass(frozen=True)
class Text(Node):
    """A string literal: allowed only as the right side of ``choice == "..."``."""

    value: str


@dataclass(frozen=True)
class Name(Node):
    id: str


@dataclass(frozen=True)
class Unary(Node):
    op: str  # '-' or '+' or 'not'
    operand: Node


@dataclass(frozen=True)
class Binary(Node):
    op: str  # + - * / ^
    left: Node
    right: Node


@dataclass(frozen=True)
class Compare(Node):
    """A (possibly chained) comparison: ``0 <= phi <= 22``."""

    ops: tuple[str, ...]
    operands: tuple[Node, ...]


@dataclass(frozen=True)
class Logic(Node):
    op: str  # 'and' / 'or'
    values: tuple[Node, ...]


@dataclass(frozen=True)
class Call(Node):
    func: str
    args: tuple[Node, ...]


@dataclass(frozen=True)
class Matrix(Node):
    """``[1, 2, 3]`` (a column vector, as Mathcad's) or ``[[4, 1], [2, 3]]`` (by rows)."""

    rows: tuple[tuple[Node, ...], ...]


@dataclass(frozen=True)
class Index(Node):
    """``v[i]`` or ``M[i, j]`` (counted from the sheet's origin)."""

    target: Node
    indices: tuple[Node, ...]


@dataclass(frozen=True)
class IfElse(Node):
    """``VALUE if CONDITION otherwise OTHER`` (Python's ``else`` is read too)."""

    value: Node
    condition: Node
    other: Node


_BINOPS = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/", ast.Pow: "^"}
_CMPOPS = {ast.Lt: "<", ast.LtE: "<=", ast.Gt: ">", ast.GtE: ">=", ast.Eq: "==", ast.NotEq: "!="}
_IDENT = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")


def is_identifier(text: str) -> bool:
    """Names allowed in worksheets: a letter, then letters, digits, underscores."""
    return bool(_IDENT.match(text)) and not text.startswith("__")


def parse(text: str, *, what: str = "expression") -> Node:
    """Parse worksheet expression text into a tree (raises TemplateError)."""
    if not isinstance(text, str):
        raise TemplateError(f"{what}: expected an expression as text, got {type(text).__name__}")
    if len(text) > MAX_TEXT:
        raise LimitError(f"{what}: expression is {len(text)} characters long (limit {MAX_TEXT})")
    source = _powers(text).strip()
    if not source:
        raise TemplateError(f"{what}: empty expression")
    if source.count("(") > MAX_DEPTH:
        # The parser itself recurses; refuse absurd nesting before it does.
        depth = _paren_depth(source)
        if depth > MAX_DEPTH:
            raise LimitError(f"{what}: parentheses nested {depth} deep (limit {MAX_DEPTH})")
    if "otherwise" in source:
        source = _otherwise_as_else(source)
    if _MAYBE_LITERAL.search(source):
        source = _quantity_literals(source)
    try:
        with warnings.catch_warnings():  # Python's own warnings (1if) are not the user's
            warnings.simplefilter("ignore", SyntaxWarning)
            tree = ast.parse(source, mode="eval")
    except SyntaxError as exc:
        col = f" at column {exc.offset}" if exc.offset else ""
        raise TemplateError(f"{what}: cannot parse {_short(text)!r}{col}: {exc.msg}") from None
    except (RecursionError, MemoryError):
        raise LimitError(f"{what}: expression nested too deeply (limit {MAX_DEPTH})") from None
    return _convert(tree.body, _short(text), what, 0)


def _powers(text: str) -> str:
    """``^`` as Python's ``**``, outside text literals: a text ``"As (in^2)"`` keeps its
    ``^``."""
    if "^" not in text:
        return text
    out, quote, i = [], None, 0
    while i < len(text):
        c = text[i]
        if quote:
            if c == "\\" and i + 1 < len(text):  # an escaped character stays in the text
                out.append(text[i : i + 2])
                i += 2
                continue
            if c == quote:
                quote = None
        elif c in "\"'":
            quote = c
        elif c == "^":
            c = "**"
        out.append(c)
        i += 1
    return "".join(out)


def _otherwise_as_else(source: str) -> str:
    """The word ``otherwise`` (outside strings) as Python's ``else``; a comma before it is
    read as Mathcad writes it (``1 if x > 0, otherwise 0``)."""
    import io
    import tokenize

    try:
        tokens = list(tokenize.generate_tokens(io.StringIO(source).readline))
    except (tokenize.TokenError, SyntaxError):
        return source  # ast.parse says what is wrong
    starts = [0]
    for line in source.splitlines(keepends=True):
        starts.append(starts[-1] + len(line))
    out = source
    for i in reversed(range(len(tokens))):
        tok = tokens[i]
        if tok.type == tokenize.NAME and tok.string == "otherwise":
            at = starts[tok.start[0] - 1] + tok.start[1]
            out = out[:at] + "else" + out[at + len("otherwise") :]
            before = tokens[i - 1] if i else None
            if before is not None and before.type == tokenize.OP and before.string == ",":
                # "1 if x > 0, otherwise 0", as the report prints a condition
                comma = starts[before.start[0] - 1] + before.start[1]
                out = out[:comma] + " " + out[comma + 1 :]
    return out


_MAYBE_LITERAL = re.compile(r"[\d.]\s*(?:[^\W\d]|%)")
#: Words that may follow a number without being its unit (``1 if x > 0 otherwise 0``).
_NOT_UNITS = frozenset({"if", "else", "and", "or", "not", "in", "is", "for", "otherwise"})


def _quantity_literals(source: str) -> str:
    """Each number followed by a unit (``20 mm``, ``9.81 m/s**2``, ``5 W/(m*K)``) as the
    Python ``(20 @ "mm")``, which :func:`_convert` reads as a :class:`Quantity` (``@`` is no
    operator of the language). The unit is the name after the number and what is joined to it
    without a space by ``*``, ``/``, ``**`` and a power: ``2 m * x`` is 2 m times x, and so is
    ``10 mm*cos(x)`` 10 mm times cos(x) (a name followed by ``(`` is a call, never a unit)."""
    import io
    import tokenize

    try:
        tokens = [
            t
            for t in tokenize.generate_tokens(io.StringIO(source).readline)
            if t.type not in (tokenize.NL, tokenize.NEWLINE, tokenize.ENDMARKER)
        ]
    except (tokenize.TokenError, SyntaxError):
        return source  # ast.parse says what is wrong
    starts = [0]
    for line in source.splitlines(keepends=True):
        starts.append(starts[-1] + len(line))

    def at(pos: tuple[int, int]) -> int:
        return starts[pos[0] - 1] + pos[1]

    spans = []
    i = 0
    while i < len(tokens) - 1:
        num, name = tokens[i], tokens[i + 1]
        if num.type == tokenize.NUMBER and name.string in ("i", "j") and name.start == num.end:
            # 4i, as Mathcad writes the imaginary unit: Python's 4j (j alone stays a name)
            unit = tokens[i + 2] if i + 2 < len(tokens) else None
            if unit is not None and unit.type == tokenize.NAME and unit.string not in _NOT_UNITS:
                end = _unit_end(tokens, i + 2)  # 4i ohm: refused with what to write
                spans.append((at(num.start), at(name.end), at(unit.start), at(tokens[end - 1].end)))
                i = end
                continue
            spans.append((at(num.start), at(num.end), at(name.start), at(name.end)))
            i += 2
        elif (
            num.type == tokenize.NUMBER
            and name.type == tokenize.NAME
            and name.string not in _NOT_UNITS
            and name.start[0] == num.end[0]
        ):
            end = _unit_end(tokens, i + 1)
            spans.append((at(num.start), at(num.end), at(name.start), at(tokens[end - 1].end)))
            i = end
        elif num.type == tokenize.NUMBER and name.string == "%" and name.start[0] == num.end[0]:
            # a percentage (Mathcad's 15%); the language has no % operator, so '7 % 2' (a
            # remainder in Python) stays an error that points to mod(x, y)
            after = tokens[i + 2] if i + 2 < len(tokens) else None
            signed = (  # '7 % -2', a remainder by -2 as Python reads it: left an error too
                after is not None
                and after.string in ("-", "+")
                and i + 3 < len(tokens)
                and tokens[i + 3].start == after.end
                and after.start != name.end
            )
            if not signed and (
                after is None
                or not (after.type in (tokenize.NUMBER, tokenize.NAME) or after.string == "(")
            ):
                spans.append((at(num.start), at(num.end), at(name.start), at(name.end)))
            i += 2
        else:
            i += 1
    out = source
    for n0, n1, u0, u1 in reversed(spans):
        unit = out[u0:u1].replace('"', "")
        if unit in ("i", "j") and u0 == n1:
            out = f"{out[:n0]}{out[n0:n1]}j{out[u1:]}"
            continue
        number = out[n0:n1]
        if number[-1] in "ij":  # 4i ohm
            number = number[:-1] + "j"
        out = f"{out[:n0]}({number} @ {unit!r}){out[u1:]}"
    return out


def _unit_end(tokens, i: int) -> int:
    """Index after the last token of the unit that starts with the name ``tokens[i]``: names
    joined by ``*`` and ``/`` with no space, each with a power, and parenthesised groups."""
    import tokenize

    def joined(j: int) -> bool:
        return j < len(tokens) and tokens[j].start == tokens[j - 1].end

    j, depth = i + 1, 0
    while j < len(tokens) and joined(j):
        tok = tokens[j]
        if tok.string == "**" and joined(j + 1):
            k = j + 1
            fraction = _fraction_end(tokens, k, joined)  # m^(1/2)
            if fraction:
                j = fraction
                continue
            if tokens[k].string in "-+" and joined(k + 1):
                k += 1
            if tokens[k].type != tokenize.NUMBER:
                break
            j = k + 1
        elif tok.string in ("*", "/") and joined(j + 1):
            k = j + 1
            while tokens[k].string == "(" and joined(k + 1):
                k, depth = k + 1, depth + 1
            if tokens[k].type != tokenize.NAME or tokens[k].string in _NOT_UNITS:
                break
            if joined(k + 1) and tokens[k + 1].string == "(":  # 10 mm*cos(x): a call
                break
            j = k + 1
        elif tok.string == ")" and depth:
            j, depth = j + 1, depth - 1
        else:
            break
    return j


def _fraction_end(tokens, k: int, joined) -> int:
    """Index after a power written as a fraction, ``(1/2)`` or ``(-3/2)`` at ``tokens[k]``,
    joined with no space; 0 when there is none."""
    import tokenize

    want = ["(", "-", tokenize.NUMBER, "/", tokenize.NUMBER, ")"]
    j = k
    for w in want:
        if j >= len(tokens) or (j > k and not joined(j)):
            return 0
        tok = tokens[j]
        if w == "-":
            if tok.string in ("-", "+"):
                j += 1
            continue
        if tok.type != w if isinstance(w, int) else tok.string != w:
            return 0
        j += 1
    return j


def _short(text: str, limit: int = 80) -> str:
    """The expression as quoted in messages: long texts are cut."""
    return text if len(text) <= limit else text[: limit - 20] + " ... " + text[-15:]


def _paren_depth(source: str) -> int:
    depth = best = 0
    for ch in source:
        if ch == "(":
            depth += 1
            best = max(best, depth)
        elif ch == ")":
            depth -= 1
    return best


def _convert(node: ast.AST, text: str, what: str, depth: int) -> Node:
    if depth > MAX_DEPTH:
        raise LimitError(f"{what}: expression nested more than {MAX_DEPTH} deep")
    d = depth + 1
    if isinstance(node, ast.Constant):
        if isinstance(node.value, complex):  # 4j (or 4i, read as 4j): only the imaginary part
            return Imaginary(_finite(node.value.imag, text, what))
        if isinstance(node.value, bool) or not isinstance(node.value, (int, float, str)):
            raise TemplateError(f"{what}: {node.value!r} is not allowed in {text!r}")
        if isinstance(node.value, str):
            return Text(node.value)
        return Number(_finite(node.value, text, what))
    if isinstance(node, ast.Name):
        if not is_identifier(node.id):
            raise TemplateError(f"{what}: name {node.id!r} is not allowed in {text!r}")
        return Name(node.id)
    if isinstance(node, ast.UnaryOp):
        ops = {ast.USub: "-", ast.UAdd: "+", ast.Not: "not"}
        if type(node.op) not in ops:
            raise TemplateError(f"{what}: operator not allowed in {text!r}")
        return Unary(ops[type(node.op)], _convert(node.operand, text, what, d))
    if isinstance(node, ast.BinOp):
        if isinstance(node.op, ast.MatMult):
            return _quantity(node, text, what)
        if isinstance(node.op, ast.Mod):
            raise TemplateError(
                f"{what}: % between two values is not an operator of the language in {text!r}: "
                "mod(x, y) is the remainder, and a percentage is a number followed by % (15 %)"
            )
        if type(node.op) not in _BINOPS:
            raise TemplateError(
                f"{what}: operator {type(node.op).__name__} not allowed in {text!r} (use + - * / ^)"
            )
        return Binary(
            _BINOPS[type(node.op)],
            _convert(node.left, text, what, d),
            _convert(node.right, text, what, d),
        )
    if isinstance(node, ast.Compare):
        ops = []
        for op in node.ops:
            if type(op) not in _CMPOPS:
                raise TemplateError(f"{what}: comparison not allowed in {text!r}")
            ops.append(_CMPOPS[type(op)])
        operands = [node.left, *node.comparators]
        return Compare(tuple(ops), tuple(_convert(o, text, what, d) for o in operands))
    if isinstance(node, ast.BoolOp):
        op = "and" if isinstance(node.op, ast.And) else "or"
        return Logic(op, tuple(_convert(v, text, what, d) for v in node.values))
    if isinstance(node, ast.Call):
        if not isinstance(node.func, ast.Name) or not is_identifier(node.func.id):
            raise TemplateError(
                f"{what}: only plain function calls like f(x) are allowed in {text!r}"
            )
        if node.keywords:
            raise TemplateError(f"{what}: keyword arguments are not allowed in {text!r}")
        if any(isinstance(a, ast.Starred) for a in node.args):
            raise TemplateError(f"{what}: starred arguments are not allowed in {text!r}")
        return Call(node.func.id, tuple(_convert(a, text, what, d) for a in node.args))
    if isinstance(node, ast.List):
        return _matrix(node, text, what, d)
    if isinstance(node, ast.Subscript):
        index = node.slice
        items = index.elts if isinstance(index, ast.Tuple) else [index]
        if not 1 <= len(items) <= 2 or any(isinstance(i, (ast.Slice, ast.Starred)) for i in items):
            raise TemplateError(f"{what}: write v[i] or M[i, j] (no slices) in {text!r}")
        return Index(
            _convert(node.value, text, what, d),
            tuple(_convert(i, text, what, d) for i in items),
        )
    if isinstance(node, ast.IfExp):
        return IfElse(
            _convert(node.body, text, what, d),
            _convert(node.test, text, what, d),
            _convert(node.orelse, text, what, d),
        )
    kind = type(node).__name__
    raise TemplateError(f"{what}: {kind} is not allowed in worksheet expressions ({text!r})")


def _quantity(node: ast.BinOp, text: str, what: str) -> Quantity:
    """``(20 @ "mm")``, as :func:`_quantity_literals` writes ``20 mm``."""
    number, unit = node.left, node.right
    if not (
        isinstance(number, ast.Constant)
        and isinstance(number.value, (int, float))
        and not isinstance(number.value, bool)
        and isinstance(unit, ast.Constant)
        and isinstance(unit.value, str)
    ):
        if isinstance(number, ast.Constant) and isinstance(number.value, complex):
            z = f"{number_text(number.value.imag)}i"
            raise TemplateError(
                f"{what}: a unit after the imaginary number {z} in {text!r}: write the unit "
                f"as a factor, {z}*1 {unit.value}"
            )
        raise TemplateError(f"{what}: operator MatMult not allowed in {text!r} (use + - * / ^)")
    return Quantity(_finite(number.value, text, what), unit.value.replace("**", "^"))


def _finite(number: int | float, text: str, what: str) -> float:
    """A number of the text as a float; one past the largest double is refused (an int of
    310 digits raises OverflowError in float(), a float literal becomes inf)."""
    try:
        value = float(number)
    except OverflowError:
        value = math.inf
    if not math.isfinite(value):
        raise TemplateError(f"{what}: a number in {text!r} is too large (limit about 1.8e308)")
    return value


def _matrix(node: ast.List, text: str, what: str, depth: int) -> Matrix:
    """``[a, b]`` is a column; ``[[a, b], [c, d]]`` a matrix by rows (``[[a, b]]`` a row);
    a column with some bracketed elements, ``[n, [0, 30]]``, holds those arrays as elements
    (a nested array)."""
    if not node.elts:
        raise TemplateError(f"{what}: an empty vector [] in {text!r}")
    nested = [isinstance(e, ast.List) for e in node.elts]
    if not all(nested):
        return Matrix(tuple((_convert(e, text, what, depth),) for e in node.elts))
    rows = []
    for r in node.elts:
        if any(isinstance(e, ast.List) for e in r.elts) or not r.elts:
            raise TemplateError(f"{what}: a matrix has two levels of brackets, in {text!r}")
        rows.append(tuple(_convert(e, text, what, depth) for e in r.elts))
    if len({len(r) for r in rows}) != 1:
        lengths = ", ".join(str(len(r)) for r in rows)
        raise TemplateError(
            f"{what}: the rows of a matrix differ in length ({lengths}) in {text!r}"
        )
    return Matrix(tuple(rows))


def map_children(node: Node, f) -> Node:
    """``node`` with ``f`` applied to each direct sub-tree (a leaf is returned as it is)."""
    if isinstance(node, Unary):
        return Unary(node.op, f(node.operand))
    if isinstance(node, Binary):
        return Binary(node.op, f(node.left), f(node.right))
    if isinstance(node, Compare):
        return Compare(node.ops, tuple(f(o) for o in node.operands))
    if isinstance(node, Logic):
        return Logic(node.op, tuple(f(v) for v in node.values))
    if isinstance(node, Call):
        return Call(node.func, tuple(f(a) for a in node.args))
    if isinstance(node, IfElse):
        return IfElse(f(node.value), f(node.condition), f(node.other))
    if isinstance(node, Index):
        return Index(f(node.target), tuple(f(i) for i in node.indices))
    if isinstance(node, Matrix):
        return Matrix(tuple(tuple(f(e) for e in row) for row in node.rows))
    return node


class _Children(Visitor):
    """The direct sub-trees of a node."""

    def visit_Number(self, node: Number) -> tuple[Node, ...]:
        return ()

    visit_Text = visit_Name = visit_Quantity = visit_Imaginary = visit_Number

    def visit_Unary(self, node: Unary) -> tuple[Node, ...]:
        return (node.operand,)

    def visit_Binary(self, node: Binary) -> tuple[Node, ...]:
        return (node.left, node.right)

    def visit_Compare(self, node: Compare) -> tuple[Node, ...]:
        return node.operands

    def visit_Logic(self, node: Logic) -> tuple[Node, ...]:
        return node.values

    def visit_Call(self, node: Call) -> tuple[Node, ...]:
        return node.args

    def visit_Matrix(self, node: Matrix) -> tuple[Node, ...]:
        return tuple(e for row in node.rows for e in row)

    def visit_Index(self, node: Index) -> tuple[Node, ...]:
        return (node.target, *node.indices)

    def visit_IfElse(self, node: IfElse) -> tuple[Node, ...]:
        return (node.value, node.condition, node.other)


_CHILDREN = _Children()


def children(node: Node) -> tuple[Node, ...]:
    """The nodes directly below ``node`` (none for a name or a number)."""
    return _CHILDREN.visit(node)


def walk(node: Node):
    """Yield every node of the tree, parents first."""
    yield node
    for child in children(node):
        yield from walk(child)


def names(node: Node) -> set[str]:
    """Names a tree refers to (variables and called functions)."""
    found = set()
    for n in walk(node):
        if isinstance(n, Name):
            found.add(n.id)
        elif isinstance(n, Call):
            found.add(n.func)
    return found


#: Precedence of operators, shared by every printer of text (worksheet text, typed text,
#: Excel): a sub-expression whose level is below its parent's is bracketed.
PREC = {
    "or": 1,
    "and": 2,
    "not": 3,
    "cmp": 4,
    "+": 5,
    "-": 5,
    "*": 6,
    "/": 6,
    "neg": 7,
    "^": 8,
    "atom": 9,
}


def number_text(v: float) -> str:
    """A number as worksheet text: integers without a decimal point."""
    return repr(int(v)) if float(v).is_integer() and abs(v) < 1e15 else repr(float(v))


class TextPrinter(Visitor):
    """Prints a tree as worksheet text; ``visit`` returns (text, precedence level)."""

    def text(self, node: Node, parent: int = 0) -> str:
        s, p = self.visit(node)
        return f"({s})" if p < parent else s

    def visit_Number(self, node: Number) -> tuple[str, int]:
        # a negative number reads back as a unary minus: bracketed as one (under a power)
        level = PREC["neg"] if math.copysign(1.0, node.value) < 0 else PREC["atom"]
        return number_text(node.value), level

    def visit_Imaginary(self, node: Imaginary) -> tuple[str, int]:
        level = PREC["neg"] if math.copysign(1.0, node.value) < 0 else PREC["atom"]
        return number_text(node.value) + "i", level

    def visit_Quantity(self, node: Quantity) -> tuple[str, int]:
        # a product for the precedence of what is around it: F/(20 mm^2) keeps its brackets
        return f"{number_text(node.value)} {node.unit}", PREC["*"]

    def visit_Text(self, node: Text) -> tuple[str, int]:
        return '"' + node.value.replace('"', "") + '"', PREC["atom"]

    def visit_Name(self, node: Name) -> tuple[str, int]:
        return node.id, PREC["atom"]

    def visit_Call(self, node: Call) -> tuple[str, int]:
        return f"{node.func}({', '.join(self.text(a) for a in node.args)})", PREC["atom"]

    def visit_Unary(self, node: Unary) -> tuple[str, int]:
        if node.op == "not":
            return "not " + self.text(node.operand, PREC["not"]), PREC["not"]
        if isinstance(node.operand, Quantity):  # -20 mm, not -(20 mm)
            return node.op + self.visit(node.operand)[0], PREC["neg"]
        return node.op + self.text(node.operand, PREC["neg"]), PREC["neg"]

    def visit_Binary(self, node: Binary) -> tuple[str, int]:
        p = PREC[node.op]
        if node.op == "^":
            return f"{self.text(node.left, p + 1)}^{self.text(node.right, p)}", p
        return f"{self.text(node.left, p)} {node.op} {self.text(node.right, p + 1)}", p

    def visit_Compare(self, node: Compare) -> tuple[str, int]:
        p = PREC["cmp"]
        parts = [self.text(node.operands[0], p + 1)]
        for op, o in zip(node.ops, node.operands[1:]):
            parts += [op, self.text(o, p + 1)]
        return " ".join(parts), p

    def visit_Logic(self, node: Logic) -> tuple[str, int]:
        p = PREC[node.op]
        return f" {node.op} ".join(self.text(v, p + 1) for v in node.values), p

    def visit_Matrix(self, node: Matrix) -> tuple[str, int]:
        if all(len(r) == 1 for r in node.rows):
            return "[" + ", ".join(self.text(r[0]) for r in node.rows) + "]", PREC["atom"]
        rows = ("[" + ", ".join(self.text(e) for e in r) + "]" for r in node.rows)
        return "[" + ", ".join(rows) + "]", PREC["atom"]

    def visit_Index(self, node: Index) -> tuple[str, int]:
        inner = ", ".join(self.text(i) for i in node.indices)
        return f"{self.text(node.target, PREC['atom'])}[{inner}]", PREC["atom"]

    def visit_IfElse(self, node: IfElse) -> tuple[str, int]:
        p = PREC["or"] - 1
        cond = self.text(node.condition, p + 1)
        return f"{self.text(node.value, p + 1)} if {cond} otherwise {self.text(node.other, p)}", p


def to_text(node: Node) -> str:
    """Print a tree back as worksheet text (fully parenthesised where needed)."""
    return TextPrinter().text(node)
