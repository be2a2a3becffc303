"""``workbook bench NAME`` for the numerical built-ins: error against run time, no scene code.

Every scalar definition and every table column whose formula uses a numerical built-in
(root, integral, maximum, ...; also through the sheet's functions) is computed from fresh
sheets: its time is the median of repeated runs at the sheet's tolerance; its reference is
the same definition with every built-in computed by mpmath on EXPR's typed tree at 32
digits or more (:mod:`workbook.numerics.mpref`), or, where EXPR has a node without an
mpmath form, by other algorithms in doubles (:mod:`workbook.numerics.reference`: Brent's
method, QUADPACK, dense sampling then a bounded Brent search), never the engine's own
routine at another tolerance. The line gives the time, the reference's time, the largest
error estimate the engine reported, the largest difference from the reference, the
reference's method, and a verdict: "ok" only where that difference is within the sheet's
tolerance (or the reference's own accuracy, if that is larger) and the estimate is at
least a tenth of it; a reference that cannot be computed is named, not a crash.
"""

from __future__ import annotations

import statistics
import time
from dataclasses import dataclass

import numpy as np

from ..errors import WorkbookError
from ..functions.numerical import current, reference_methods, sheet_tolerance
from ..language import typed as ty

#: the relative accuracy the reference methods in doubles are trusted to
REFERENCE_ACCURACY = 1e-12
#: ... and the mpmath reference (its value is rounded to a double, and the arithmetic of the
#: definition around the built-in is the sheet's, in doubles)
MPMATH_ACCURACY = 1e-14
#: ... and for the place of an extremum (argmax, argmin): f is flat there
WHERE_ACCURACY = 1e-7
#: the rounding of a double result (relative): a difference below it is no error to estimate
ROUNDING = 4 * float(np.finfo(float).eps)
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
    checked: int = 0  # the built-ins' values compared with the reference's
    reference: str = "mpmath"  # the reference's method(s)
    refused: str = ""  # why the engine refused the definition (its error's first line)

    @property
    def verdict(self) -> str:
        """ok, ESTIMATE LOW, beyond tolerance (estimated), WRONG, the engine's refusal, or the
        reference's failure."""
        if self.refused:
            return f"refused by the engine: {self.refused}"
        if self.failed:
            return f"no reference: {self.failed}"
        # the place of a smooth extremum is known to about sqrt(eps) by any method
        floor = MPMATH_ACCURACY if self.reference == "mpmath" else REFERENCE_ACCURACY
        if "arg" in self.builtins:
            floor = WHERE_ACCURACY
        within = self.difference <= max(self.tolerance, floor)
        # a difference within the rounding of a double needs no estimate to cover it
        honest = self.estimate >= self.difference / 10 or self.difference <= ROUNDING
        if within:
            return "ok" if honest else "ESTIMATE LOW"
        return "beyond tolerance (estimated)" if honest else "WRONG"

    def text(self) -> str:
        diff = "" if self.failed or self.refused else f"{self.difference:>10.1e}"
        count = f"{self.values} ({self.checked})"
        ref = "" if self.failed else _ms(self.reference_seconds)
        return (
            f"{self.what:<34} {self.builtins:<18} {count:>13} {_ms(self.seconds):>10} "
            f"{ref:>10} {self.estimate:>10.1e} {diff:>10}  {self.reference:<8} {self.verdict}"
        )


HEADER = (
    f"{'definition or column':<34} {'built-ins':<18} {'values (ref.)':>13} {'time':>10} "
    f"{'ref. time':>10} {'est. error':>10} {'vs ref.':>10}  {'ref.':<8} verdict"
)


def _ms(s: float) -> str:
    return f"{1000 * s:.1f} ms" if s < 10 else f"{s:.1f} s"


def _estimate(name: str) -> str:
    """How the error of built-in ``name`` is estimated: "iterative", "condition" or ""."""
    from .registry import REGISTRY  # imported here: the registry imports numerics

    entry = REGISTRY.get(name)
    return entry.estimate if entry is not None else ""


