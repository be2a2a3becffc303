"""The numpy back end: compile a typed tree into a closure over plain arrays.

Units were resolved by :mod:`workbook.language.typecheck`, so evaluation works on bare
float magnitudes (no pint in the hot path) and attaches the unit at the end.

Within one evaluation (``with evaluator.sharing():``, which ``Sheet`` entry points open, and
any shared subtree called outside one opens for its call) a subtree that occurs more than
once among the sheet's definitions (:mod:`workbook.language.subtrees`) is computed once per
environment: a call ``f(x)`` written twice, ``sin(phi*deg)`` in h1, v1 and j1, the pieces of
h, v and j that share their conditions.
"""

from __future__ import annotations

import functools
import operator
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager

import numpy as np

from ..errors import DomainError, InputError, LimitError, WorkbookError
from ..language import typecheck as tc
from ..language import typed as ty
from ..language.expr import COMPARE
from ..language.subtrees import plan
from ..language.typed import children
from ..language.visitor import Visitor
from ..limits import matrix_work
from ..numerics.bound import Bound
from ..numerics.registry import REGISTRY
from . import runtime as rt

Env = dict[str, object]
Fn = Callable[[Env], object]

_CMP = COMPARE
# Powers by products and square roots (x^1.5, x^3 and x^4 in Evaluator._power_by_parts):
# several times faster than np.power, within 2 ulp (tests/numerics/test_numeric_golden.py, mpmath).
_POWERS = {
    2.0: np.square,
    0.5: np.sqrt,
    -1.0: lambda x: np.true_divide(1.0, x),
}
# np.true_divide: x/0 of plain floats gives inf/nan (a DomainError later), not ZeroDivisionError
_ARITH = {"+": operator.add, "-": operator.sub, "*": operator.mul, "/": np.true_divide}


