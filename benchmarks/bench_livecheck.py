"""Ratio 6: the independent check of the live formulas (workbook.compute.livecheck). Writing a
workbook with the check against writing the same workbook without it (``verify=False``),
alternately, in one process; medians. Two sheets: one whose formulas all need the check (a
table of N rows with an integral and a nested integral in its columns, scalar integrals) and
concave-cam, whose formulas are scalar arithmetic only (nothing to compute). The first check
in a process also pays for importing the `formulas` package and compiling its Excel
functions; a cold `workbook run` of a sheet that has something to check pays that once
(information line)."""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _timing import INSTALLED_ENV, ROOT, Result, alternate, median, ms, report  # noqa: E402

TARGET_CHECKED = 3.0
TARGET_PLAIN = 1.15

TEMPLATE = """\
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


def template_text(n: int) -> str:
    return TEMPLATE.format(n=n, step=6 / (n - 1))


def _pair(sheet, path: Path, reps: int) -> tuple[float, float]:
    report_ = sheet.check()

    def checked():
        sheet.write_xlsx(path, force=True, report=report_)

    def unchecked():
        sheet.write_xlsx(path, force=True, report=report_, verify=False)

    tc, tu = alternate(checked, unchecked, reps=reps)
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


def run(n: int = 1_000, reps: int = 5) -> list[Result]:
    import workbook

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        src = tmp / "livecheck-bench.toml"
        src.write_text(template_text(n), encoding="utf-8")
        sheet = workbook.load(src)
        c1, u1 = _pair(sheet, tmp / "integrals.xlsx", reps)
        c2, u2 = _pair(workbook.load("concave-cam"), tmp / "cam.xlsx", reps)
        cold = _cold(src, tmp / "cold.xlsx")
    return [
        Result(
            f"write {n:,} rows of integrals + nested integrals: with the check / without",
            c1 / u1,
            TARGET_CHECKED,
            detail=f"with {ms(c1)}, without {ms(u1)}, medians of {reps}",
        ),
        Result(
            "write concave-cam (scalar arithmetic only): with the check / without",
            c2 / u2,
            TARGET_PLAIN,
            detail=f"with {ms(c2)}, without {ms(u2)}, medians of {reps}",
        ),
        Result(
            "  (information) a cold `workbook run` of the integrals sheet, seconds",
            cold,
            60.0,
            unit=" s",
            detail="one fresh process: imports, load, compute, write, check",
            info=True,
        ),
    ]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rows", type=int, default=1_000)
    ap.add_argument("--reps", type=int, default=5)
    args = ap.parse_args(argv)
    return report(run(args.rows, args.reps))


if __name__ == "__main__":
    sys.exit(main())