def uses(sheet, t: ty.T) -> set[str]:
    """Numerical built-ins a typed tree calls, also through the sheet's functions and scalars."""
    found: set[str] = set()
    stack, seen = [t], set()
    while stack:
        n = stack.pop()
        estimate = _estimate(n.func) if isinstance(n, ty.TFunc) else ""
        if estimate == "iterative" and len(n.args) > 1:
            found.add(n.func)  # sum(v) of a vector (one argument) has no estimate
        if estimate == "condition":
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


def _differences(engine: list, reference: list) -> tuple[float, int]:
    """(largest difference, values compared): each call of a built-in against the
    reference's call of the same EXPR (the n-th with the n-th), relative to the larger of
    the two calls' largest |value| (as the estimate is relative to the call's value). A call
    inside another built-in's EXPR (an inner integral) is part of the outer one's reference
    and has no call of its own there."""
    by_body: dict = {}
    for body, values in reference:
        by_body.setdefault(body, []).append(values)
    seen: dict = {}
    worst, count = 0.0, 0
    for r in engine:
        body = r.notes.get("body")
        k = seen[body] = seen.get(body, -1) + 1
        refs = by_body.get(body, [])
        if k >= len(refs):
            continue
        got, want = np.ravel(r.value), np.ravel(refs[k])
        if got.shape != want.shape:
            continue
        rows = np.isfinite(want)
        size = max(
            float(np.max(np.abs(want[rows]), initial=0.0)),
            float(np.max(np.abs(got[rows]), initial=0.0)),
        )
        diff = float(np.max(np.abs(got - want)[rows], initial=0.0))
        if size > 0:
            worst = max(worst, diff / size)
        count += int(rows.sum())
    return worst, count


def run(sheet, repeats: int = REPEATS) -> list[Line]:
    """One :class:`Line` per target of :func:`targets` (each computed once untimed first)."""
    base = current(sheet_tolerance(sheet.spec.meta))
    lines = []
    for what, found, compute in targets(sheet):
        try:
            compute(sheet.with_inputs())  # untimed: imports and first-call costs
        except WorkbookError as err:  # one refusal does not stop the others' lines
            why = getattr(err, "message", str(err)).splitlines()[0]
            builtins = ", ".join(sorted(found))
            lines.append(Line(what, builtins, 0, 0.0, 0.0, 0.0, 0.0, base.rtol, refused=why))
            continue
        times = []
        for _ in range(max(repeats, 1)):
            fresh = sheet.with_inputs()
            t0 = time.perf_counter()
            values = np.atleast_1d(np.asarray(compute(fresh), dtype=float))
            times.append(time.perf_counter() - t0)
        engine = [r for _, r in fresh.evaluator.records if r.error.size]
        estimates = [_relative(r) for r in engine]
        failed, ref_seconds, log = "", 0.0, None
        try:
            with reference_methods() as log:
                t0 = time.perf_counter()
                compute(sheet.with_inputs())
                ref_seconds = time.perf_counter() - t0
        except WorkbookError as err:
            failed = getattr(err, "message", str(err)).splitlines()[0]
        difference, count = _differences(engine, log.values) if log else (0.0, 0)
        if not failed and not count:
            failed = "no row computed"
        methods = sorted({method for method, _, _ in log.methods}) if log else []
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
                count,
                "; ".join(methods) or "mpmath",
            )
        )
    return lines


def text(sheet, lines: list[Line]) -> str:
    """The report ``workbook bench`` prints."""
    tol = sheet_tolerance(sheet.spec.meta)
    head = (
        f"{sheet.name}: numerical built-ins at tolerance {tol.rtol:g} (samples {tol.samples}),"
        f" times the median of the runs; reference: mpmath at 32+ digits on the same formula "
        "(quad, bisection, dense sampling then golden section; of a long table, 16 rows spread "
        "over it), or other methods in doubles where the formula has no mpmath form (Brent, "
        "QUADPACK, dense sampling; 64 rows); errors of each built-in call relative to its "
        "largest value; values (ref.): the definition's values (the built-ins' values "
        "compared)"
    )
    return "\n".join([head, HEADER, *(line.text() for line in lines)])
