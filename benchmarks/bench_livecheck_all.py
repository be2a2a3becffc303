"""Ratio 6b: the live-cell check of every formula cell (workbook.compute.livecheck with its
own reader of Excel formulas, workbook.compute.xleval). Writing a workbook with the check
against writing it without (``verify=False``), alternately, in one process, CPU time;
medians. Every template, and a range table of N rows whose columns read ratios of prefixed
units, percentages and degrees (scalar arithmetic, a text column from an inline condition,
a chart)."""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _timing import Result, alternate, median, ms, report  # noqa: E402

TARGET = 1.3

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


def table_text(n: int) -> str:
    return TABLE.format(n=n, step=1 / (n - 1))


def _pair(sheet, path: Path, reps: int) -> tuple[float, float]:
    report_ = sheet.check()

    def checked():
        sheet.write_xlsx(path, force=True, report=report_)

    def unchecked():
        sheet.write_xlsx(path, force=True, report=report_, verify=False)

    tc, tu = alternate(checked, unchecked, reps=reps, clock=time.process_time)
    return median(tc), median(tu)


def run(n: int = 10_000, reps: int = 5, templates: list[str] | None = None) -> list[Result]:
    import workbook

    out = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        src = tmp / "livecheck-table.toml"
        src.write_text(table_text(n), encoding="utf-8")
        sheets = [(f"a table of {n:,} rows x 5 columns + a chart", workbook.load(src))]
        names = workbook.list_templates() if templates is None else templates
        sheets += [(f"template {name}", workbook.load(name)) for name in names]
        for what, sheet in sheets:
            c, u = _pair(sheet, tmp / "out.xlsx", reps)
            out.append(
                Result(
                    f"write {what}: with the check of every formula cell / without",
                    c / u,
                    TARGET,
                    detail=f"with {ms(c)}, without {ms(u)} of CPU, medians of {reps}",
                )
            )
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rows", type=int, default=10_000)
    ap.add_argument("--reps", type=int, default=5)
    args = ap.parse_args(argv)
    return report(run(args.rows, args.reps))


if __name__ == "__main__":
    sys.exit(main())
