"""Translating a Mathcad worksheet (regions in reading order) into the worksheet language.

Mathcad's math trees become the language's expression trees (:mod:`workbook.language.expr`), names
go through :mod:`.names`, units through :mod:`.units`, built-in functions through
:mod:`.functions`. Every result Mathcad stored becomes a printed value. What the language
cannot express is kept as a list of untranslated regions (id, what, why); a definition
that uses an untranslated one is untranslated too.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from ..language import expr as ex
from ..language.visitor import Visitor
from . import names as nm
from .functions import (
    MATHCAD_FUNCTIONS,
    OPERATOR_FUNCTIONS,
    OPERATOR_FUNCTIONS_2,
    ORIGIN_FUNCTIONS,
    REFUSED,
    WRITERS,
    language_functions,
)
from .reader import MNode, Region, Worksheet
from .symbols import Sym, Unknown, Untranslatable, matrix_size, whole_number
from .symbols import key as _key
from .symbols import what as _what
from .units import FORMULA_UNITS, result_unit


@dataclass
class Item:
    """One entry of the worksheet in Mathcad's order."""

    kind: str  # note | input | definition | function | range
    region: str = ""
    sym: Sym | None = None
    params: list[Sym] = field(default_factory=list)
    body: ex.Node | None = None
    pieces: list[tuple[ex.Node, ex.Node | None]] | None = None
    value: str = ""  # input: quantity text; note: the text
    unit: str = ""  # display unit (pint text)
    range: tuple[ex.Node, ex.Node | None, ex.Node] | None = None
    range_values: list[float] | None = None
    program: list | None = None  # lines of a program: (indent, [text or tree, ...])
    solve: tuple | None = None  # a solve block: ([(unknown, guess text)], equations, regions)
    chart: list | None = None  # a plot: its traces, [(x, y, range item, points?, number)]


@dataclass
class Result:
    """A result Mathcad stored for one evaluation."""

    region: str
    sym: Sym | None  # what the worksheet evaluates (None: nothing could be)
    name: str  # the Mathcad expression, for messages
    unit: str
    rows: list[tuple[float | None, float | str]]
    argument: Sym | None = None
    # where Mathcad's value is round-off of a larger size (a difference whose terms cancel, a
    # stored 0 among large elements): the absolute tolerance, and why
    round_off: tuple[float, str] | None = None
    #: why the stored values do not fit what the translation computes (a unit of another
    #: dimension): each stays a value, listed as not computable with this reason
    misfit: str = ""


@dataclass
class Skipped:
    region: str
    what: str
    why: str


@dataclass
class Translation:
    items: list[Item] = field(default_factory=list)
    results: list[Result] = field(default_factory=list)
    skipped: list[Skipped] = field(default_factory=list)
    syms: list[Sym] = field(default_factory=list)
    title: str = ""
    ignored: list[str] = field(default_factory=list)  # regions that show and define nothing
    origin: int = 0
    solve_tolerance: float = 1e-3  # Mathcad's TOL (its default, or the largest the sheet sets)


_BINARY = {"plus": "+", "minus": "-", "mult": "*", "div": "/", "pow": "^"}
_COMPARE = {
    "equal": "==",
    "lessThan": "<",
    "greaterThan": ">",
    "lessOrEqual": "<=",
    "greaterOrEqual": ">=",
    "notEqual": "!=",
}
_BINDERS = {
    "summation": "sum",
    "product": "product",
    "integral": "integral",
    "derivative": "diff",
}


def _uses(sym: Sym) -> str:
    """Why a use of an untranslated name is untranslated: the name and the first reason."""
    root = sym.broken.split(", which is not translated: ", 1)[-1]
    return f"uses {sym.mathcad}, which is not translated: {root}"


