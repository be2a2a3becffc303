"""Sweeps: chosen outputs of a sheet over a grid of inputs, as a table and a chart.

An output is an expression over the sheet (``r0``, ``phi2(104.6)``, ``h(22)``) or a
reduction over a range: ``max of v(phi) over phi := 0, 0.5 .. 104`` (``max``, ``min``,
``mean``, ``argmax``, ``argmin``; argmax/argmin give the range variable where the
expression is largest/smallest). Outputs are declared in the template::

    [sweep]
    outputs = { v_peak = "max of v(phi) over phi := 0 .. 104" }
    units = { v_peak = "m/s" }          # optional: the unit a column is shown in

or given on the command line as ``--output NAME=EXPR`` (``--output "NAME[m/s]=EXPR"``).

How the cases run (``mode``):

* ``vector``: every case at once in numpy arrays (the swept inputs become arrays that
  travel with the range variable, so piecewise functions stay masked per point);
  chosen automatically when the outputs need no solver block;
* ``processes``: one case per task in a ``ProcessPoolExecutor`` (the task carries the
  template path and the input overrides, never a Sheet); chosen automatically when an
  output needs a solver block;
* ``serial``: one case after the other in this process;
* with ``scheduler`` (an address or a ``dask.distributed.Client``): the same tasks on a
  Dask cluster (dask is imported only then).

A case that fails is recorded with its error (column ``error``); the others go on.
"""

from __future__ import annotations

import itertools
import math
import os
import re
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import expr as ex
from . import typecheck as tc
from . import units as un
from .errors import InputError, TemplateError, WorkbookError
from .numeric import Evaluator

REDUCTIONS = ("max", "min", "mean", "argmax", "argmin")
_REDUCE = re.compile(r"^\s*(max|min|mean|argmax|argmin)\s+of\s+(.+?)\s+over\s+(.+?)\s*$", re.S)
_VARY = re.compile(r"^\s*(.+?)\s*\.\.\s*(.+?)\s*:\s*(\d+)\s*$")
MAX_CASES = 1_000_000
VECTOR_POINTS = 1_000_000  # vector mode: points (cases x range) evaluated per block
QUICK_SECONDS = 2.0  # auto mode: solver cases that would all run within this stay in-process


# -- outputs -------------------------------------------------------------------------------
@dataclass
class Output:
    """One sweep output: ``name = EXPR`` or ``name = REDUCTION of EXPR over RANGE``."""

    name: str
    text: str
    node: ex.Node
    reduction: str | None = None
    range: object | None = None  # template.RangeSpec
    unit_text: str | None = None

    @classmethod
    def parse(cls, name: str, text: str, unit: str | None = None) -> Output:
        from .template import parse_range

        if not ex.is_identifier(name):
            raise InputError(f"sweep output name {name!r} is not a valid name (letters, digits, _)")
        what = f"sweep output {name}"
        m = _REDUCE.match(text)
        if m:
            reduction, body, rng = m.groups()
            return cls(
                name,
                text,
                ex.parse(body, what=what),
                reduction,
                parse_range(rng, what=what),
                unit,
            )
        if re.match(r"^\s*(max|min|mean|argmax|argmin)\s+of\b", text):
            raise InputError(
                f"{what}: write a reduction as 'max of EXPR over VAR := FIRST, SECOND .. LAST'"
            )
        return cls(name, text, ex.parse(text, what=what), None, None, unit)


def parse_output_option(item: str) -> Output:
    """``--output NAME=EXPR`` or ``--output NAME[unit]=EXPR``."""
    head, sep, text = item.partition("=")
    if not sep or not head.strip() or not text.strip():
        raise InputError(
            f"--output {item!r}: write NAME=EXPR, e.g. "
            '--output "v_peak=max of v(phi) over phi := 0 .. 104"'
        )
    m = re.match(r"^\s*([A-Za-z_]\w*)\s*(?:\[(.*)\])?\s*$", head)
    if not m:
        raise InputError(f"--output {item!r}: cannot read the name {head!r}")
    return Output.parse(m.group(1), text.strip(), m.group(2))


