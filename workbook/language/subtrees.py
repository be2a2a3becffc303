"""Structural keys of typed subtrees, and which of them a sheet computes more than once.

Two typed nodes with the same key compute the same magnitudes from the same environment
(units are not part of the key: a back end reads magnitudes and factors only). The numpy
back end (:mod:`workbook.engine.numeric`) keeps, within one evaluation, the value of every subtree
whose key occurs more than once among the sheet's definitions and that is costly (a call of a
function or a built-in, a power), so ``sin(phi*deg)`` shared by h1, v1 and j1, or ``f(x)``
written twice in a body, is computed once.
"""

from __future__ import annotations

import weakref
from collections import Counter

from . import typed as ty
from .visitor import Visitor


class Keys(Visitor):
    """Interns typed nodes: ``key(t)`` is a small int, equal for structurally equal nodes."""

    def __init__(self) -> None:
        self._ids: dict[tuple, int] = {}
        self._of: dict[int, tuple[ty.T, int]] = {}  # id(node) -> (node kept alive, key)

    def key(self, t: ty.T) -> int:
        """The structural key of ``t`` (computed once per node object)."""
        hit = self._of.get(id(t))
        if hit is not None:
            return hit[1]
        sig = self.visit(t)
        k = self._ids.setdefault(sig, len(self._ids))
        self._of[id(t)] = (t, k)
        return k

    def signature(self, *parts) -> int:
        """A key for a signature built by a caller (e.g. the partition of a piecewise)."""
        return self._ids.setdefault(("extra", *parts), len(self._ids))

    def _part(self, v):
        if isinstance(v, ty.T):
            return ("node", self.key(v))
        if isinstance(v, tuple):
            return tuple(self._part(x) for x in v)
        if isinstance(v, float):
            return repr(v)  # -0.0 and 0.0 differ (atan2, 1/x)
        return v

    def _fields(self, t: ty.T, *names: str) -> tuple:
        own = (type(t).__name__, t.shape, t.text)  # a matrix or a text computes otherwise
        return (*own, *(self._part(getattr(t, n)) for n in names))

    def visit_TConst(self, t: ty.TConst) -> tuple:
        return self._fields(t, "value")

    def visit_TText(self, t: ty.TText) -> tuple:
        return self._fields(t, "value")

    def visit_TParam(self, t: ty.TParam) -> tuple:
        return self._fields(t, "name")

    def visit_TRef(self, t: ty.TRef) -> tuple:
        return self._fields(t, "name", "kind")

    def visit_TScale(self, t: ty.TScale) -> tuple:
        return self._fields(t, "child", "factor")

    def visit_TUnary(self, t: ty.TUnary) -> tuple:
        return self._fields(t, "op", "child")

    def visit_TBinary(self, t: ty.TBinary) -> tuple:
        return self._fields(t, "op", "left", "right")

    def visit_TCompare(self, t: ty.TCompare) -> tuple:
        return self._fields(t, "ops", "operands")

    def visit_TLogic(self, t: ty.TLogic) -> tuple:
        return self._fields(t, "op", "values")

    def visit_TFunc(self, t: ty.TFunc) -> tuple:
        return self._fields(t, "func", "args")

    def visit_TCall(self, t: ty.TCall) -> tuple:
        return self._fields(t, "name", "args")

    def visit_TBlock(self, t: ty.TBlock) -> tuple:
        return self._fields(t, "name", "ref", "args")

    def visit_TAggregate(self, t: ty.TAggregate) -> tuple:
        return self._fields(t, "func", "table", "column")

    def visit_TPiecewise(self, t: ty.TPiecewise) -> tuple:
        return self._fields(t, "conditions", "values", "texts")

    def visit_TMatrix(self, t: ty.TMatrix) -> tuple:
        return self._fields(t, "rows")

    def visit_TIndex(self, t: ty.TIndex) -> tuple:
        return self._fields(t, "target", "indices", "origin")

    def visit_TProgram(self, t: ty.TProgram) -> tuple:
        return (*self._fields(t, "name", "params"), ("program", id(t.program)))

    def visit_TOde(self, t: ty.TOde) -> tuple:
        return self._fields(t, "ode", "state", "name", "args")


_LEAVES = (ty.TConst, ty.TText, ty.TParam, ty.TRef)
_COSTLY = (ty.TFunc, ty.TCall, ty.TBlock, ty.TBinary, ty.TPiecewise)


class Plan:
    """The keys of a typer's definitions and the subtrees that occur more than once."""

    def __init__(self, typer) -> None:
        self.keys = Keys()
        self.size = (-1, -1)
        self.repeated: set[int] = set()
        self.update(typer)

    def update(self, typer) -> None:
        """Count again if the typer has typed more definitions since."""
        size = (len(typer.functions), len(typer.scalars))
        if size == self.size:
            return
        self.size = size
        counts: Counter[int] = Counter()
        todo = [f.body for f in typer.functions.values()] + list(typer.scalars.values())
        while todo:
            t = todo.pop()
            if isinstance(t, _LEAVES):
                continue
            counts[self.keys.key(t)] += 1
            todo.extend(ty.children(t))
        self.repeated = {k for k, n in counts.items() if n > 1}

    def shared(self, t: ty.T) -> int | None:
        """The key of ``t`` if its value is worth keeping within an evaluation, else None.

        Only calls and powers are kept: keeping the arrays of cheap arithmetic costs more
        (memory traffic) than computing them again (measured with
        benchmarks/bench_evaluate.py: 1.1x hand-written numpy against 1.4x keeping all).
        """
        if not isinstance(t, _COSTLY) or (isinstance(t, ty.TBinary) and t.op != "^"):
            return None
        k = self.keys.key(t)
        return k if k in self.repeated else None


_PLANS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def plan(typer) -> Plan:
    """The plan of a typer (one per typer, shared by every sheet built on it)."""
    p = _PLANS.get(typer)
    if p is None:
        p = _PLANS[typer] = Plan(typer)
    else:
        p.update(typer)
    return p
