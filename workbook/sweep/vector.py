"""Every case at once: the swept inputs become arrays that travel with the range variable."""

from __future__ import annotations

import numpy as np

from ..engine.numeric import Evaluator
from ..errors import InputError, WorkbookError
from ..language import expr as ex
from ..language import units as un
from ..language.uses import dependencies
from .grid import Vary
from .outputs import Output, reduce_values, type_output

VECTOR_POINTS = 1_000_000  # points (cases x range) evaluated per block


class CaseEvaluator(Evaluator):
    """Evaluate with some inputs as arrays that travel through every call with the arguments.

    The swept inputs are entries of the environment (keys ``"\\x00NAME"``), so piecewise
    functions mask them together with the range variable, point by point.
    """

    def __init__(self, sheet, swept: set[str]):
        super().__init__(sheet.typer, sheet.scalar_value, sheet.describe_call)
        self.spec = sheet.spec
        self.swept = swept
        self.env_keys = tuple("\x00" + n for n in sorted(swept))
        self._depends: dict[str, bool] = {}

    def depends(self, name: str) -> bool:
        """Whether definition ``name`` depends on a swept input."""
        if name not in self._depends:
            deps = dependencies(self.spec, ex.Name(name))
            self._depends[name] = bool(deps & self.swept)
        return self._depends[name]

    def reference(self, t):
        """Swept inputs are read from the environment."""
        if t.kind == "input" and t.name in self.swept:
            key = "\x00" + t.name
            return lambda env: env[key]
        if t.kind == "definition" and self.depends(t.name):
            return self.compile(self.typer.scalar(t.name))
        return super().reference(t)

    def visit_TCall(self, t):
        f = self.function(t.name)
        params = self.typer.function(t.name).params
        args = [self.compile(a) for a in t.args]
        keys = self.env_keys

        def call(env):
            inner = {p: a(env) for p, a in zip(params, args)}
            for k in keys:
                inner[k] = env[k]
            return f(inner)

        return call


def vector_blockers(sheet, outputs: list[Output], varies: list[Vary]) -> list[str]:
    """Why the outputs cannot be computed for all cases at once (empty: they can)."""
    why = []
    for v in varies:
        if sheet.spec.inputs[v.name].options:
            why.append(f"{v.name} is a choice")
    swept = {v.name for v in varies}
    for out in outputs:
        deps = dependencies(sheet.spec, out.node, (out.range.var,) if out.range else ())
        blocks = sorted(deps & set(sheet.spec.blocks))
        if blocks:
            why.append(f"{out.name} needs the solver block(s) {', '.join(blocks)}")
        stepwise = sorted(
            n
            for n in deps
            if n in sheet.spec.definitions
            and (sheet.spec.definitions[n].program is not None or sheet.spec.definitions[n].ode)
        )
        if stepwise:
            why.append(f"{out.name} uses programs or ODE solutions ({', '.join(stepwise)})")
        limited = sorted(  # a scalar's declared limits are checked where a Sheet computes it
            n
            for n in deps
            if n in sheet.spec.definitions
            and sheet.spec.definitions[n].limits is not None
            and not sheet.spec.definitions[n].is_function
        )
        if limited:
            why.append(f"{out.name} uses values with declared limits ({', '.join(limited)})")
        aggregates = sorted(deps & {"max_over", "min_over"} - set(sheet.spec.definitions))
        if aggregates:
            why.append(f"{out.name} uses the table aggregate {', '.join(aggregates)}()")
        if out.range is not None:
            for node in (out.range.first, out.range.second, out.range.last, out.range.points):
                if node is not None and dependencies(sheet.spec, node) & swept:
                    why.append(f"the range of {out.name} depends on a swept input")
                    break
    return why