def template_outputs(spec) -> dict[str, Output]:
    """Outputs declared in the template's ``[sweep]`` section (empty if none)."""
    try:
        import tomllib
    except ImportError:  # Python 3.10
        import tomli as tomllib

    data = tomllib.loads(spec.text).get("sweep", {})
    if not isinstance(data, dict):
        raise TemplateError("[sweep] must be a table", file=str(spec.path))
    outs = data.get("outputs", {})
    units = data.get("units", {})
    if not isinstance(outs, dict) or not isinstance(units, dict):
        raise TemplateError(
            '[sweep] outputs = { v_peak = "max of v(phi) over phi := 0 .. 104" }',
            file=str(spec.path),
        )
    result = {}
    for name, raw in outs.items():
        unit = units.get(name)
        if isinstance(raw, dict):
            unit = raw.get("unit", unit)
            raw = raw.get("expr", "")
        try:
            result[name] = Output.parse(name, str(raw), None if unit is None else str(unit))
        except WorkbookError as err:
            raise err.located(file=str(spec.path), definition=f"[sweep] {name}") from None
    return result


@dataclass
class _Typed:
    out: Output
    t: tc.T
    unit: object  # pint.Unit shown
    factor: float  # typed magnitude -> shown unit
    var_unit: object | None = None


def _type_output(sheet, out: Output) -> _Typed:
    what = f"sweep output {out.name}"
    scope = {}
    if out.range is not None:
        spec = sheet.spec.arguments.get(out.range.var)
        if spec is None:
            raise TemplateError(
                f"{what}: the range variable '{out.range.var}' is not declared in [arguments]"
            )
        scope = {out.range.var: spec.binding_unit}
    t = sheet.typer.expression(out.node, scope, what)
    if isinstance(t, tc.TText) or getattr(t, "boolean", False):
        raise TemplateError(f"{what}: the output must be a number")
    if out.reduction in ("argmax", "argmin"):
        shown = sheet.spec.arguments[out.range.var].unit
        return _Typed(out, t, shown, 1.0, shown)
    shown = un.unit(out.unit_text, what=what) if out.unit_text is not None else t.unit
    try:
        f = un.factor(t.unit, shown)
    except Exception:
        raise InputError(
            f"{what}: cannot show {un.dims(t.unit)} ({un.pretty(t.unit)}) in {out.unit_text!r}"
        ) from None
    return _Typed(out, t, shown, f)


def _reduce(kind: str, values: np.ndarray, grid: np.ndarray, axis: int = -1):
    if kind == "max":
        return values.max(axis=axis)
    if kind == "min":
        return values.min(axis=axis)
    if kind == "mean":
        return values.mean(axis=axis)
    idx = values.argmax(axis=axis) if kind == "argmax" else values.argmin(axis=axis)
    return grid[idx]


def evaluate_outputs(sheet, outputs: list[Output]) -> dict[str, float]:
    """The outputs of one sheet (one case), each a float in its shown unit."""
    result = {}
    for out in outputs:
        typed = _type_output(sheet, out)
        fn = sheet.evaluator.compile(typed.t)
        if out.range is None:
            value = np.asarray(fn({}), dtype=float)
            if value.ndim:
                raise InputError(f"sweep output {out.name} is not one number")
            value = float(value)
        else:
            grid = sheet.range_values(out.range, f"sweep output {out.name}")
            vals = np.broadcast_to(np.asarray(fn({out.range.var: grid}), dtype=float), grid.shape)
            bad = ~np.isfinite(vals)
            if bad.any():
                raise InputError(
                    f"sweep output {out.name}: not a finite number at "
                    f"{out.range.var} = {grid[bad][0]:g}"
                )
            value = float(_reduce(out.reduction, vals, grid))
        value *= typed.factor
        if not math.isfinite(value):
            raise InputError(f"sweep output {out.name} is not a finite number ({value})")
        result[out.name] = value
    return result


# -- the grid ------------------------------------------------------------------------------
@dataclass
class Vary:
    """One swept input and its values (magnitudes in ``unit``, or words for a choice)."""

    name: str
    values: list
    unit: str = ""  # pint unit text of the magnitudes ('' for a choice or dimensionless)

    def header(self, sheet) -> str:
        spec = sheet.spec.inputs[self.name]
        if spec.options:
            return self.name
        shown = spec.label or un.pretty(spec.unit)
        return f"{self.name} [{shown}]" if shown else self.name


