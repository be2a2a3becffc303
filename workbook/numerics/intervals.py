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

import math
from collections.abc import Callable

import numpy as np

from ..language import typed as ty
from ..language.visitor import Visitor

_INF = np.inf
_EPS = float(np.finfo(float).eps)
_TINY = float(np.finfo(float).tiny)
#: units in the last place each result is widened by (numpy's elementary functions are
#: within 1-2 ulp; the rest of the margin covers the constants the rules use)
_ULPS = 4.0
#: a sheet function nested deeper than this is not expanded
_MAX_DEPTH = 20


class NoEnclosure(Exception):
    """EXPR has a node without an interval extension here."""


class Iv:
    """Intervals [lo, hi] (numpy arrays of one shape); lo may be -inf, hi +inf."""

    __slots__ = ("lo", "hi")

    def __init__(self, lo, hi):
        self.lo, self.hi = lo, hi

    @staticmethod
    def point(v) -> Iv:
        v = np.asarray(v, dtype=float)
        return Iv(v, v)

    def contains_zero(self) -> np.ndarray:
        """Where 0 may be in the interval (also where it is NaN: unknown)."""
        return ~(self.lo > 0) & ~(self.hi < 0)


def _out(lo, hi, ulps: float = _ULPS) -> Iv:
    """[lo, hi] widened outward by ``ulps`` units of rounding (relative, and absolute below
    the normal range). A NaN (inf - inf, 0 * inf) stays NaN: an unknown enclosure, which the
    users of enclosures read as unbounded."""
    k = ulps * _EPS
    lo = np.asarray(lo, dtype=float)
    hi = np.asarray(hi, dtype=float)
    return Iv(lo - (np.abs(lo) * k + _TINY), hi + (np.abs(hi) * k + _TINY))


def add(a: Iv, b: Iv) -> Iv:
    return _out(a.lo + b.lo, a.hi + b.hi, 1)


def sub(a: Iv, b: Iv) -> Iv:
    return _out(a.lo - b.hi, a.hi - b.lo, 1)


def neg(a: Iv) -> Iv:
    if a.lo is a.hi:
        v = -a.lo
        return Iv(v, v)
    return Iv(-a.hi, -a.lo)


def scale(a: Iv, k: float) -> Iv:
    lo, hi = a.lo * k, a.hi * k
    return _out(np.minimum(lo, hi), np.maximum(lo, hi), 1)


def mul(a: Iv, b: Iv) -> Iv:
    if b.lo is b.hi:  # a number times an interval (a constant factor, a row's value)
        a, b = b, a
    if a.lo is a.hi:
        p, q = a.lo * b.lo, a.lo * b.hi
        return _out(np.minimum(p, q), np.maximum(p, q), 1)
    p = [a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi]
    return _out(np.minimum.reduce(p), np.maximum.reduce(p), 1)


def div(a: Iv, b: Iv) -> Iv:
    whole = b.contains_zero()
    inv = Iv(1.0 / np.where(whole, 1.0, b.hi), 1.0 / np.where(whole, 1.0, b.lo))
    q = mul(a, _out(inv.lo, inv.hi, 1))
    return Iv(np.where(whole, -_INF, q.lo), np.where(whole, _INF, q.hi))


def power(a: Iv, n: float) -> Iv:
    """a^n for a constant n (a whole n any sign of a; else a >= 0 is needed)."""
    if n == 0:
        return Iv.point(np.ones_like(a.lo))
    if n == int(n):
        k = int(n)
        if k < 0:
            return div(Iv.point(np.ones_like(a.lo)), power(a, -k))
        lo, hi = a.lo**k, a.hi**k
        if k % 2:
            return _out(lo, hi, 2 * k)
        zero = a.contains_zero()
        return _out(np.where(zero, 0.0, np.minimum(lo, hi)), np.maximum(lo, hi), 2 * k)
    neg_part = a.lo < 0
    lo, hi = np.maximum(a.lo, 0.0) ** n, np.maximum(a.hi, 0.0) ** n
    if n < 0:
        lo, hi = hi, lo
    r = _out(lo, hi, 8)
    return Iv(np.where(neg_part, -_INF, r.lo), np.where(neg_part, _INF, r.hi))


def _monotone(f: Callable, a: Iv, increasing: bool = True, ulps: float = _ULPS) -> Iv:
    lo, hi = f(a.lo), f(a.hi)
    return _out(lo, hi, ulps) if increasing else _out(hi, lo, ulps)


def _periodic(a: Iv, f: Callable, peak: float) -> Iv:
    """sin or cos: f at the ends, 1 where a point peak + 2 pi k is inside, -1 where a trough."""
    ends_lo = np.minimum(f(a.lo), f(a.hi))
    ends_hi = np.maximum(f(a.lo), f(a.hi))
    two_pi = 2 * math.pi
    top = np.ceil((a.lo - peak) / two_pi) * two_pi + peak
    bottom = np.ceil((a.lo - peak - math.pi) / two_pi) * two_pi + peak + math.pi
    # the test is made generous by a relative margin (pi is not exact)
    margin = 1e-12 * (1 + np.abs(a.lo) + np.abs(a.hi))
    wide = ~np.isfinite(a.lo) | ~np.isfinite(a.hi) | (a.hi - a.lo >= two_pi)
    has_top = wide | (top <= a.hi + margin)
    has_bottom = wide | (bottom <= a.hi + margin)
    r = _out(ends_lo, ends_hi)
    return Iv(
        np.where(has_bottom, -1.0, np.maximum(r.lo, -1.0)),
        np.where(has_top, 1.0, np.minimum(r.hi, 1.0)),
    )