class ExprTranslator(Visitor):
    """Mathcad math element -> expression tree, names resolved in a scope."""

    def __init__(self, tr: Translator, local: dict[tuple[str, str], Sym] | None = None):
        self.tr = tr
        self.local = local or {}
        self.ranges: list[Sym] = []  # range variables this expression uses

    def visit(self, node: MNode, *args):  # dispatch on the Mathcad tag
        method = getattr(self, "visit_" + node.tag, None)
        if method is None:
            raise Untranslatable(f"{_what(node.tag)} is not in the language yet")
        return method(node, *args)

    def visit_real(self, node: MNode) -> ex.Node:
        try:
            value = float(node.text.strip())
        except ValueError:
            raise Untranslatable(f"the number {node.text.strip()!r}") from None
        if not math.isfinite(value):
            raise Untranslatable(f"the number {node.text.strip()!r} is not finite")
        # Mathcad writes (-1)^2 as a literal -1 under the power: the language's tree has the
        # minus as an operator, so that printing brackets it where the precedence needs
        if math.copysign(1.0, value) < 0:
            return ex.Unary("-", ex.Number(-value))
        return ex.Number(value)

    def visit_parens(self, node: MNode) -> ex.Node:
        return self.visit(node.children[0])

    def visit_id(self, node: MNode) -> ex.Node:
        key = _key(node)
        if node.attrs.get("labels") == "UNIT" and not key[1] and key[0] in FORMULA_UNITS:
            return ex.Name(self.tr.unit_sym(key[0]).token())  # labelled a unit in Mathcad
        sym = self.local.get(key) or self.tr.scope.get(key)
        if sym is not None:
            if sym.broken:
                raise Untranslatable(_uses(sym))
            if sym.kind == "func":
                raise Untranslatable(f"uses the function {sym.mathcad} as a value")
            if sym.is_range and sym not in self.local.values():
                self.ranges.append(sym)
            return ex.Name(sym.token())
        text, sub = key
        if not sub and text == "π":
            return ex.Name("pi")
        if not sub and text == "e":
            return ex.Call("exp", (ex.Number(1.0),))
        if not sub and text == "ORIGIN":  # the ORIGIN in force where Mathcad reads it
            return ex.Number(float(self.tr.origin))
        # Mathcad Prime labels each name: one labelled a variable is never a unit
        if not sub and text in FORMULA_UNITS and node.attrs.get("labels") in (None, "UNIT"):
            return ex.Name(self.tr.unit_sym(text).token())
        raise Untranslatable(f"{nm.mathcad_text(text, sub)} is not defined before it is used")

    def visit_str(self, node: MNode) -> ex.Node:
        return ex.Text(node.text)

    def visit_apply(self, node: MNode) -> ex.Node:
        op, args = node.children[0], node.children[1:]
        if len(args) == 1 and args[0].tag == "sequence":
            args = args[0].children
        tag = op.tag
        if tag in _BINARY and len(args) == 2:
            left, right = self.value(args[0]), self.value(args[1])
            if tag == "div":
                left, right = self._radians(left, right), self._radians(right, left)
            return ex.Binary(_BINARY[tag], left, right)
        if tag in _COMPARE and len(args) == 2:
            return self._compare(tag, args)
        if tag == "neg" and len(args) == 1:
            return ex.Unary("-", self.value(args[0]))
        if tag in ("and", "or") and len(args) == 2:
            return _logic(tag, [self.condition(a) for a in args])
        if tag == "not" and len(args) == 1:
            return ex.Unary("not", self.condition(args[0]))
        if tag == "nthRoot" and len(args) == 2:
            n, x = self.value(args[0]), self.value(args[1])
            return ex.Binary("^", x, ex.Binary("/", ex.Number(1.0), n))
        if tag == "absval" and len(args) == 1:
            return self._absval(self.value(args[0]))
        if tag in OPERATOR_FUNCTIONS and len(args) == 1:
            return self._builtin(OPERATOR_FUNCTIONS[tag], tag, [self.value(args[0])])
        if tag in OPERATOR_FUNCTIONS_2 and len(args) == 2:
            pair = [self.value(a) for a in args]
            return self._builtin(OPERATOR_FUNCTIONS_2[tag], tag, pair)
        if tag == "matrow" and len(args) == 2:
            return self._row(args)
        if tag == "id":
            if _is_if(node):
                cond, a, b = _if_args(node)
                return ex.IfElse(self.value(a), self.condition(cond), self.value(b))
            return self._call(op, args)
        if tag == "indexer" and len(args) == 2:
            return self._index(args)
        if tag == "matcol" and len(args) == 2:
            return self._column(args)
        if tag in _BINDERS:
            return self._binder(tag, args)
        if tag == "vectorize" and len(args) == 1:
            return self._vectorize(self.value(args[0]))
        if tag == "Find":
            return self.tr.find(self, args, op.attrs.get("method", ""))
        if tag in ("Maximize", "Minimize"):
            return self.tr.extremum(self, args, tag == "Maximize")
        raise Untranslatable(f"{_what(tag)} is not in the language yet")

    def value(self, node: MNode) -> ex.Node:
        """``node`` where Mathcad uses a number: a comparison (Mathcad's 1 or 0) is
        ``(1 if C otherwise 0)``."""
        return _as_number(self.visit(node))

    def condition(self, node: MNode) -> ex.Node:
        """``node`` where Mathcad tests it (if, while, if()): a product of comparisons is
        ``C1 and C2`` (Mathcad's idiom for and), a sum of them ``C1 or C2``, a comparison
        itself; any other value is true where it is not 0 (``X != 0``)."""
        inner = _unparen(node)
        if inner.tag == "apply" and len(inner.children) == 3:
            op = inner.children[0].tag
            if op in ("mult", "plus") and all(_is_condition(a) for a in inner.children[1:]):
                word = "and" if op == "mult" else "or"
                return _logic(word, [self.condition(a) for a in inner.children[1:]])
        tree = self.visit(node)
        if _is_boolean(tree):
            return tree
        return ex.Compare(("!=",), (tree, ex.Number(0.0)))

    def _compare(self, tag: str, args: list[MNode]) -> ex.Node:
        """A comparison; Mathcad's ranged inequality ``a <= t <= b`` (stored as a comparison
        whose left side is an inequality, without brackets) is the chain ``a <= t <= b``."""
        left = args[0]
        if (
            tag in _INEQUALITY
            and left.tag == "apply"
            and len(left.children) == 3
            and left.children[0].tag in _INEQUALITY
        ):
            chain = self._compare(left.children[0].tag, left.children[1:])
            if isinstance(chain, ex.Compare):
                return ex.Compare(
                    (*chain.ops, _COMPARE[tag]), (*chain.operands, self.value(args[1]))
                )
        return ex.Compare((_COMPARE[tag],), (self.value(args[0]), self.value(args[1])))

    def _radians(self, node: ex.Node, other: ex.Node) -> ex.Node:
        """``node / rad`` where ``node`` is an angle in degrees (or another angle unit) and
        ``other`` a bare number: Mathcad's angles are plain numbers in radians, so its
        ``alpha*pi/180`` of ``alpha = 6 deg`` is 0.1047*pi/180; the language refuses an angle
        divided by a bare number (a plain number of degrees), so the angle is made the plain
        number in radians Mathcad divides."""
        if not isinstance(other, ex.Number) or isinstance(node, ex.Number):
            return node
        unit = self.tr.at_import().unit(node)
        from ..language.unitrules import angle_in

        if unit is None or not angle_in(unit):
            return node
        return ex.Binary("/", node, ex.Name(self.tr.unit_sym("rad").token()))

    def bound(self, var: MNode, body: MNode) -> tuple[ex.Node, ex.Node]:
        """A variable bound by a sum, product, integral, derivative or root, and the body in
        which it is bound."""
        if var.tag != "id":
            raise Untranslatable(f"a bound variable that is {_what(var.tag)}")
        key = _key(var)
        # an argument of the sheet (the language declares a bound variable's unit there)
        sym = self.tr.new_sym("param", nm.identifier(*key), nm.mathcad_text(*key))
        outer = self.local.get(key) or self.tr.scope.get(key)
        if outer is not None and (outer.kind == "param" or outer.is_range):
            sym.hint_sym = outer  # d/dt f(t) inside a function of t: t's unit
        inner = ExprTranslator(self.tr, {**self.local, key: sym})
        tree = inner.visit(body)
        self.ranges += [r for r in inner.ranges if r is not sym]
        return tree, ex.Name(sym.token())

    def _binder(self, tag: str, args: list[MNode]) -> ex.Node:
        name = _BINDERS[tag]
        lam = next((a for a in args if a.tag == "lambda"), None)
        bounds = next((a for a in args if a.tag == "bounds"), None)
        if lam is None or len(lam.children) != 2:
            raise Untranslatable(f"{_what(tag)} without a bound variable")
        bvars = lam.children[0].children
        if len(bvars) != 1:
            raise Untranslatable(f"{_what(tag)} over {len(bvars)} variables")
        body, var = self.bound(bvars[0], lam.children[1])
        if tag == "derivative":
            if bounds is not None:
                raise Untranslatable("a derivative with bounds")
            order = _derivative_order(next((a for a in args if a.tag == "degree"), None))
            if order == 1:
                return self._builtin(name, tag, [body, var])
            return self._builtin(name, tag, [body, var, ex.Number(float(order))])
        if bounds is None and tag in ("summation", "product"):
            a, b = self._range_bounds(bvars[0], tag)
            return self._builtin(name, tag, [body, var, a, b])
        if bounds is None or len(bounds.children) != 2:
            raise Untranslatable(f"{_what(tag)} over a range variable (no bounds)")
        a, b = (self.visit(c) for c in bounds.children)
        if tag == "integral":
            self.tr.sym_of(var).hint = a  # the variable's unit is its bounds'
        return self._builtin(name, tag, [body, var, a, b])

    def _range_bounds(self, var: MNode, tag: str) -> tuple[ex.Node, ex.Node]:
        """Σ over a range variable: the first and last values of its range (of step 1)."""
        sym = self.tr.scope.get(_key(var)) if var.tag == "id" else None
        item = self.tr.range_of(var) if sym is not None and sym.is_range else None
        if item is None or sym.broken:
            raise Untranslatable(f"{_what(tag)} over a range variable that is not translated")
        values = item.range_values or []
        steps = {b - a for a, b in zip(values, values[1:])}
        if not values or steps - {1.0} or any(v != int(v) for v in values):
            raise Untranslatable(f"{_what(tag)} over a range variable not of whole steps of 1")
        # the range's values as the import found them (a range's bounds are known at import)
        return ex.Number(float(values[0])), ex.Number(float(values[-1]))

    def _root(self, args: list[MNode]) -> ex.Node:
        """Mathcad's root(f(x), x, a, b), or root(f(x), x) from the current value of x."""
        if len(args) not in (2, 4):
            raise Untranslatable(f"root() with {len(args)} arguments")
        body, var = self.bound(args[1], args[0])
        rest = [self.visit(a) for a in args[2:]] if len(args) == 4 else [self.visit(args[1])]
        self.tr.sym_of(var).hint = rest[0]  # the unknown's unit is its bounds' (or guess's)
        return self._builtin("root", "root", [body, var, *rest])

    def visit_matrix(self, node: MNode) -> ex.Node:
        """Mathcad's matrix (rows x cols, stored column by column) as [a, b] or [[a, b], ...]."""
        rows, cols = matrix_size(node)
        if rows * cols != len(node.children) or rows * cols == 0:
            raise Untranslatable("a matrix whose size does not match its elements")
        cells = [self.value(c) for c in node.children]
        if cols == 1 and all(isinstance(c, ex.Matrix) for c in cells):
            raise Untranslatable(
                "a column whose every element is a vector written out (the language reads "
                "[[a, b], [c, d]] as a matrix by rows)"
            )
        return ex.Matrix(
            tuple(tuple(cells[c * rows + r] for c in range(cols)) for r in range(rows))
        )

    def _index(self, args: list[MNode]) -> ex.Node:
        target, index = args[0], args[1]
        indices = [self.value(i) for i in (index.children if index.tag == "sequence" else [index])]
        shift = self.tr.sheet_origin - self.tr.origin  # ORIGIN redefined after the first index
        if shift:
            indices = [ex.Binary("+", i, ex.Number(float(shift))) for i in indices]
        return ex.Index(self.value(target), tuple(indices))

    def _column(self, args: list[MNode]) -> ex.Node:
        """Mathcad's column M<j>: submatrix(M, first row, last row, j, j)."""
        m, j = self.value(args[0]), self.value(args[1])
        shift = self.tr.sheet_origin - self.tr.origin  # ORIGIN redefined after the first index
        if shift:
            j = ex.Binary("+", j, ex.Number(float(shift)))
        o = self.tr.sheet_origin
        last = ex.Call("rows", (m,))
        if o != 1:
            last = (
                ex.Binary("-", last, ex.Number(float(1 - o)))
                if o < 1
                else ex.Binary("+", last, ex.Number(float(o - 1)))
            )
        return ex.Call("submatrix", (m, ex.Number(float(o)), last, j, j))

    def _row(self, args: list[MNode]) -> ex.Node:
        """Prime's row M<i> (a row of one row): submatrix(M, i, i, first column, last)."""
        m, i = self.value(args[0]), self.value(args[1])
        shift = self.tr.sheet_origin - self.tr.origin  # ORIGIN redefined after the first index
        if shift:
            i = ex.Binary("+", i, ex.Number(float(shift)))
        o = self.tr.sheet_origin
        last = ex.Binary("+", ex.Call("cols", (m,)), ex.Number(float(o - 1)))
        return ex.Call("submatrix", (m, i, i, ex.Number(float(o)), last))

    def visit_sqrt(self, node: MNode) -> ex.Node:  # <ml:sqrt> used as an element
        return self._builtin("sqrt", "sqrt", [self.value(node.children[0])])

    def _vectorize(self, tree: ex.Node) -> ex.Node:
        """Mathcad's vectorize: the expression element by element over the vectors in it (of
        one length known at import), as a vector of the elements' expressions."""
        o = self.tr.sheet_origin
        lengths: set[int] = set()
        unknown: list[ex.Node] = []  # arrays whose length the import does not know

        def vector_length(node: ex.Node) -> int | None:
            if isinstance(node, ex.Matrix):
                if all(len(r) == 1 for r in node.rows):
                    return len(node.rows)
                raise Untranslatable("a vectorised expression over a matrix")
            if isinstance(node, ex.Name) and self.tr.is_array(node.id):
                n = self.tr.vector_length_of(node)
                if n is None:
                    unknown.append(node)
                    return -1
                return n
            return None

        def scan(node: ex.Node) -> None:
            n = vector_length(node)
            if n is not None:
                lengths.add(n)
                return
            if isinstance(node, ex.Call):
                for a in node.args:
                    if vector_length(a) is not None and node.func not in _ELEMENTWISE:
                        called = self.tr.mathcad_name(node.func)
                        raise Untranslatable(
                            f"a vectorised call of {called} (only functions of one "
                            "number are applied element by element)"
                        )
            if isinstance(node, ex.Index):
                raise Untranslatable("a vectorised expression with an index")
            for child in ex._CHILDREN.visit(node):
                scan(child)

        scan(tree)
        if unknown:  # the language's vectorize, element by element when it is computed
            return ex.Call("vectorize", (tree,))
        if not lengths:
            return tree  # no vector in it: vectorize changes nothing
        if len(lengths) > 1:
            raise Untranslatable("a vectorised expression over vectors of different lengths")
        (n,) = lengths

        def element(node: ex.Node, k: int) -> ex.Node:
            if isinstance(node, ex.Matrix):
                return node.rows[k][0]
            if vector_length(node) is not None:
                return ex.Index(node, (ex.Number(float(o + k)),))
            return ex.map_children(node, lambda c: element(c, k))

        return ex.Matrix(tuple((element(tree, k),) for k in range(n)))

    def _absval(self, x: ex.Node) -> ex.Node:
        """Mathcad's |x|: abs of a number, but the length of a vector and the determinant of
        a square matrix: ``mag`` (the shape decides at load) where x may be a vector (it
        reads a function's parameter, a program's local, a matrix or a vector the sheet
        defines), else ``abs``."""
        local = {s.token() for s in self.local.values()}
        names = ex.names(x)
        vectors = any(self.tr.is_array(n) for n in names)
        if names & local or vectors or _has_matrix(x):
            return self._builtin("mag", "absval", [x])
        return self._builtin("abs", "absval", [x])

    def _builtin(self, name: str, mathcad: str, args: list[ex.Node]) -> ex.Node:
        if name not in language_functions():
            raise Untranslatable(f"Mathcad's {mathcad}() has no built-in in the language yet")
        return ex.Call(name, tuple(args))

    def _call(self, op: MNode, args: list[MNode]) -> ex.Node:
        key = _key(op)
        sym = self.local.get(key) or self.tr.scope.get(key)
        if sym is not None:
            if sym.broken:
                raise Untranslatable(_uses(sym))
            if sym.kind != "func":
                raise Untranslatable(
                    f"{sym.mathcad}(...) multiplies or indexes a value (not a function call)"
                )
            call = ex.Call(sym.token(), tuple(self.value(a) for a in args))
            if sym.token() in self.tr.inline:
                return self.tr.local_call(sym, call.args)
            self.tr.calls.setdefault(sym, []).append(call.args)
            return call
        text = key[0]
        if text == "root" and not key[1]:
            return self._root(args)
        if text == "matrix" and not key[1] and len(args) == 3:
            return self._matrix_of_function(args)
        if text == "sort" and not key[1] and len(args) == 1:
            values = _eigenvals_argument(args[0])
            if values is not None:  # sorted: Prime's order of eigenvalues does not matter
                inner = self._builtin("eigenvals", "eigenvals", [self.value(values)])
                return self._builtin("sort", "sort", [inner])
        if text == "histogram" and not key[1] and len(args) == 2:
            return self._histogram(args)
        if text in ("min", "max") and len(args) == 1 and args[0].tag == "matrix":
            args = args[0].children  # min of a literal vector: min of its elements
        if text in ORIGIN_FUNCTIONS and not key[1] and self.tr.origin != self.tr.sheet_origin:
            raise Untranslatable(
                f"{text}() where ORIGIN is {self.tr.origin}, and the worksheet's origin (ORIGIN "
                f"at its first index) is {self.tr.sheet_origin}: its indices would be off"
            )
        if text in MATHCAD_FUNCTIONS and not key[1]:
            name, order = MATHCAD_FUNCTIONS[text]
            if order is not None:
                if len(args) != len(order):
                    raise Untranslatable(f"{text}() with {len(args)} arguments")
                args = [args[i] for i in order]
            return self._builtin(name, text, [self.value(a) for a in args])
        if text in REFUSED and not key[1]:
            raise Untranslatable(f"Mathcad's {text}() {REFUSED[text]}")
        raise Untranslatable(
            f"{nm.mathcad_text(*key)}() is neither defined before nor a known built-in"
        )

    def _histogram(self, args: list[MNode]) -> ex.Node:
        """Mathcad's histogram(intervals, data) counts every element of data, a matrix too:
        a matrix of columns known at import is the stack of its columns (the counts do not
        depend on the order of the values)."""
        n, data = self.value(args[0]), self.value(args[1])
        if not isinstance(n, ex.Number):  # a count of intervals: a number the engine sees
            try:
                n = ex.Number(float(_whole_at_import(self.tr, args[0], "histogram()")))
            except Untranslatable:
                pass  # intervals given as a vector, or a count not known at import
        try:
            columns = self.tr.quantity(
                MNode("apply", {}, "", [MNode("id", {}, "cols", []), args[1]])
            )
            columns = int(float(columns.to("").magnitude))
        except Exception:  # noqa: BLE001 - not known at import: the data as it is
            columns = 1
        if 1 < columns <= MAX_STACKED_COLUMNS:
            o = self.tr.sheet_origin
            last = ex.Binary("+", ex.Call("rows", (data,)), ex.Number(float(o - 1)))
            data = ex.Call(
                "stack",
                tuple(
                    ex.Call(
                        "submatrix", (data, ex.Number(float(o)), last, ex.Number(j), ex.Number(j))
                    )
                    for j in (float(o + k) for k in range(columns))
                ),
            )
        return self._builtin("histogram", "histogram", [n, data])

    def _matrix_of_function(self, args: list[MNode]) -> ex.Node:
        """Mathcad's matrix(m, n, f): the m x n matrix of f(i, j), i and j counted from 0
        (whatever ORIGIN), written out as a matrix of calls; m and n must be whole numbers
        known at import. At an ORIGIN other than 0, only a function that does not read its
        arguments is translated: no stored result shows which indices Mathcad gives f there."""
        f = _unparen(args[2])
        sym = (self.local.get(_key(f)) or self.tr.scope.get(_key(f))) if f.tag == "id" else None
        if sym is None or sym.kind != "func":
            raise Untranslatable("matrix(m, n, f) whose f is not the name of a function")
        if sym.broken:
            raise Untranslatable(_uses(sym))
        m, n = (_whole_at_import(self.tr, a, "matrix(m, n, f)") for a in args[:2])
        if m * n > MAX_WRITTEN_ELEMENTS:
            raise Untranslatable(f"matrix(m, n, f) of more than {MAX_WRITTEN_ELEMENTS} elements")
        if self.tr.origin != 0 and not self.tr.ignores_arguments(sym):
            raise Untranslatable(
                f"matrix(m, n, f) at ORIGIN {self.tr.origin} of a function of its indices "
                "(which indices Mathcad gives f there is not known)"
            )
        rows = []
        for i in range(m):
            row = []
            for j in range(n):
                args = (ex.Number(float(i)), ex.Number(float(j)))
                if sym.token() in self.tr.inline:
                    row.append(self.tr.local_call(sym, args))
                    continue
                self.tr.calls.setdefault(sym, []).append(args)
                row.append(ex.Call(sym.token(), args))
            rows.append(tuple(row))
        return ex.Matrix(tuple(rows))


