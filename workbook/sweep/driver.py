"""The sweep: choose how the cases run, run them, gather the table."""

from __future__ import annotations

import itertools
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError, LimitError
from ..language import units as un
from ..limits_time import check_time
from .grid import Vary, as_varies, grid
from .outputs import Output, as_outputs, type_output
from .runners import make_tasks, run_case, run_tasks
from .vector import vector_blockers, vector_cases

QUICK_SECONDS = 2.0  # auto mode: solver cases that would all run within this stay in-process


@dataclass
class SweepResult:
    """A finished sweep: the table (swept inputs, outputs, error per case) and how it ran."""

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
        """Number of cases that failed."""
        return int(self.table["error"].notna().sum()) if "error" in self.table else 0

    def summary(self) -> str:
        """One line: cases, outputs, mode, seconds, failures."""
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


#: Points of a sweep's reductions: cases x the points of each output's range (10^8 points of
#: a sine took 5 s in vector mode).
MAX_SWEEP_POINTS = 50_000_000


def check_points(sheet, outs: list[Output], cases: int) -> None:
    """Refuse a sweep whose reductions would evaluate more than :data:`MAX_SWEEP_POINTS`
    points, before any case runs."""
    for out in outs:
        if out.range is None:
            continue
        points = len(sheet.range_values(out.range, f"sweep output {out.name}"))
        if cases * points > MAX_SWEEP_POINTS:
            raise LimitError(
                f"sweep output {out.name}: {cases:,} cases x {points:,} points of its range is "
                f"{cases * points:,} points (limit {MAX_SWEEP_POINTS:,}); fewer cases or a "
                "coarser range",
                file=sheet.file,
                line=_declared_line(sheet, out),
                definition=f"sweep output {out.name}",
            )


def _declared_line(sheet, out: Output) -> int | None:
    """The line of ``[sweep] outputs`` when ``out`` is the template's own (not --output's)."""
    from .outputs import template_outputs

    declared = template_outputs(sheet.spec).get(out.name)
    if declared is None or declared.text != out.text:
        return None
    return sheet.spec.line_of(out.name, "sweep") or sheet.spec.line_of("outputs", "sweep")


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
    varies = as_varies(sheet, vary)
    outs = as_outputs(sheet, outputs)
    for out in outs:  # type every output once here: a mistake is one error, not N
        type_output(sheet, out)
    cases = grid(varies)
    n = len(cases)
    check_points(sheet, outs, n)
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
        tasks = make_tasks(sheet, outs, cases)

        def one(i):
            _, values, error, _ = run_case(tasks[i])
            return values, error

        with np.errstate(all="ignore"):
            results, errors = vector_cases(sheet, outs, varies, cases, one)
        if progress:
            for e in errors:
                progress(e is None)
    if chosen != "vector":
        tasks = make_tasks(sheet, outs, cases)
        done = []
        if mode == "auto" and chosen == "processes" and n > 1:
            # run two cases here (the first pays for imports) and time the second:
            # quick cases are not worth starting a pool for
            done += [run_case(t) for t in tasks[:2]]
            tasks = tasks[2:]
            if done[-1][3] * len(tasks) < QUICK_SECONDS:
                chosen = "serial"
        for k, (index, values, error, secs) in enumerate(
            itertools.chain(done, run_tasks(tasks, chosen, scheduler, workers, connect_timeout)), 1
        ):
            results[index], errors[index], seconds[index] = values, error, secs
            check_time(f"the sweep ({k:,} of {n:,} cases done)")
            if progress:
                progress(error is None)
    elapsed = time.perf_counter() - start

    data = {}
    for v in varies:
        data[v.header(sheet)] = [c[v.name][0] for c in cases]
    units = {}
    for out in outs:
        typed = type_output(sheet, out)
        units[out.name] = un.pretty(typed.unit)
        head = f"{out.name} [{units[out.name]}]" if units[out.name] else out.name
        data[head] = [np.nan if r is None else r[out.name] for r in results]
    data["error"] = pd.Series(errors, dtype=object)
    table = pd.DataFrame(data)
    return SweepResult(sheet.name, table, varies, outs, units, chosen, elapsed, seconds)