class Evaluator(Visitor):
    """Compiles typed trees of one sheet; scalar values are memoised per sheet.

    ``compile(t)`` returns a closure ``env -> magnitude``; one ``visit_<Node>`` per typed node.
    """

    #: entries of the environment that references read besides the parameters (a sweep's
    #: varied inputs); built-ins that bind a variable carry them through their rows
    env_keys: tuple[str, ...] = ()

    def __init__(
        self,
        typer: tc.Typer,
        scalar_value: Callable[[str, str], object],
        describe_args: Callable[[str, tuple, dict], str],
        column_values: Callable[[str, str, object], object] | None = None,
    ):
        self.typer = typer
        self.defs = typer.defs  # the typed definitions, read (the typer types nothing more)
        self.column_values = column_values  # (table, column, unit) -> values, for max_over()
        self.solve_at: Callable | None = None  # (unknown, env) -> values, set by the Sheet
        self.scalar_value = scalar_value  # (name, kind) -> magnitude in the ref's unit
        self.describe_args = describe_args
        self._functions: dict[str, Fn] = {}
        self.records: list = []  # (built-in, numerics.Result) of each solve: workbook bench
        self.plan = plan(typer)
        self._shared: dict | None = None  # values of shared subtrees, during one evaluation

    @contextmanager
    def sharing(self) -> Iterator[None]:
        """One evaluation: shared subtrees are computed once inside (nested: the outer one)."""
        if self._shared is not None:
            yield
            return
        self._shared = {}
        try:
            with matrix_work():  # one evaluation's budget of matrix work
                yield
        finally:
            self._shared = None

    def _kept(self, key: int, fn: Fn) -> Fn:
        """``fn`` computed once per environment during an evaluation."""

        def run(env):
            cache = self._shared
            if cache is None:  # called outside an evaluation: this call is one
                with self.sharing():
                    return run(env)
            k = (key, tuple([(n, id(v)) for n, v in env.items()]))
            hit = cache.get(k)
            if hit is None:
                # the environment's values are kept with the result, so no id is reused
                hit = cache[k] = (fn(env), tuple(env.values()))
            return hit[0]

        return run

    def function(self, name: str) -> Fn:
        """Compiled user function: env of its parameters -> magnitude in its unit."""
        if name not in self._functions:
            f = self.defs.function(name)
            self.plan.update(self.typer)
            compiled: list[Fn] = []
            # a call inside its own body (recursion) reaches the function once it is compiled
            self._functions[name] = lambda env: compiled[0](env)
            try:
                fn = _checked(name, f.params, self.compile(f.body), self.describe_args)
            except BaseException:
                del self._functions[name]
                raise
            fn.explain = lambda env, f=f: _explain(self, f, env)
            d = self.typer.spec.definitions.get(name)
            if d is not None and d.limits is not None:
                fn = _limited(name, f.params, fn, d, f.unit, self.describe_args)
            if name in self.typer.recursive:
                fn = _recursion_bounded(name, fn)
            compiled.append(fn)
            self._functions[name] = fn
        return self._functions[name]

    def compile(self, t: ty.T) -> Fn:
        """A closure computing ``t`` from an environment of parameter values."""
        fn = self.visit(t)
        key = self.plan.shared(t)
        return fn if key is None else self._kept(key, fn)

    def visit_TConst(self, t: ty.TConst) -> Fn:
        v = t.value
        return lambda env: v

    def visit_TText(self, t: ty.TText) -> Fn:
        v = t.value
        return lambda env: v

    def visit_TParam(self, t: ty.TParam) -> Fn:
        n = t.name
        return lambda env: env[n]

    def visit_TRef(self, t: ty.TRef) -> Fn:
        return self.reference(t)

    def reference(self, t: ty.TRef) -> Fn:
        """How this evaluator reads a name in an environment; the interval and mpmath forms
        of EXPR read names through it, so that they compute the function numpy computes."""
        name, kind, get = t.name, t.kind, self.scalar_value
        if kind == "solve" and self.typer.spec.solve_of(name).parameters:
            at = self.solve_at  # a [[solve]] block with parameters: solved at env's values
            return lambda env: at(name, env)
        return lambda env: get(name, kind)

    def visit_TScale(self, t: ty.TScale) -> Fn:
        f = t.factor
        c = t.child
        if f != 1.0 and isinstance(c, ty.TBinary) and c.op == "*":
            # a unit factor joins the constant side of a product: (omega*R)*x*f = x*(omega*R*f)
            for const, other in ((c.left, c.right), (c.right, c.left)):
                if _constant(const):
                    k, x = self.compile(const), self.compile(other)
                    return lambda env: x(env) * (k(env) * f)
        child = self.compile(c)
        if f == 1.0:
            return child
        if ty.is_runtime(t.shape):  # an array that holds text: its numbers scaled
            return lambda env: rt.scale(rt.value(child(env)), f)
        return lambda env: child(env) * f

    def visit_TUnary(self, t: ty.TUnary) -> Fn:
        child = self.compile(t.child)
        if t.op == "not":
            return lambda env: np.logical_not(child(env))
        if ty.is_runtime(t.shape):
            what = _text(t)
            return lambda env: rt.negate(child(env), what)
        return lambda env: -child(env)

    def visit_TBinary(self, t: ty.TBinary) -> Fn:
        left, right = self.compile(t.left), self.compile(t.right)
        if ty.is_runtime(t.shape):
            op, what = t.op, _text(t)
            return lambda env: rt.binary(op, left(env), right(env), what)
        if t.left.shape is not None or t.right.shape is not None:
            return _matrix_binary(t, left, right)
        if t.op == "^":
            if isinstance(t.right, ty.TConst):
                n = t.right.value
                if n in (1.5, 3.0, 4.0):
                    return self._power_by_parts(t, n)
                short = _POWERS.get(n)
                if short is not None:
                    return lambda env: short(left(env))
                return lambda env: np.power(left(env), n)
            return lambda env: np.power(left(env), right(env))
        op = _ARITH[t.op]
        return lambda env: op(left(env), right(env))

    def _power_by_parts(self, t: ty.TBinary, n: float) -> Fn:
        """x^1.5 = x*sqrt(x), x^3 = x*x^2, x^4 = (x^2)^2: the sqrt(x) or x^2 written
        elsewhere in the sheet is then computed once (and a product is cheaper than a power)."""
        base = self.compile(t.left)
        if n == 1.5:
            root = self.compile(ty.TFunc(t.left.unit**0.5, func="sqrt", args=(t.left,)))
            return lambda env: base(env) * root(env)
        two = ty.TConst(t.right.unit, value=2.0)
        square = self.compile(ty.TBinary(t.left.unit**2, op="^", left=t.left, right=two))
        if n == 3.0:
            return lambda env: base(env) * square(env)
        return lambda env: np.square(square(env))

    def visit_TCompare(self, t: ty.TCompare) -> Fn:
        parts = [self.compile(o) for o in t.operands]
        if any(ty.is_runtime(o.shape) for o in t.operands):
            ops_text, what = t.ops, _text(t)

            def runtime_chain(env):
                vals = [p(env) for p in parts]
                return all(rt.compare(op, x, y, what) for op, x, y in zip(ops_text, vals, vals[1:]))

            return runtime_chain
        ops = [_CMP[o] for o in t.ops]
        if len(parts) == 2:
            a, b, op = parts[0], parts[1], ops[0]
            return lambda env: op(a(env), b(env))

        def chain(env):
            vals = [p(env) for p in parts]
            out = ops[0](vals[0], vals[1])
            for op, x, y in zip(ops[1:], vals[1:], vals[2:]):
                out = np.logical_and(out, op(x, y))
            return out

        return chain

    def visit_TLogic(self, t: ty.TLogic) -> Fn:
        parts = [self.compile(v) for v in t.values]
        join = np.logical_and if t.op == "and" else np.logical_or

        def logic(env):
            out = parts[0](env)
            for p in parts[1:]:
                out = join(out, p(env))
            return out

        return logic

    def visit_TFunc(self, t: ty.TFunc) -> Fn:
        entry = REGISTRY[t.func]
        f = entry.numpy
        if entry.binds and len(t.args) > max(entry.binds):
            return self._binding(t, entry)
        if entry.arrays and any(ty.is_runtime(a.shape) for a in t.args):
            args, hook, what = [self.compile(a) for a in t.args], f, _text(t)

            sizes = entry.sizes  # an array that holds texts may be given (else numbers)

            def runtime_call(env):
                values = [rt.value(a(env)) for a in args]
                if not sizes:
                    values = [rt.no_text(v, what) for v in values]
                try:
                    return rt.value(hook(*values, shapes=rt.shapes(values)))
                except (TypeError, ValueError) as err:  # numpy refusing a nested array
                    raise InputError(f"{what}: {err}") from None

            return runtime_call
        if entry.arrays:
            f = functools.partial(f, shapes=tuple(a.shape for a in t.args))
        args = [self.compile(a) for a in t.args]
        if any(ty.is_runtime(a.shape) for a in t.args):  # an element that may be text
            what, plain = _text(t), args
            args = [
                (lambda env, a=a: rt.no_text(a(env), what)) if ty.is_runtime(arg.shape) else a
                for a, arg in zip(plain, t.args)
            ]
        if len(args) == 1:
            a0 = args[0]
            return lambda env: f(a0(env))
        if len(args) == 2:
            a0, a1 = args
            return lambda env: f(a0(env), a1(env))
        return lambda env: f(*[a(env) for a in args])

    def _binding(self, t: ty.TFunc, entry) -> Fn:
        """A built-in binding a variable: its hook gets EXPR as a function of the variable
        (a :class:`workbook.numerics.bound.Bound`: ``of(value)``, and the row-wise form
        SciPy's vectorised solvers call)."""
        expr_at, var_at = entry.binds
        body_t, var_t = t.args[expr_at], t.args[var_at]
        body = self.compile(body_t)
        rest = [self.compile(a) for i, a in enumerate(t.args) if i not in (expr_at, var_at)]
        hook = entry.numpy

        def call(env):
            values = [a(env) for a in rest]
            # EXPR is evaluated at many values of the variable (a solver's iterations): its
            # values are not kept, the evaluation's memory stays bounded
            kept, self._shared = self._shared, None
            try:
                return hook(Bound(self, body_t, body, var_t, env), *values)
            finally:
                self._shared = kept

        return call

    def visit_TCall(self, t: ty.TCall) -> Fn:
        f = self.function(t.name)
        params = self.defs.function(t.name).params
        args = [self.compile(a) for a in t.args]
        if len(args) == 1:
            p0, a0 = params[0], args[0]
            return lambda env: f({p0: a0(env)})
        return lambda env: f({p: a(env) for p, a in zip(params, args)})

    def visit_TBlock(self, t: ty.TBlock) -> Fn:
        return self._block(t)

    def visit_TAggregate(self, t: ty.TAggregate) -> Fn:
        get, red = self.column_values, (np.max if t.func == "max" else np.min)
        if get is None:
            raise InputError(f"{t.func}_over({t.table}, {t.column}) needs a sheet's tables")
        return lambda env: float(red(get(t.table, t.column, t.unit)))

    def visit_TPiecewise(self, t: ty.TPiecewise) -> Fn:
        if ty.is_runtime(t.shape):
            return self._runtime_piecewise(t)
        conds = [None if k is None else self.compile(k) for k in t.conditions]
        matrices, used = _matrix_names(t), frozenset(ty.parameters(t)) | set(self.env_keys)
        split = _partition(conds, t.texts, matrices, used)
        keys = tuple(None if k is None else self.plan.keys.key(k) for k in t.conditions)
        split = self._kept(self.plan.keys.signature("pieces", keys), split)
        return _piecewise(t, conds, [self.compile(v) for v in t.values], split, matrices, used)

    def _runtime_piecewise(self, t: ty.TPiecewise) -> Fn:
        """``a if c otherwise b`` whose values are known when they run (elements of run-time
        arrays): one point at a time, and each value given must be a number."""
        conds = [None if k is None else self.compile(k) for k in t.conditions]
        values = [self.compile(v) for v in t.values]
        what, texts = _text(t), t.texts
        matrices, used = _matrix_names(t), frozenset(ty.parameters(t)) | set(self.env_keys)

        def one(env):
            for cond, val in zip(conds, values):
                if cond is None or bool(cond(env)):
                    return rt.number(val(env), what)
            raise _NoPiece(env, texts)

        def evaluate(env):
            if any(np.ndim(env.get(k)) > 2 for k in matrices):
                raise InputError(f"{what}: a matrix over a range where a number is wanted")
            arrays = {
                k: env[k]
                for k in used
                if k not in matrices and isinstance(env.get(k), np.ndarray) and env[k].ndim > 0
            }
            if not arrays:
                return one(env)
            grid = np.broadcast_shapes(*[a.shape for a in arrays.values()])
            full = {k: np.broadcast_to(a, grid) for k, a in arrays.items()}
            out = np.empty(grid)
            for ix in np.ndindex(grid):
                out[ix] = one({**env, **{k: float(a[ix]) for k, a in full.items()}})
            return out

        return evaluate

    def visit_TMatrix(self, t: ty.TMatrix) -> Fn:
        from ..functions.matrix import build

        rows = [[self.compile(e) for e in row] for row in t.rows]
        if ty.is_runtime(t.shape):  # an array of arrays
            return lambda env: rt.build([[e(env) for e in row] for row in rows])
        if all(isinstance(e, ty.TConst) for row in t.rows for e in row):
            value = np.array([[e.value for e in row] for row in t.rows])
            return lambda env: value
        return lambda env: build([[e(env) for e in row] for row in rows])

    def visit_TIndex(self, t: ty.TIndex) -> Fn:
        from ..functions.matrix import index
        from .analysis import typed_text

        target = self.compile(t.target)
        idx = [self.compile(i) for i in t.indices]
        shape, origin = t.target.shape, t.origin
        what = typed_text(t)
        if ty.is_runtime(shape):
            return lambda env: rt.index(
                target(env), [i(env) for i in idx], origin=origin, what=what
            )
        if len(idx) == 1:
            i0 = idx[0]
            return lambda env: index(target(env), i0(env), origin=origin, shape=shape, what=what)
        i0, j0 = idx
        return lambda env: index(
            target(env), i0(env), j0(env), origin=origin, shape=shape, what=what
        )

    def visit_TProgram(self, t: ty.TProgram) -> Fn:
        from ..program.run import NoValue, compile_program

        run = compile_program(t.program, self.compile, t.name)
        params, is_text, name = t.params, t.text, t.name
        runtime = ty.is_runtime(t.shape)
        matrix = () if runtime else tuple(t.shape or ())

        matrices = t.matrices

        def each(point):
            out = run(point)
            if runtime:  # over a range, each point's value must be a number
                return rt.number(out, f"'{name}' over a range")
            return out

        def program(env):
            arrays = {
                p: np.asarray(env[p])
                for p in params
                if p in env and np.ndim(env[p]) > (2 if p in matrices else 0)
            }
            try:
                if not arrays:
                    return run(env)
                grid, at = _range_points(arrays, matrices)
                out = np.empty(matrix + grid, dtype=object if is_text else float)
                lead = (slice(None),) * len(matrix)  # a matrix value: its axes come first
                for ix in np.ndindex(grid):
                    out[lead + ix] = each({**env, **at(ix)})
                return out
            except NoValue:
                raise InputError(
                    f"the program of '{name}' ended without a value (no return, and no value "
                    "line was reached)",
                    definition=name,
                ) from None

        return program

    def visit_TOde(self, t: ty.TOde) -> Fn:
        time = self.compile(t.args[0])
        k, name = t.state, t.ode
        solution = self.ode_solution

        def state(env):
            return solution(name)(k, time(env))

        return state

    def ode_solution(self, name: str):
        """The solution of ``[[ode]] name`` (solved once per sheet, when first needed)."""
        from .ode import solve_typed

        cache = self.__dict__.setdefault("_odes", {})
        if name not in cache:
            cache[name] = None  # solving: a derivative that asks for the solution is circular
            try:
                cache[name] = solve_typed(self.defs.ode(name), self.compile)
            except WorkbookError as err:  # a run that failed is remembered, not run again
                cache[name] = err
                raise
            except BaseException:
                del cache[name]
                raise
        elif cache[name] is None:
            raise InputError(f"ode '{name}': its derivatives refer to its own solution")
        if isinstance(cache[name], WorkbookError):
            raise cache[name]
        return cache[name]

    def _block(self, t: ty.TBlock) -> Fn:
        from .. import blocks

        blk = blocks.get(t.ref, "function")
        args = [self.compile(a) for a in t.args]
        func = blk.func
        if blk.vectorized:
            return lambda env: func(*[a(env) for a in args])

        def looped(env):
            vals = np.broadcast_arrays(*[np.asarray(a(env), dtype=float) for a in args])
            if vals[0].ndim == 0:
                return float(func(*[float(v) for v in vals]))
            out = np.empty(vals[0].shape)
            for idx in np.ndindex(out.shape):
                out[idx] = func(*[float(v[idx]) for v in vals])
            return out

        return looped


