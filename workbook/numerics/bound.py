"""EXPR of a built-in that binds a variable, as the numpy hooks receive it."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ..functions.numerical import Result, Tolerance, current, defined, num, sheet_tolerance
from ..language import typed as ty
from ..language import units as un


class Bound:
    """EXPR as a function of the bound variable, in the environment of the call.

    ``bound(v)`` evaluates EXPR with the variable set to ``v`` (the rest of the environment as
    in the call). SciPy's vectorised routines solve only the rows still unconverged and pass
    their arguments compressed, so :meth:`over` gives ``f(x, row)``: EXPR with the
    environment's arrays taken at the flat indices ``row`` of the call's shape.
    """

    #: why :meth:`enclosure` gave None: the node of EXPR without an interval extension
    no_enclosure = ""

    def __init__(self, evaluator, body: ty.T, fn: Callable, var: ty.TParam, env: dict):
        self.evaluator = evaluator
        self.body, self.fn, self.env = body, fn, env
        self.var, self.var_param = var.name, var
        self.unit_text = un.pretty(var.unit)
        used = self.names_read = ty.parameters(body) - {self.var} | set(evaluator.env_keys)
        self.arrays = {k: np.asarray(env[k]) for k in used if k in env and np.ndim(env[k]) > 0}
        self.shape = np.broadcast_shapes(*(a.shape for a in self.arrays.values()))

    #: the names EXPR reads from the call's environment besides the variable: its parameters
    #: and, in a vectorised sweep, the swept inputs' cases (under their own keys); what an
    #: mpmath form of EXPR is evaluated with
    names_read: set[str]

    def __call__(self, value):
        return self.fn({**self.env, self.var: value})

    @property
    def tolerance(self) -> Tolerance:
        """The sheet's tolerance, or the one :func:`workbook.numerics.tolerance` sets."""
        return current(sheet_tolerance(self.evaluator.typer.spec.meta))

    def _flat(self, shape) -> dict[str, np.ndarray]:
        return {k: np.broadcast_to(a, shape).reshape(-1) for k, a in self.arrays.items()}

    def over(self, shape: tuple[int, ...]) -> Callable:
        """``f(x, row)`` for SciPy: the environment's arrays at the flat indices ``row``."""
        flat, env, var, fn = self._flat(shape), self.env, self.var, self.fn

        def f(x, row):
            idx = np.asarray(row).astype(np.intp)
            return fn({**env, **{k: a[idx] for k, a in flat.items()}, var: x})

        return f

    def enclosure(self, shape: tuple[int, ...]) -> Callable | None:
        """``g(lo, hi, row) -> (F, D)``: enclosures of EXPR and of its derivative for the
        variable anywhere in [lo, hi] at the flat rows ``row`` (see numerics.intervals); None
        where a node of EXPR has no interval extension."""
        from ..functions.interval_arith import Iv
        from .intervals import NoEnclosure, enclosure

        try:
            g = enclosure(self.evaluator, self.body, self.var)
        except NoEnclosure as err:
            self.no_enclosure = _node_text(str(err))
            return None
        flat, env, var = self._flat(shape), self.env, self.var

        def at(lo, hi, row):
            idx = np.asarray(row).astype(np.intp)
            with np.errstate(all="ignore"):
                return g({**env, **{k: a[idx] for k, a in flat.items()}, var: Iv(lo, hi)})

        return at

    def describe_row(self, shape: tuple[int, ...]) -> Callable[[int], str]:
        """'for Re = 10000' naming the values of the environment's arrays at one row."""
        flat = self._flat(shape)
        args = self.evaluator.typer.spec.arguments

        def label(i: int) -> str:
            if not flat:
                return f"row {i + 1} of {math.prod(shape)}" if math.prod(shape) > 1 else ""
            parts = []
            for k, a in flat.items():
                unit = un.pretty(args[k].unit) if k in args else ""
                parts.append(f"{k} = {num(a[i])} {unit}".rstrip())
            return "for " + ", ".join(parts)

        return label

    def breaks(self, shape: tuple[int, ...]) -> list[np.ndarray]:
        """Points of the variable where EXPR may have a kink, per row (see numerics.kinks)."""
        from .kinks import breaks

        out = []
        for t in breaks(self.evaluator.defs, self.body, self.var):
            v = np.asarray(self.evaluator.compile(t)(self.env), dtype=float)
            out.append(np.broadcast_to(v, shape))
        return out

    def switches(self, shape: tuple[int, ...]) -> list[tuple[Callable, Callable]]:
        """(g, h) per sub-tree whose zeros are kinks or jumps of EXPR (numerics.kinks.
        switching) and that has interval enclosures: ``g(lo, hi, row) -> (F, D)`` and
        ``h(x, row)`` its values, as :meth:`enclosure` and :meth:`over`."""
        from .switches import switching

        return self._pairs(switching(self.body, self.var), shape)

    def poles(self, shape: tuple[int, ...]) -> list[tuple[Callable, Callable]]:
        """(g, h) as :meth:`switches`, per sub-tree whose zeros are singular points of EXPR
        (numerics.singular: a denominator, a power's base, tan's cosine, ...)."""
        from .singular import singular_arguments

        return self._pairs(singular_arguments(self.evaluator.defs, self.body, self.var), shape)

    def _pairs(self, subtrees, shape) -> list[tuple[Callable, Callable]]:
        from ..functions.interval_arith import Iv
        from .intervals import NoEnclosure, enclosure

        flat, env, var = self._flat(shape), self.env, self.var
        out = []
        for u in subtrees:
            if not ty.parameters(u) <= {var, *env}:
                continue
            try:
                g = enclosure(self.evaluator, u, var)
            except NoEnclosure:
                continue
            fn = self.evaluator.compile(u)

            def at(lo, hi, row, g=g):
                idx = np.asarray(row).astype(np.intp)
                with np.errstate(all="ignore"):
                    return g({**env, **{k: a[idx] for k, a in flat.items()}, var: Iv(lo, hi)})

            def value(x, row, fn=fn):
                idx = np.asarray(row).astype(np.intp)
                with np.errstate(all="ignore"):
                    return fn({**env, **{k: a[idx] for k, a in flat.items()}, var: x})

            out.append((at, value))
        return out

    def singular(self, shape: tuple[int, ...]) -> list[Callable]:
        """``h(x, row)`` per sub-tree whose zeros are singular points of EXPR (a denominator,
        a power's base, the argument of sqrt or ln: numerics.singular), as :meth:`over`."""
        from .singular import singular_arguments

        flat, env, var = self._flat(shape), self.env, self.var
        out = []
        for u in singular_arguments(self.evaluator.defs, self.body, var):
            if not ty.parameters(u) <= {var, *env}:
                continue
            fn = self.evaluator.compile(u)

            def value(x, row, fn=fn):
                idx = np.asarray(row).astype(np.intp)
                with np.errstate(all="ignore"):
                    return fn({**env, **{k: a[idx] for k, a in flat.items()}, var: x})

            out.append(value)
        return out

    def record(self, name: str, result: Result) -> None:
        """Keep the result's error estimate (``workbook bench``, the estimate findings), with
        the definition being computed."""
        result.notes.setdefault("in", defined())
        result.notes["body"] = self.body  # which call it is (workbook bench's comparison)
        self.evaluator.records.append((name, result))

    def record_series(self, lo, hi, value, absolute, count=None, kind: str = "sum") -> None:
        """Keep the estimate of a sum or product of this EXPR over i = lo..hi (per row):
        :func:`workbook.numerics.series.record_series` (a built-in's hook, below the numerics,
        reaches it through the EXPR it is given)."""
        from .series import record_series

        record_series(self, lo, hi, value, absolute, count, kind)


_NODES = {
    "TPiecewise": "a piecewise value",
    "TIndex": "indexing",
    "TBlock": "a solve block",
    "TProgram": "a program",
    "TMatrix": "a vector",
    "TAggregate": "max_over or min_over",
    "TOde": "an ODE state",
    "TCompare": "a comparison",
    "TLogic": "a condition",
}


def _node_text(node: str) -> str:
    """The node that has no interval extension, as a message says it: ``sign()``, ``a
    piecewise value``."""
    if node in _NODES:
        return _NODES[node]
    return f"{node}()" if node.isidentifier() and not node.startswith("T") else node
