"""Mathcad's expressions as the language's trees: names, numbers, operators, calls of built-in
and worksheet functions, indices and columns, sums, integrals and derivatives, vectorize."""

from __future__ import annotations

import math

from ..language import expr as ex
from ..language.visitor import Visitor
from ..numerics.registry import REGISTRY
from . import names as nm
from . import trees as tt
from .context import TranslatorContext
from .functions import (
    BINDERS,
    FIXED_ORDER,
    MATHCAD_FUNCTIONS,
    OPERATOR_FUNCTIONS,
    OPERATOR_FUNCTIONS_2,
    ORIGIN_FUNCTIONS,
    REFUSED,
    language_functions,
)
from .reader import MNode
from .symbols import Sym, Untranslatable, matrix_size
from .symbols import key as _key
from .symbols import what as _what
from .translation import uses
from .units import FORMULA_UNITS


def _vector_sum(bvars: list[MNode], args: list[MNode], lam: MNode) -> bool:
    """Prime's vector sum: Σ whose bound variable and upper bound are empty placeholders."""
    if len(bvars) != 1 or bvars[0].tag != "placeholder":
        return False
    rest = [a for a in args if a is not lam]
    return all(
        a.tag == "upperBound" and all(c.tag == "placeholder" for c in a.children) for a in rest
    )


#: Mathcad's tests of a value's shape: 1 or 0
SHAPE_TESTS = ("IsArray", "IsScalar")