#: How deep a function may call itself (Mathcad's recursion), and the Python frames that
#: takes: each level runs through a few closures, so the interpreter's limit is raised while
#: such a function runs (Python 3.11 calls Python closures without growing the C stack).
MAX_RECURSION = 1000
_FRAMES_PER_LEVEL = 40
#: Calls of a function to itself within one outer call: a shallow recursion that branches
#: (``fib(n - 1) + fib(n - 2)``) grows exponentially long before it grows deep.
MAX_RECURSIVE_CALLS = 100_000


def _recursion_bounded(name: str, fn: Fn) -> Fn:
    """``fn`` (a function that calls itself) with its depth counted: deeper than
    MAX_RECURSION is a LimitError naming it, never Python's RecursionError; so is more than
    MAX_RECURSIVE_CALLS calls within one outer call."""
    depth, calls = [0], [0]

    def run(env):
        if depth[0] >= MAX_RECURSION:
            raise LimitError(
                f"{name}() called itself more than {MAX_RECURSION} deep (a recursion that does "
                "not end?)",
                definition=name,
            )
        calls[0] = calls[0] + 1 if depth[0] else 0
        if calls[0] > MAX_RECURSIVE_CALLS:
            raise LimitError(
                f"{name}() called itself more than {MAX_RECURSIVE_CALLS:,} times in one call "
                "(a recursion that branches grows exponentially; write it as a loop)",
                definition=name,
            )
        before = sys.getrecursionlimit()
        need = max(before, 1000 + _FRAMES_PER_LEVEL * (depth[0] + 1))
        if need > before:
            sys.setrecursionlimit(need)
        depth[0] += 1
        try:
            return fn(env)
        finally:
            depth[0] -= 1
            if depth[0] == 0 and sys.getrecursionlimit() != before:
                sys.setrecursionlimit(before)

    run.explain = getattr(fn, "explain", None)
    return run