def parse_vary(item: str, sheet) -> Vary:
    """``R3=40mm..60mm:21`` (21 values, ends included), ``R3=40mm,45mm,50mm`` or a choice list."""
    name, sep, text = item.partition("=")
    name, text = name.strip(), text.strip()
    if not sep or not name or not text:
        raise InputError(f"--vary {item!r}: write NAME=FIRST..LAST:COUNT, e.g. R3=40mm..60mm:21")
    spec = sheet.spec.inputs.get(name)
    if spec is None:
        raise InputError(
            f"--vary {item!r}: '{name}' is not an input of {sheet.name} "
            f"(inputs: {', '.join(sheet.spec.inputs)})"
        )
    if spec.options:
        words = [w.strip() for w in text.split(",") if w.strip()]
        for w in words:
            if w not in spec.options:
                raise InputError(f"--vary {name}: {w!r} is not one of {', '.join(spec.options)}")
        return Vary(name, words)
    unit_text = str(spec.unit)
    m = _VARY.match(text)
    if m:
        first, last, count = m.group(1), m.group(2), int(m.group(3))
        if count < 1:
            raise InputError(f"--vary {name}: the count must be at least 1")
        if count > MAX_CASES:
            raise InputError(f"--vary {name}: {count:,} values is more than {MAX_CASES:,}")
        a = _magnitude(spec, first, name)
        b = _magnitude(spec, last, name)
        values = [a] if count == 1 else np.linspace(a, b, count).tolist()
    else:
        values = [_magnitude(spec, v, name) for v in text.split(",") if v.strip()]
        if not values:
            raise InputError(f"--vary {name}: no values")
    return Vary(name, values, unit_text)


def _magnitude(spec, text: str, name: str) -> float:
    """A value in the input's unit; units are checked here, bounds per case (a case error)."""
    import pint

    text = text.strip()
    if ".." in text:
        raise InputError(f"--vary {name}: cannot read {text!r}; write FIRST..LAST:COUNT")
    # "40mm" reads as 40 mm; a bare number is taken in the input's own unit
    try:
        q = un.registry().Quantity(float(text), spec.unit)
    except ValueError:
        q = un.quantity(text, str(spec.unit) if spec.unit.dimensionless else None, what=name)
    try:
        value = float(q.to(spec.unit).magnitude)
    except pint.DimensionalityError:
        raise InputError(
            f"--vary {name}: {text} is {un.dims(q.units)}, but {name} is "
            f"{un.dims(spec.unit)} ({un.pretty(spec.unit) or 'dimensionless'})"
        ) from None
    if not math.isfinite(value):
        raise InputError(f"--vary {name}: {text} is not a finite number")
    return value


def grid(varies: list[Vary]) -> list[dict]:
    """Cartesian product of the swept values; the first input varies slowest."""
    total = math.prod(len(v.values) for v in varies)
    if total > MAX_CASES:
        raise InputError(f"the sweep has {total:,} cases (limit {MAX_CASES:,})")
    return [
        {v.name: (val, v.unit) for v, val in zip(varies, combo)}
        for combo in itertools.product(*[v.values for v in varies])
    ]


# -- running one case (also in worker processes and on Dask workers) ----------------------
_SHEETS: dict[tuple[str, str], object] = {}


def _sheet_for(path: str, text: str):
    """The template's Sheet (with its own defaults), loaded once per process.

    The task carries the template's text too: a worker that cannot read the same file
    (a remote Dask worker) loads a copy of it.
    """
    import hashlib

    key = (path, hashlib.sha256(text.encode("utf-8")).hexdigest())
    if key not in _SHEETS:
        import workbook

        p = Path(path)
        try:
            same = p.is_file() and p.read_text(encoding="utf-8") == text
        except OSError:
            same = False
        if not same:
            import tempfile

            p = Path(tempfile.mkdtemp(prefix="workbook-sweep-")) / Path(path).name
            p.write_text(text, encoding="utf-8")
        _SHEETS[key] = workbook.load(p)
    return _SHEETS[key]


def _prime(sheet) -> tuple[str, str]:
    """Put ``sheet``'s template into this process's cache (forked workers inherit it)."""
    import hashlib

    from .sheet import Sheet

    path = str(Path(sheet.spec.path).resolve())
    text = sheet.spec.text
    key = (path, hashlib.sha256(text.encode("utf-8")).hexdigest())
    if key not in _SHEETS:
        _SHEETS[key] = Sheet(sheet.full_spec, None, sheet.typer, sheet.parts)
    return path, text


