"""EXPR evaluated with mpmath over the typed tree: ``workbook bench``'s reference arithmetic.

``MpForm(evaluator, ctx).compile(t)`` gives ``env -> mpf``: the same typed tree the numpy
back end computes, every operation in the precision of the mpmath context ``ctx`` (the
constants of the tree are the doubles numpy computes with, so both compute the same
function; only the rounding differs). The sheet's inputs and definitions are read as the
doubles the sheet computed. A node without an mpmath form here (a vector, a data
interpolant, a program, a solve block, a probability distribution, a numerical built-in
other than an inner integral or diff) raises :class:`NoMpForm` when compiled, naming it; a point
where EXPR has no real value (a negative square root, a division by zero, no piece whose
condition holds) raises :class:`NoValue` when evaluated.

:func:`quad` is the integral in mpmath on pieces: the one of an inner integral here, and the
reference's integral in :mod:`workbook.numerics.mpref` (which builds on this module).
"""

from __future__ import annotations

import contextvars
import operator
from collections.abc import Callable, Iterator
from contextlib import contextmanager

from ..functions.entry import ENTRIES  # as registered: the registry imports this one's users
from ..language import typed as ty
from ..language.expr import COMPARE
from ..language.visitor import Visitor

#: a sheet function nested deeper than this is not expanded
_MAX_DEPTH = 20
#: the relative estimate a piece of an integral is accepted at (fixed: an inner integral runs
#: at the raised precision of the outer one's nodes, where mpmath's estimate stays near 1e-23)
GOAL = "1e-20"
#: pieces of one integral at most
MAX_PIECES = 256


Mp = Callable[[dict], object]


class NoMpForm(Exception):
    """EXPR has a node without an mpmath form; the message names it."""


class NoValue(ArithmeticError):
    """EXPR has no real value at this point."""


class Unconverged(ArithmeticError):
    """The mpmath method did not reach its accuracy."""


class TooCostly(ArithmeticError):
    """The integrands of EXPR's integrals ran past the evaluations allowed
    (:func:`evaluations`): an integral nested in an integral, checked at many points."""


#: evaluations of integrands left to the mpmath forms of this context (None: no bound)
_LEFT: contextvars.ContextVar[list[int] | None] = contextvars.ContextVar("left", default=None)


@contextmanager
def evaluations(most: int) -> Iterator[None]:
    """Within: the integrands of the integrals in mpmath forms are evaluated at most ``most``
    times in all, then :class:`TooCostly` is raised (an inner integral costs hundreds of
    evaluations at every point of the outer one: nested twice, millions)."""
    token = _LEFT.set([most])
    try:
        yield
    finally:
        _LEFT.reset(token)


def spend_evaluation() -> None:
    """Count one evaluation of an integrand against the budget in force (TooCostly past it)."""
    left = _LEFT.get()
    if left is not None:
        left[0] -= 1
        if left[0] < 0:
            raise TooCostly("the integrals' integrands evaluated more often than allowed")


def _real(ctx, v):
    if isinstance(v, ctx.mpc):
        if v.imag:
            raise NoValue("a complex value")
        return v.real
    return v


def _functions(ctx) -> dict[str, Callable]:
    """The plain built-ins of one argument (numpy's meaning, in mpmath): each entry's own (by
    the time a typed tree is compiled here, the typer has read the complete registry)."""
    return {e.name: getattr(ctx, e.mpmath) for e in ENTRIES.values() if e.mpmath}


