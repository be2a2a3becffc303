"""``workbook bench NAME`` for the numerical built-ins: error against run time, no scene code.

Every scalar definition and every table column whose formula uses a numerical built-in
(root, integral, maximum, ...; also through the sheet's functions) is computed twice from a
fresh sheet: at the sheet's tolerance, and at a reference tolerance of 1e-14 (the same SciPy
routines driven to full double precision). The line gives both run times, the largest error
estimate the solver reported, and the largest difference from the reference.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from .. import typed as ty
from ._common import current, sheet_tolerance, tolerance

#: built-ins whose values come from an iterative method with an error estimate
NUMERICAL = ("root", "integral", "maximum", "minimum", "argmax", "argmin")
REFERENCE_RTOL = 1e-14


@dataclass
class Line:
    what: str
    builtins: str
    values: int
    seconds: float
    reference_seconds: float
    estimate: float  # largest estimated error, relative to the largest |value|
    difference: float  # largest |value - reference|, relative to the largest |reference|

    def text(self) -> str:
        ok = "ok" if self.difference <= max(self.estimate, 1e-15) * 1.0001 else "ESTIMATE LOW"
        return (
            f"{self.what:<34} {self.builtins:<18} {self.values:>8} {_ms(self.seconds):>10} "
            f"{_ms(self.reference_seconds):>10} {self.estimate:>10.1e} {self.difference:>10.1e}"
            f"  {ok}"
        )


HEADER = (
    f"{'definition or column':<34} {'built-ins':<18} {'values':>8} {'time':>10} "
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


def run(sheet) -> list[Line]:
    """One :class:`Line` per target of :func:`targets` (each computed once untimed first)."""
    base = current(sheet_tolerance(sheet.spec.meta))
    lines = []
    for what, found, compute in targets(sheet):
        compute(sheet.with_inputs())  # untimed: imports and first-call costs
        fresh = sheet.with_inputs()
        t0 = time.perf_counter()
        values = np.atleast_1d(np.asarray(compute(fresh), dtype=float))
        seconds = time.perf_counter() - t0
        estimates = [np.max(np.abs(r.error)) for _, r in fresh.evaluator.records if r.error.size]
        with tolerance(base.tighter(REFERENCE_RTOL)):
            ref_sheet = sheet.with_inputs()
            t0 = time.perf_counter()
            ref = np.atleast_1d(np.asarray(compute(ref_sheet), dtype=float))
            ref_seconds = time.perf_counter() - t0
        scale = max(float(np.max(np.abs(ref))), np.finfo(float).tiny)
        lines.append(
            Line(
                what,
                ", ".join(sorted(found)),
                values.size,
                seconds,
                ref_seconds,
                (max(estimates) if estimates else 0.0) / scale,
                float(np.max(np.abs(values - ref))) / scale,
            )
        )
    return lines


def text(sheet, lines: list[Line]) -> str:
    """The report ``workbook bench`` prints."""
    tol = sheet_tolerance(sheet.spec.meta)
    head = (
        f"{sheet.name}: numerical built-ins at tolerance {tol.rtol:g} (samples {tol.samples}), "
        f"reference at {REFERENCE_RTOL:g}; errors relative to the largest value"
    )
    return "\n".join([head, HEADER, *(line.text() for line in lines)])