def _coerced(sheet, vary: Vary) -> dict:
    """Each value of ``vary`` -> (its magnitude in the input's unit, None) or (None, the
    error): all values converted in one array when every one is valid (a sweep of 100,000
    values converted one by one spent 4 s in pint), else one by one for their errors."""
    from ..engine.sheet import coerce_input
    from ..language.template import check_input_value

    spec = sheet.spec.inputs[vary.name]
    Q = un.registry().Quantity
    if not spec.options:
        try:
            q = Q(np.asarray(vary.values, dtype=float), vary.unit).to(spec.unit)
            check_input_value(spec, q)
        except Exception:  # noqa: BLE001 - a unit or a value at fault: one by one below
            pass
        else:
            return {v: (float(m), None) for v, m in zip(vary.values, q.magnitude)}
    out = {}
    for v in vary.values:
        try:
            out[v] = (float(coerce_input(spec, Q(float(v), vary.unit)).magnitude), None)
        except WorkbookError as err:
            out[v] = (None, err.message)
    return out


def vector_cases(sheet, outputs: list[Output], varies: list[Vary], cases: list[dict], one=None):
    """All cases at once, in blocks; returns (values per case, errors per case).

    A block in which some case leaves a formula's domain is done again case by case with
    ``one(i) -> (values, error)``, so that the failing case gets its own error.
    """
    n = len(cases)
    swept = {v.name for v in varies}
    errors: list[str | None] = [None] * n
    mags = {name: np.empty(n) for name in swept}
    coerced = {v.name: _coerced(sheet, v) for v in varies}
    for i, case in enumerate(cases):
        for name, (mag, _unit) in case.items():
            value, error = coerced[name][mag]
            if error is not None:
                errors[i] = error
                value = float(sheet.values[name].magnitude)  # a placeholder
            mags[name][i] = value
    ok = np.flatnonzero([e is None for e in errors])
    ev = CaseEvaluator(sheet, swept)
    typed = [(out, type_output(sheet, out)) for out in outputs]
    fns = [ev.compile(t.t) for _, t in typed]
    grids = [
        None if out.range is None else sheet.range_values(out.range, f"sweep output {out.name}")
        for out in outputs
    ]
    points = max([1] + [len(g) for g in grids if g is not None])
    chunk = max(1, VECTOR_POINTS // points)  # cases per block: bounded memory
    results: list[dict | None] = [None] * n
    bad = (WorkbookError, FloatingPointError, ValueError, ZeroDivisionError)

    def solve(idx):
        try:
            with ev.sharing():  # subtrees shared by the outputs computed once per block
                cols = vector_block(mags, idx, typed, fns, grids)
        except bad:
            if one is None:
                raise
            if len(idx) == 1:  # the failing case, evaluated alone for its own error
                results[idx[0]], errors[idx[0]] = one(idx[0])
                return
            half = len(idx) // 2  # halve the block until the failing cases are alone
            solve(idx[:half])
            solve(idx[half:])
            return
        for j, i in enumerate(idx):
            results[i] = {name: float(cols[name][j]) for name in cols}

    for lo in range(0, len(ok), chunk):
        solve(ok[lo : lo + chunk])
    return results, errors


def vector_block(mags, idx, typed, fns, grids) -> dict:
    """The outputs of the cases ``idx`` at once (raises if any value is not finite)."""
    m = len(idx)
    cols = {}
    for (out, t), fn, g in zip(typed, fns, grids):
        env = {"\x00" + k: v[idx] for k, v in mags.items()}
        if g is None:
            vals = np.broadcast_to(np.asarray(fn(env), dtype=float), (m,)).copy()
        else:
            env = {k: np.repeat(v, len(g)) for k, v in env.items()}
            env[out.range.var] = np.tile(g, m)
            flat = np.broadcast_to(np.asarray(fn(env), dtype=float), (m * len(g),))
            if not np.all(np.isfinite(flat)):
                raise InputError("not finite")
            vals = reduce_values(out.reduction, flat.reshape(m, len(g)), g, axis=1)
        vals = vals * t.factor
        if not np.all(np.isfinite(vals)):
            raise InputError("not finite")
        cols[out.name] = vals
    return cols