# -- an integral in mpmath: EXPR's inner integral, and the reference's (mpref) ------------
def quad(ctx, g, a, b, points, refine: bool = True) -> object:
    """The integral of g over [a, b] (an mpf), split at ``points``; with ``refine``, also in
    8 equal pieces, and a piece whose estimate is above GOAL of the scale is halved (an
    inner integral is not refined: its error is part of the outer integrand's, which the
    outer integral's estimate sees)."""
    a, b = ctx.mpf(a), ctx.mpf(b)
    if a == b:
        return ctx.zero
    sign = 1
    if a > b:
        a, b, sign = b, a, -1
    edges = sorted({a, b, *(ctx.mpf(p) for p in points if a < p < b)})
    if refine:
        edges = sorted({*edges, *(a + (b - a) * k / 8 for k in range(1, 8))})
    scale = (b - a) * max(_abs_or_zero(g, a + (b - a) * (k + 0.5) / 33) for k in range(33))
    goal = ctx.mpf(GOAL)
    pieces, total, done = list(zip(edges, edges[1:])), ctx.zero, 0
    while pieces:
        lo, hi = pieces.pop()
        v, e = ctx.quad(lambda x, lo=lo, hi=hi: _inside(g, x, lo, hi), [lo, hi], error=True)
        scale = max(scale, abs(v))
        share = (hi - lo) / (b - a)
        if not refine or e <= goal * max(scale, ctx.mpf(10) ** -300) * share:
            total += v
            done += 1
            continue
        if done + len(pieces) + 2 > MAX_PIECES:
            raise Unconverged(
                f"mpmath quad: estimate {float(e):.1e} on [{float(lo):.6g}, {float(hi):.6g}] "
                f"after {MAX_PIECES} pieces"
            )
        mid = (lo + hi) / 2
        pieces += [(lo, mid), (mid, hi)]
    return sign * total


def _inside(g, x, lo, hi):
    """g at a node of a piece; 0 at a node that rounds to an end (a singular end's nodes
    come closer to it than the precision: they weigh less than 1e-16 of an integrable
    singularity's integral, below the reference's accuracy)."""
    spend_evaluation()
    return 0 if x in (lo, hi) else g(x)


def _abs_or_zero(g, x):
    spend_evaluation()
    try:
        return abs(g(x))
    except (NoValue, ZeroDivisionError):
        return 0