#: Absolute tolerance of a stored 0 (in its unit), and of a value of a difference relative to
#: its terms' size, and of an array's element relative to its largest element: Mathcad's value
#: where terms cancel is round-off of their size (a residual N x - w: 5e-12 for terms up to
#: 2401; an element of a sum of stiffness matrices stored as 0 is -5.8e-11 here, of 1.3e8).
ZERO_TOLERANCE = 1e-12
DIFFERENCE_TOLERANCE = 1e-9
MATRIX_ZERO_TOLERANCE = 1e-15

#: The most elements a construct written out element by element may have (matrix(m, n, f)).
MAX_WRITTEN_ELEMENTS = 10_000


def _whole_at_import(tr: Translator, node: MNode, what: str) -> int:
    """A size Mathcad gives as an expression: a whole number of at least 1 known at import."""
    try:
        value = float(tr.quantity(node).to("").magnitude)
    except Exception:  # noqa: BLE001 - not a value known at import, or not a plain number
        raise Untranslatable(f"{what} whose size is not a number known at import") from None
    if not (math.isfinite(value) and value == int(value) and value >= 1):
        raise Untranslatable(f"{what} whose size {value:g} is not a whole number of at least 1")
    return int(value)


class Translator:
    """Regions in order -> a :class:`Translation`. ``at_import(translator)`` makes what gives
    the unit and value of an expression of the translation so far (the engine's
    :class:`workbook.mathcad.engine.AtImport`; passed in, as the engine builds on this module)."""

    def __init__(self, at_import: Callable[[Translator], Any]):
        self._make_at_import = at_import
        self.scope: dict[tuple[str, str], Sym] = {}
        self.units: dict[str, Sym] = {}
        self.out = Translation()
        self.note: list[str] = []
        self.calls: dict[Sym, list[tuple[ex.Node, ...]]] = {}  # call sites of each function
        self._index: Sym | None = None
        self.region = ""  # the region being translated
        self.given: list[str] | None = None  # regions of the open solve block
        self.constraints: list[MNode] = []
        self.origin = 0  # Mathcad's ORIGIN where the translation is
        self.sheet_origin = 0  # the worksheet's [sheet] origin
        self.writes = 0  # values written to a file (WRITEPRN and friends) so far
        self.shown: dict[str, tuple[str, list]] = {}  # a name -> (unit, values Mathcad stored)
        # local functions of programs, written out at each call: token -> (parameters, body)
        self.inline: dict[str, tuple[list[str], ex.Node]] = {}
        self._at_import = None

    def at_import(self):
        """The engine's unit and value of an expression of the translation so far."""
        if self._at_import is None:
            self._at_import = self._make_at_import(self)
        return self._at_import

    def quantity(self, node: MNode, why: str = "a value that is not known at import"):
        """The value (a pint quantity) of a Mathcad expression of numbers, units, inputs and
        definitions, as the engine computes it."""
        try:
            return self.at_import().quantity(ExprTranslator(self).visit(node))
        except Unknown:
            raise Untranslatable(why) from None

    # -- symbols --------------------------------------------------------------
    def new_sym(self, kind: str, base: str, mathcad: str, region: str = "", **kw) -> Sym:
        sym = Sym(kind, base, mathcad, region=region, **kw)
        self.out.syms.append(sym)
        return sym

    def sym_of(self, name: ex.Name) -> Sym:
        return next(s for s in self.out.syms if s.token() == name.id)

    def mathcad_name(self, name: str) -> str:
        """The name as Mathcad shows it, for a message (a symbol's token is an object id)."""
        sym = next((s for s in self.out.syms if s.token() == name), None)
        return name if sym is None else sym.mathcad

    def unit_sym(self, name: str) -> Sym:
        if name not in self.units:
            self.units[name] = self.new_sym("unit", nm.identifier(name), name)
            self.units[name].unit = FORMULA_UNITS[name]
        return self.units[name]

    def local_call(self, sym: Sym, args: tuple[ex.Node, ...]) -> ex.Node:
        """A call of a program's local function: its body with the arguments in place of
        its parameters."""
        params, body = self.inline[sym.token()]
        if len(params) != len(args):
            raise Untranslatable(f"{sym.mathcad}() called with {len(args)} arguments")
        return _substitute(body, dict(zip(params, args)))

    def ignores_arguments(self, sym: Sym) -> bool:
        """Is the function ``sym`` one whose value does not depend on its arguments (a
        single expression without its parameters)?"""
        if sym.token() in self.inline:
            params, body = self.inline[sym.token()]
            return not ex.names(body) & set(params)
        item = next((i for i in self.out.items if i.sym is sym and i.kind == "function"), None)
        if item is None or item.body is None or item.pieces or item.program:
            return False
        return not ex.names(item.body) & {p.token() for p in item.params}

    def define(self, key: tuple[str, str], kind: str, region: str) -> Sym:
        sym = self.new_sym(kind, nm.identifier(*key), nm.mathcad_text(*key), region)
        self.scope[key] = sym
        return sym

    # -- regions --------------------------------------------------------------
    def run(self, ws: Worksheet, regions: list[Region]) -> Translation:
        self.origin = ws.origin
        self.sheet_origin = self.out.origin = _first_index_origin(ws.origin, regions)
        # Mathcad evaluates global definitions (≡) first, top to bottom, then the others
        first = [r for r in regions if r.math is not None and r.math.tag == "globalDefine"]
        regions = first + [r for r in regions if r not in first]
        for region in regions:
            if region.kind == "text":
                if region.text:
                    if not self.out.title:
                        self.out.title = region.text.splitlines()[0][:120]
                    self.out.items.append(Item("note", region.id, value=region.text))
                continue
            if region.kind == "plot":
                try:
                    self.plot(region)
                except Untranslatable as why:
                    self.skip(region.id, "a plot", str(why))
                continue
            if region.kind == "component":
                self.component(region)
                continue
            if region.kind == "listed":  # a region its reader cannot give: what, and why
                self.skip(region.id, region.text, region.href)
                continue
            if region.kind != "math":
                what = {"plot": "a plot", "picture": "a picture"}.get(region.kind, "a component")
                if region.kind in ("reference", "area"):
                    continue  # followed by the caller; an area holds regions read on their own
                self.skip(region.id, what, "not translated: the language has no such region")
                continue
            if region.math is None:
                continue
            if region.disabled:
                self.skip(region.id, self.describe(region.math), "disabled in Mathcad")
                continue
            try:
                self.math(region)
            except Untranslatable as why:
                self.skip(region.id, self.describe(region.math), str(why))
        self.close_given("a solve block without Find")
        self.argument_units()
        return self.out

    def component(self, region: Region) -> None:
        """A data table of numbers: a matrix definition of its name. Any other component (a
        spreadsheet, ...): not translated; the names it defines are untranslated names
        (never a unit of the same name, as S for siemens)."""
        names = ", ".join(nm.mathcad_text(*_key(n)) for n in region.outputs)
        try:
            self.data_table(region)
            return
        except Untranslatable as error:
            why = str(error)
        self.skip(region.id, "a component" + (f" defining {names}" if names else ""), why)
        for node in region.outputs:
            sym = self.define(_key(node), "var", region.id)
            sym.broken = f"defined by a component (region {region.id}), {why}"

    def data_table(self, region: Region) -> None:
        """A data table (Insert > Data > Table) whose cells are numbers: ``S := [[...]]``
        by rows, or a column vector ``[a, b, ...]`` for a single column."""
        from .table import TABLE_CLSID, grid

        if region.component.get("clsid-buddy", "").upper() != TABLE_CLSID:
            raise Untranslatable("not translated: the language has no such region")
        if len(region.outputs) != 1 or region.outputs[0].tag != "id":
            raise Untranslatable("a data table that defines more than one name")
        if not region.binary:
            raise Untranslatable("a data table without its binary item (its cells)")
        if region.component.get("disable-calc") == "true":
            raise Untranslatable("disabled in Mathcad")
        cells = grid(region.binary)
        if not all(math.isfinite(v) for row in cells for v in row):
            raise Untranslatable("a data table with an empty cell or a value that is not a number")

        def number(v: float) -> ex.Node:
            return ex.Unary("-", ex.Number(-v)) if v < 0 else ex.Number(v)

        body = ex.Matrix(tuple(tuple(number(v) for v in row) for row in cells))
        sym = self.define(_key(region.outputs[0]), "var", region.id)
        rows, cols = len(cells), len(cells[0])
        self.out.items.append(
            Item("note", region.id, value=f"a data table of Mathcad ({rows} x {cols})")
        )
        self.out.items.append(Item("definition", region.id, sym=sym, body=body))

    def plot(self, region: Region) -> None:
        """An X-Y plot: a chart whose series are its traces, each over the range variable its
        expressions use (Mathcad plots a trace at every value of it)."""
        from .plot import payload, traces, x_limits

        if not region.binary:
            raise Untranslatable("a plot without its binary item (its definition)")
        series, why = [], []
        data = payload(region.binary)
        pairs, polar = traces(data)
        limits = None if polar else x_limits(data)
        for n, (x, y) in enumerate(pairs, 1):
            try:
                series.append((*self.trace(x, y, limits), n))
            except Untranslatable as err:
                why.append(f"trace {n}: {err}")
        if not series:
            raise Untranslatable("; ".join(why))
        if why:
            self.skip(region.id, "a plot (traces left out)", "; ".join(why))
        self.out.items.append(Item("chart", region.id, chart=series, value="polar" * polar))

    def trace(self, x: MNode, y: MNode, limits=None) -> tuple:
        free = self._free_names(x)
        if len(free) == 1:
            return self.quick_plot(free[0], x, y, limits if x.tag == "id" else None)
        et = ExprTranslator(self)
        xt, yt = et.visit(x), et.visit(y)
        ranges = list(dict.fromkeys(et.ranges))
        if not ranges:
            return self.points(xt, yt)
        if len(ranges) > 1:
            names = ", ".join(r.mathcad for r in ranges)
            raise Untranslatable(f"over two range variables at once ({names})")
        item = next(
            (i for i in reversed(self.out.items) if i.kind == "range" and i.sym is ranges[0]),
            None,
        )
        if item is None or ranges[0].broken:
            raise Untranslatable(f"the range variable {ranges[0].mathcad} is not translated")
        return xt, yt, item, False

    def _free_names(self, node: MNode) -> list[tuple[str, str]]:
        """Names in ``node`` that the worksheet has not defined (not units, not pi)."""
        out: list[tuple[str, str]] = []

        def walk(n: MNode, head: bool = False) -> None:
            if n.tag == "id":
                key = _key(n)
                if not head and self.scope.get(key) is None and key[0] not in _KNOWN:
                    out.append(key)
                return
            for i, c in enumerate(n.children):
                walk(c, head=n.tag == "apply" and i == 0)

        walk(node)
        return list(dict.fromkeys(out))

    def quick_plot(self, key, x: MNode, y: MNode, limits) -> tuple:
        """Mathcad's quick plot: a name the x expression uses that the worksheet has not
        defined is a variable from -10 to 10 (over the x axis's limits where the user set
        them and x is that name), drawn at QUICK_PLOT_STEPS steps."""
        lo, hi = limits or (-10.0, 10.0)
        sym = self.new_sym("var", nm.identifier(*key), nm.mathcad_text(*key), unit="")
        sym.is_range = True
        step = (hi - lo) / QUICK_PLOT_STEPS
        rng = Item(
            "range",
            "",
            sym=sym,
            range=(ex.Number(lo), ex.Number(lo + step), ex.Number(hi)),
        )
        et = ExprTranslator(self, {key: sym})
        return et.visit(x), et.visit(y), rng, False

    def points(self, xt: ex.Node, yt: ex.Node) -> tuple:
        """A trace without a range variable: a vector against a vector (Mathcad draws a point
        for each element: a series over their index) or a single point (a marker)."""
        lengths = [self.vector_length_of(t) for t in (xt, yt)]
        o = self.sheet_origin
        index = self.index_sym()
        if lengths == [None, None]:  # numbers: one point (the engine refuses a vector here)
            n, xt_, yt_ = 1, xt, yt
        elif None in lengths or lengths[0] != lengths[1]:
            raise Untranslatable(
                "a vector against a vector whose lengths are not both known at import"
                if None in lengths
                else f"a vector of {lengths[1]} against a vector of {lengths[0]}"
            )
        else:
            n = lengths[0]
            at = (ex.Name(index.token()),)
            xt_, yt_ = ex.Index(xt, at), ex.Index(yt, at)
        rng = Item("range", "", sym=index, range=(ex.Number(o), None, ex.Number(o + n - 1)))
        return xt_, yt_, rng, True

    def is_array(self, token: str) -> bool:
        """Does the definition ``token`` (a name of the worksheet) hold a vector or matrix
        as far as the import sees (a matrix written in it, or a name that does)?"""
        memo = self.__dict__.setdefault("_arrays", {})
        if token not in memo:
            memo[token] = False  # a cycle is not an array
            item = next(
                (i for i in self.out.items if i.sym is not None and i.sym.token() == token), None
            )
            if item is not None and item.kind == "definition" and item.body is not None:
                body = item.body
                memo[token] = _has_matrix(body) or any(self.is_array(n) for n in ex.names(body))
        return memo[token]

    def written_out(self, tree: ex.Node) -> ex.Node | None:
        """The expression a name stands for, following definitions of one name by another
        (None: a name not defined before, or defined by a region the translation left out)."""
        seen: set[str] = set()
        while isinstance(tree, ex.Name) and tree.id not in seen:
            seen.add(tree.id)
            item = next(
                (i for i in self.out.items if i.sym is not None and i.sym.token() == tree.id),
                None,
            )
            if item is None or item.kind != "definition" or item.body is None:
                return None
            tree = item.body
        return tree

    def vector_length_of(self, tree: ex.Node) -> int | None:
        """The length of a vector the worksheet defines by name (None: not a known vector)."""
        tree = self.written_out(tree)
        if isinstance(tree, ex.Matrix) and all(len(r) == 1 for r in tree.rows):
            return len(tree.rows)
        return None

    def argument_units(self) -> None:
        """Mathcad's functions are untyped: an argument takes the unit of the values the
        worksheet calls the function with (the first call whose unit is known)."""
        at = self.at_import()

        def unit_of(node: ex.Node) -> str | None:
            u = at.unit(node)
            return None if u is None else ("" if u.dimensionless else str(u))

        for item in self.out.items:
            if item.kind != "function" or item.sym is None or item.sym.kind == "helper":
                continue
            for k, param in enumerate(item.params):
                if param.unit:
                    continue
                for args in self.calls.get(item.sym, []):
                    if k < len(args):
                        unit = unit_of(args[k])
                        if unit is not None:
                            param.unit = unit
                            break
        for sym in self.out.syms:  # variables bound by root, integral, diff
            if sym.kind == "param" and not sym.unit:
                if sym.hint is not None:
                    sym.unit = unit_of(sym.hint) or ""
                elif sym.hint_sym is not None:
                    sym.unit = sym.hint_sym.unit

    def skip(self, region: str, what: str, why: str) -> None:
        self.out.skipped.append(Skipped(region, what, why))

    def describe(self, node: MNode) -> str:
        if node.tag == "define":
            lhs = node.children[0]
            if lhs.tag == "id":
                return f"{nm.mathcad_text(*_key(lhs))} := ..."
            if lhs.tag == "function":
                return f"{nm.mathcad_text(*_key(lhs.children[0]))}(...) := ..."
            if _is_indexer(lhs) and lhs.children[1].tag == "id":
                return f"{nm.mathcad_text(*_key(lhs.children[1]))}[...] := ..."
            return f"{_what(lhs.tag)} := ..."
        if node.tag == "eval":
            return "an evaluation ( = )"
        if node.tag == "id":
            return f"the name {nm.mathcad_text(*_key(node))} alone"
        return _what(node.tag)

    def math(self, region: Region) -> None:
        node = region.math
        self.region = region.id
        if node.tag in ("define", "globalDefine"):
            self.definition(region, node)
        elif node.tag == "eval":
            self.evaluation(region, node, None)
        elif node.tag == "id" and node.text.strip() == "Given":
            self.close_given("a solve block without Find")
            self.given = [region.id]
            self.constraints = []
        elif node.tag == "apply" and node.children and node.children[0].tag in _COMPARE:
            if self.given is None:  # a comparison shown outside a solve block: nothing
                self.out.ignored.append(region.id)
                return
            self.given.append(region.id)
            self.constraints.append(node)
        else:  # a name or an expression alone: Mathcad shows nothing, defines nothing
            self.out.ignored.append(region.id)

    def close_given(self, why: str | None) -> None:
        """End the open solve block: its regions are listed if it was not translated."""
        if self.given is not None and why is not None:
            for rid in self.given:
                self.skip(rid, "a region of a solve block (Given ... Find)", why)
        self.given = None
        self.constraints = []

    def find(self, et: ExprTranslator, args: list[MNode], method: str = "") -> ex.Node:
        """Find(x, ...) of a solve block: a [[solve]] block of the language (its unknowns are
        names of their own, the guesses the values the variables had before the block, as in
        Mathcad's)."""
        if self.given is None:
            raise Untranslatable("Find without Given")
        try:
            tree = self.solve_block(et, args, method)
        except Untranslatable as why:
            self.close_given(str(why))
            raise
        self.close_given(None)
        return tree

    def definition(self, region: Region, node: MNode) -> None:
        lhs, rhs = node.children[0], node.children[1]
        evaluation = rhs if rhs.tag == "eval" else None
        if evaluation is not None:
            rhs = evaluation.children[0]
        writer = _writer(lhs, 1)  # WRITEPRN("file") := M
        if writer is not None:
            self.written(region, *writer[:2], rhs, evaluation)
            return
        if lhs.tag == "function":
            fname, bound = lhs.children[0], lhs.children[1]
            self.function(region, fname, [c for c in bound.children if c.tag == "id"], rhs)
            return
        if _is_indexer(lhs):  # v[i] := f(i), shown (= the whole vector) or not
            target = lhs.children[1] if len(lhs.children) > 1 else None
            try:
                self.elements(region, lhs, rhs, _shown_rows(evaluation))
            except Untranslatable:
                if evaluation is not None:
                    sym = self.scope.get(_key(target)) if target is not None else None
                    if sym is not None and sym.region == region.id:
                        self.evaluation(region, evaluation, sym)
                    else:
                        self.stored_but_broken(region, evaluation, "an element assignment")
                raise
            if evaluation is not None:
                key = _key(target)
                # v[k] := expr = shows the element (one number): the value of expr
                element = not _shows_array(evaluation) and not _mentions(rhs, key)
                self.evaluation(region, evaluation, None if element else self.scope[key])
            return
        if lhs.tag == "matrix" and evaluation is None:
            self.destructure(region, lhs, rhs)
            return
        if lhs.tag != "id":
            if evaluation is not None:
                self.stored_but_broken(region, evaluation, f"{_what(lhs.tag)} := ...")
            what = "an element assignment" if _is_indexer(lhs) else _what(lhs.tag)
            raise Untranslatable(f"a definition of {what} is not in the language yet")
        key = _key(lhs)
        if rhs.tag == "id" and self.range_of(rhs) is not None:  # j := i, a range again
            self.range_alias(region, key, self.range_of(rhs))
            return
        if key == ("TOL", "") and _quantity_text(rhs) is not None:
            try:
                tol = float(self.quantity(rhs).magnitude)
                self.out.solve_tolerance = max(self.out.solve_tolerance, tol)
            except Exception:  # noqa: BLE001 - a TOL that is not a number: the default
                pass
        if key == ("ORIGIN", "") and rhs.tag == "real":
            self.origin = int(float(rhs.text))
            self.out.items.append(
                Item("note", region.id, value=f"ORIGIN := {self.origin} (the first index)")
            )
            return
        if rhs.tag == "range":
            self.range_variable(region, key, rhs)
            return
        rhs = _symbolic_result(rhs)
        display = _override_unit(evaluation) if evaluation is not None else ""
        try:
            item = self.value_item(region, rhs, display)
        except Untranslatable as why:
            sym = self.define(key, "var", region.id)
            sym.broken = str(why)
            if evaluation is not None:
                self.evaluation(region, evaluation, sym)
            raise
        sym = self.define(key, "var", region.id)
        item.sym = sym
        self.out.items.append(item)
        if evaluation is not None:
            self.evaluation(region, evaluation, sym)

    def written(self, region: Region, func: str, file: str, value: MNode, evaluation):
        """The value Mathcad's WRITEPRN (and friends) wrote to a file: a definition of its
        own (``written_1``, ...) with a note naming the file, so that its stored result is
        compared; the worksheet writes no file."""
        self.writes += 1
        sym = self.new_sym("var", f"written_{self.writes}", f'{func}("{file}")', region.id)
        self.out.items.append(
            Item(
                "note",
                region.id,
                value=f'Mathcad\'s {func} wrote this value to the file "{file}" (the '
                "worksheet writes no files)",
            )
        )
        try:
            item = self.value_item(region, value, "")
        except Untranslatable as why:
            sym.broken = sym.broken or str(why)
            if evaluation is not None:
                self.evaluation(region, evaluation, sym)
            raise
        item.sym = sym
        self.out.items.append(item)
        if evaluation is not None:
            self.evaluation(region, evaluation, sym)

    def stored_but_broken(self, region: Region, evaluation: MNode, what: str) -> None:
        sym = self.new_sym("helper", f"result_{region.id}", what, region.id)
        sym.broken = "not translated"
        self.evaluation(region, evaluation, sym)

    def value_item(self, region: Region, rhs: MNode, display: str) -> Item:
        """The item a scalar definition becomes: an input for a number (with units), a
        piecewise definition for a program of ifs, or a definition."""
        literal = _quantity_text(rhs)
        if literal is not None:
            return Item("input", region.id, value=literal, unit=display)
        if rhs.tag == "program":
            return Item("definition", region.id, unit=display, **self.program(rhs, {}))
        if _is_if(rhs):
            return Item("definition", region.id, pieces=self.if_pieces(rhs, {}), unit=display)
        et = ExprTranslator(self)
        body = et.value(rhs)
        if et.ranges:
            raise Untranslatable(
                f"uses the range variable {et.ranges[0].mathcad} outside a function "
                "(a vector of values: arrays are not in the language yet)"
            )
        return Item("definition", region.id, body=body, unit=display)

    def program(self, program: MNode, local) -> dict:
        """A program made of `value if condition` lines and `otherwise` as a piecewise
        definition; any other as a program of the language."""
        try:
            return {"pieces": self.pieces(program, local)}
        except Untranslatable as why:
            from .program import ProgramTranslator

            try:
                return {"program": ProgramTranslator(self, local, ExprTranslator).lines(program)}
            except Untranslatable as why2:
                raise why2 from why

    def pieces(self, program: MNode, local) -> list[tuple[ex.Node, ex.Node | None]]:
        """A Mathcad program made only of `value if condition` lines and `otherwise`."""
        out = []
        for line in program.children:
            et = ExprTranslator(self, local)
            if line.tag == "ifThen" and len(line.children) == 2:
                cond, value = line.children
                if value.tag in ("program", "localDefine"):
                    raise Untranslatable("a program with local definitions or blocks")
                out.append((et.value(value), et.condition(cond)))
            elif line.tag == "otherwise" and len(line.children) == 1:
                out.append((et.value(line.children[0]), None))
            else:
                raise Untranslatable(
                    f"a program with {_what(line.tag)} lines (only 'if' and 'otherwise' "
                    "lines translate: as a piecewise definition)"
                )
            if et.ranges:
                raise Untranslatable("a program over a range variable")
        if not out:
            raise Untranslatable("an empty program")
        # Mathcad runs every line and the program's value is the last one it ran: where
        # conditions overlap, the last true `if` wins; pieces take the first true one
        ifs = [p for p in out if p[1] is not None][::-1]
        return ifs + [p for p in out if p[1] is None]

    def if_pieces(self, node: MNode, local) -> list[tuple[ex.Node, ex.Node | None]]:
        """Mathcad's if(cond, a, b), with further ifs in b, as pieces."""
        out = []
        while _is_if(node):
            cond, a, b = _if_args(node)
            et = ExprTranslator(self, local)
            out.append((et.value(a), et.condition(cond)))
            if et.ranges:
                raise Untranslatable("an if() over a range variable")
            node = b
        et = ExprTranslator(self, local)
        out.append((et.value(node), None))
        if et.ranges:
            raise Untranslatable("an if() over a range variable")
        return out

    def range_of(self, node: MNode) -> Item | None:
        sym = self.scope.get(_key(node))
        if sym is None or not sym.is_range or sym.broken:
            return None
        return next((i for i in self.out.items if i.sym is sym), None)

    def range_alias(self, region: Region, key, item: Item) -> None:
        sym = self.define(key, "var", region.id)
        sym.is_range, sym.unit = True, item.sym.unit
        self.out.items.append(
            Item(
                "range",
                region.id,
                sym=sym,
                range=item.range,
                range_values=item.range_values,
            )
        )

    def elements(self, region: Region, lhs: MNode, rhs: MNode, shown: int | None = None) -> None:
        """v[i] := f(i) over range variables with whole values (Mathcad builds the vector
        element by element): the vector [v_of(0), v_of(1), ...] of a function v_of, 0 where
        the range does not reach. ``shown``: the rows of the vector Mathcad showed after it
        (where it shows no more rows than the range reaches, nothing of v before is kept)."""
        target, index = lhs.children[1], lhs.children[2]
        if target.tag != "id":
            raise Untranslatable("an element assignment to something that is not a name")
        key = _key(target)
        nodes = index.children if index.tag == "sequence" else [index]
        ranges = [self.range_of(n) if n.tag == "id" else None for n in nodes]
        if all(r is None for r in ranges):
            self.element(region, key, lhs, rhs)
            return
        before = self.scope.get(key)
        sym = self.define(key, "var", region.id)
        try:
            if any(r is None for r in ranges) or len(ranges) > 2:
                raise Untranslatable(
                    "an element assignment v[k] := ... at a single index (the language "
                    "defines whole vectors)"
                )
            unique: list[Item] = []  # M[i, i] := ...: one range at two indices (a diagonal)
            for r in ranges:
                if all(r is not u for u in unique):
                    unique.append(r)
            place = [next(k for k, u in enumerate(unique) if u is r) for r in ranges]
            values = [[int(v) for v in u.range_values] for u in unique]
            if any(v != u.range_values for v, u in zip(values, unique)):
                raise Untranslatable("an element assignment over a range of fractional values")
            if any(min(v) < self.origin for v in values):
                raise Untranslatable("an element assignment below ORIGIN")
            old = None
            reach = max(values[place[0]]) - self.origin + 1
            if shown is not None and len(ranges) == 1 and shown == reach:
                before = None  # Mathcad showed the range's elements only: none kept
            if before is not None:  # Mathcad keeps the elements the range does not reach
                old = self._shape_of(before)
                if old is None or (len(ranges) == 1 and old[1] != 1):
                    raise Untranslatable(
                        "an element assignment over a range to a name defined before whose "
                        "size is not known at import"
                    )
            size = [max(values[place[k]]) - self.origin + 1 for k in range(len(ranges))]
            if old is not None:
                size = [max(n, old[k]) for k, n in enumerate(size)]
            if math.prod(size) > 10_000:
                raise Untranslatable("an element assignment of more than 10,000 elements")
            local, params = {}, []
            for u in unique:
                n = nodes[ranges.index(u)]
                p = self.new_sym("param", u.sym.base, u.sym.mathcad, unit="")
                local[_key(n)] = p
                params.append(p)
            if rhs.tag == "program":  # K[i] := a program of i: a function of i
                parts = self.program(rhs, local)
            else:
                et = ExprTranslator(self, local)
                parts = {"body": et.value(rhs)}
                if et.ranges:
                    raise Untranslatable("an element assignment over another range variable")
        except Untranslatable as why:
            sym.broken = str(why)
            raise
        of = self.new_sym("func", sym.base + "_of", nm.mathcad_text(*key) + "[...]", region.id)
        self.out.items.append(Item("function", region.id, sym=of, params=params, **parts))
        o = self.origin

        def cell(*at: int) -> ex.Node:
            chosen: dict[int, int] = {}
            reached = True
            for k, a in enumerate(at):
                u = place[k]
                if a not in values[u] or chosen.setdefault(u, a) != a:
                    reached = False
            if reached:
                return ex.Call(
                    of.token(), tuple(ex.Number(float(chosen[u])) for u in range(len(unique)))
                )
            if old is not None and all(a - o < old[k] for k, a in enumerate(at)):
                return ex.Index(ex.Name(before.token()), tuple(ex.Number(float(a)) for a in at))
            return ex.Number(0.0)

        if len(size) == 1:
            rows = tuple((cell(o + r),) for r in range(size[0]))
        else:
            rows = tuple(tuple(cell(o + r, o + c) for c in range(size[1])) for r in range(size[0]))
        self.out.items.append(Item("definition", region.id, sym=sym, body=ex.Matrix(rows)))

    def _shape_of(self, before: Sym) -> tuple[int, int] | None:
        """(rows, columns) of a vector or matrix the worksheet wrote out before (None: not
        known at import)."""
        if before.broken:
            return None
        tree = self.written_out(ex.Name(before.token()))
        if isinstance(tree, ex.Matrix) and not any(
            isinstance(e, ex.Matrix) for row in tree.rows for e in row
        ):
            return len(tree.rows), len(tree.rows[0])
        return None

    def destructure(self, region: Region, lhs: MNode, rhs: MNode) -> None:
        """[a; b] := value: the value a definition of its own (``parts``), then each name
        its element at ORIGIN."""
        rows, cols = matrix_size(lhs)
        names = lhs.children
        if rows * cols != len(names) or not names or any(n.tag != "id" for n in names):
            raise Untranslatable("a definition of a matrix of something that is not names")
        whole = self.new_sym("var", "parts", f"[...] := (region {region.id})", region.id)
        whole.generated = True
        try:
            if rhs.tag == "program":  # [a; b] := a program giving them
                parts = self.program(rhs, {})
            else:
                et = ExprTranslator(self)
                parts = {"body": et.value(rhs)}
                if et.ranges:
                    raise Untranslatable(
                        f"uses the range variable {et.ranges[0].mathcad} outside a function"
                    )
        except Untranslatable as why:
            for n in names:
                self.define(_key(n), "var", region.id).broken = str(why)
            raise
        self.out.items.append(Item("definition", region.id, sym=whole, **parts))
        o = self.sheet_origin
        for c in range(cols):
            for r in range(rows):
                at = (r,) if cols == 1 else (r, c)
                index = tuple(ex.Number(float(o + a)) for a in at)
                sym = self.define(_key(names[c * rows + r]), "var", region.id)
                item = ex.Index(ex.Name(whole.token()), index)
                self.out.items.append(Item("definition", region.id, sym=sym, body=item))

    def element(self, region: Region, key, lhs: MNode, rhs: MNode) -> None:
        """v[k] := value at an index that is not a range variable (Mathcad sets one element
        of v, making or growing it): a new definition of v, a program that copies the
        previous definition of v (if there is one), sets the element and gives it."""
        previous = self.scope.get(key)
        sym = self.define(key, "var", region.id)
        try:
            if previous is not None and previous.broken:
                raise Untranslatable(_uses(previous))
            if previous is not None and (previous.kind == "func" or previous.is_range):
                raise Untranslatable(
                    f"an element of {previous.mathcad}, which is a "
                    + ("function" if previous.kind == "func" else "range variable")
                )
            et = ExprTranslator(self)
            self.scope.pop(key)  # the right side sees the previous definition (if any)
            if previous is not None:
                self.scope[key] = previous
            try:
                value = et.value(rhs)
            finally:
                self.scope[key] = sym
            local = self.new_sym("local", sym.base, sym.mathcad)
            lines = []
            if previous is not None:
                lines.append((0, [ex.Name(local.token()), " := ", ex.Name(previous.token())]))
            inner = ExprTranslator(self, {key: local})
            index = inner.value(lhs)  # v[k], its index shifted by ORIGIN
            if et.ranges or inner.ranges:
                raise Untranslatable(
                    "an element assignment whose index or value uses a range variable (other "
                    "than as the index itself)"
                )
            lines += [(0, [index, " := ", value]), (0, [ex.Name(local.token())])]
        except Untranslatable as why:
            sym.broken = str(why)
            raise
        self.out.items.append(Item("definition", region.id, sym=sym, program=lines))

    def range_variable(self, region: Region, key, rng: MNode) -> None:
        sym = self.define(key, "var", region.id)
        sym.is_range = True
        try:
            first_node = rng.children[0]
            et = ExprTranslator(self)
            if first_node.tag == "sequence":
                first, second = (et.visit(c) for c in first_node.children[:2])
                second_src = first_node.children[1]
                first_src = first_node.children[0]
            else:
                first, second, first_src, second_src = et.visit(first_node), None, first_node, None
            last = et.visit(rng.children[1])
            values = _range_values(self, first_src, second_src, rng.children[1])
        except Untranslatable as why:
            sym.broken = str(why)
            raise
        sym.unit = values[1]
        self.out.items.append(
            Item("range", region.id, sym=sym, range=(first, second, last), range_values=values[0])
        )

    def function(self, region: Region, fname: MNode, params: list[MNode], body: MNode) -> None:
        key = _key(fname)
        body = _symbolic_result(body)
        local: dict[tuple[str, str], Sym] = {}
        psyms = []
        for p in params:
            pkey = _key(p)
            outer = self.scope.get(pkey)
            unit = outer.unit if outer is not None and outer.is_range else ""
            ps = self.new_sym("param", nm.identifier(*pkey), nm.mathcad_text(*pkey), unit=unit)
            local[pkey] = ps
            psyms.append(ps)
        # a call of f inside f is Mathcad's recursion, unless f was a function before: then
        # it is that function (B(x) := stack(B(x), M) redefines B from the previous B)
        previous = self.scope.get(key)
        if previous is not None and previous.kind == "func":
            sym = self.new_sym("func", nm.identifier(*key), nm.mathcad_text(*key), region.id)
        else:
            sym = self.define(key, "func", region.id)
        try:
            if body.tag == "program":
                item = Item("function", region.id, params=psyms, **self.program(body, local))
            elif _is_if(body):
                item = Item("function", region.id, params=psyms, pieces=self.if_pieces(body, local))
            else:
                et = ExprTranslator(self, local)
                item = Item("function", region.id, params=psyms, body=et.value(body))
                if et.ranges:
                    raise Untranslatable(
                        f"uses the range variable {et.ranges[0].mathcad} inside a function"
                    )
        except Untranslatable as why:
            sym.broken = str(why)
            self.scope[key] = sym
            raise
        self.scope[key] = sym
        item.sym = sym
        self.out.items.append(item)

    # -- results --------------------------------------------------------------
    def evaluation(self, region: Region, node: MNode, target: Sym | None) -> None:
        """An `expr =` with its stored result: a printed value (or several)."""
        result = node.find("result")
        if result is None or not result.children:
            return  # Mathcad stored nothing (not calculated, or an error)
        expr = node.children[0]
        mathcad = self.describe_expr(expr)
        if _is_nested(result.children[0]):
            self.nested(region, expr, target, result.children[0], mathcad)
            return
        try:
            unit, values = _stored(result.children[0])
            shape = _shape(result.children[0])
        except Untranslatable as why:
            self.out.results.append(Result(region.id, None, mathcad, "", []))
            self.skip(region.id, f"the result of {mathcad}", str(why))
            return
        writer = _writer(expr, 2) if target is None else None  # WRITEPRN("file", M) =
        if writer is not None:
            self.written(region, *writer[:2], writer[2], node)
            return
        self.remember_shown(expr, target, unit, values)
        before = len(self.out.results)
        try:
            self.evaluation_values(region, expr, target, unit, values, shape, mathcad)
        finally:
            for res in self.out.results[before:]:
                res.round_off = self.round_off(expr, unit, values)

    def round_off(self, expr: MNode, unit: str, values) -> tuple[float, str] | None:
        """The absolute tolerance of an evaluation whose stored values include round-off of a
        larger size than 1e-12 (the tolerance of a stored 0), and why; None: there is none."""
        size = self.terms_size(expr, unit)
        if size is not None and DIFFERENCE_TOLERANCE * size > ZERO_TOLERANCE:
            return DIFFERENCE_TOLERANCE * size, (
                f"a difference, within {DIFFERENCE_TOLERANCE:g} of its terms' size ({size:g}, "
                "as Mathcad showed a term)"
            )
        numbers = [abs(v) for v in values if isinstance(v, float)]
        if len(numbers) > 1 and 0.0 in numbers:
            largest = max(numbers)
            if MATRIX_ZERO_TOLERANCE * largest > ZERO_TOLERANCE:
                return MATRIX_ZERO_TOLERANCE * largest, (
                    f"an array with elements stored as 0, within {MATRIX_ZERO_TOLERANCE:g} of "
                    f"its largest element ({largest:g})"
                )
        return None

    def remember_shown(self, expr: MNode, target: Sym | None, unit: str, values) -> None:
        """The values Mathcad stored for a name (``w =``, or ``w := ... =``)."""
        expr = _unparen(expr)
        sym = target
        if sym is None and expr.tag == "id":
            sym = self.scope.get(_key(expr))
        numbers = [v for v in values if isinstance(v, float)]
        if sym is not None and numbers:
            self.shown[sym.token()] = (unit, numbers)

    def terms_size(self, expr: MNode, unit: str) -> float | None:
        """For a difference ``a - b`` (or a sum) of which a or b is a name whose values Mathcad
        stored, in the same unit: the largest of them. Mathcad's value of a difference whose
        terms cancel is round-off of that size (a residual ``N x - w`` stores 5e-12 for terms
        near 2401), which no other computation reproduces digit for digit."""
        expr = _unparen(expr)
        if expr.tag != "apply" or len(expr.children) != 3:
            return None
        if expr.children[0].tag not in ("minus", "plus"):
            return None
        sizes = []
        for term in expr.children[1:]:
            term = _unparen(term)
            sym = self.scope.get(_key(term)) if term.tag == "id" else None
            shown = self.shown.get(sym.token()) if sym is not None else None
            if shown is not None and shown[0] == unit:
                sizes.append(max(abs(v) for v in shown[1]))
        return max(sizes) if sizes else None

    def evaluation_values(self, region: Region, expr: MNode, target, unit, values, shape, mathcad):
        """The printed values of an evaluation whose stored values are read."""
        if target is not None:  # a definition with its value shown: x := ... = value
            if len(values) == 1:
                self.out.results.append(
                    Result(region.id, target, mathcad, unit, [(None, values[0])])
                )
                return
            try:
                if target.broken:
                    raise Untranslatable(target.broken)
                self.array_result(region, ex.Name(target.token()), shape, values, unit, mathcad)
            except Untranslatable as why:
                self.broken_result(region, mathcad, unit, values, str(why))
                if not target.broken:
                    self.skip(region.id, f"the result of {mathcad}", str(why))
            return
        try:
            self.standalone(region, expr, unit, values, mathcad, shape)
        except Untranslatable as why:
            self.broken_result(region, mathcad, unit, values, str(why))
            raise

    def broken_result(self, region: Region, mathcad: str, unit: str, values, why: str) -> None:
        """Stored values whose evaluation is not translated: kept, so they count."""
        sym = self.new_sym("helper", f"result_{region.id}", mathcad, region.id)
        sym.broken = why
        self.out.results.append(Result(region.id, sym, mathcad, unit, [(None, v) for v in values]))

    def index_sym(self) -> Sym:
        if self._index is None:
            self._index = self.new_sym("param", "index", "an index", unit="")
        return self._index

    def array_result(self, region: Region, base: ex.Node, shape, values, unit, mathcad) -> None:
        """A vector or matrix Mathcad shows: each element a printed value of a function of
        its index (for a matrix, of the element's number row by row from 0)."""
        rows, cols = shape
        if rows * cols != len(values):
            raise Untranslatable("an array result whose size does not match its values")
        if not isinstance(base, ex.Name):
            whole = self.new_sym("helper", f"result_{region.id}_value", mathcad, region.id)
            self.out.items.append(Item("definition", region.id, sym=whole, body=base))
            base = ex.Name(whole.token())
        k = self.index_sym()
        kn = ex.Name(k.token())
        o = ex.Number(float(self.sheet_origin))
        if cols == 1:
            body = ex.Index(base, (kn,))
            at = [(self.sheet_origin + r, values[r]) for r in range(rows)]
        else:
            row = ex.Call("floor", (ex.Binary("/", kn, ex.Number(float(cols))),))
            col = ex.Binary("-", kn, ex.Binary("*", ex.Number(float(cols)), row))
            body = ex.Index(base, (ex.Binary("+", o, row), ex.Binary("+", o, col)))
            at = [
                (float(r * cols + c), values[c * rows + r])
                for r in range(rows)
                for c in range(cols)
            ]
        sym = self.new_sym("helper", f"result_{region.id}", mathcad, region.id)
        self.out.items.append(Item("function", region.id, sym=sym, params=[k], body=body))
        self.out.results.append(Result(region.id, sym, mathcad, unit, at, k))

    def nested(self, region: Region, expr: MNode, target: Sym | None, stored: MNode, mathcad):
        """A nested array Mathcad shows (a vector of vectors...): each leaf a printed value,
        read by chained indices; the leaves at one place inside the outer elements
        (``TT[i][2][1]`` for every i) are a function of the outer index, as an array
        result's elements are."""
        try:
            leaves = list(_leaves(stored))
        except Untranslatable as why:
            self.out.results.append(Result(region.id, None, mathcad, "", []))
            self.skip(region.id, f"the result of {mathcad}", str(why))
            return
        try:
            if target is not None:
                if target.broken:
                    raise Untranslatable(target.broken)
                base = ex.Name(target.token())
            else:
                et = ExprTranslator(self)
                base = et.value(expr)
                if et.ranges:
                    raise Untranslatable("an evaluation of a nested array over a range variable")
            self.nested_result(region, base, leaves, mathcad)
        except Untranslatable as why:
            unit = next((u for _, u, _ in leaves if u), "")
            self.broken_result(region, mathcad, unit, [v for _, _, v in leaves], str(why))
            if target is None or not target.broken:
                self.skip(region.id, f"the result of {mathcad}", str(why))

    def nested_result(self, region: Region, base: ex.Node, leaves, mathcad: str) -> None:
        if not isinstance(base, ex.Name):
            whole = self.new_sym("helper", f"result_{region.id}_value", mathcad, region.id)
            self.out.items.append(Item("definition", region.id, sym=whole, body=base))
            base = ex.Name(whole.token())
        o = self.sheet_origin
        k = self.index_sym()
        kn = ex.Name(k.token())
        groups: dict[tuple, list] = {}
        for path, unit, value in leaves:
            row, col, _, cols = path[0]
            groups.setdefault(path[1:], []).append((float(row * cols + col), unit, value))
        _, _, _, cols = leaves[0][0][0]
        if cols == 1:  # the index of the element itself
            outer: tuple = (kn,)
        else:  # the element's number row by row from 0
            row = ex.Call("floor", (ex.Binary("/", kn, ex.Number(float(cols))),))
            col = ex.Binary("-", kn, ex.Binary("*", ex.Number(float(cols)), row))
            first = ex.Number(float(o))
            outer = (ex.Binary("+", first, row), ex.Binary("+", first, col))
        for tail, rows in groups.items():
            body: ex.Node = ex.Index(base, outer)
            text = suffix = ""
            for r, c, _, ncols in tail:
                at = [o + a for a in ((r,) if ncols == 1 else (r, c))]
                body = ex.Index(body, tuple(ex.Number(float(a)) for a in at))
                text += "[" + ", ".join(map(str, at)) + "]"
                suffix += "_" + "_".join(map(str, at))
            what = f"{mathcad}[...]{text}"
            sym = self.new_sym("helper", f"result_{region.id}{suffix}", what, region.id)
            self.out.items.append(Item("function", region.id, sym=sym, params=[k], body=body))
            at = [(a + o if cols == 1 else a, v) for a, _, v in rows]
            unit = next((u for _, u, _ in rows if u), "")
            self.out.results.append(Result(region.id, sym, what, unit, at, k))

    def solve_block(self, et: ExprTranslator, args: list[MNode], method: str = "") -> ex.Node:
        if not args or any(a.tag != "id" for a in args):
            raise Untranslatable("Find of something that is not a list of names")
        # Mathcad's chain a = b = c (a comparison whose left side is one, without brackets)
        # is two equations, a = b and b = c
        eqs = [
            pair
            for c in self.constraints
            if c.children[0].tag == "equal"
            for pair in _equal_chain(c)
        ]
        ineqs = [c for c in self.constraints if c.children[0].tag != "equal"]
        if any(c.children[0].tag not in _INEQUALITY for c in ineqs):
            raise Untranslatable("a solve block with a condition that is not < <= > >=")
        method = _METHODS.get(method, "")
        if len(eqs) != len(args) and not (0 < len(eqs) < len(args) and method):
            raise Untranslatable(f"a solve block of {len(eqs)} equations in {len(args)} unknowns")
        local, unknowns = {}, []
        for a in args:
            key = _key(a)
            q = self.guess(et, a)  # the value before the block
            sym = self.new_sym("var", nm.identifier(*key), nm.mathcad_text(*key), self.given[0])
            local[key] = sym
            magnitude = float(q.magnitude)
            unit = "" if q.dimensionless else f" {q.units:~}"
            unknowns.append((sym, f"{magnitude!r}{unit}"))
        inner = ExprTranslator(self, {**et.local, **local})
        equations = []
        for lhs, rhs in eqs:
            left, right = inner.value(lhs), inner.value(rhs)
            equations.append(ex.Compare(("==",), (left, right)))
        conditions = [inner.visit(c) for c in ineqs]  # checked at the root found
        if inner.ranges:
            raise Untranslatable("a solve block over a range variable")
        self.out.items.append(
            Item(
                "solve",
                self.given[0],
                solve=(unknowns, equations, list(self.given), conditions),
                value=method,
            )
        )
        names = [ex.Name(sym.token()) for sym, _ in unknowns]
        if len(names) == 1:
            return names[0]
        return ex.Matrix(tuple((n,) for n in names))

    def guess(self, et: ExprTranslator, name: MNode):
        """The value of the name ``name`` before a solve block (its guess), as the engine
        computes it."""
        try:
            return self.at_import().quantity(et.visit(name))
        except Unknown:
            what = nm.mathcad_text(*_key(name))
            raise Untranslatable(f"the guess of {what} is not known") from None

    def extremum(self, et: ExprTranslator, args: list[MNode], largest: bool) -> ex.Node:
        """Maximize(f, x) / Minimize(f, x) from the guess x (and the inequalities of an open
        Given block): the stationary point of f nearest the guess where f curves down (up),
        a [[solve]] block of f's slope (a helper function of the derivative) == 0 by the
        `nearest` method, with the curvature's sign a condition."""
        what = "Maximize" if largest else "Minimize"
        given, constraints = self.given, self.constraints
        try:
            if len(args) != 2 or any(a.tag != "id" for a in args):
                raise Untranslatable(f"{what} of a function of {len(args) - 1} unknowns")
            if any(c.children[0].tag not in _INEQUALITY for c in constraints):
                raise Untranslatable(f"{what} with an equation in its Given block")
            fsym = et.local.get(_key(args[0])) or self.scope.get(_key(args[0]))
            if fsym is None or fsym.kind != "func" or fsym.broken:
                raise Untranslatable(f"{what} of something that is not a function of the sheet")
            key = _key(args[1])
            q = self.guess(et, args[1])  # the value before
            guess = et.visit(args[1])
            region = given[0] if given else self.region
            slope = self._derivative(fsym, fsym, "slope", region, guess)
            curve = self._derivative(slope, fsym, "curvature", region, guess)
            sym = self.new_sym("var", nm.identifier(*key), nm.mathcad_text(*key), region)
            inner = ExprTranslator(self, {**et.local, key: sym})
            conditions = [inner.visit(c) for c in constraints]
            u = ex.Name(sym.token())
            conditions.append(
                ex.Compare(
                    ("<" if largest else ">",), (ex.Call(curve.token(), (u,)), ex.Number(0.0))
                )
            )
            equation = ex.Compare(("==",), (ex.Call(slope.token(), (u,)), ex.Number(0.0)))
            unit = "" if q.dimensionless else f" {q.units:~}"
        except Untranslatable as why:
            if given is not None:
                self.close_given(str(why))
            raise
        if given is not None:
            self.close_given(None)
        self.out.items.append(
            Item(
                "solve",
                region,
                solve=([(sym, f"{float(q.magnitude)!r}{unit}")], [equation], [region], conditions),
                value="nearest",
            )
        )
        return u

    def _derivative(self, fsym: Sym, of: Sym, word: str, region: str, guess: ex.Node) -> Sym:
        """A helper function: the derivative of the function ``fsym`` of one argument (the
        ``word`` of the function ``of``)."""
        param = self.new_sym("param", "x", "x")
        body = ex.Call(
            "diff", (ex.Call(fsym.token(), (ex.Name(param.token()),)), ex.Name(param.token()))
        )
        out = self.new_sym("func", f"{of.base}_{word}", f"the {word} of {of.mathcad}", region)
        self.out.items.append(Item("function", region, sym=out, params=[param], body=body))
        self.calls.setdefault(out, []).append((guess,))
        self.calls.setdefault(fsym, []).append((guess,))
        return out

    def standalone(self, region: Region, expr: MNode, unit: str, values, mathcad: str, shape):
        et = ExprTranslator(self)
        body = et.value(expr)
        ranges = list(dict.fromkeys(et.ranges))
        if not ranges:
            if len(values) != 1:
                self.array_result(region, body, shape, values, unit, mathcad)
                return
            sym = None
            if isinstance(body, ex.Name) and body.id.startswith("\x00"):
                sym = next(s for s in self.out.syms if s.token() == body.id)
                if sym.kind == "unit":
                    sym = None
            if sym is None:
                sym = self.new_sym("helper", f"result_{region.id}", mathcad, region.id)
                self.out.items.append(Item("definition", region.id, sym=sym, body=body, unit=unit))
            self.out.results.append(Result(region.id, sym, mathcad, unit, [(None, values[0])]))
            return
        if len(ranges) > 1:
            raise Untranslatable("an evaluation over two range variables (a matrix)")
        var = ranges[0]
        item = next(i for i in self.out.items if i.sym is var)
        at = item.range_values
        if len(at) != len(values):
            raise Untranslatable(
                f"Mathcad lists {len(values)} values of the range {var.mathcad}, which has "
                f"{len(at)}"
            )
        if (
            isinstance(body, ex.Call)
            and len(body.args) == 1
            and body.args[0] == ex.Name(var.token())
        ):
            fsym = next(s for s in self.out.syms if s.token() == body.func)
            fitem = next(i for i in self.out.items if i.sym is fsym)
            if fitem.params[0].unit == var.unit:
                self.out.results.append(
                    Result(region.id, fsym, mathcad, unit, list(zip(at, values)), fitem.params[0])
                )
                return
        param = self.new_sym("param", var.base, var.mathcad, unit=var.unit)
        sym = self.new_sym("helper", f"result_{region.id}", mathcad, region.id)
        body = _rename(body, {var.token(): param.token()})
        self.out.items.append(Item("function", region.id, sym=sym, params=[param], body=body))
        self.out.results.append(Result(region.id, sym, mathcad, unit, list(zip(at, values)), param))

    def describe_expr(self, node: MNode) -> str:
        if node.tag == "id":
            return nm.mathcad_text(*_key(node))
        if node.tag == "apply" and node.children[0].tag == "id":
            return nm.mathcad_text(*_key(node.children[0])) + "(...)"
        return "an expression"


