"""Where an integrand may have a kink or a jump, read from its typed tree.

A piecewise condition comparing the variable with something free of it (``x <= L``), and
``abs``, ``min``, ``max`` of the variable against such a value (``abs(x - c)``,
``min(x, c)``), the points of the data ``linterp`` reads, and where ``min`` or ``max`` of such
an interpolant and a value switches, give a break point: the integral is split there so that
every piece is smooth. Inside a sheet function called with the variable as an argument, the same is
found for the parameter it is bound to; the function's other parameters are replaced by
the arguments of the call. Kinks this walker does not recognise are left to the adaptive
rule.
"""

from __future__ import annotations

import dataclasses

from ..language import typed as ty
from ..language.visitor import Visitor


class Kinks(Visitor):
    """Collects typed break points (in the variable's unit) of an expression in ``var``.

    ``aliases`` maps a parameter to f where the parameter is the variable times f; ``subst``
    maps a function's other parameters to the typed arguments of the call (None at the top,
    where parameters are the environment's).
    """

    def __init__(self, defs):
        self.defs = defs
        self.found: list[ty.T] = []

    def _children(self, t, aliases, subst):
        for c in ty.children(t):
            self.visit(c, aliases, subst)

    visit_TConst = visit_TText = visit_TParam = visit_TRef = visit_TAggregate = _children
    visit_TScale = visit_TUnary = visit_TBinary = visit_TLogic = visit_TBlock = _children
    visit_TPiecewise = visit_TMatrix = visit_TIndex = visit_TProgram = visit_TOde = _children

    def _linear(self, t: ty.T, aliases) -> float | None:
        """The factor f if ``t`` is the variable times f, else None."""
        if isinstance(t, ty.TParam) and t.name in aliases:
            return aliases[t.name]
        if isinstance(t, ty.TScale):
            inner = self._linear(t.child, aliases)
            return None if inner is None else inner * t.factor
        return None

    def _outer(self, t: ty.T, aliases, subst) -> ty.T | None:
        """``t`` in the scope of the integral (parameters replaced), or None if it depends
        on the variable or cannot be replaced."""
        stack = [t]
        while stack:
            n = stack.pop()
            if isinstance(n, ty.TParam):
                if n.name in aliases or (subst is not None and n.name not in subst):
                    return None
            stack.extend(ty.children(n))
        return t if not subst else substitute(t, subst)

    def _pair(self, x: ty.T, y: ty.T, aliases, subst) -> None:
        for lin, other in ((x, y), (y, x)):
            f = self._linear(lin, aliases)
            if f:
                outer = self._outer(other, aliases, subst)
                if outer is not None:
                    self.found.append(ty.TScale(outer.unit, child=outer, factor=1.0 / f))
                return

    def visit_TCompare(self, t: ty.TCompare, aliases, subst):
        for x, y in zip(t.operands, t.operands[1:]):
            self._pair(x, y, aliases, subst)
        self._children(t, aliases, subst)

    def visit_TFunc(self, t: ty.TFunc, aliases, subst):
        if t.func == "abs" and isinstance(t.args[0], ty.TBinary) and t.args[0].op == "-":
            self._pair(t.args[0].left, t.args[0].right, aliases, subst)
        elif t.func in ("min", "max") and len(t.args) == 2:
            self._pair(t.args[0], t.args[1], aliases, subst)
            for lin, other in ((t.args[0], t.args[1]), (t.args[1], t.args[0])):
                self._crossings(lin, other, aliases, subst)
        elif self._interpolant(t, aliases):  # linear between the points: a kink at each
            xs, _, f = self._interpolant(t, aliases)
            self.found += [ty.TConst(t.args[2].unit, value=float(x) / f) for x in xs]
        elif t.func == "integral" and len(t.args) == 4:
            self._bound_crossings(t, aliases, subst)
        self._children(t, aliases, subst)

    def _bound_crossings(self, t: ty.TFunc, aliases, subst) -> None:
        """An inner integral whose bound is the variable times f: its integrand's break
        points c (free of the variable) are kinks of the integral in the variable, at c/f
        (its derivative in the bound is the integrand there: a beam's moment, integrated
        twice, has a kink in its slope where the load is)."""
        inner = Kinks(self.defs)
        inner.visit(t.args[0], {t.args[1].name: 1.0}, None)
        for end in t.args[2:]:
            f = self._linear(end, aliases)
            if not f:
                continue
            for c in inner.found:
                outer = self._outer(c, aliases, subst)
                if outer is not None:
                    self.found.append(ty.TScale(outer.unit, child=outer, factor=1.0 / f))

    def _interpolant(self, t: ty.T, aliases):
        """(X, Y, f) if ``t`` is linterp(X, Y, x) of the variable times f, else None."""
        if not (isinstance(t, ty.TFunc) and t.func == "linterp"):
            return None
        f = self._linear(t.args[2], aliases)
        if not f or not all(isinstance(a, ty.TRef) for a in t.args[:2]):
            return None
        data = self.defs.spec.data
        return data[t.args[0].name].values, data[t.args[1].name].values, f

    def _crossings(self, lin: ty.T, other: ty.T, aliases, subst) -> None:
        """min/max(c, linterp(X, Y, x)): where each piece of the interpolant crosses c."""
        g = 1.0
        while isinstance(lin, ty.TScale):
            g, lin = g * lin.factor, lin.child
        found = self._interpolant(lin, aliases)
        c = self._outer(other, aliases, subst)
        if found is None or c is None:
            return
        xs, ys, f = found
        unit = lin.args[2].unit
        for x0, x1, y0, y1 in zip(xs[:-1], xs[1:], ys[:-1], ys[1:]):
            if y1 != y0:  # x0 + (c/g - y0)*(x1 - x0)/(y1 - y0), in the variable's unit
                shift = ty.TBinary(
                    c.unit,
                    op="-",
                    left=ty.TScale(c.unit, child=c, factor=1 / g),
                    right=ty.TConst(c.unit, value=float(y0)),
                )
                step = ty.TScale(unit, child=shift, factor=float((x1 - x0) / (y1 - y0)) / f)
                self.found.append(
                    ty.TBinary(unit, op="+", left=ty.TConst(unit, value=float(x0) / f), right=step)
                )

    def visit_TCall(self, t: ty.TCall, aliases, subst):
        self._children(t, aliases, subst)
        f = self.defs.function(t.name)
        inner, values = {}, {}
        for p, a in zip(f.params, t.args):
            factor = self._linear(a, aliases)
            if factor:
                inner[p] = factor
            else:
                outer = self._outer(a, aliases, subst)
                if outer is not None:
                    values[p] = outer
        if inner:
            self.visit(f.body, inner, values)


def substitute(t: ty.T, subst: dict[str, ty.T]) -> ty.T:
    """``t`` with parameters replaced by typed trees (their units are the parameters')."""
    if isinstance(t, ty.TParam):
        return subst.get(t.name, t)
    changes = {}
    for field in dataclasses.fields(t):
        v = getattr(t, field.name)
        if isinstance(v, ty.T):
            changes[field.name] = substitute(v, subst)
        elif isinstance(v, tuple) and any(isinstance(x, ty.T) for x in v):
            changes[field.name] = tuple(
                substitute(x, subst) if isinstance(x, ty.T) else x for x in v
            )
    return dataclasses.replace(t, **changes) if changes else t


def breaks(defs, body: ty.T, var: str) -> list[ty.T]:
    """Typed break points of ``body`` in ``var`` (in the variable's unit), possibly repeated."""
    k = Kinks(defs)
    k.visit(body, {var: 1.0}, None)
    return k.found
