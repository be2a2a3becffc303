"""Typing of vectors, matrices, indexing, inline conditions, programs and ODE states.

A mixin of :class:`workbook.typecheck.Typer`: the rules for the node kinds that carry a
shape (rows, columns) or text. A matrix has one unit (a matrix whose elements differ in
dimension is refused at load); shapes are known at load, so a product of a 2x3 by a 2x2
matrix, ``det`` of a non-square matrix or a constant index out of range are load errors.

Operators on matrices, as in Mathcad: ``+ -`` element by element (same shape, or a matrix and
a scalar); ``*`` a scalar times a matrix, the matrix product (typed op ``@``), or the dot
product of two vectors of one length; ``/`` by a scalar; ``M^n`` the matrix power of a square
matrix (``M^-1`` its inverse; typed op ``@^``). Inside ``vectorize(...)`` (Mathcad's
vectorize arrow) ``* / ^`` work element by element. Functions of one number (sin, sqrt, ...)
apply to each element.
"""

from __future__ import annotations

from dataclasses import replace

import pint

from . import expr as ex
from . import units as un
from .errors import ShapeError, TemplateError, UnitError
from .typed import (
    RUNTIME,
    T,
    TBinary,
    TConst,
    TFunc,
    TIndex,
    TMatrix,
    TOde,
    TParam,
    TPiecewise,
    TProgram,
    is_runtime,
    is_zero,
    shape_text,
)

#: Most elements of one matrix written out.
MAX_ELEMENTS = 10_000