#: Built-ins of one number that vectorize applies element by element.
_ELEMENTWISE = frozenset(
    {"sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "exp", "ln",
     "log10", "sqrt", "abs", "floor", "ceil", "round", "trunc", "sign", "atan2", "mod"}
)  # fmt: skip


def _shows_array(evaluation: MNode) -> bool:
    """Whether the result Mathcad stored for ``evaluation`` is a vector or matrix."""
    result = evaluation.find("result")
    return result is None or any(_has_tag(c, "matrix") for c in result.children)


def _has_tag(node: MNode, tag: str) -> bool:
    return node.tag == tag or any(_has_tag(c, tag) for c in node.children)


def _mentions(node: MNode, key: tuple[str, str]) -> bool:
    """Whether the Mathcad name ``key`` occurs in ``node``."""
    if node.tag == "id" and _key(node) == key:
        return True
    return any(_mentions(c, key) for c in node.children)


def _derivative_order(degree: MNode | None) -> int:
    """The order of Mathcad's derivative from its ``degree`` (none, or an empty placeholder
    as Prime writes it: the first); an order that is not a whole number written in the
    worksheet (1 to 5, as Mathcad's numerical derivative allows) is refused, never read as
    the first."""
    if degree is None:
        return 1
    kids = degree.children
    if kids and all(c.tag == "placeholder" for c in kids):
        return 1
    if not kids:  # the order as the element's text
        text = degree.text
    elif len(kids) == 1 and kids[0].tag == "real":
        text = kids[0].text
    else:
        text = ""
    try:
        value = float(text.strip())
    except ValueError:
        value = 0.5
    if value.is_integer() and 1 <= value <= 5:
        return int(value)
    raise Untranslatable("a derivative whose order is not a whole number from 1 to 5 written in it")