def sin(a: Iv) -> Iv:
    return _periodic(a, np.sin, math.pi / 2)


def cos(a: Iv) -> Iv:
    return _periodic(a, np.cos, 0.0)


def tan(a: Iv) -> Iv:
    """tan, unbounded where a pole pi/2 + k pi may be inside."""
    k = np.floor((a.lo - math.pi / 2) / math.pi)
    pole = (k + 1) * math.pi + math.pi / 2
    margin = 1e-12 * (1 + np.abs(a.lo) + np.abs(a.hi))
    bad = ~np.isfinite(a.lo) | ~np.isfinite(a.hi) | (pole <= a.hi + margin)
    r = _monotone(np.tan, a)
    return Iv(np.where(bad, -_INF, r.lo), np.where(bad, _INF, r.hi))


def exp(a: Iv) -> Iv:
    r = _monotone(np.exp, a)
    return Iv(np.maximum(r.lo, 0.0), r.hi)


def _domain(a: Iv, low: float, f: Callable, strict: bool = False) -> Iv:
    """f increasing on (low, inf): unbounded where a reaches below its domain."""
    bad = (a.lo <= low) if strict else (a.lo < low)
    r = _monotone(f, Iv(np.where(bad, low + 1.0, a.lo), a.hi))
    return Iv(np.where(bad, -_INF, r.lo), np.where(bad, _INF, r.hi))


def sqrt(a: Iv) -> Iv:
    r = _domain(a, 0.0, np.sqrt)
    return Iv(np.where(np.isfinite(r.lo), np.maximum(r.lo, 0.0), r.lo), r.hi)


def absolute(a: Iv) -> Iv:
    zero = a.contains_zero()
    lo = np.where(zero, 0.0, np.minimum(np.abs(a.lo), np.abs(a.hi)))
    return Iv(lo, np.maximum(np.abs(a.lo), np.abs(a.hi)))


def hull(a: Iv, b: Iv) -> Iv:
    return Iv(np.minimum(a.lo, b.lo), np.maximum(a.hi, b.hi))


def _bounded(a: Iv, lo: float, hi: float) -> Iv:
    return Iv(np.clip(a.lo, lo, hi), np.clip(a.hi, lo, hi))


# (value rule, derivative factor rule f'(a)) of the one-argument built-ins
def _unary_rules() -> dict[str, tuple[Callable, Callable]]:
    one = lambda a: Iv.point(np.ones_like(a.lo))  # noqa: E731
    return {
        "sin": (sin, cos),
        "cos": (cos, lambda a: neg(sin(a))),
        "tan": (tan, lambda a: add(one(a), power(tan(a), 2))),
        "exp": (exp, exp),
        "ln": (lambda a: _domain(a, 0.0, np.log, True), lambda a: div(one(a), a)),
        "log10": (
            lambda a: _domain(a, 0.0, np.log10, True),
            lambda a: scale(div(one(a), a), 1 / math.log(10)),
        ),
        "sqrt": (sqrt, lambda a: div(Iv.point(np.full_like(a.lo, 0.5)), sqrt(a))),
        "tanh": (
            lambda a: _bounded(_monotone(np.tanh, a), -1.0, 1.0),
            lambda a: sub(one(a), power(_bounded(_monotone(np.tanh, a), -1.0, 1.0), 2)),
        ),
        "atan": (_atan, lambda a: div(one(a), add(one(a), power(a, 2)))),
        "sinh": (lambda a: _monotone(np.sinh, a), lambda a: _cosh(a)),
        "cosh": (_cosh, lambda a: _monotone(np.sinh, a)),
        "abs": (absolute, _sign),
    }


def _atan(a: Iv) -> Iv:
    return _bounded(_monotone(np.arctan, a), -math.pi / 2 - 1e-15, math.pi / 2 + 1e-15)


def _cosh(a: Iv) -> Iv:
    m = absolute(a)
    return _monotone(np.cosh, m)


def _sign(a: Iv) -> Iv:
    lo = np.where(a.lo > 0, 1.0, -1.0)
    hi = np.where(a.hi < 0, -1.0, 1.0)
    return Iv(lo, hi)


#: function name -> (its interval enclosure, the enclosure of its derivative)
UNARY_RULES = _unary_rules()

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
            log = UNARY_RULES["ln"]

            def general_power(env):  # exp(y ln x)
                (x, dx), (y, dy) = left(env), right(env)
                lx = log[0](x)
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
        rule = UNARY_RULES.get(t.func)
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
        if key in self.evaluator.typer.recursive or self.depth > _MAX_DEPTH:
            raise NoEnclosure(key)
        f = self.evaluator.typer.function(key)
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