class ArrayTyping:
    """Typing rules of the array, text, program and ODE node kinds (mixed into Typer)."""

    _elementwise = 0  # depth of vectorize(...) around the node being typed

    # -- literals and indexing ------------------------------------------------------------
    def visit_Matrix(self, node: ex.Matrix, scope) -> T:
        r, c = len(node.rows), len(node.rows[0])
        if r * c > MAX_ELEMENTS:
            raise TemplateError(f"a matrix of {r * c} elements (limit {MAX_ELEMENTS})")
        typed = [[self.visit(e, scope) for e in row] for row in node.rows]
        first = None
        nested = any(e.shape is not None for row in typed for e in row)
        # text beside numbers (a table of load kinds): its elements are looked at when it runs
        texts = any(e.text for row in typed for e in row)
        for i, row in enumerate(typed):
            for j, e in enumerate(row):
                where = f"element [{i}, {j}] of the matrix"
                if e.boolean:
                    raise TemplateError(f"{where} is a comparison; elements are numbers or text")
                if e.text:
                    continue
                self._number(e, where)
                if first is None and not is_zero(e):
                    first = (e, i, j)
        unit = first[0].unit if first else self.dimensionless
        rows = []
        for i, row in enumerate(typed):
            out = []
            for j, e in enumerate(row):
                if e.text:
                    out.append(e)
                    continue
                if not is_zero(e) and e.unit.dimensionality != unit.dimensionality:
                    f, fi, fj = first
                    raise UnitError(
                        f"a matrix has one unit: element [{i}, {j}] is {un.dims(e.unit)} "
                        f"({un.pretty(e.unit) or '1'}), element [{fi}, {fj}] is "
                        f"{un.dims(unit)} ({un.pretty(unit) or '1'}); split it into "
                        "matrices of one dimension each"
                    )
                out.append(self.convert(e, unit, f"element [{i}, {j}] of the matrix"))
            rows.append(tuple(out))
        # an array of arrays (Mathcad's nested array): its shape is looked at when it runs
        return TMatrix(unit, rows=tuple(rows), shape=RUNTIME if nested or texts else (r, c))

    def visit_Index(self, node: ex.Index, scope) -> T:
        target = self.visit(node.target, scope)
        if target.shape is None:
            raise ShapeError(
                f"{ex.to_text(node.target)} is not a vector or matrix; it cannot be indexed"
            )
        n = len(node.indices)
        if is_runtime(target.shape):  # its shape, and the element's, are known when it runs
            if n > 2:
                raise TemplateError(f"{ex.to_text(node)}: at most two indices, M[i, j]")
            words = ("row", "column") if n == 2 else ("element",)
            idx = tuple(
                self.typed_index(i, scope, None, w, ex.to_text(node))
                for i, w in zip(node.indices, words)
            )
            return TIndex(
                target.unit, target=target, indices=idx, origin=self.spec.origin, shape=RUNTIME
            )
        r, c = target.shape
        if n == 1 and c != 1:
            raise TemplateError(
                f"{ex.to_text(node.target)} is a {shape_text(target.shape)}: "
                "write M[i, j] (one index is for a vector)"
            )
        idx = []
        for k, (i, size) in enumerate(zip(node.indices, (r, c) if n == 2 else (r,))):
            word = ("row", "column")[k] if n == 2 else "element"
            idx.append(self.typed_index(i, scope, size, word, ex.to_text(node)))
        return TIndex(target.unit, target=target, indices=tuple(idx), origin=self.spec.origin)

    def typed_index(self, i: ex.Node, scope, size: int | None, word: str, what: str) -> T:
        """An index: a plain number; a constant one is checked against ``size`` here (None:
        a run-time array, checked when it runs)."""
        origin = self.spec.origin
        t = self.plain(self._number(self.visit(i, scope), "an index"), f"the {word} index")
        if t.shape is not None and not is_runtime(t.shape):
            raise TemplateError(f"the {word} index is a matrix; an index is a number")
        if isinstance(t, TConst) and size is not None:
            v = t.value
            if v != int(v) or not origin <= v < origin + size:
                raise TemplateError(
                    f"{what}: {word} index {v:g} is out of range "
                    f"({size} {word}s: {origin} .. {origin + size - 1} with origin {origin})"
                )
        return t

    def visit_IfElse(self, node: ex.IfElse, scope) -> T:
        value = self.visit(node.value, scope)
        other = self.visit(node.other, scope)
        cond = self.visit(node.condition, scope)
        if not cond.boolean:
            raise TemplateError(f"the condition of {ex.to_text(node)!r} is not a comparison")
        if value.boolean or other.boolean:
            raise TemplateError(f"{ex.to_text(node)!r} gives a comparison, not a value")
        runtime = is_runtime(value.shape) or is_runtime(other.shape)
        if not runtime and (value.shape is not None or other.shape is not None):
            raise TemplateError(f"{ex.to_text(node)!r}: the values of a condition are numbers")
        if runtime and any(v.shape is not None and not is_runtime(v.shape) for v in (value, other)):
            raise TemplateError(f"{ex.to_text(node)!r}: the values of a condition are numbers")
        if value.text != other.text:
            raise TemplateError(
                f"{ex.to_text(node)!r} gives text on one side, a number on the other"
            )
        unit = value.unit
        if not value.text:
            self._number(value, "a value")
            self._number(other, "a value")
            if is_zero(value) and not is_zero(other):
                unit = other.unit
            value = self.convert(value, unit, "the value if the condition holds")
            other = self.convert(other, unit, f"the value otherwise ({ex.to_text(node.other)})")
        texts = (ex.to_text(node.value) + " if " + ex.to_text(node.condition),)
        return TPiecewise(
            unit,
            conditions=(cond, None),
            values=(value, other),
            texts=texts + (ex.to_text(node.other) + " otherwise",),
            text=value.text,
            # a value known when it runs (an element of a run-time array): a number, checked
            shape=RUNTIME if runtime else None,
        )

    # -- operators -------------------------------------------------------------------------
    def matrix_binary(self, op: str, left: T, right: T) -> T:
        """``left op right`` where at least one side is a vector or matrix."""
        ls, rs = left.shape, right.shape
        if is_runtime(ls) or is_runtime(rs):
            return self.runtime_binary(op, left, right)
        if op in "+-":
            if ls is not None and rs is not None and ls != rs:
                raise TemplateError(
                    f"cannot {'add' if op == '+' else 'subtract'} a {shape_text(rs)} "
                    f"{'to' if op == '+' else 'from'} a {shape_text(ls)}"
                )
            if right.unit.dimensionality != left.unit.dimensionality and not is_zero(right):
                self._mismatch(op, left, right)
            right = self.convert(right, left.unit, "sum")
            return TBinary(left.unit, op=op, left=left, right=right, shape=ls or rs)
        if op == "*":
            unit = left.unit * right.unit
            if ls is None or rs is None:
                return TBinary(unit, op="*", left=left, right=right, shape=ls or rs)
            if self._elementwise:
                self._same_shape("multiply", ls, rs)
                return TBinary(unit, op="*", left=left, right=right, shape=ls)
            if ls[1] == 1 and rs[1] == 1 and ls[0] == rs[0] and ls[0] > 1:
                return TFunc(unit, func="dot", args=(left, right))  # Mathcad's v*w
            if ls[1] != rs[0]:
                raise TemplateError(
                    f"cannot multiply a {shape_text(ls)} by a {shape_text(rs)}: the columns "
                    f"of the left ({ls[1]}) must equal the rows of the right ({rs[0]}); "
                    "for element by element write vectorize(...)"
                )
            return TBinary(unit, op="@", left=left, right=right, shape=(ls[0], rs[1]))
        if op == "/":
            if rs is not None and not self._elementwise:
                raise TemplateError(
                    "cannot divide by a vector or matrix; multiply by inverse(M), or write "
                    "vectorize(a/b) for element by element"
                )
            if ls is not None and rs is not None:
                self._same_shape("divide", ls, rs)
            return TBinary(left.unit / right.unit, op="/", left=left, right=right, shape=ls or rs)
        # power
        if rs is not None:
            if not self._elementwise:
                raise TemplateError("an exponent must be a number, not a vector or matrix")
            if ls is not None:
                self._same_shape("raise", ls, rs)
        if not right.unit.dimensionless or right.unit.dimensionality:
            raise UnitError(f"an exponent must be dimensionless, got {un.dims(right.unit)}")
        right = self.convert(right, self.dimensionless, "exponent")
        if self._elementwise or ls is None:
            if left.unit.dimensionality and not isinstance(right, TConst):
                raise UnitError(f"{un.dims(left.unit)} raised to a variable power has no unit")
            unit = left.unit**right.value if isinstance(right, TConst) else left.unit
            return TBinary(unit, op="^", left=left, right=right, shape=ls or rs)
        if not isinstance(right, TConst) or right.value != int(right.value):
            raise TemplateError(
                "a matrix power M^n needs a constant integer n (M^-1 is the inverse); "
                "for element by element write vectorize(M^x)"
            )
        if ls[0] != ls[1]:
            raise TemplateError(f"a power of a {shape_text(ls)}: the matrix must be square")
        n = int(right.value)
        if abs(n) > 1000:
            raise UnitError(f"matrix power {n} is out of range (at most 1000)")
        return TBinary(left.unit**n, op="@^", left=left, right=right, shape=ls)

    def runtime_binary(self, op: str, left: T, right: T) -> T:
        """``left op right`` with a run-time array on one side: the units as for numbers
        (:meth:`scalar_binary`), the shapes by Mathcad's rules when it runs
        (:func:`workbook.runtime.binary`)."""
        if self._elementwise:
            raise TemplateError(
                "vectorize(...) of an array whose size is known only when it runs; write a "
                "loop over its elements"
            )
        return replace(self.scalar_binary(op, left, right), shape=RUNTIME)

    def _same_shape(self, verb: str, ls, rs) -> None:
        if ls != rs:
            raise TemplateError(
                f"cannot {verb} a {shape_text(ls)} and a {shape_text(rs)} element by element"
            )

    def vectorize(self, node: ex.Call, scope) -> T:
        """``vectorize(EXPR)``: ``* / ^`` inside work element by element."""
        if len(node.args) != 1:
            raise TemplateError(f"vectorize() takes 1 argument, got {len(node.args)}")
        self._elementwise += 1
        try:
            return self.visit(node.args[0], scope)
        finally:
            self._elementwise -= 1

    def elementwise_call(self, name: str, entry, args: tuple, typed: T) -> T:
        """A built-in of numbers called with a matrix: it applies to each element."""
        shaped = [a.shape for a in args if a.shape is not None]
        if not shaped:
            return typed
        if any(is_runtime(s) for s in shaped):  # numbers, or arrays element by element
            return replace(typed, shape=RUNTIME)
        if len(args) != 1:
            raise TemplateError(
                f"{name}() takes numbers, not a vector or matrix; index the elements, or "
                "use a function of vectors"
            )
        return replace(typed, shape=shaped[0])

    # -- definitions written as programs or as ODE states ----------------------------------
    def program_body(self, d, scope: dict[str, pint.Unit]) -> T:
        from .program import typer as pg

        def type_expr(node, sc):
            return self.visit(node, sc)

        def convert(t, unit, where):
            if t.text:
                raise TemplateError(f"{where}: text where a number is wanted")
            return self.convert(t, unit, where)

        typing = pg.ExprTyping(
            type_expr=type_expr,
            convert=convert,
            is_boolean=lambda t: t.boolean,
            is_text=lambda t: t.text,
            is_zero=is_zero,
            unit_of=lambda t: t.unit,
            shape_of=lambda t: t.shape,
            scope_entry=lambda unit, shape: unit if shape is None else (unit, shape),
            index=lambda i, sc, size, word: self.typed_index(i, sc, size, word, "an element"),
            origin=self.spec.origin,
        )
        reserved = frozenset(self.spec.inputs) | frozenset(self.spec.definitions)
        typed = pg.type_program(d.program, dict(scope), typing, reserved=reserved - set(scope))
        return TProgram(
            typed.unit,
            name=d.name,
            program=typed,
            params=tuple(d.params),
            matrices=tuple(p for p in d.params if isinstance(scope[p], tuple)),
            text=typed.text,
            shape=typed.shape,
        )

    def ode_body(self, d, scope: dict[str, pint.Unit]) -> T:
        name, k = d.ode
        typed = self.ode(name)
        (var,) = d.params
        t = TParam(scope[var], name=var)
        shape = typed.shapes[k] if typed.shapes else None
        return TOde(typed.units[k], ode=name, state=k, name=d.name, args=(t,), shape=shape)

    def ode(self, name: str):
        """The typed section ``[[ode]] name`` (units checked once)."""
        from .ode import type_ode

        cache = self.__dict__.setdefault("_odes", {})
        if name not in cache:
            spec = self.spec.odes[name]
            key = f"ode {name}"
            if key in self._stack:
                raise TemplateError(f"ode '{name}' refers to its own solution")
            self._stack.append(key)
            try:
                cache[name] = type_ode(self, spec)
            finally:
                self._stack.pop()
        return cache[name]