def _equal_chain(node: MNode) -> list[tuple[MNode, MNode]]:
    """The equations of Mathcad's ``a = b = c`` (stored as ``(a = b) = c``): ``[(a, b), (b,
    c)]``; of ``a = b``, ``[(a, b)]``."""
    left, right = node.children[1], node.children[2]
    if left.tag == "apply" and len(left.children) == 3 and left.children[0].tag == "equal":
        inner = _equal_chain(left)
        return [*inner, (inner[-1][1], right)]
    return [(left, right)]


def _rename(node: ex.Node, mapping: dict[str, str]) -> ex.Node:
    """The tree with names (and called functions) replaced as mapped."""
    if isinstance(node, ex.Name):
        return ex.Name(mapping.get(node.id, node.id))
    node = ex.map_children(node, lambda c: _rename(c, mapping))
    if isinstance(node, ex.Call):
        return ex.Call(mapping.get(node.func, node.func), node.args)
    return node


def _eigenvals_argument(node: MNode) -> MNode | None:
    """M of ``eigenvals(M)`` (None: ``node`` is not that call)."""
    node = _unparen(node)
    if node.tag != "apply" or len(node.children) != 2 or node.children[0].tag != "id":
        return None
    if _key(node.children[0]) != ("eigenvals", ""):
        return None
    arg = node.children[1]
    if arg.tag == "sequence":
        return arg.children[0] if len(arg.children) == 1 else None
    return arg