class ExprTranslator(Visitor):
    """Mathcad math element -> expression tree, names resolved in a scope."""

    def __init__(self, tr: TranslatorContext, local: dict[tuple[str, str], Sym] | None = None):
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

    def visit_imag(self, node: MNode) -> ex.Node:
        """Mathcad's imaginary literal (``4i``, ``2j``: its text is the imaginary part)."""
        try:
            value = float(node.text.strip())
        except ValueError:
            raise Untranslatable(f"the imaginary number {node.text.strip()!r}") from None
        if not math.isfinite(value):
            raise Untranslatable(f"the imaginary number {node.text.strip()!r} is not finite")
        if math.copysign(1.0, value) < 0:
            return ex.Unary("-", ex.Imaginary(-value))
        return ex.Imaginary(value)

    def visit_parens(self, node: MNode) -> ex.Node:
        return self.visit(node.children[0])

    def visit_id(self, node: MNode) -> ex.Node:
        key = _key(node)
        if node.attrs.get("labels") == "UNIT" and not key[1] and key[0] in FORMULA_UNITS:
            return ex.Name(self.tr.unit_sym(key[0]).token())  # labelled a unit in Mathcad
        sym = self.local.get(key) or self.tr.scope.get(key)
        if sym is not None:
            if sym.broken:
                raise Untranslatable(uses(sym))
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
        if tag in tt.BINARY and len(args) == 2:
            left, right = self.value(args[0]), self.value(args[1])
            if tag == "div":
                left, right = self._radians(left, right), self._radians(right, left)
                if self._prime_number_over_vector(left, right):
                    # Prime divides a number by a vector element by element (it stores the
                    # vector of quotients); Mathcad 15 refuses it
                    return ex.Call("vectorize", (ex.Binary("/", left, right),))
            return ex.Binary(tt.BINARY[tag], left, right)
        if tag in tt.COMPARE and len(args) == 2:
            return self._compare(tag, args)
        if tag == "neg" and len(args) == 1:
            return ex.Unary("-", self.value(args[0]))
        if tag in ("and", "or") and len(args) == 2:
            return tt.logic(tag, [self.condition(a) for a in args])
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
            if tt.is_if(node):
                cond, a, b = tt.if_args(node)
                return ex.IfElse(self.value(a), self.condition(cond), self.value(b))
            return self._call(op, args)
        if tag == "indexer" and len(args) == 2:
            return self._index(args)
        if tag == "matcol" and len(args) == 2:
            return self._column(args)
        if tag in BINDERS:
            return self._binder(tag, args)
        if tag == "vectorize" and len(args) == 1:
            return self._vectorize(self.value(args[0]))
        if tag == "Find":
            return self.tr.find(self, args, op.attrs.get("method", ""))
        if tag in ("Maximize", "Minimize"):
            return self.tr.extremum(self, args, tag == "Maximize")
        raise Untranslatable(f"{_what(tag)} is not in the language yet")

    def _prime_number_over_vector(self, left: ex.Node, right: ex.Node) -> bool:
        """A number of the sheet divided by a vector of the sheet, in a Prime worksheet."""
        if self.tr.out.generator != "Mathcad Prime" or self.local:
            return False
        vector = isinstance(right, ex.Name) and self.tr.is_array(right.id)
        number = not tt.has_matrix(left) and not any(self.tr.is_array(n) for n in ex.names(left))
        return vector and number

    def value(self, node: MNode) -> ex.Node:
        """``node`` where Mathcad uses a number: a comparison (Mathcad's 1 or 0) is
        ``(1 if C otherwise 0)``."""
        return tt.as_number(self.visit(node))

    def condition(self, node: MNode) -> ex.Node:
        """``node`` where Mathcad tests it (if, while, if()): a product of comparisons is
        ``C1 and C2`` (Mathcad's idiom for and), a sum of them ``C1 or C2``, a comparison
        itself; any other value is true where it is not 0 (``X != 0``)."""
        inner = tt.unparen(node)
        if inner.tag == "apply" and len(inner.children) == 3:
            op = inner.children[0].tag
            if op in ("mult", "plus") and all(tt.is_condition(a) for a in inner.children[1:]):
                word = "and" if op == "mult" else "or"
                return tt.logic(word, [self.condition(a) for a in inner.children[1:]])
        tree = self.visit(node)
        if tt.is_boolean(tree):
            return tree
        return ex.Compare(("!=",), (tree, ex.Number(0.0)))

    def _compare(self, tag: str, args: list[MNode]) -> ex.Node:
        """A comparison; Mathcad's ranged inequality ``a <= t <= b`` (stored as a comparison
        whose left side is an inequality, without brackets) is the chain ``a <= t <= b``."""
        left = args[0]
        if (
            tag in tt.INEQUALITY
            and left.tag == "apply"
            and len(left.children) == 3
            and left.children[0].tag in tt.INEQUALITY
        ):
            chain = self._compare(left.children[0].tag, left.children[1:])
            if isinstance(chain, ex.Compare):
                return ex.Compare(
                    (*chain.ops, tt.COMPARE[tag]), (*chain.operands, self.value(args[1]))
                )
        return ex.Compare((tt.COMPARE[tag],), (self.value(args[0]), self.value(args[1])))

    def _radians(self, node: ex.Node, other: ex.Node) -> ex.Node:
        """``node / rad`` where ``node`` is an angle in degrees (or another angle unit) and
        ``other`` a bare number: Mathcad's angles are plain numbers in radians, so its
        ``alpha*pi/180`` of ``alpha = 6 deg`` is 0.1047*pi/180; the language refuses an angle
        divided by a bare number (a plain number of degrees), so the angle is made the plain
        number in radians Mathcad divides."""
        if not isinstance(other, ex.Number) or isinstance(node, ex.Number):
            return node
        unit = self.tr.at_import().unit(node)
        from ..language.units import angle_in

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
        name = BINDERS[tag]
        lam = next((a for a in args if a.tag == "lambda"), None)
        bounds = next((a for a in args if a.tag == "bounds"), None)
        if lam is None or len(lam.children) != 2:
            raise Untranslatable(f"{_what(tag)} without a bound variable")
        bvars = lam.children[0].children
        if tag == "summation" and _vector_sum(bvars, args, lam):
            # Prime's vector sum (Σv: Σ with empty placeholders) is the sum of v's elements
            return self._builtin("sum", "the vector sum", [self.value(lam.children[1])])
        if len(bvars) != 1:
            raise Untranslatable(f"{_what(tag)} over {len(bvars)} variables")
        body, var = self.bound(bvars[0], lam.children[1])
        if tag == "derivative":
            if bounds is not None:
                raise Untranslatable("a derivative with bounds")
            order = tt.derivative_order(next((a for a in args if a.tag == "degree"), None))
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
        m, j, first, last = self._slice(args, "rows")
        return ex.Call("submatrix", (m, first, last, j, j))

    def _row(self, args: list[MNode]) -> ex.Node:
        """Prime's row M<i> (a row of one row): submatrix(M, i, i, first column, last)."""
        m, i, first, last = self._slice(args, "cols")
        return ex.Call("submatrix", (m, i, i, first, last))

    def _slice(self, args: list[MNode], size: str) -> tuple[ex.Node, ...]:
        """M, the index of its column or row, and the first and last index along the other
        axis (``size``: rows or cols) in the sheet's origin."""
        m, k = self.value(args[0]), self.value(args[1])
        shift = self.tr.sheet_origin - self.tr.origin  # ORIGIN redefined after the first index
        if shift:
            k = ex.Binary("+", k, ex.Number(float(shift)))
        o = self.tr.sheet_origin
        last = ex.Call(size, (m,))
        if o != 1:
            last = ex.Binary("-" if o < 1 else "+", last, ex.Number(float(abs(o - 1))))
        return m, k, ex.Number(float(o)), last

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

        sheet_calls: list[str] = []  # the worksheet's functions called with a vector

        def scan(node: ex.Node) -> None:
            n = vector_length(node)
            if n is not None:
                lengths.add(n)
                return
            if isinstance(node, ex.Call):
                for a in node.args:
                    if vector_length(a) is None or _of_numbers(node.func):
                        continue
                    if self._sheet_function(node.func):
                        # Mathcad calls a function of the worksheet once per element
                        sheet_calls.append(node.func)
                        continue
                    called = self.tr.mathcad_name(node.func)
                    raise Untranslatable(
                        f"a vectorised call of {called} (only functions of one "
                        "number are applied element by element)"
                    )
            if isinstance(node, ex.Index):
                raise Untranslatable("a vectorised expression with an index")
            for child in ex.children(node):
                scan(child)

        scan(tree)
        if unknown and sheet_calls:
            called = self.tr.mathcad_name(sheet_calls[0])
            raise Untranslatable(
                f"a vectorised call of {called}, a function of the worksheet, over a vector "
                "whose length is not known at import"
            )
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

    def _sheet_function(self, token: str) -> bool:
        """Is ``token`` (a call's function) a function the worksheet defines?"""
        if not token.startswith("\x00"):
            return False
        sym = next((s for s in self.tr.out.syms if s.token() == token), None)
        return sym is not None and sym.kind == "func"

    def _absval(self, x: ex.Node) -> ex.Node:
        """Mathcad's |x|: abs of a number, but the length of a vector and the determinant of
        a square matrix: ``mag`` (the shape decides at load) where x may be a vector (it
        reads a function's parameter, a program's local, a matrix or a vector the sheet
        defines), else ``abs``."""
        local = {s.token() for s in self.local.values()}
        names = ex.names(x)
        vectors = any(self.tr.is_array(n) for n in names)
        if names & local or vectors or tt.has_matrix(x):
            return self._builtin("mag", "absval", [x])
        return self._builtin("abs", "absval", [x])

    def _builtin(self, name: str, mathcad: str, args: list[ex.Node]) -> ex.Node:
        if name not in language_functions():
            raise Untranslatable(f"Mathcad's {mathcad}() has no built-in in the language yet")
        if name == "sqrt" and self.tr.complex_roots and len(args) == 1:
            # Mathcad 15's square root of a negative number is imaginary (sqrt(-4) = 2i):
            # in a definition whose values Mathcad stored as complex, the complex root
            args = [ex.Binary("+", args[0], ex.Imaginary(0.0))]
        return ex.Call(name, tuple(args))

    def _call(self, op: MNode, args: list[MNode]) -> ex.Node:
        key = _key(op)
        sym = self.local.get(key) or self.tr.scope.get(key)
        if sym is not None:
            if sym.broken:
                raise Untranslatable(uses(sym))
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
            values = tt.eigenvals_argument(args[0])
            if values is not None:  # sorted: Prime's order of eigenvalues does not matter
                inner = self._builtin("eigenvals", "eigenvals", [self.value(values)])
                return self._builtin("sort", "sort", [inner])
        if text == "eigenvals" and not key[1] and len(args) == 1 and self.tr.prime:
            # Prime gives the eigenvalues from the largest down (every result it stored, of
            # matrices of 2 to 6 rows, symmetric or not): the language's sorted, reversed.
            # Mathcad 15's order is its solver's (ascending in one worksheet, descending in
            # another), so eigenvals alone stays refused there. Complex eigenvalues are not
            # sorted by the language (refused, never reordered another way).
            inner = self._builtin("eigenvals", "eigenvals", [self.value(args[0])])
            return self._builtin("reverse", "eigenvals", [self._builtin("sort", "sort", [inner])])
        if text == "rkfixed" and not key[1]:
            from .odes import rkfixed

            return rkfixed(self, args)
        if text == "linfit" and not key[1] and len(args) == 3:
            return self._linfit(args)
        if text == "histogram" and not key[1] and len(args) == 2:
            return self._histogram(args)
        if text in ("min", "max") and len(args) == 1 and args[0].tag == "matrix":
            args = args[0].children  # min of a literal vector: min of its elements
        if text in ORIGIN_FUNCTIONS and not key[1] and self.tr.origin != self.tr.sheet_origin:
            raise Untranslatable(
                f"{text}() where ORIGIN is {self.tr.origin}, and the worksheet's origin (ORIGIN "
                f"at its first index) is {self.tr.sheet_origin}: its indices would be off"
            )
        if text in SHAPE_TESTS and not key[1] and len(args) == 1:
            return self._shape_test(text, args[0])
        if text == "norm" and not key[1] and len(args) == 1:
            return self._vector_norm(args[0])
        if text in MATHCAD_FUNCTIONS and not key[1]:
            name, order = MATHCAD_FUNCTIONS[text]
            if order is not None:
                if len(args) != len(order):
                    raise Untranslatable(f"{text}() with {len(args)} arguments")
                args = [args[i] for i in order]
            return self._builtin(name, text, [self.value(a) for a in args])
        if text in FIXED_ORDER and not key[1] and len(args) == 1:
            name, order = FIXED_ORDER[text]
            return self._builtin(name, text, [ex.Number(float(order)), self.value(args[0])])
        if text in REFUSED and not key[1]:
            raise Untranslatable(f"Mathcad's {text}() {REFUSED[text]}")
        raise Untranslatable(
            f"{nm.mathcad_text(*key)}() is neither defined before nor a known built-in"
        )

    def _shape_of(self, arg: MNode, what: str) -> tuple[ex.Node, tuple[int, int] | None]:
        """The translated ``arg`` and its (rows, columns), None for one number, as the engine
        types it at import; a value whose shape is not known then is untranslatable."""
        tree = self.value(arg)
        at = self.tr.at_import()
        shape = at.shape(tree)
        if shape is None and at.unit(tree) is None:
            raise Untranslatable(f"{what} of a value whose shape is not known at import")
        return tree, shape

    def _shape_test(self, text: str, arg: MNode) -> ex.Node:
        """Mathcad's IsArray(x) and IsScalar(x): 1 or 0, from x's shape (an array or one
        number), which the language fixes when the worksheet is loaded."""
        _, shape = self._shape_of(arg, f"{text}()")
        array = shape is not None
        return ex.Number(1.0 if array == (text == "IsArray") else 0.0)

    def _vector_norm(self, arg: MNode) -> ex.Node:
        """Prime's norm(v) of a vector: its length, the square root of the sum of its
        elements' squares (the language's norm, of a matrix the Frobenius norm, is that of a
        vector). Of a matrix or a number it is not translated (which of its norms Prime
        gives there no stored result shows)."""
        tree, shape = self._shape_of(arg, "norm()")
        if shape is None or 1 not in shape:
            raise Untranslatable("Prime's norm() of something that is not a vector")
        return self._builtin("norm", "norm", [tree])

    def _histogram(self, args: list[MNode]) -> ex.Node:
        """Mathcad's histogram(intervals, data) counts every element of data, a matrix too:
        a matrix of columns known at import is the stack of its columns (the counts do not
        depend on the order of the values)."""
        n, data = self.value(args[0]), self.value(args[1])
        if not isinstance(n, ex.Number):  # a count of intervals: a number the engine sees
            try:
                n = ex.Number(float(whole_at_import(self.tr, args[0], "histogram()")))
            except Untranslatable:
                pass  # intervals given as a vector, or a count not known at import
        try:
            columns = self.tr.quantity(
                MNode("apply", {}, "", [MNode("id", {}, "cols", []), args[1]])
            )
            columns = int(float(columns.to("").magnitude))
        except Exception:  # noqa: BLE001 - not known at import: the data as it is
            columns = 1
        if 1 < columns <= tt.MAX_STACKED_COLUMNS:
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

    def _linfit(self, args: list[MNode]) -> ex.Node:
        """Mathcad's linfit(vx, vy, F): the coefficients of the combination of the functions
        of F (a function of x giving a vector) nearest vy in least squares, ``geninv(A) *
        vy`` where row i of A is F(vx[i]) (vx a vector of the sheet of a length known at
        import, written out row by row)."""
        vx, vy = self.value(args[0]), self.value(args[1])
        f = tt.unparen(args[2])
        sym = (self.local.get(_key(f)) or self.tr.scope.get(_key(f))) if f.tag == "id" else None
        if sym is None or sym.kind != "func":
            raise Untranslatable("linfit(vx, vy, F) whose F is not the name of a function")
        if sym.broken:
            raise Untranslatable(uses(sym))
        n = self.tr.vector_length_of(vx) if isinstance(vx, ex.Name) else None
        if n is None or n > MAX_WRITTEN_ELEMENTS:
            raise Untranslatable("linfit(vx, vy, F) whose vx is not a vector of a known length")
        rows = []
        for i in range(n):
            x = (ex.Index(vx, (ex.Number(float(self.tr.sheet_origin + i)),)),)
            if sym.token() in self.tr.inline:
                row = self.tr.local_call(sym, x)
            else:
                self.tr.calls.setdefault(sym, []).append(x)
                row = ex.Call(sym.token(), x)
            rows.append(ex.Call("transpose", (row,)))
        return ex.Binary("*", ex.Call("geninv", (ex.Call("stack", tuple(rows)),)), vy)

    def _matrix_of_function(self, args: list[MNode]) -> ex.Node:
        """Mathcad's matrix(m, n, f): the m x n matrix of f(i, j), i and j counted from 0
        (whatever ORIGIN), written out as a matrix of calls; m and n must be whole numbers
        known at import. At an ORIGIN other than 0, only a function that does not read its
        arguments is translated: no stored result shows which indices Mathcad gives f there."""
        f = tt.unparen(args[2])
        sym = (self.local.get(_key(f)) or self.tr.scope.get(_key(f))) if f.tag == "id" else None
        if sym is None or sym.kind != "func":
            raise Untranslatable("matrix(m, n, f) whose f is not the name of a function")
        if sym.broken:
            raise Untranslatable(uses(sym))
        if any(_key(n) in self.local for a in args[:2] for n in tt.walk(a) if n.tag == "id"):
            # a program's local or parameter: never the sheet's name of the same spelling
            raise Untranslatable("matrix(m, n, f) whose size is not a number known at import")
        m, n = (whole_at_import(self.tr, a, "matrix(m, n, f)") for a in args[:2])
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


#: The most elements a construct written out element by element may have (matrix(m, n, f)).
MAX_WRITTEN_ELEMENTS = 10_000


def _of_numbers(name: str) -> bool:
    """A built-in of numbers: vectorize applies it element by element (the language refuses
    one of several arguments called with a vector, with its reason)."""
    entry = REGISTRY.get(name)
    return entry is not None and entry.of_numbers


def whole_at_import(tr: TranslatorContext, node: MNode, what: str) -> int:
    """A size Mathcad gives as an expression: a whole number of at least 1 known at import."""
    try:
        value = float(tr.quantity(node).to("").magnitude)
    except Exception:  # noqa: BLE001 - not a value known at import, or not a plain number
        raise Untranslatable(f"{what} whose size is not a number known at import") from None
    if not (math.isfinite(value) and value == int(value) and value >= 1):
        raise Untranslatable(f"{what} whose size {value:g} is not a whole number of at least 1")
    return int(value)
