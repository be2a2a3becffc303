"""The shape rules of operators and built-ins on vectors and matrices.

A base of :class:`workbook.language.typecheck.Typer` (which types the array, index, program and ODE
nodes): the rules take typed operands and give the typed result, calling only the unit rules
(:mod:`workbook.language.unitrules`) below them. A matrix has one unit; shapes are known at load, so
a product of a 2x3 by a 2x2 matrix is a load error.

Operators on matrices, as in Mathcad: ``+ -`` element by element (same shape, or a matrix and
a scalar); ``*`` a scalar times a matrix, the matrix product (typed op ``@``), or the dot
product of two vectors of one length; ``/`` by a scalar; ``M^n`` the matrix power of a square
matrix (``M^-1`` its inverse; typed op ``@^``). Inside ``vectorize(...)`` (Mathcad's
vectorize arrow) ``* / ^`` work element by element. Functions of one number (sin, sqrt, ...)
apply to each element.
"""

from __future__ import annotations

from dataclasses import replace

from ..errors import TemplateError, UnitError
from . import units as un
from .typed import (
    RUNTIME,
    T,
    TBinary,
    TConst,
    TFunc,
    is_runtime,
    is_zero,
    shape_text,
)


class ArrayTyping:
    """Shape rules of the operators on arrays (a base of the typer)."""

    _elementwise = 0  # depth of vectorize(...) around the node being typed

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
                self.mismatch(op, left, right)
            if not is_zero(left) and not is_zero(right):  # T - 20 degC: differences
                left, right, unit = self.temperature_sum(op, left, right)
                if unit is not None:
                    return TBinary(unit, op=op, left=left, right=right, shape=ls or rs)
            right = self.convert(right, left.unit, "sum")
            return TBinary(left.unit, op=op, left=left, right=right, shape=ls or rs)
        left, right = self.kelvin(left), self.kelvin(right)  # 2*T: in kelvin, as numbers
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
        (:func:`workbook.engine.runtime.binary`)."""
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