def _text(t: ty.T) -> str:
    """The source text of a typed node, for run-time errors."""
    from .analysis import typed_text

    return typed_text(t)


def _constant(t: ty.T) -> bool:
    """True if ``t`` does not depend on the environment (no parameter in it)."""
    if isinstance(t, ty.TParam):
        return False
    return all(_constant(c) for c in children(t))


def _matrix_names(t: ty.T) -> frozenset:
    """The parameters and program locals that are vectors or matrices, read in ``t``."""
    out, todo = set(), [t]
    while todo:
        n = todo.pop()
        if isinstance(n, ty.TParam) and n.shape is not None:
            out.add(n.name)
        todo.extend(ty.children(n))
    return frozenset(out)


def _points(env: dict, matrices: frozenset) -> tuple[tuple, dict]:
    """The grid of points of ``env`` (the shape its values vary over) and those values
    broadcast to it: a number varying over a range, or a vector or matrix (``matrices``)
    whose axes after its two matrix axes are a range's."""
    from ..functions import matrix as mx

    keys = [k for k, v in env.items() if isinstance(v, np.ndarray) and v.ndim > 0]
    scalars = [k for k in keys if k not in matrices]
    mats = [k for k in keys if k in matrices and env[k].ndim > 2]
    if not mats:
        shaped = np.broadcast_arrays(*[env[k] for k in scalars])
        return shaped[0].shape, dict(zip(scalars, shaped))
    depth = max([env[k].ndim for k in scalars] + [env[k].ndim - 2 for k in mats])
    padded = {k: mx.pad(env[k], depth - (env[k].ndim - 2)) for k in mats}
    shape = np.broadcast_shapes(
        *[env[k].shape for k in scalars], *[m.shape[2:] for m in padded.values()]
    )
    full = {k: np.broadcast_to(env[k], shape) for k in scalars}
    full.update({k: np.broadcast_to(m, m.shape[:2] + shape) for k, m in padded.items()})
    return shape, full