def _overrides(values: dict) -> dict:
    out = {}
    for name, v in values.items():
        if isinstance(v, tuple):
            mag, unit = v
            if isinstance(mag, str):  # a choice
                out[name] = mag
            else:
                out[name] = un.registry().Quantity(float(mag), unit) if unit else float(mag)
        else:
            out[name] = v
    return out


def run_case(task: tuple) -> tuple[int, dict | None, str | None, float]:
    """One case: ``(index, (template_path, template_text), base_values, case_values, outputs)``.

    Only plain data crosses process boundaries; the Sheet is loaded (once per process)
    from the template path. Returns (index, values or None, error or None, seconds).
    """
    index, (path, text), base, case, outputs = task
    start = time.perf_counter()
    try:
        sheet = _sheet_for(path, text)
        sheet = sheet.with_inputs(**_overrides({**base, **case}))
        outs = [Output.parse(n, text, unit) for n, text, unit in outputs]
        with np.errstate(all="ignore"):  # a domain error is reported as this case's error
            values = evaluate_outputs(sheet, outs)
        return index, values, None, time.perf_counter() - start
    except WorkbookError as err:
        return index, None, getattr(err, "message", str(err)), time.perf_counter() - start
    except Exception as err:  # a solver may fail in its own way; record it, go on
        return index, None, f"{type(err).__name__}: {err}", time.perf_counter() - start


# -- the vectorised evaluator ---------------------------------------------------------------
class _CaseEvaluator(Evaluator):
    """Evaluate with some inputs as arrays that travel through every call with the arguments.

    The swept inputs are entries of the environment (keys ``"\\x00NAME"``), so piecewise
    functions mask them together with the range variable, point by point.
    """

    def __init__(self, sheet, swept: set[str]):
        super().__init__(sheet.typer, sheet._scalar_value, sheet._describe)
        self.spec = sheet.spec
        self.swept = swept
        self.keys = tuple("\x00" + n for n in sorted(swept))
        self._depends: dict[str, bool] = {}

    def depends(self, name: str) -> bool:
        if name not in self._depends:
            deps = tc.dependencies(self.spec, ex.Name(name))
            self._depends[name] = bool(deps & self.swept)
        return self._depends[name]

    def compile(self, t):
        if isinstance(t, tc.TRef):
            if t.kind == "input" and t.name in self.swept:
                key = "\x00" + t.name
                return lambda env: env[key]
            if t.kind == "definition" and self.depends(t.name):
                return self.compile(self.typer.scalar(t.name))
            return super().compile(t)
        if isinstance(t, tc.TCall):
            f = self.function(t.name)
            params = self.typer.function(t.name).params
            args = [self.compile(a) for a in t.args]
            keys = self.keys

            def call(env):
                inner = {p: a(env) for p, a in zip(params, args)}
                for k in keys:
                    inner[k] = env[k]
                return f(inner)

            return call
        return super().compile(t)


def vector_blockers(sheet, outputs: list[Output], varies: list[Vary]) -> list[str]:
    """Why the outputs cannot be computed for all cases at once (empty: they can)."""
    why = []
    for v in varies:
        if sheet.spec.inputs[v.name].options:
            why.append(f"{v.name} is a choice")
    swept = {v.name for v in varies}
    for out in outputs:
        deps = tc.dependencies(sheet.spec, out.node, (out.range.var,) if out.range else ())
        blocks = sorted(deps & set(sheet.spec.blocks))
        if blocks:
            why.append(f"{out.name} needs the solver block(s) {', '.join(blocks)}")
        aggregates = sorted(deps & {"max_over", "min_over"} - set(sheet.spec.definitions))
        if aggregates:
            why.append(f"{out.name} uses the table aggregate {', '.join(aggregates)}()")
        if out.range is not None:
            for node in (out.range.first, out.range.second, out.range.last):
                if node is not None and tc.dependencies(sheet.spec, node) & swept:
                    why.append(f"the range of {out.name} depends on a swept input")
                    break
    return why


