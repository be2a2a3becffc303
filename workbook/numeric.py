"""The numpy back end: compile a typed tree into a closure over plain arrays.

Units were resolved by :mod:`workbook.typecheck`, so evaluation works on bare
float magnitudes (no pint in the hot path) and attaches the unit at the end.
"""

from __future__ import annotations

import functools
import operator
from collections.abc import Callable

import numpy as np

from . import typecheck as tc
from .builtins import REGISTRY
from .errors import DomainError, InputError
from .numerics.bound import Bound
from .visitor import Visitor

Env = dict[str, object]
Fn = Callable[[Env], object]

_CMP = {
    "<": operator.lt,
    "<=": operator.le,
    ">": operator.gt,
    ">=": operator.ge,
    "==": operator.eq,
    "!=": operator.ne,
}
# np.true_divide: x/0 of plain floats gives inf/nan (a DomainError later), not ZeroDivisionError
_ARITH = {"+": operator.add, "-": operator.sub, "*": operator.mul, "/": np.true_divide}


class Evaluator(Visitor):
    """Compiles typed trees of one sheet; scalar values are memoised per sheet.

    ``compile(t)`` returns a closure ``env -> magnitude``; one ``visit_<Node>`` per typed node.
    """

    def __init__(
        self,
        typer: tc.Typer,
        scalar_value: Callable[[str, str], object],
        describe_args: Callable[[str, tuple, dict], str],
        column_values: Callable[[str, str], object] | None = None,
    ):
        self.typer = typer
        self.column_values = column_values  # (table, column) -> values, for max_over()
        self.scalar_value = scalar_value  # (name, kind) -> magnitude in the ref's unit
        self.describe_args = describe_args
        self._functions: dict[str, Fn] = {}
        self.records: list = []  # (built-in, numerics.Result) of each solve: workbook bench

    def function(self, name: str) -> Fn:
        """Compiled user function: env of its parameters -> magnitude in its unit."""
        if name not in self._functions:
            f = self.typer.function(name)
            self._functions[name] = _checked(
                name, f.params, self.compile(f.body), self.describe_args
            )
            self._functions[name].explain = lambda env, f=f: _explain(self, f, env)
        return self._functions[name]

    def compile(self, t: tc.T) -> Fn:
        """A closure computing ``t`` from an environment of parameter values."""
        return self.visit(t)

    def visit_TConst(self, t: tc.TConst) -> Fn:
        v = t.value
        return lambda env: v

    def visit_TText(self, t: tc.TText) -> Fn:
        v = t.value
        return lambda env: v

    def visit_TParam(self, t: tc.TParam) -> Fn:
        n = t.name
        return lambda env: env[n]

    def visit_TRef(self, t: tc.TRef) -> Fn:
        name, kind, get = t.name, t.kind, self.scalar_value
        return lambda env: get(name, kind)

    def visit_TScale(self, t: tc.TScale) -> Fn:
        child, f = self.compile(t.child), t.factor
        if f == 1.0:
            return child
        return lambda env: child(env) * f

    def visit_TUnary(self, t: tc.TUnary) -> Fn:
        child = self.compile(t.child)
        if t.op == "not":
            return lambda env: np.logical_not(child(env))
        return lambda env: -child(env)

    def visit_TBinary(self, t: tc.TBinary) -> Fn:
        left, right = self.compile(t.left), self.compile(t.right)
        if t.left.shape is not None or t.right.shape is not None:
            return _matrix_binary(t, left, right)
        if t.op == "^":
            if isinstance(t.right, tc.TConst):
                n = t.right.value
                if n == 2.0:
                    return lambda env: np.square(left(env))
                if n == 0.5:
                    return lambda env: np.sqrt(left(env))
                return lambda env: np.power(left(env), n)
            return lambda env: np.power(left(env), right(env))
        op = _ARITH[t.op]
        return lambda env: op(left(env), right(env))

    def visit_TCompare(self, t: tc.TCompare) -> Fn:
        parts = [self.compile(o) for o in t.operands]
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

    def visit_TLogic(self, t: tc.TLogic) -> Fn:
        parts = [self.compile(v) for v in t.values]
        join = np.logical_and if t.op == "and" else np.logical_or

        def logic(env):
            out = parts[0](env)
            for p in parts[1:]:
                out = join(out, p(env))
            return out

        return logic

    def visit_TFunc(self, t: tc.TFunc) -> Fn:
        entry = REGISTRY[t.func]
        f = entry.numpy
        if entry.binds and len(t.args) > max(entry.binds):
            return self._binding(t, entry)
        if entry.arrays:
            f = functools.partial(f, shapes=tuple(a.shape for a in t.args))
        args = [self.compile(a) for a in t.args]
        if len(args) == 1:
            a0 = args[0]
            return lambda env: f(a0(env))
        if len(args) == 2:
            a0, a1 = args
            return lambda env: f(a0(env), a1(env))
        return lambda env: f(*[a(env) for a in args])

    def _binding(self, t: tc.TFunc, entry) -> Fn:
        """A built-in binding a variable: its hook gets EXPR as a function of the variable
        (a :class:`workbook.numerics.bound.Bound`: ``of(value)``, and the row-wise form
        SciPy's vectorised solvers call)."""
        expr_at, var_at = entry.binds
        body_t, var_t = t.args[expr_at], t.args[var_at]
        body = self.compile(body_t)
        rest = [self.compile(a) for i, a in enumerate(t.args) if i not in (expr_at, var_at)]
        hook = entry.numpy

        def call(env):
            return hook(Bound(self, body_t, body, var_t, env), *[a(env) for a in rest])

        return call

    def visit_TCall(self, t: tc.TCall) -> Fn:
        f = self.function(t.name)
        params = self.typer.function(t.name).params
        args = [self.compile(a) for a in t.args]
        if len(args) == 1:
            p0, a0 = params[0], args[0]
            return lambda env: f({p0: a0(env)})
        return lambda env: f({p: a(env) for p, a in zip(params, args)})

    def visit_TBlock(self, t: tc.TBlock) -> Fn:
        return self._block(t)

    def visit_TAggregate(self, t: tc.TAggregate) -> Fn:
        get, red = self.column_values, (np.max if t.func == "max" else np.min)
        if get is None:
            raise InputError(f"{t.func}_over({t.table}, {t.column}) needs a sheet's tables")
        return lambda env: float(red(get(t.table, t.column)))

    def visit_TPiecewise(self, t: tc.TPiecewise) -> Fn:
        return _piecewise(
            t,
            [None if k is None else self.compile(k) for k in t.conditions],
            [self.compile(v) for v in t.values],
        )

    def visit_TMatrix(self, t: tc.TMatrix) -> Fn:
        from .matrix import build

        rows = [[self.compile(e) for e in row] for row in t.rows]
        if all(isinstance(e, tc.TConst) for row in t.rows for e in row):
            value = np.array([[e.value for e in row] for row in t.rows])
            return lambda env: value
        return lambda env: build([[e(env) for e in row] for row in rows])

    def visit_TIndex(self, t: tc.TIndex) -> Fn:
        from .analysis import typed_text
        from .matrix import index

        target = self.compile(t.target)
        idx = [self.compile(i) for i in t.indices]
        shape, origin = t.target.shape, t.origin
        what = typed_text(t)
        if len(idx) == 1:
            i0 = idx[0]
            return lambda env: index(target(env), i0(env), origin=origin, shape=shape, what=what)
        i0, j0 = idx
        return lambda env: index(
            target(env), i0(env), j0(env), origin=origin, shape=shape, what=what
        )

    def visit_TProgram(self, t: tc.TProgram) -> Fn:
        from .program import NoValue, compile_program

        run = compile_program(t.program, self.compile, t.name)
        params, is_text, name = t.params, t.text, t.name
        matrix = tuple(t.shape or ())

        def program(env):
            arrays = {p: env[p] for p in params if p in env and np.ndim(env[p]) > 0}
            try:
                if not arrays:
                    return run(env)
                keys = list(arrays)
                shaped = np.broadcast_arrays(*[np.asarray(arrays[k]) for k in keys])
                grid = shaped[0].shape
                out = np.empty(matrix + grid, dtype=object if is_text else float)
                lead = (slice(None),) * len(matrix)  # a matrix value: its axes come first
                for ix in np.ndindex(grid):
                    one = {**env, **{k: float(a[ix]) for k, a in zip(keys, shaped)}}
                    out[lead + ix] = run(one)
                return out
            except NoValue:
                raise InputError(
                    f"the program of '{name}' ended without a value (no return, and no value "
                    "line was reached)",
                    definition=name,
                ) from None

        return program

    def visit_TOde(self, t: tc.TOde) -> Fn:
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
                cache[name] = solve_typed(self.typer.ode(name), self.compile)
            except BaseException:
                del cache[name]
                raise
        elif cache[name] is None:
            raise InputError(f"ode '{name}': its derivatives refer to its own solution")
        return cache[name]

    def _block(self, t: tc.TBlock) -> Fn:
        from . import blocks

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


