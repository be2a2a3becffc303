"""``workbook bench NAME`` for the numerical built-ins: error against run time, no scene code.

Every scalar definition and every table column whose formula uses a numerical built-in
(root, integral, maximum, ...; also through the sheet's functions) is computed from fresh
sheets: its time is the median of repeated runs at the sheet's tolerance; its reference is
the same definition computed by other algorithms (:mod:`workbook.numerics.reference`:
Brent's method, QUADPACK, dense sampling then a bounded Brent search), never the engine's
own routine at another tolerance. The line gives the time, the reference's time, the
largest error estimate the engine reported, the largest difference from the reference, and
a verdict: "ok" only where that difference is within the sheet's tolerance (or the
reference's own accuracy, 1e-12, if that is larger) and the estimate is at least a tenth of
it; a reference that cannot be computed is named, not a crash.
"""

from __future__ import annotations

import statistics
import time
from dataclasses import dataclass

import numpy as np

from .. import typed as ty
from ..errors import WorkbookError
from ._common import current, reference_methods, sheet_tolerance

#: built-ins whose values come from an iterative method with an error estimate
NUMERICAL = ("root", "integral", "maximum", "minimum", "argmax", "argmin")
#: the relative accuracy the reference methods are trusted to
REFERENCE_ACCURACY = 1e-12
#: ... and for the place of an extremum (argmax, argmin): f is flat there
WHERE_ACCURACY = 1e-7
#: a tighter tolerance of the same methods (a scene's own study of its error may use it)
REFERENCE_RTOL = 1e-14
#: timed runs of each target (the median is shown)
REPEATS = 5


@dataclass
class Line:
    what: str
    builtins: str
    values: int
    seconds: float
    reference_seconds: float
    estimate: float  # largest estimated error of a built-in, relative to its largest |value|
    difference: float  # largest |value - reference|, relative to the largest |reference|
    tolerance: float = 1e-10
    failed: str = ""  # why the reference could not be computed
    checked: int = 0  # values compared with the reference (rows spread over a long table)

    @property
    def verdict(self) -> str:
        """ok, ESTIMATE LOW, beyond tolerance (estimated), WRONG, or the reference's failure."""
        if self.failed:
            return f"no reference: {self.failed}"
        # the place of a smooth extremum is known to about sqrt(eps) by any method
        floor = WHERE_ACCURACY if "arg" in self.builtins else REFERENCE_ACCURACY
        within = self.difference <= max(self.tolerance, floor)
        honest = self.estimate >= self.difference / 10
        if within:
            return "ok" if honest else "ESTIMATE LOW"
        return "beyond tolerance (estimated)" if honest else "WRONG"

    def text(self) -> str:
        diff = "" if self.failed else f"{self.difference:>10.1e}"
        count = (
            f"{self.values}"
            if self.checked in (0, self.values)
            else f"{self.checked}/{self.values}"
        )
        ref = "" if self.failed else _ms(self.reference_seconds)
        return (
            f"{self.what:<34} {self.builtins:<18} {count:>11} {_ms(self.seconds):>10} "
            f"{ref:>10} {self.estimate:>10.1e} {diff:>10}  {self.verdict}"
        )


HEADER = (
    f"{'definition or column':<34} {'built-ins':<18} {'values':>11} {'time':>10} "
    f"{'ref. time':>10} {'est. error':>10} {'vs ref.':>10}"
)


def _ms(s: float) -> str:
    return f"{1000 * s:.1f} ms" if s < 10 else f"{s:.1f} s"


def uses(sheet, t: ty.T) -> set[str]:
    """Numerical built-ins a typed tree calls, also through the sheet's functions and scalars."""
    found: set[str] = set()
    stack, seen = [t], set()
    while stack:
        n = stack.pop()
        if isinstance(n, ty.TFunc) and n.func in NUMERICAL:
            found.add(n.func)
        if isinstance(n, ty.TCall) and n.name not in seen:
            seen.add(n.name)
            stack.append(sheet.typer.function(n.name).body)
        if isinstance(n, ty.TRef) and n.kind == "definition" and n.name not in seen:
            seen.add(n.name)
            stack.append(sheet.typer.scalar(n.name))
        stack.extend(ty.children(n))
    return found


def targets(sheet) -> list[tuple[str, set[str], object]]:
    """(what, built-ins, compute(fresh sheet) -> values) for each place the built-ins are used."""
    out = []
    for name, d in sheet.spec.definitions.items():
        if d.is_function or sheet.typer.scalar(name).text:
            continue  # a text (a verdict, a method's name) has no error to measure
        found = uses(sheet, sheet.typer.scalar(name))
        if found:
            out.append((name, found, lambda s, name=name: s.evaluate(name).magnitude))
    for table in sheet.spec.tables:
        if table.range is None:
            continue
        for col in table.columns:
            t = sheet.typed_column(col, table.range.var, f"table {table.name}")
            found = uses(sheet, t)
            if found:
                what = f"table {table.name}"

                def compute(s, table=table, col=col, what=what):
                    values = s.range_values(table.range, what)
                    return s.column(col, table.range.var, values, what).values

                out.append((f"{what}: {col.text}", found, compute))
    return out


def _relative(result) -> float:
    """A built-in's largest error estimate relative to its largest |value| (both in the unit
    it computes in, which is not the unit the sheet shows)."""
    size = float(np.max(np.abs(result.value), initial=0.0))
    err = float(np.max(np.abs(result.error), initial=0.0))
    return err / size if size > 0 else err


def run(sheet, repeats: int = REPEATS) -> list[Line]:
    """One :class:`Line` per target of :func:`targets` (each computed once untimed first)."""
    base = current(sheet_tolerance(sheet.spec.meta))
    lines = []
    for what, found, compute in targets(sheet):
        compute(sheet.with_inputs())  # untimed: imports and first-call costs
        times = []
        for _ in range(max(repeats, 1)):
            fresh = sheet.with_inputs()
            t0 = time.perf_counter()
            values = np.atleast_1d(np.asarray(compute(fresh), dtype=float))
            times.append(time.perf_counter() - t0)
        estimates = [_relative(r) for _, r in fresh.evaluator.records if r.error.size]
        failed, ref_seconds, ref = "", 0.0, values
        try:
            with reference_methods():
                t0 = time.perf_counter()
                ref = np.atleast_1d(np.asarray(compute(sheet.with_inputs()), dtype=float))
                ref_seconds = time.perf_counter() - t0
        except WorkbookError as err:
            failed = getattr(err, "message", str(err)).splitlines()[0]
        checked = np.isfinite(ref)
        scale = max(float(np.max(np.abs(ref[checked]), initial=0.0)), np.finfo(float).tiny)
        difference = float(np.max(np.abs(values - ref)[checked], initial=0.0)) / scale
        if not failed and not checked.any():
            failed = "no row computed"
        lines.append(
            Line(
                what,
                ", ".join(sorted(found)),
                values.size,
                statistics.median(times),
                ref_seconds,
                max(estimates, default=0.0),
                difference,
                base.rtol,
                failed,
                int(checked.sum()),
            )
        )
    return lines


def text(sheet, lines: list[Line]) -> str:
    """The report ``workbook bench`` prints."""
    tol = sheet_tolerance(sheet.spec.meta)
    head = (
        f"{sheet.name}: numerical built-ins at tolerance {tol.rtol:g} (samples {tol.samples}),"
        f" times the median of the runs; reference by other methods (Brent, QUADPACK, dense "
        "sampling; of a long table, 64 rows spread over it); errors relative to the largest "
        "value"
    )
    return "\n".join([head, HEADER, *(line.text() for line in lines)])