def _vector_cases(sheet, outputs: list[Output], varies: list[Vary], cases: list[dict], one=None):
    """All cases at once, in blocks; returns (values per case, errors per case).

    A block in which some case leaves a formula's domain is done again case by case with
    ``one(i) -> (values, error)``, so that the failing case gets its own error.
    """
    from .sheet import coerce_input

    n = len(cases)
    swept = {v.name for v in varies}
    errors: list[str | None] = [None] * n
    mags = {name: np.empty(n) for name in swept}
    for i, case in enumerate(cases):
        for name, (mag, unit) in case.items():
            spec = sheet.spec.inputs[name]
            try:
                q = coerce_input(spec, un.registry().Quantity(float(mag), unit))
                mags[name][i] = float(q.magnitude)
            except WorkbookError as err:
                errors[i] = err.message
                mags[name][i] = float(sheet.values[name].magnitude)  # a placeholder
    ok = np.flatnonzero([e is None for e in errors])
    ev = _CaseEvaluator(sheet, swept)
    typed = [(out, _type_output(sheet, out)) for out in outputs]
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
            cols = _vector_block(mags, idx, typed, fns, grids)
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


def _vector_block(mags, idx, typed, fns, grids) -> dict:
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
            vals = _reduce(out.reduction, flat.reshape(m, len(g)), g, axis=1)
        vals = vals * t.factor
        if not np.all(np.isfinite(vals)):
            raise InputError("not finite")
        cols[out.name] = vals
    return cols


# -- the sweep -------------------------------------------------------------------------------
@dataclass
class SweepResult:
    sheet_name: str
    table: object  # pandas DataFrame: input columns, output columns, error
    varies: list[Vary]
    outputs: list[Output]
    output_units: dict[str, str]
    mode: str
    seconds: float
    case_seconds: list[float] = field(default_factory=list)

    @property
    def failed(self) -> int:
        return int(self.table["error"].notna().sum()) if "error" in self.table else 0

    def summary(self) -> str:
        n = len(self.table)
        text = f"{n} cases, {len(self.outputs)} outputs, {self.mode}, {self.seconds:.2f} s"
        if self.failed:
            text += f", {self.failed} failed"
        return text


class Progress:
    """Progress on stderr for sweeps that take more than a moment."""

    def __init__(self, total: int, stream=None, every: float = 2.0):
        self.total, self.done, self.failed = total, 0, 0
        self.stream = stream if stream is not None else sys.stderr
        self.every = every
        self.start = time.perf_counter()
        self.last = self.start
        self.shown = False

    def __call__(self, ok: bool) -> None:
        self.done += 1
        self.failed += not ok
        now = time.perf_counter()
        if now - self.last >= self.every or (self.shown and self.done == self.total):
            self.last = now
            self.shown = True
            rate = self.done / max(now - self.start, 1e-9)
            left = (self.total - self.done) / rate if rate else 0.0
            msg = f"sweep: {self.done}/{self.total} cases"
            if self.failed:
                msg += f" ({self.failed} failed)"
            msg += f", {now - self.start:.1f} s"
            if self.done < self.total:
                msg += f", about {left:.0f} s left"
            end = "\n" if self.done == self.total else ""
            if getattr(self.stream, "isatty", lambda: False)():
                print("\r" + msg, end=end, file=self.stream, flush=True)
            else:
                print(msg, file=self.stream, flush=True)


