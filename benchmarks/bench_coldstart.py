"""Ratio 2: cold start. `workbook run concave-cam` in a fresh process (imports, load, unit
check, compute, checks, write the xlsx with its charts) against a fresh
`python -c "import numpy, pint, xlsxwriter"`. Both run alternately as subprocesses; medians.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _timing import Result, median, ms, run_seconds, workbook_command  # noqa: E402

TARGET = 2.0
BARE = [sys.executable, "-c", "import numpy, pint, xlsxwriter"]


STAGES = """
import sys, time
t = [time.perf_counter()]
import numpy, pint, xlsxwriter
t.append(time.perf_counter())
import workbook, workbook.cli, workbook.sheet, workbook.xlsx
from workbook import units
units.registry()
t.append(time.perf_counter())
sheet = workbook.load(sys.argv[1])
t.append(time.perf_counter())
report = sheet.check()
t.append(time.perf_counter())
sheet.write_xlsx(sys.argv[2], report=report, force=True)
t.append(time.perf_counter())
heavy = [m for m in ("sympy", "scipy", "pandas", "matplotlib") if m in sys.modules]
print(*[b - a for a, b in zip(t, t[1:])], ",".join(heavy) or "-")
"""
STAGE_NAMES = (
    "bare imports",
    "engine imports + pint registry",
    "load + unit check",
    "checks (printed values, findings)",
    "write xlsx",
)


def stages(template: str = "concave-cam") -> str:
    """Where one cold `workbook run` spends its time (one fresh process, informational)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = (
            subprocess.run(
                [sys.executable, "-c", STAGES, template, str(Path(tmp) / "s.xlsx")],
                check=True,
                capture_output=True,
                text=True,
            )
            .stdout.splitlines()[-1]
            .split()
        )  # the last line: blocks may print progress
    parts = [f"{name} {ms(float(x))}" for name, x in zip(STAGE_NAMES, out)]
    return "; ".join(parts) + f"; heavy modules imported: {out[-1]}"


def core_template(folder: Path, template: str = "concave-cam") -> Path:
    """A copy of the template with only the Mathcad sheet: inputs, definitions, range tables,
    their charts and printed values; without [[relations]], [[findings]] and block tables
    (and the charts drawn from them), which other issues added for the hand checks."""
    import shutil

    import workbook

    src = workbook.template_path(template)
    blocks, current = [], []
    for line in src.read_text(encoding="utf-8").splitlines(keepends=True):
        if line.startswith("["):
            blocks.append(current)
            current = []
        current.append(line)
    blocks.append(current)
    kept = []
    for block in blocks:
        head = block[0].strip() if block else ""
        text = "".join(block)
        if head in ("[[relations]]", "[[findings]]"):
            continue
        if head in ("[[tables]]", "[[charts]]") and ("block =" in text or "table =" in text):
            continue
        kept.append(text)
    out = folder / f"{template}-core.toml"
    out.write_text("".join(kept), encoding="utf-8")
    for csv in src.parent.glob(f"{template}.*.csv"):
        shutil.copy(csv, folder / csv.name)
    return out


def engine_command(out: Path, template: str = "concave-cam") -> list[str]:
    return workbook_command() + ["run", template, "--out", str(out)]


def measure(reps: int = 7, template: str = "concave-cam") -> tuple[list[float], list[float]]:
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "cold.xlsx"
        cmd = engine_command(out, template)
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


def run(reps: int = 7, template: str = "concave-cam", core: bool = True) -> list[Result]:
    te, tb = measure(reps, template)
    extra = []
    if core:
        with tempfile.TemporaryDirectory() as tmp:
            path = core_template(Path(tmp), template)
            tc, tb2 = measure(reps, str(path))
        extra.append(
            Result(
                f"  (information) the same for the Mathcad sheet alone ({template} without "
                "relations, findings and block tables)",
                median(tc) / median(tb2),
                TARGET,
                detail=f"run {ms(median(tc))}, bare imports {ms(median(tb2))}, medians of {reps}",
                info=True,
            )
        )
    return [
        Result(
            f"cold start: workbook run {template} / python -c 'import numpy, pint, xlsxwriter'",
            median(te) / median(tb),
            TARGET,
            detail=f"run {ms(median(te))}, bare imports {ms(median(tb))}, medians of {reps}",
        )
    ] + extra


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=7)
    args = ap.parse_args(argv)
    results = run(args.reps)
    for r in results:
        print(r.line())
    print("  one cold run, in stages:", stages())
    return 0 if all(r.ok for r in results) else 1


if __name__ == "__main__":
    sys.exit(main())