def _at(full: dict, matrices: frozenset, take) -> dict:
    """The values of ``full`` at the points ``take`` (a mask over the grid)."""
    lead = (slice(None), slice(None))
    return {k: v[lead + (take,)] if k in matrices else v[take] for k, v in full.items()}


def _partition(
    conds: list, texts: tuple, matrices: frozenset = frozenset(), used: frozenset | None = None
) -> Fn:
    """env with arrays -> (shape, [(piece, mask, env of the piece's points)]): first true wins.
    Only the names the pieces use (``used``) span the grid: a program's other locals do not."""

    def split(env):
        seen = env if used is None else {k: v for k, v in env.items() if k in used}
        shape, points = _points(seen, matrices)
        full = {**env, **points}
        todo = np.ones(shape, dtype=bool)
        pieces = []
        for i, cond in enumerate(conds):
            if cond is None:
                take = todo
            else:
                take = todo & np.broadcast_to(np.asarray(cond(full), dtype=bool), shape)
            if take.any():
                pieces.append((i, take, {**env, **_at(points, matrices, take)}))
                todo = todo & ~take
            if not todo.any():
                return shape, pieces
        missed = {k: v for k, v in _at(points, matrices, todo).items() if k not in matrices}
        raise _NoPiece(missed, texts)

    return split