def sweep(
    sheet,
    vary: list[Vary] | dict,
    outputs: list[Output] | dict | None = None,
    *,
    mode: str = "auto",
    scheduler=None,
    workers: int | None = None,
    progress: Callable[[bool], None] | None = None,
    connect_timeout: float = 20.0,
) -> SweepResult:
    """Evaluate ``outputs`` of ``sheet`` for every combination of the ``vary`` values.

    ``vary``: list of :class:`Vary`, ``{"R3": ["40 mm", "45 mm"]}`` or ``{"R3": "40mm..60mm:21"}``.
    ``outputs``: list of :class:`Output`, ``{"v_peak": "max of v(phi) over phi := 0 .. 104"}``,
    or None for the template's ``[sweep]`` outputs.
    """
    import pandas as pd

    if isinstance(sheet, (str, Path)):
        import workbook

        sheet = workbook.load(sheet)
    varies = _as_varies(sheet, vary)
    outs = _as_outputs(sheet, outputs)
    for out in outs:  # type every output once here: a mistake is one error, not N
        _type_output(sheet, out)
    cases = grid(varies)
    n = len(cases)
    if mode not in ("auto", "vector", "serial", "processes"):
        raise InputError(f"sweep mode {mode!r}: auto, vector, serial or processes")
    blockers = vector_blockers(sheet, outs, varies)
    if scheduler is not None:
        chosen = "dask"
    elif mode == "auto":
        needs_block = any("solver block" in b for b in blockers)
        chosen = "processes" if needs_block else ("vector" if not blockers else "serial")
    else:
        chosen = mode
    if chosen == "vector" and blockers:
        raise InputError("cannot vectorise this sweep: " + "; ".join(blockers))

    start = time.perf_counter()
    results: list[dict | None] = [None] * n
    errors: list[str | None] = [None] * n
    seconds = [0.0] * n
    if chosen == "vector":
        tasks = _tasks(sheet, outs, cases)

        def one(i):
            _, values, error, _ = run_case(tasks[i])
            return values, error

        with np.errstate(all="ignore"):
            results, errors = _vector_cases(sheet, outs, varies, cases, one)
        if progress:
            for e in errors:
                progress(e is None)
    if chosen != "vector":
        tasks = _tasks(sheet, outs, cases)
        done = []
        if mode == "auto" and chosen == "processes" and n > 1:
            # run two cases here (the first pays for imports) and time the second:
            # quick cases are not worth starting a pool for
            done += [run_case(t) for t in tasks[:2]]
            tasks = tasks[2:]
            if done[-1][3] * len(tasks) < QUICK_SECONDS:
                chosen = "serial"
        for index, values, error, secs in itertools.chain(
            done, _run(tasks, chosen, scheduler, workers, connect_timeout)
        ):
            results[index], errors[index], seconds[index] = values, error, secs
            if progress:
                progress(error is None)
    elapsed = time.perf_counter() - start

    data = {}
    for v in varies:
        data[v.header(sheet)] = [c[v.name][0] for c in cases]
    units = {}
    for out in outs:
        typed = _type_output(sheet, out)
        units[out.name] = un.pretty(typed.unit)
        head = f"{out.name} [{units[out.name]}]" if units[out.name] else out.name
        data[head] = [np.nan if r is None else r[out.name] for r in results]
    data["error"] = pd.Series(errors, dtype=object)
    table = pd.DataFrame(data)
    return SweepResult(sheet.name, table, varies, outs, units, chosen, elapsed, seconds)


def _as_varies(sheet, vary) -> list[Vary]:
    if isinstance(vary, dict):
        out = []
        for name, values in vary.items():
            if isinstance(values, str):
                out.append(parse_vary(f"{name}={values}", sheet))
            else:
                out.append(parse_vary(f"{name}=" + ",".join(_text(v) for v in values), sheet))
        vary = out
    if not vary:
        raise InputError("nothing to vary: give --vary NAME=FIRST..LAST:COUNT")
    names = [v.name for v in vary]
    if len(set(names)) != len(names):
        raise InputError("an input is varied twice")
    return list(vary)


def _text(v) -> str:
    import pint

    if isinstance(v, pint.Quantity):
        return f"{v.magnitude!r} {v.units}"
    return str(v)


def _as_outputs(sheet, outputs) -> list[Output]:
    if outputs is None:
        found = list(template_outputs(sheet.spec).values())
        if not found:
            raise InputError(
                f"{sheet.name} declares no sweep outputs: add [sweep] outputs = {{ ... }} "
                "to the template or give --output NAME=EXPR"
            )
        return found
    if isinstance(outputs, dict):
        declared = template_outputs(sheet.spec)
        out = []
        for name, text in outputs.items():
            if text is None and name in declared:
                out.append(declared[name])
            else:
                out.append(Output.parse(name, str(text)))
        return out
    return list(outputs)


def _base_values(sheet) -> dict:
    out = {}
    for name, v in sheet.values.items():
        out[name] = v if isinstance(v, str) else (float(v.magnitude), str(v.units))
    return out


def _tasks(sheet, outs: list[Output], cases: list[dict]) -> list[tuple]:
    template = _prime(sheet)
    base = _base_values(sheet)
    spec = tuple((o.name, o.text, o.unit_text) for o in outs)
    return [(i, template, base, case, spec) for i, case in enumerate(cases)]


