"""Ratio 2: cold start. `workbook run concave-cam` in a fresh process (imports, load, unit
check, compute, checks, write the xlsx with its charts) against a fresh
`python -c "import numpy, pint, xlsxwriter"`. Both run alternately as subprocesses; medians.
The optional part hand-checks (sympy, scipy, mpmath) is left out by `workbook run` unless asked
for; the information line measures `workbook run concave-cam --part all` the same way.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _timing import (  # noqa: E402
    INSTALLED_ENV,
    Result,
    median,
    ms,
    report,
    run_seconds,
    workbook_command,
)

TARGET = 2.0
BARE = [sys.executable, "-c", "import numpy, pint, xlsxwriter"]


STAGES = """
import sys, time
t = [time.perf_counter()]
import numpy, pint, xlsxwriter
t.append(time.perf_counter())
bare = set(sys.modules)
import workbook, workbook.cli, workbook.engine.sheet, workbook.outputs.xlsx
from workbook.language import units
units.registry()
t.append(time.perf_counter())
sheet = workbook.load(sys.argv[1], parts=sys.argv[3:] or None)
t.append(time.perf_counter())
report = sheet.check()
t.append(time.perf_counter())
sheet.write_xlsx(sys.argv[2], report=report, force=True)
t.append(time.perf_counter())
heavy = [m for m in ("sympy", "scipy", "pandas", "mpmath") if m in set(sys.modules) - bare]
print(*[b - a for a, b in zip(t, t[1:])], ",".join(heavy) or "-")
"""
STAGE_NAMES = (
    "bare imports",
    "engine imports + pint registry",
    "load + unit check",
    "checks (printed values, findings)",
    "write xlsx",
)


def stages(template: str = "concave-cam", parts: tuple[str, ...] = ()) -> str:
    """Where one cold `workbook run` spends its time (one fresh process, informational)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = (
            subprocess.run(
                [sys.executable, "-c", STAGES, template, str(Path(tmp) / "s.xlsx"), *parts],
                check=True,
                capture_output=True,
                text=True,
                env=INSTALLED_ENV,
            )
            .stdout.splitlines()[-1]
            .split()
        )  # the last line: blocks may print progress
    parts_done = [f"{name} {ms(float(x))}" for name, x in zip(STAGE_NAMES, out)]
    return "; ".join(parts_done) + f"; imported beyond the bare imports: {out[-1]}"


def engine_command(out: Path, template: str = "concave-cam", *parts: str) -> list[str]:
    command = workbook_command() + ["run", template, "--out", str(out)]
    for part in parts:
        command += ["--part", part]
    return command


def measure(
    reps: int = 7, template: str = "concave-cam", parts: tuple[str, ...] = ()
) -> tuple[list[float], list[float]]:
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "cold.xlsx"
        cmd = engine_command(out, template, *parts)
        run_seconds(cmd)  # warm the OS file cache and .pyc files on both sides
        run_seconds(BARE)
        te, tb = [], []
        for i in range(reps):
            pair = [(cmd, te), (BARE, tb)]
            if i % 2:
                pair.reverse()
            for c, acc in pair:
                acc.append(run_seconds(c))
        if not out.is_file():
            raise RuntimeError("workbook run wrote no file")
    return te, tb


def run(reps: int = 7, template: str = "concave-cam", whole: bool = True) -> list[Result]:
    te, tb = measure(reps, template)
    results = [
        Result(
            f"cold start: workbook run {template} / python -c 'import numpy, pint, xlsxwriter'",
            median(te) / median(tb),
            TARGET,
            detail=f"run {ms(median(te))}, bare imports {ms(median(tb))}, medians of {reps}",
        )
    ]
    if whole:
        tw, tb2 = measure(reps, template, ("all",))
        results.append(
            Result(
                f"  (information) the same with every optional part: workbook run {template} "
                "--part all",
                median(tw) / median(tb2),
                TARGET,
                detail=f"run {ms(median(tw))}, bare imports {ms(median(tb2))}, medians of {reps}",
                info=True,
            )
        )
    return results


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=7)
    args = ap.parse_args(argv)
    results = run(args.reps)
    status = report(results)
    print("  one cold run, in stages:", stages())
    print("  the same with --part all:", stages(parts=("all",)))
    return status


if __name__ == "__main__":
    sys.exit(main())