def _piecewise(
    t: ty.TPiecewise,
    conds: list,
    values: list,
    split: Fn,
    matrices: frozenset = frozenset(),
    used: frozenset | None = None,
) -> Fn:
    texts = t.texts

    def evaluate(env):
        seen = env.items() if used is None else ((k, env[k]) for k in used if k in env)
        if not any(
            isinstance(v, np.ndarray) and v.ndim > 0 and k not in matrices for k, v in seen
        ) and not any(np.ndim(env.get(k)) > 2 for k in matrices):
            for cond, val in zip(conds, values):
                if cond is None or bool(cond(env)):
                    return val(env)
            raise _NoPiece(env, texts)
        shape, pieces = split(env)
        out = np.empty(shape, dtype=object if t.text else complex if t.complex else float)
        for i, take, sub in pieces:
            out[take] = values[i](sub)
        return out

    return evaluate


def _matrix_binary(t: ty.TBinary, left: Fn, right: Fn) -> Fn:
    """An operator with a vector or matrix operand (matrix axes first, see
    workbook.functions.matrix)."""
    from ..functions import matrix as mx

    if t.op == "@":
        return lambda env: mx.matmul(left(env), right(env))
    if t.op == "@^":
        n = int(t.right.value)
        return lambda env: mx.power(left(env), n)
    op = {**_ARITH, "^": np.power}[t.op]
    lm, rm = t.left.shape is not None, t.right.shape is not None
    return lambda env: mx.elementwise(op, left(env), right(env), lm, rm)