def _run(tasks: list[tuple], mode: str, scheduler, workers: int | None, timeout: float = 20.0):
    if mode == "serial" or (mode == "processes" and len(tasks) == 1):
        for task in tasks:
            yield run_case(task)
        return
    if mode == "processes":
        import multiprocessing as mp
        import threading
        from concurrent.futures import ProcessPoolExecutor, as_completed
        from concurrent.futures.process import BrokenProcessPool

        # fork (the workers inherit the loaded sheet) when this process has no other
        # threads to copy in a half-held state (a notebook or a Dask client has some)
        methods = mp.get_all_start_methods()
        if "fork" in methods and threading.active_count() == 1:
            method = "fork"
        else:
            method = "forkserver" if "forkserver" in methods else "spawn"
        n = max(1, min(workers or os.cpu_count() or 1, len(tasks)))
        pool = ProcessPoolExecutor(max_workers=n, mp_context=mp.get_context(method))
        futures = {pool.submit(run_case, t): t[0] for t in tasks}
        try:
            for fut in as_completed(futures):
                try:
                    yield fut.result()
                except BrokenProcessPool as err:  # a worker died (crash, out of memory)
                    yield futures[fut], None, f"worker process died: {err}", 0.0
        except BaseException:  # Ctrl-C or an error: do not wait for the queued cases
            pool.shutdown(wait=False, cancel_futures=True)
            raise
        pool.shutdown(wait=True)
        return
    if mode == "dask":
        yield from _run_dask(tasks, scheduler, timeout)
        return
    raise InputError(f"unknown sweep mode {mode!r}")


def _run_dask(tasks: list[tuple], scheduler, timeout: float = 20.0):
    try:
        from dask.distributed import Client, as_completed
    except ImportError:
        raise InputError(
            "--scheduler needs dask.distributed: pip install 'workbook[dask]'"
        ) from None
    own = not isinstance(scheduler, Client)
    try:
        client = Client(scheduler, timeout=f"{timeout}s") if own else scheduler
    except OSError as err:
        raise InputError(f"cannot reach the Dask scheduler at {scheduler}: {err}") from None
    try:
        futures = client.map(run_case, tasks, pure=False)
        for fut in as_completed(futures):
            if fut.status == "error":
                exc = fut.exception()
                index = futures.index(fut)
                yield index, None, f"{type(exc).__name__}: {exc}", 0.0
            else:
                yield fut.result()
    finally:
        if own:
            client.close()


# -- writing -------------------------------------------------------------------------------
def write(result: SweepResult, path: Path, *, force: bool = False, command: str = "") -> Path:
    """Write the sweep: ``.csv`` (the table) or ``.xlsx`` (table, chart, about), atomically."""
    from .atomic import check_target, replacing

    path = Path(path)
    kind = "csv" if path.suffix.lower() == ".csv" else "xlsx"
    if kind == "xlsx" and path.suffix.lower() != ".xlsx":
        raise InputError(f"sweep output {path}: write a .xlsx or a .csv file")
    check_target(path, kind=kind, force=force)
    with replacing(path) as tmp:
        if kind == "csv":
            result.table.to_csv(tmp, index=False)
        else:
            _write_xlsx(result, tmp, command)
    return path


