"""Ratio 6: the independent check of the live formulas (workbook.compute.livecheck, every
formula cell, with its own reader of Excel formulas, workbook.compute.xleval, and the
`formulas` package for the rest). Writing a workbook with the check against writing the same
workbook without it (``verify=False``), alternately, in one process, CPU time, medians. Each
write computes the sheet's workbook form again and saves it (the Sheet's memo is bypassed:
a write that reuses the form computed before would check nothing).

Sheets: a table of N rows with an integral and a nested integral in its columns (target 3),
a range table of M rows whose columns read ratios of prefixed units, percentages and
degrees (scalar arithmetic, a text column from an inline condition, a chart), and every
template (target 1.3). The check compiles each distinct formula once a process (table
columns share one formula): the first write in a process also pays for compiling them and
for importing the `formulas` package; a cold `workbook run` pays that once (information
line)."""

from __future__ import annotations

import argparse
import gc
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _timing import INSTALLED_ENV, ROOT, Result, alternate, median, ms, report  # noqa: E402

TARGET_INTEGRALS = 3.0
TARGET = 1.3

INTEGRALS = """\
[sheet]
title = "Live check benchmark: {n} rows of integrals"

[inputs]
w = "10 N/m"
L = "6 m"

[arguments]
x = {{ unit = "m" }}
s = {{ unit = "m" }}

[definitions]
"V(x)" = {{ expr = "integral(w*s/L, s, 0, x)", unit = "N" }}
"M(x)" = {{ expr = "integral(V(s), s, 0, x)", unit = "N*m" }}
M_L = {{ expr = "integral(integral(w*s^2/L^2, s, 0, x), x, 0, L)", unit = "N*m" }}
V_L = {{ expr = "integral(w*s/L, s, 0, L)", unit = "N" }}

[[tables]]
name = "beam"
title = "Shear and moment"
range = "x := 0, {step} .. 6"
columns = {{ V = "N", M = "N*m" }}
"""

TABLE = """\
[sheet]
title = "Live check benchmark: {n} rows of scalar arithmetic"

[inputs]
P1 = "1.5 kW"
P2 = "2000 W"
d = "10 mm"
D = "0.6 m"
eta = "85 %"
theta = "30 deg"

[arguments]
x = {{ unit = "" }}

[definitions]
r = "P1/P2"
s = "d/D"
"f(x)" = "x*r*eta"
"g(x)" = "sin(theta*x)*s + r"
"h(x)" = "(x*P1/P2)^2 + s"
"k(x)" = "\\"high\\" if f(x) > 0.3 otherwise \\"low\\""

[[tables]]
name = "T"
range = "x := 0, {step} .. 1"
columns = ["x", "f", "g", "h", "k"]

[[charts]]
name = "curves"
range = "x := 0, {step} .. 1"
x = {{ expr = "x" }}
series = [{{ y = "f(x)", name = "f" }}, {{ y = "g(x)", name = "g" }}]
"""


def integrals_text(n: int) -> str:
    return INTEGRALS.format(n=n, step=6 / (n - 1))


def table_text(n: int) -> str:
    return TABLE.format(n=n, step=1 / (n - 1))


def _pair(sheet, path: Path, reps: int) -> tuple[float, float]:
    """Medians of the CPU time of a write with the check and of one without."""
    from workbook.compute.computed import compute
    from workbook.outputs.xlsx import write_workbook

    report_ = sheet.check()
    gc.collect()  # each sheet from a collected heap: what the sheets before left is garbage

    def write(verify: bool) -> None:
        computed = compute(sheet, report=report_, excel=True, verify=verify)
        write_workbook(computed, path, force=True)

    tc, tu = alternate(
        lambda: write(True), lambda: write(False), reps=reps, clock=time.process_time
    )
    return median(tc), median(tu)


def _cold(path: Path, out: Path) -> float:
    code = "import sys; from workbook.cli import main; sys.exit(main())"
    t0 = time.perf_counter()
    subprocess.run(
        [sys.executable, "-c", code, "run", str(path), "--out", str(out)],
        check=True,
        capture_output=True,
        cwd=ROOT,
        env=INSTALLED_ENV,
    )
    return time.perf_counter() - t0


def _result(what: str, c: float, u: float, target: float, reps: int) -> Result:
    return Result(
        f"write {what}: with the check / without",
        c / u,
        target,
        detail=f"with {ms(c)}, without {ms(u)} of CPU, medians of {reps}",
    )


def run(
    n: int = 1_000, rows: int = 10_000, reps: int = 5, templates: list[str] | None = None
) -> list[Result]:
    """The ratios: ``n`` rows of integrals, a table of ``rows`` rows, each template (all by
    default), and a cold run of the integrals sheet (information)."""
    import workbook

    out = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        src = tmp / "livecheck-integrals.toml"
        src.write_text(integrals_text(n), encoding="utf-8")
        c, u = _pair(workbook.load(src), tmp / "integrals.xlsx", reps)
        out.append(_result(f"{n:,} rows of integrals", c, u, TARGET_INTEGRALS, reps))
        table = tmp / "livecheck-table.toml"
        table.write_text(table_text(rows), encoding="utf-8")
        c, u = _pair(workbook.load(table), tmp / "table.xlsx", reps)
        out.append(_result(f"a table of {rows:,} rows x 5 columns + a chart", c, u, TARGET, reps))
        for name in workbook.list_templates() if templates is None else templates:
            c, u = _pair(workbook.load(name), tmp / "out.xlsx", reps)
            out.append(_result(f"template {name}", c, u, TARGET, reps))
        cold = _cold(src, tmp / "cold.xlsx")
    out.append(
        Result(
            "  (information) a cold `workbook run` of the integrals sheet, seconds",
            cold,
            60.0,
            unit=" s",
            detail="one fresh process: imports, load, compute, write, check",
            info=True,
        )
    )
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--integrals", type=int, default=1_000, help="rows of the integrals table")
    ap.add_argument("--rows", type=int, default=10_000, help="rows of the arithmetic table")
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--template", action="append", help="only these templates")
    args = ap.parse_args(argv)
    return report(run(args.integrals, args.rows, args.reps, args.template))


if __name__ == "__main__":
    sys.exit(main())