def _shown_rows(evaluation: MNode | None) -> int | None:
    """The rows of the array Mathcad stored for ``v[i] := ... =`` (None: none stored)."""
    result = evaluation.find("result") if evaluation is not None else None
    if result is None or not result.children or result.children[0].tag != "matrix":
        return None
    try:
        return matrix_size(result.children[0])[0]
    except Untranslatable:
        return None


def _substitute(node: ex.Node, values: dict[str, ex.Node]) -> ex.Node:
    """The tree with the names in ``values`` replaced by their trees."""
    if isinstance(node, ex.Name):
        return values.get(node.id, node)
    return ex.map_children(node, lambda c: _substitute(c, values))


def _writer(node: MNode, arity: int) -> tuple[str, str, MNode | None] | None:
    """(function, file, value) of a call of a Mathcad function that writes a file with a
    literal file name: ``WRITEPRN("f")`` (arity 1, the value is the right side of ``:=``)
    or ``WRITEPRN("f", M)`` (arity 2); None for anything else."""
    if node.tag != "apply" or len(node.children) != 2 or node.children[0].tag != "id":
        return None
    func = _key(node.children[0])
    if func[1] or func[0] not in WRITERS:
        return None
    args = node.children[1]
    args = args.children if args.tag == "sequence" else [args]
    if len(args) != arity or args[0].tag != "str":
        return None
    return func[0], args[0].text, args[1] if arity == 2 else None