def _write_xlsx(result: SweepResult, path: Path, command: str) -> None:
    import xlsxwriter

    from . import __version__

    df = result.table
    wb = xlsxwriter.Workbook(str(path), {"nan_inf_to_errors": True})
    head = wb.add_format({"bold": True, "bottom": 1, "text_wrap": True, "valign": "top"})
    num = wb.add_format({"num_format": "General"})
    bad = wb.add_format({"font_color": "#9C0006", "bg_color": "#FFC7CE"})
    ws = wb.add_worksheet("Sweep")
    ws.write_row(0, 0, list(df.columns), head)
    for i, row in enumerate(df.itertuples(index=False), start=1):
        for j, v in enumerate(row):
            if v is None or (isinstance(v, float) and math.isnan(v)):
                continue
            if isinstance(v, (int, float, np.floating, np.integer)):
                ws.write_number(i, j, float(v), num)
            else:
                ws.write_string(i, j, str(v), bad if df.columns[j] == "error" else None)
    ws.set_column(0, len(df.columns) - 2, 14)
    ws.set_column(len(df.columns) - 1, len(df.columns) - 1, 60)
    ws.freeze_panes(1, 0)
    n = len(df)
    nv = len(result.varies)
    charts = wb.add_worksheet("Charts")
    # x is the last swept input (it varies fastest, so each series is a block of rows);
    # one series per combination of the other swept inputs
    x = result.varies[-1]
    xcol = nv - 1
    row = 0
    if x.unit or all(isinstance(v, (int, float)) for v in x.values):
        groups = _series_groups(result)
        for k, out in enumerate(result.outputs):
            col = nv + k
            c = wb.add_chart({"type": "scatter", "subtype": "straight_with_markers"})
            for label, first, last in groups:
                c.add_series(
                    {
                        "name": label or out.name,
                        "categories": ["Sweep", first, xcol, last, xcol],
                        "values": ["Sweep", first, col, last, col],
                        "marker": {"type": "circle", "size": 4},
                    }
                )
            unit = result.output_units[out.name]
            c.set_title({"name": f"{out.name} over {x.name} ({result.sheet_name})"})
            c.set_x_axis(
                {
                    "name": df.columns[xcol],
                    "major_gridlines": {"visible": True, "line": {"color": "#D9D9D9"}},
                }
            )
            c.set_y_axis(
                {
                    "name": f"{out.name}, {unit}" if unit else out.name,
                    "major_gridlines": {"visible": True, "line": {"color": "#D9D9D9"}},
                }
            )
            c.set_legend({"position": "bottom"} if len(groups) > 1 else {"none": True})
            c.set_size({"width": 760, "height": 430})
            charts.insert_chart(row, 0, c)
            row += 24
    about = wb.add_worksheet("About")
    about.set_column(0, 0, 20)
    about.set_column(1, 1, 100)
    rows = [
        ("Worksheet", result.sheet_name),
        ("Swept", ", ".join(f"{v.name} ({len(v.values)} values)" for v in result.varies)),
        ("Outputs", "; ".join(f"{o.name} = {o.text}" for o in result.outputs)),
        ("Cases", f"{n} ({result.failed} failed)"),
        ("Ran as", f"{result.mode}, {result.seconds:.2f} s"),
        ("Engine", f"workbook {__version__}"),
        ("Regenerate with", command),
        ("Values", "numbers computed by the engine (a sweep is not live)"),
    ]
    for i, (k, v) in enumerate(rows):
        about.write_string(i, 0, k, head)
        about.write_string(i, 1, v)
    wb.close()


def _series_groups(result: SweepResult) -> list[tuple[str, int, int]]:
    """(label, first row, last row) of each series; rows are 0-based sheet rows."""
    n_last = len(result.varies[-1].values)
    rest = result.varies[:-1]
    combos = list(itertools.product(*[v.values for v in rest])) if rest else [()]
    groups = []
    for j, combo in enumerate(combos):
        label = ", ".join(
            f"{v.name} = {val:g}" if isinstance(val, float) else f"{v.name} = {val}"
            for v, val in zip(rest, combo)
        )
        groups.append((label, 1 + j * n_last, j * n_last + n_last))
    return groups


# -- command line ----------------------------------------------------------------------------
def cmd_sweep(args) -> int:
    """``workbook sweep NAME --vary R3=40mm..60mm:21 [--output NAME=EXPR] [--out FILE]``."""
    from .cli import load_sheet

    sheet = load_sheet(args)
    if not args.vary:
        raise InputError("give at least one --vary NAME=FIRST..LAST:COUNT, e.g. R3=40mm..60mm:21")
    varies = [parse_vary(item, sheet) for item in args.vary]
    outputs = [parse_output_option(o) for o in args.output] if args.output else None
    out = Path(args.out) if args.out else Path("reports") / f"{sheet.name}.sweep.xlsx"
    if not args.out:
        out.parent.mkdir(parents=True, exist_ok=True)
    from .atomic import check_target

    check_target(out, kind="csv" if out.suffix.lower() == ".csv" else "xlsx", force=args.force)
    n = math.prod(len(v.values) for v in varies)
    progress = Progress(n)
    result = sweep(
        sheet,
        varies,
        outputs,
        mode=args.mode,
        scheduler=args.scheduler,
        workers=args.workers,
        progress=progress,
    )
    write(result, out, force=args.force, command=_command(args))
    print(f"wrote {out}: {result.summary()}")
    for i, err in enumerate(result.table["error"]):
        if err is not None:
            case = ", ".join(
                f"{h} = {result.table.iloc[i][h]}" for h in result.table.columns[: len(varies)]
            )
            print(f"  case {i + 1} ({case}) failed: {err}", file=sys.stderr)
    return 0


def _command(args) -> str:
    parts = ["workbook", "sweep", args.name]
    parts += [f'--set "{s}"' for s in args.set]
    parts += [f"--vary {v}" for v in args.vary]
    parts += [f'--output "{o}"' for o in args.output]
    return " ".join(parts)
