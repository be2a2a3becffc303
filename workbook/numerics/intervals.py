"""Interval arithmetic over the typed tree, with the derivative in the bound variable.

Callers silence numpy's floating-point warnings (``np.errstate``) around a call: an
overflow or a 0 * inf is an unbounded or unknown (NaN) end, which is what it should be.

``enclosure(evaluator, body, var)`` compiles EXPR into ``g(env, lo, hi) -> (F, D)``: for the
variable anywhere in [lo, hi] (arrays, one box each), EXPR lies in F = (F.lo, F.hi) and its
derivative in the variable lies in D. Every operation rounds outward (a few units in the last
place, more than numpy's functions are off), so the enclosures are proofs: F without 0 means
no root in the box, D without 0 means at most one. A tree with a node that has no interval
extension here (a piecewise value, a data interpolant, another numerical built-in, a vector)
raises :class:`NoEnclosure` when compiled, and the caller falls back to sampling.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..functions.interval_arith import Iv, add, div, exp, hull, ln, mul, neg, power, scale, sub
from ..language import typed as ty
from ..language.visitor import Visitor
from .registry import REGISTRY

#: a sheet function nested deeper than this is not expanded
_MAX_DEPTH = 20


class NoEnclosure(Exception):
    """EXPR has a node without an interval extension here."""


#: a value and its derivative in the variable (None: 0, the node does not depend on it)
Pair = tuple[Iv, Iv | None]


class Enclosure(Visitor):
    """Compiles a typed tree into ``env -> (value interval, derivative interval or None)``;
    ``env`` maps the variable to an :class:`Iv` and other parameters to numbers or arrays."""

    def __init__(self, evaluator, var: str):
        self.evaluator, self.var = evaluator, var
        self.depth = 0

    def compile(self, t: ty.T) -> Callable[[dict], Pair]:
        if t.shape is not None or t.boolean or t.text:
            raise NoEnclosure(type(t).__name__)
        return self.visit(t)

    def visit_TConst(self, t):
        v = Iv.point(t.value)  # the double numpy computes with: exact
        return lambda env: (v, None)

    def visit_TParam(self, t):
        name = t.name
        if self.var == _CALL:  # inside a sheet function: the pair its argument computed
            return lambda env: env[_CALL][name]
        if name == self.var:
            return lambda env: (env[name], Iv.point(np.ones_like(env[name].lo)))

        def param(env):
            v = env[name]
            return (v, None) if isinstance(v, Iv) else (Iv.point(v), None)

        return param

    def visit_TRef(self, t):
        if t.kind == "solve" and self.evaluator.typer.spec.solve_of(t.name).parameters:
            raise NoEnclosure(f"the solve block {t.name}")
        read = self.evaluator.reference(t)  # a sweep's evaluator reads its cases in env
        return lambda env: (Iv.point(read(env)), None)

    def visit_TScale(self, t):
        child, k = self.compile(t.child), t.factor

        def scaled(env):
            v, d = child(env)
            return scale(v, k), (None if d is None else scale(d, k))

        return scaled

    def visit_TUnary(self, t):
        if t.op != "-":
            raise NoEnclosure(t.op)
        child = self.compile(t.child)

        def negated(env):
            v, d = child(env)
            return neg(v), (None if d is None else neg(d))

        return negated

    def visit_TBinary(self, t):
        left, right = self.compile(t.left), self.compile(t.right)
        op = t.op
        if op == "^":
            if isinstance(t.right, ty.TConst):
                n = t.right.value

                def const_power(env):
                    v, d = left(env)
                    dv = None if d is None else mul(scale(power(v, n - 1), n), d)
                    return power(v, n), dv

                return const_power

            def general_power(env):  # exp(y ln x)
                (x, dx), (y, dy) = left(env), right(env)
                lx = ln(x)
                value = exp(mul(y, lx))
                terms = []
                if dy is not None:
                    terms.append(mul(dy, lx))
                if dx is not None:
                    terms.append(mul(y, div(dx, x)))
                if not terms:
                    return value, None
                d = terms[0] if len(terms) == 1 else add(*terms)
                return value, mul(value, d)

            return general_power

        def binary(env):
            (a, da), (b, db) = left(env), right(env)
            if op == "+":
                return add(a, b), _sum(da, db, add)
            if op == "-":
                return sub(a, b), _sum(da, None if db is None else db, sub)
            if op == "*":
                d = _sum(
                    None if da is None else mul(da, b), None if db is None else mul(a, db), add
                )
                return mul(a, b), d
            q = div(a, b)
            if da is None and db is None:
                return q, None
            num = da if db is None else (neg(mul(q, db)) if da is None else sub(da, mul(q, db)))
            return q, div(num, b)

        return binary

    def visit_TFunc(self, t):
        entry = REGISTRY.get(t.func)
        rule = None if entry is None else entry.interval
        if t.func in ("min", "max") and len(t.args) == 2:
            return self._min_max(t)
        if rule is None or len(t.args) != 1:
            raise NoEnclosure(t.func)
        value, slope = rule
        child = self.compile(t.args[0])

        def func(env):
            v, d = child(env)
            return value(v), (None if d is None else mul(slope(v), d))

        return func

    def _min_max(self, t):
        a, b = (self.compile(x) for x in t.args)
        pick = np.minimum if t.func == "min" else np.maximum

        def min_max(env):
            (x, dx), (y, dy) = a(env), b(env)
            v = Iv(pick(x.lo, y.lo), pick(x.hi, y.hi))
            if dx is None and dy is None:
                return v, None
            zero = Iv.point(np.zeros_like(v.lo))
            return v, hull(dx or zero, dy or zero)

        return min_max

    def visit_TCall(self, t):
        key = t.name
        if key in self.evaluator.defs.recursive or self.depth > _MAX_DEPTH:
            raise NoEnclosure(key)
        f = self.evaluator.defs.function(key)
        args = [self.compile(a) for a in t.args]
        inner = Enclosure(self.evaluator, _CALL)
        inner.depth = self.depth + 1
        body = inner.in_call(f.body, f.params)

        def call(env):
            return body([a(env) for a in args], env)

        return call

    def in_call(self, body: ty.T, params) -> Callable:
        """A function body of pairs: each parameter is a pair its argument computed; the
        caller's entries that references read (a sweep's cases) go along."""
        names, keys = list(params), self.evaluator.env_keys
        compiled = self.compile(body)

        def run(pairs, env=None):
            outer = {} if env is None else {k: env[k] for k in keys if k in env}
            return compiled({**outer, _CALL: dict(zip(names, pairs))})

        return run

    def visit_TBlock(self, t):
        raise NoEnclosure("solve block")

    def __getattr__(self, name):
        if name.startswith("visit_"):  # every other node kind: no interval extension here
            raise NoEnclosure(name[6:])
        raise AttributeError(name)


#: the environment key of a sheet function's parameters inside its body
_CALL = "\0call"


def _sum(a, b, op):
    if a is None:
        return None if b is None else (neg(b) if op is sub else b)
    if b is None:
        return a
    return op(a, b)


def enclosure(evaluator, body: ty.T, var: str) -> Callable[[dict], Pair]:
    """EXPR's interval extension with its derivative in ``var`` (raises NoEnclosure)."""
    return Enclosure(evaluator, var).compile(body)