def _is_indexer(node: MNode) -> bool:
    return node.tag == "apply" and len(node.children) == 3 and node.children[0].tag == "indexer"


#: the solver Mathcad's Find used (its AutoSelect stores the one that succeeded) -> the
#: [[solve]] method that reaches the same root: Mathcad's Levenberg-Marquardt is MINPACK's;
#: where it fell back to its conjugate-gradient solver (the Levenberg-Marquardt root missed a
#: condition), the root nearest the guess that meets the conditions is the one it reports in
#: the worksheets measured; the others (linear, quasi-Newton): the default method
_METHODS = {"levenberg": "levenberg-marquardt", "conjugate": "nearest"}

#: at most this many columns of a matrix are stacked for histogram()
MAX_STACKED_COLUMNS = 1000

#: steps of the range of a quick plot (an x that the worksheet has not defined)
QUICK_PLOT_STEPS = 200
_KNOWN = {*FORMULA_UNITS, "π", "e"}

_INEQUALITY = {"lessThan", "greaterThan", "lessOrEqual", "greaterOrEqual"}


def _has_index(node: MNode) -> bool:
    if node.tag in ("indexer", "matcol"):
        return True
    if node.tag == "id" and node.text.strip() in ORIGIN_FUNCTIONS:
        return True  # a function whose indices count from ORIGIN
    return any(_has_index(c) for c in node.children)


