"""The numpy back end: compile a typed tree into a closure over plain arrays.

Units were resolved by :mod:`workbook.typecheck`, so evaluation works on bare
float magnitudes (no pint in the hot path) and attaches the unit at the end.
"""

from __future__ import annotations

import operator
from collections.abc import Callable

import numpy as np

from . import typecheck as tc
from .errors import DomainError, InputError

Env = dict[str, object]
Fn = Callable[[Env], object]

_MATH = {
    "sin": np.sin,
    "cos": np.cos,
    "tan": np.tan,
    "asin": np.arcsin,
    "acos": np.arccos,
    "atan": np.arctan,
    "sinh": np.sinh,
    "cosh": np.cosh,
    "tanh": np.tanh,
    "sqrt": np.sqrt,
    "exp": np.exp,
    "ln": np.log,
    "log10": np.log10,
    "abs": np.abs,
    "sign": np.sign,
    "floor": np.floor,
    "ceil": np.ceil,
}
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


class Evaluator:
    """Compiles typed trees of one sheet; scalar values are memoised per sheet."""

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
        c = self.compile
        if isinstance(t, tc.TConst):
            v = t.value
            return lambda env: v
        if isinstance(t, tc.TText):
            v = t.value
            return lambda env: v
        if isinstance(t, tc.TParam):
            n = t.name
            return lambda env: env[n]
        if isinstance(t, tc.TRef):
            name, kind, get = t.name, t.kind, self.scalar_value
            return lambda env: get(name, kind)
        if isinstance(t, tc.TScale):
            child, f = c(t.child), t.factor
            if f == 1.0:
                return child
            return lambda env: child(env) * f
        if isinstance(t, tc.TUnary):
            child = c(t.child)
            if t.op == "not":
                return lambda env: np.logical_not(child(env))
            return lambda env: -child(env)
        if isinstance(t, tc.TBinary):
            left, right = c(t.left), c(t.right)
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
        if isinstance(t, tc.TCompare):
            parts = [c(o) for o in t.operands]
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
        if isinstance(t, tc.TLogic):
            parts = [c(v) for v in t.values]
            join = np.logical_and if t.op == "and" else np.logical_or

            def logic(env):
                out = parts[0](env)
                for p in parts[1:]:
                    out = join(out, p(env))
                return out

            return logic
        if isinstance(t, tc.TFunc):
            args = [c(a) for a in t.args]
            if t.func in _MATH:
                f, a0 = _MATH[t.func], args[0]
                return lambda env: f(a0(env))
            if t.func == "atan2":
                y, x = args
                return lambda env: np.arctan2(y(env), x(env))
            red = np.minimum if t.func == "min" else np.maximum

            def minmax(env):
                out = args[0](env)
                for a in args[1:]:
                    out = red(out, a(env))
                return out

            return minmax
        if isinstance(t, tc.TCall):
            f = self.function(t.name)
            params = self.typer.function(t.name).params
            args = [c(a) for a in t.args]
            if len(args) == 1:
                p0, a0 = params[0], args[0]
                return lambda env: f({p0: a0(env)})
            return lambda env: f({p: a(env) for p, a in zip(params, args)})
        if isinstance(t, tc.TBlock):
            return self._block(t)
        if isinstance(t, tc.TAggregate):
            get, red = self.column_values, (np.max if t.func == "max" else np.min)
            if get is None:
                raise InputError(f"{t.func}_over({t.table}, {t.column}) needs a sheet's tables")
            return lambda env: float(red(get(t.table, t.column)))
        if isinstance(t, tc.TPiecewise):
            return _piecewise(
                t, [None if k is None else c(k) for k in t.conditions], [c(v) for v in t.values]
            )
        raise TypeError(t)  # pragma: no cover

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
        out = np.empty(shape, dtype=float)
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


class _NoPiece(Exception):
    def __init__(self, env, texts):
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