def _piecewise(t: tc.TPiecewise, conds: list, values: list) -> Fn:
    texts = t.texts

    def evaluate(env):
        arrays = {k: v for k, v in env.items() if isinstance(v, np.ndarray) and v.ndim > 0}
        if not arrays:
            for cond, val in zip(conds, values):
                if cond is None or bool(cond(env)):
                    return val(env)
            raise _NoPiece(env, texts)
        keys = list(arrays)
        shaped = np.broadcast_arrays(*[arrays[k] for k in keys])
        shape = shaped[0].shape
        full = {**env, **dict(zip(keys, shaped))}
        out = np.empty(shape, dtype=object if t.text else float)
        todo = np.ones(shape, dtype=bool)
        for cond, val in zip(conds, values):
            if cond is None:
                take = todo
            else:
                take = todo & np.broadcast_to(np.asarray(cond(full), dtype=bool), shape)
            if take.any():
                sub = {**env, **{k: full[k][take] for k in keys}}
                out[take] = val(sub)
                todo &= ~take
            if not todo.any():
                return out
        raise _NoPiece({k: full[k][todo] for k in keys}, texts)

    return evaluate


def _matrix_binary(t: tc.TBinary, left: Fn, right: Fn) -> Fn:
    """An operator with a vector or matrix operand (matrix axes first, see workbook.matrix)."""
    from . import matrix as mx

    if t.op == "@":
        return lambda env: mx.matmul(left(env), right(env))
    if t.op == "@^":
        n = int(t.right.value)
        return lambda env: mx.power(left(env), n)
    op = {**_ARITH, "^": np.power}[t.op]
    lm, rm = t.left.shape is not None, t.right.shape is not None
    return lambda env: mx.elementwise(op, left(env), right(env), lm, rm)


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


def _explain_of(run, env) -> str:
    explain = getattr(run, "explain", None)
    return explain(env) if explain is not None else ""


def _explain(evaluator: Evaluator, f: tc.TypedFunction, env) -> str:
    """Which sub-expression left its domain, and for which arguments (workbook.analysis)."""
    try:
        from . import units as un
        from .analysis import explain_domain

        args = evaluator.typer.spec.arguments
        text = explain_domain(evaluator, f, env, {p: un.pretty(args[p].unit) for p in f.params})
    except Exception:  # noqa: BLE001 - the explanation must never hide the error itself
        return ""
    return f": {text}" if text else ""