def _first_index_origin(origin: int, regions: list[Region]) -> int:
    """ORIGIN where the worksheet first indexes an array (the worksheet's origin)."""
    for r in regions:
        if r.math is None:
            continue
        m = r.math
        if m.tag == "define" and len(m.children) == 2:
            lhs, rhs = m.children
            if lhs.tag == "id" and _key(lhs) == ("ORIGIN", "") and rhs.tag == "real":
                origin = int(float(rhs.text))
                continue
        if _has_index(m):
            return origin
    return origin


def _if_args(node: MNode) -> list[MNode]:
    args = node.children[1:]
    if len(args) == 1 and args[0].tag == "sequence":
        args = args[0].children
    return args


def _is_if(node: MNode) -> bool:
    """Mathcad's function if(cond, a, b)."""
    return (
        node.tag == "apply"
        and bool(node.children)
        and node.children[0].tag == "id"
        and node.children[0].text.strip() == "if"
        and not node.children[0].attrs.get("subscript")
        and len(_if_args(node)) == 3
    )


def _symbolic_result(node: MNode) -> MNode:
    """A symbolic evaluation (→) stands for the expression Mathcad found: that one is used."""
    if node.tag == "symEval":
        res = node.find("symResult")
        if res is not None and len(res.children) == 1:
            return res.children[0]
        raise Untranslatable("a symbolic evaluation without its result")
    return node


def _has_matrix(tree: ex.Node) -> bool:
    """Is a vector or matrix written inside ``tree``?"""
    return any(isinstance(n, ex.Matrix) for n in ex.walk(tree))


# -- stored values, units, literals ----------------------------------------------
def _unit_monomial(node: MNode) -> str:
    if "text" in node.attrs:  # a unit its reader wrote as pint text (Mathcad Prime's)
        return node.attrs["text"]
    parts = []
    for ref in node.children:
        if ref.tag != "unitReference":
            continue
        name = result_unit(ref.attrs.get("unit", ""))
        num = whole_number(ref.attrs.get("power-numerator", "1"), "a unit's power")
        den = whole_number(ref.attrs.get("power-denominator", "1"), "a unit's power")
        if den == 0:
            raise Untranslatable("a unit's power with the denominator 0")
        power = num / den
        if power == 1:
            parts.append(name)
        else:
            p = int(power) if power.is_integer() else power
            parts.append(f"{name} ** {p}" if p > 0 else f"{name} ** ({p})")
    return " * ".join(parts)


def _is_nested(node: MNode) -> bool:
    """Is ``node`` a stored array whose elements are arrays (Mathcad's nested array)?"""
    return node.tag == "matrix" and any(c.tag == "matrix" for c in node.children)


def _leaves(node: MNode, path: tuple = ()):
    """(path, unit, value) of every number or text of a stored nested array; the path has
    (row, column, rows, columns) of each array it passes, outermost first (Mathcad stores a
    matrix column by column)."""
    if node.tag != "matrix":
        unit, values = _stored(node)
        if len(values) != 1:
            raise Untranslatable("a nested array result with a matrix that has units")
        yield path, unit, values[0]
        return
    rows, cols = matrix_size(node)
    if rows * cols != len(node.children):
        raise Untranslatable("an array result whose size does not match its values")
    for n, child in enumerate(node.children):
        col, row = divmod(n, rows)
        yield from _leaves(child, (*path, (row, col, rows, cols)))


def _shape(node: MNode) -> tuple[int, int]:
    """(rows, cols) of a stored result: (1, 1) for a scalar."""
    inner = node.children[0] if node.tag == "unitedValue" and node.children else node
    if inner.tag == "matrix":
        return matrix_size(inner)
    return 1, 1


def _stored(node: MNode) -> tuple[str, list[float | str]]:
    """(unit text, values) of a stored result: a number, a number with units, a matrix (its
    values column by column), a text."""
    if node.tag == "real":
        try:
            value = float(node.text)
        except ValueError:
            raise Untranslatable(f"a stored number {node.text.strip()[:40]!r}") from None
        if not math.isfinite(value):
            raise Untranslatable(f"a stored number that is not finite ({node.text.strip()})")
        return "", [value]
    if node.tag == "str":
        return "", [node.text]
    if node.tag == "unitedValue":
        inner = node.children[0]
        mono = node.find("unitMonomial")
        unit, values = _stored(inner)
        return (_unit_monomial(mono) if mono is not None else unit), values
    if node.tag == "matrix":
        values = []
        units = set()
        for c in node.children:
            if c.tag == "matrix":
                raise Untranslatable(
                    "a nested array result (an array of arrays is not in the language)"
                )
            u, v = _stored(c)
            units.add(u)
            values += v
        if len(units) > 1:
            raise Untranslatable("a matrix result whose elements have different units")
        return (units.pop() if units else ""), values
    if node.tag == "unreadable":
        raise Untranslatable(node.attrs.get("why", "a stored result that cannot be read"))
    if node.tag == "complex":
        raise Untranslatable("a complex result (complex numbers are not in the language)")
    raise Untranslatable(f"a result of kind <{node.tag}>")


def _override_unit(evaluation: MNode) -> str:
    """The display unit of a result whose unit was chosen (Mathcad's unit placeholder)."""
    if evaluation.find("unitOverride") is None:
        return ""
    result = evaluation.find("result")
    if result is None or not result.children or result.children[0].tag != "unitedValue":
        return ""
    mono = result.children[0].find("unitMonomial")
    return _unit_monomial(mono) if mono is not None else ""


def _unit_text(node: MNode) -> str | None:
    """pint text of a product of Mathcad units (m, kN/m^2), or None."""
    if node.tag == "id" and not node.attrs.get("subscript") and node.text.strip() in FORMULA_UNITS:
        return FORMULA_UNITS[node.text.strip()]
    if node.tag == "parens":
        inner = _unit_text(node.children[0])
        return None if inner is None else f"({inner})"
    if node.tag == "apply" and len(node.children) == 3:
        op, a, b = node.children
        if op.tag in ("mult", "div"):
            ua, ub = _unit_text(a), _unit_text(b)
            if ua is not None and ub is not None:
                return f"{ua} {'*' if op.tag == 'mult' else '/'} {ub}"
        if op.tag == "pow" and b.tag == "real":
            ua = _unit_text(a)
            if ua is not None:
                return f"{ua} ** {b.text.strip()}"
    return None


def _quantity_text(node: MNode) -> str | None:
    """`24 m/s` for Mathcad's 24*m/s (a number times units), `1.3` for a number, else None."""
    if node.tag == "real":
        return node.text.strip()
    if node.tag == "apply" and node.children[0].tag == "neg" and len(node.children) == 2:
        inner = _quantity_text(node.children[1])
        return None if inner is None else "-" + inner
    if (
        node.tag == "apply"
        and len(node.children) == 3
        and node.children[0].tag
        in (
            "mult",
            "div",
        )
    ):
        op, a, b = node.children
        if a.tag == "real":
            unit = _unit_text(b)
            if unit is not None:
                if op.tag == "mult":
                    return f"{a.text.strip()} {unit}"
                return f"{a.text.strip()} / ({unit})"
    return None


def _range_values(tr: Translator, first: MNode, second: MNode | None, last: MNode):
    """Mathcad's values of a range first, second .. last (up to last, not beyond), and the
    range's unit; the bounds must be values known at import (numbers, inputs, definitions)."""
    why = "a range whose bounds are not values known at import"
    try:
        a, c = tr.quantity(first, why), tr.quantity(last, why)
        b = tr.quantity(second, why) if second is not None else None
        unit = c.units if a.magnitude == 0 and not a.dimensionless else a.units
        if a.magnitude == 0 and a.dimensionless:
            unit = c.units
        a, c = (float(q.to(unit).magnitude) if q.magnitude != 0 else 0.0 for q in (a, c))
        b = float(b.to(unit).magnitude) if b is not None else (a + 1 if c >= a else a - 1)
    except Untranslatable:
        raise
    except Exception:  # noqa: BLE001 - pint's unit errors and numeric ones alike
        raise Untranslatable("a range whose bounds are not values known at import") from None
    if not all(math.isfinite(v) for v in (a, b, c)):
        raise Untranslatable("a range whose bounds are not finite numbers")
    step = b - a
    if step == 0:
        raise Untranslatable("a range with step 0")
    count = (c - a) / step * (1 + 1e-12) + 1e-9
    if not math.isfinite(count) or count > 100_000:
        raise Untranslatable("a range of more than 100,000 values")
    n = math.floor(count)
    if n < 0:
        raise Untranslatable("an empty range")
    if n > 100_000:
        raise Untranslatable("a range of more than 100,000 values")
    dimensionless = unit == "" or not str(unit) or unit.dimensionless
    return [a + k * step for k in range(n + 1)], ("" if dimensionless else str(unit))


# -- Mathcad's comparisons are numbers (1 or 0), its numbers conditions (true where not 0) --
def _is_boolean(tree: ex.Node) -> bool:
    """Is ``tree`` a condition of the language (a comparison, and/or, not)?"""
    return isinstance(tree, (ex.Compare, ex.Logic)) or (
        isinstance(tree, ex.Unary) and tree.op == "not"
    )


def _as_number(tree: ex.Node) -> ex.Node:
    """A condition where Mathcad uses its value: ``(1 if C otherwise 0)``."""
    if _is_boolean(tree):
        return ex.IfElse(ex.Number(1.0), tree, ex.Number(0.0))
    return tree


def _logic(op: str, values: list[ex.Node]) -> ex.Node:
    """``a and b and c`` (nested ands flattened)."""
    flat: list[ex.Node] = []
    for v in values:
        flat += list(v.values) if isinstance(v, ex.Logic) and v.op == op else [v]
    return ex.Logic(op, tuple(flat))


def _unparen(node: MNode) -> MNode:
    while node.tag == "parens" and node.children:
        node = node.children[0]
    return node


def _is_condition(node: MNode) -> bool:
    """Is ``node`` a comparison, and/or/not, or a product or sum of such (Mathcad's idioms
    for and, or)?"""
    node = _unparen(node)
    if node.tag != "apply" or not node.children:
        return False
    op = node.children[0].tag
    if op in _COMPARE or op in ("and", "or", "not"):
        return True
    return (
        op in ("mult", "plus")
        and len(node.children) == 3
        and all(_is_condition(a) for a in node.children[1:])
    )
