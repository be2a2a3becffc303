"""Limit 4: loading and unit-checking every installed template takes less than one cold start.

Measured in fresh processes, alternating with cold starts (`workbook run concave-cam`): the
load side times, after `import numpy, pint, xlsxwriter`, importing the engine, building the
pint registry and `workbook.load(name)` (parse + unit inference of every definition, table
column and chart series) of every template. The ratio is load-all / cold start (< 1).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _timing import INSTALLED_ENV, Result, median, ms, report, run_seconds  # noqa: E402
from bench_coldstart import engine_command  # noqa: E402

TARGET = 1.0

LOAD_ALL = """
import time, numpy, pint, xlsxwriter
t0 = time.perf_counter()
import workbook
loaded, failed = [], []
for name in workbook.list_templates():
    try:
        workbook.load(name)
        loaded.append(name)
    except workbook.WorkbookError:
        failed.append(name)
print(time.perf_counter() - t0, ",".join(loaded) or "-", ",".join(failed) or "-")
"""


def load_all_seconds() -> tuple[float, list[str], list[str]]:
    """Seconds, templates loaded, templates that failed to load (a template error)."""
    out = (
        subprocess.run(
            [sys.executable, "-c", LOAD_ALL],
            check=True,
            capture_output=True,
            text=True,
            env=INSTALLED_ENV,
        )
        .stdout.splitlines()[-1]
        .split()
    )
    names = [[n for n in part.split(",") if n != "-"] for part in out[1:3]]
    return float(out[0]), names[0], names[1]


def run(reps: int = 5) -> list[Result]:
    with tempfile.TemporaryDirectory() as tmp:
        cold = engine_command(Path(tmp) / "cold.xlsx")
        run_seconds(cold)
        load_all_seconds()
        tl, tc = [], []
        loaded, failed = [], []
        for i in range(reps):
            steps = ["load", "cold"] if i % 2 == 0 else ["cold", "load"]
            for step in steps:
                if step == "load":
                    t, loaded, failed = load_all_seconds()
                    tl.append(t)
                else:
                    tc.append(run_seconds(cold))
    note = f"; {len(failed)} failed to load, not counted: {', '.join(failed)}" if failed else ""
    return [
        Result(
            f"load and unit-check all {len(loaded)} templates / one cold start",
            median(tl) / median(tc),
            TARGET,
            detail=f"load all {ms(median(tl))} (incl. engine imports and pint registry), "
            f"cold start {ms(median(tc))}, medians of {reps}{note}",
        )
    ]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=5)
    args = ap.parse_args(argv)
    results = run(args.reps)
    return report(results)


if __name__ == "__main__":
    sys.exit(main())