class MpForm(Visitor):
    """Compiles a scalar typed tree into ``env -> mpf`` (``env``: parameter -> number)."""

    def __init__(self, evaluator, ctx, depth: int = 0):
        self.evaluator, self.ctx, self.depth = evaluator, ctx, depth
        self.plain = _functions(ctx)

    def compile(self, t: ty.T) -> Mp:
        if t.shape is not None:
            raise NoMpForm("a vector or matrix")
        return self.visit(t)

    def visit_TText(self, t):
        v = t.value
        return lambda env: v

    def visit_TConst(self, t):
        v = self.ctx.mpf(t.value)
        return lambda env: v

    def visit_TParam(self, t):
        name, mpf = t.name, self.ctx.mpf
        return lambda env: mpf(env[name])

    def visit_TRef(self, t):
        if t.kind == "solve" and self.evaluator.typer.spec.solve_of(t.name).parameters:
            raise NoMpForm(f"the solve block {t.name}")
        read, mpf = self.evaluator.reference(t), self.ctx.mpf  # a sweep's cases are in env

        def ref(env):
            v = read(env)
            return v if isinstance(v, str) else mpf(float(v))  # a choice: 'law == "stepped"'

        return ref

    def visit_TScale(self, t):
        child, k = self.compile(t.child), self.ctx.mpf(t.factor)
        return lambda env: child(env) * k

    def visit_TUnary(self, t):
        child = self.compile(t.child)
        if t.op == "not":
            return lambda env: not child(env)
        return lambda env: -child(env)

    def visit_TBinary(self, t):
        left, right, ctx = self.compile(t.left), self.compile(t.right), self.ctx
        if t.op == "^":
            return lambda env: _real(ctx, ctx.power(left(env), right(env)))
        if t.op == "/":

            def divide(env):
                d = right(env)
                if not d:
                    raise NoValue("a division by zero")
                return left(env) / d

            return divide
        op = {"+": operator.add, "-": operator.sub, "*": operator.mul}.get(t.op)
        if op is None:
            raise NoMpForm(f"the operator {t.op}")
        return lambda env: op(left(env), right(env))

    def visit_TCompare(self, t):
        parts = [self.compile(o) for o in t.operands]
        ops = [COMPARE[o] for o in t.ops]

        def chain(env):
            vals = [p(env) for p in parts]
            return all(op(x, y) for op, x, y in zip(ops, vals, vals[1:]))

        return chain

    def visit_TLogic(self, t):
        parts = [self.compile(v) for v in t.values]
        if t.op == "and":
            return lambda env: all(p(env) for p in parts)
        return lambda env: any(p(env) for p in parts)

    def visit_TPiecewise(self, t):
        conds = [None if k is None else self.compile(k) for k in t.conditions]
        values = [self.compile(v) for v in t.values]

        def piecewise(env):
            for cond, val in zip(conds, values):
                if cond is None or cond(env):
                    return val(env)
            raise NoValue("no piece whose condition holds")

        return piecewise

    def visit_TFunc(self, t):
        ctx, args = self.ctx, t.args
        if t.func == "integral" and len(args) == 4:
            return self._integral(t)
        if t.func == "diff":
            return self._derivative(t)
        if t.func in ("min", "max") and all(a.shape is None for a in args):
            parts = [self.compile(a) for a in args]
            pick = min if t.func == "min" else max
            return lambda env: pick(p(env) for p in parts)
        if t.func == "atan2" and len(args) == 2:
            x, y = (self.compile(a) for a in args)  # atan2(x, y), x first
            return lambda env: ctx.atan2(y(env), x(env))
        f = self.plain.get(t.func)
        if f is None or len(args) != 1:
            raise NoMpForm(f"{t.func}()")
        a = self.compile(args[0])
        if t.func in ("ln", "log10"):

            def log(env):
                v = a(env)
                if v <= 0:
                    raise NoValue(f"{t.func} of a value that is not positive")
                return f(v)

            return log
        return lambda env: _real(ctx, f(a(env)))

    def _integral(self, t):
        from .kinks import breaks

        body, var = self.compile(t.args[0]), t.args[1].name
        lo, hi = self.compile(t.args[2]), self.compile(t.args[3])
        ctx = self.ctx
        # split at the integrand's kinks the tree shows (a beam's piecewise moment): tanh-sinh
        # across a kink is off by far more than the reference's accuracy
        kinks = []
        for k in breaks(self.evaluator.defs, t.args[0], var):
            try:
                kinks.append(self.compile(k))
            except NoMpForm:
                continue

        def integral(env):
            a, b = lo(env), hi(env)
            inside = []
            for k in kinks:
                try:
                    c = k(env)
                except (NoValue, ZeroDivisionError, ValueError, TypeError):
                    continue
                if min(a, b) < c < max(a, b):
                    inside.append(c)
            return quad(ctx, lambda x: body({**env, var: x}), a, b, sorted(inside), refine=False)

        return integral

    def _derivative(self, t):
        """diff(EXPR, X, N): the compiled formula of the derivative SymPy found (the one the
        numpy back end computes)."""
        from .derivative import formula

        order = t.args[2] if len(t.args) > 2 else ty.TConst(t.unit, value=1.0)
        if not isinstance(order, ty.TConst):
            raise NoMpForm("diff() of a computed order")
        tree = formula(self.evaluator.defs, t.args[0], t.args[1], int(order.value))
        return self.compile(tree)

    def visit_TCall(self, t):
        defs = self.evaluator.defs
        if t.name in defs.recursive or self.depth > _MAX_DEPTH:
            raise NoMpForm(f"the recursive function {t.name}")
        f = defs.function(t.name)
        body = MpForm(self.evaluator, self.ctx, self.depth + 1).compile(f.body)
        names, keys = list(f.params), self.evaluator.env_keys  # a sweep's cases go along
        args = [self.compile(a) for a in t.args]
        return lambda env: body(
            {**{k: env[k] for k in keys if k in env}, **{n: a(env) for n, a in zip(names, args)}}
        )

    def __getattr__(self, name):
        if name.startswith("visit_"):  # every other node kind: no mpmath form here
            raise NoMpForm(_NODES.get(name[6:], name[6:]))
        raise AttributeError(name)


_NODES = {
    "TBlock": "a solve block",
    "TIndex": "indexing",
    "TProgram": "a program",
    "TOde": "an ODE state",
    "TAggregate": "max_over or min_over",
    "TMatrix": "a vector or matrix",
    "TText": "a text",
}


def mp_form(evaluator, ctx, body: ty.T) -> Mp:
    """EXPR's mpmath form (raises :class:`NoMpForm`)."""
    return MpForm(evaluator, ctx).compile(body)