def _range_points(arrays: dict, matrices: tuple):
    """The grid of range points of a program's arguments that vary over a range, and the
    arguments at one point (a matrix argument's range axes follow its two matrix axes)."""
    from ..functions import matrix as mx

    depth = max(a.ndim - 2 if k in matrices else a.ndim for k, a in arrays.items())
    padded = {k: mx.pad(a, depth - (a.ndim - 2)) if k in matrices else a for k, a in arrays.items()}
    grid = np.broadcast_shapes(
        *[a.shape[2:] if k in matrices else a.shape for k, a in padded.items()]
    )
    full = {
        k: np.broadcast_to(a, a.shape[:2] + grid if k in matrices else grid)
        for k, a in padded.items()
    }
    lead = (slice(None), slice(None))

    def at(ix) -> dict:
        return {k: a[lead + ix] if k in matrices else float(a[ix]) for k, a in full.items()}

    return grid, at


class _NoPiece(InputError):
    """No piece of a piecewise definition applies: an input error wherever it surfaces
    (a function says for which arguments; a scalar definition gets its location from the sheet)."""

    def __init__(self, env, texts):
        super().__init__("no piece applies; its pieces are: " + "; ".join(texts))
        self.env, self.texts = env, texts


def _checked(name: str, params: tuple, body: Fn, describe) -> Fn:
    """Wrap a function so that leaving the domain names the function and the argument interval."""

    def run(env):
        try:
            out = body(env)
        except _NoPiece as miss:
            where = describe(name, params, miss.env)
            raise InputError(
                f"{name}: no piece applies {where}; its pieces are: " + "; ".join(miss.texts),
                definition=name,
            ) from None
        if isinstance(out, np.ndarray) and out.dtype == object:
            return out  # texts
        if isinstance(out, np.ndarray):
            # one pass without a temporary array: a NaN or an infinity makes the sum not
            # finite (an overflowing sum of finite values is looked at point by point)
            if np.isfinite(np.sum(out)):
                return out
            bad = ~np.isfinite(out)
            if bad.any():
                sub = {
                    p: (
                        env[p][bad]
                        if isinstance(env[p], np.ndarray) and env[p].shape == out.shape
                        else env[p]
                    )
                    for p in params
                }
                raise DomainError(
                    f"{name} is not a finite number {describe(name, params, sub)}"
                    + _explain_of(run, env),
                    definition=name,
                )
        elif isinstance(out, float) and not np.isfinite(out):
            raise DomainError(
                f"{name} is not a finite number {describe(name, params, env)}"
                + _explain_of(run, env),
                definition=name,
            )
        return out

    return run


def outside_limits(d, unit, values) -> tuple[np.ndarray, str]:
    """Which of ``values`` (magnitudes in ``unit``) break definition d's declared limits, and
    the limits in words."""
    from ..language import units as un

    lo, hi, positive = d.limits.magnitudes(unit, d.unit, f"'{d.name}'")
    if np.iscomplexobj(values):
        raise InputError(
            f"'{d.name}' is complex: its limits (min, max, positive) compare real numbers; "
            f"declare them on abs({d.name}) or Re({d.name})"
        )
    v = np.asarray(values, dtype=float)
    bad = (v < lo) | (v > hi)
    if positive:
        bad |= v <= 0
    shown = un.pretty(d.unit) if d.unit is not None else un.pretty(unit)
    return bad, d.limits.text(shown)


def limits_error(d, unit, value: float, where: str = "") -> DomainError:
    """The error of a value of d outside its declared limits, in the unit it is shown in."""
    from ..language import units as un

    shown = d.unit if d.unit is not None else unit
    q = un.registry().Quantity(value, unit).to(shown)
    v = float(q.magnitude)
    number = str(int(v)) if v.is_integer() and abs(v) < 1e15 else f"{v:.6g}"
    return DomainError(
        f"{d.name} = {number} {un.pretty(shown)}".rstrip()
        + (f" {where}" if where else "")
        + f" breaks its declared limit ({d.limits.text(un.pretty(shown))})"
        + (
            f": {d.note}"
            if d.note
            else ": the inputs are outside the range where the worksheet's formulas hold"
        ),
        definition=d.name,
    )


def _limited(name: str, params: tuple, body: Fn, d, unit, describe) -> Fn:
    """Wrap a function so that a value outside the definition's declared limits is an error
    naming the definition, its limit and the arguments where it is broken."""

    def run(env):
        out = body(env)
        if isinstance(out, np.ndarray) and out.dtype == object:
            return out
        bad, _ = outside_limits(d, unit, out)
        if np.any(bad):
            first = int(np.flatnonzero(np.ravel(bad))[0])
            value = float(np.ravel(out)[first])
            sub = {
                p: (
                    np.ravel(env[p])[first]
                    if isinstance(env[p], np.ndarray) and np.shape(env[p]) == np.shape(out)
                    else env[p]
                )
                for p in params
            }
            raise limits_error(d, unit, value, describe(name, params, sub))
        return out

    run.explain = getattr(body, "explain", None)
    return run


def _explain_of(run, env) -> str:
    explain = getattr(run, "explain", None)
    return explain(env) if explain is not None else ""


def _explain(evaluator: Evaluator, f: ty.TypedFunction, env) -> str:
    """Which sub-expression left its domain, and for which arguments (workbook.engine.analysis)."""
    try:
        from ..language import units as un
        from .analysis import explain_domain

        args = evaluator.typer.spec.arguments
        text = explain_domain(evaluator, f, env, {p: un.pretty(args[p].unit) for p in f.params})
    except Exception:  # noqa: BLE001 - the explanation must never hide the error itself
        return ""
    return f": {text}" if text else ""
