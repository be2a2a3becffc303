"""Ratio 3: writing. A table of N rows by 4 formula columns (cached values) plus one chart,
through the engine (sheet.write_xlsx: evaluate, print formulas, write, close) against raw
xlsxwriter writing the same cells (the same formula texts, numbers and cached values,
prepared before timing) and the same chart. Alternately, in one process; medians.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _timing import Result, alternate, median, ms, report  # noqa: E402

TARGET = 1.3

TEMPLATE = """\
[sheet]
title = "Write benchmark: {n} rows by 4 formula columns"

[inputs]
a = {{ value = "20 mm", note = "crank radius", positive = true }}
L = {{ value = "80 mm", note = "rod length", positive = true }}
omega = {{ value = "104.6 1/s", note = "angular speed", positive = true }}

[arguments]
phi = {{ unit = "deg", plain = true, note = "crank angle, plain degrees" }}

[definitions]
deg = "pi/180"
"x(phi)" = {{ expr = "a*cos(phi*deg) + sqrt(L^2 - a^2*sin(phi*deg)^2)", unit = "mm" }}
"s(phi)" = "sqrt(L^2 - a^2*sin(phi*deg)^2)"
"v(phi)" = {{ expr = "-a*omega*sin(phi*deg)*(1 + a*cos(phi*deg)/s(phi))", unit = "m/s" }}
"acc(phi)" = {{ expr = "-a*omega^2*cos(phi*deg)", unit = "m/s^2" }}
"beta(phi)" = {{ expr = "asin(a/L*sin(phi*deg))", unit = "deg" }}

[[tables]]
name = "big"
title = "Slider: phi := 0, 1 .. {last}"
range = "phi := 0, 1 .. {last}"
columns = {{ x = "mm", v = "m/s", acc = "m/s^2", beta = "deg" }}

[[charts]]
name = "slider"
title = "Slider position"
range = "phi := 0, 1 .. {last}"
x = {{ expr = "phi", title = "phi, deg" }}
y_title = "x, mm"
series = [{{ y = "x", unit = "mm", name = "x, mm" }}]
"""


def template_text(n: int) -> str:
    return TEMPLATE.format(n=n, last=n - 1)


class Raw:
    """Everything the raw xlsxwriter side needs, prepared outside the timing."""

    def __init__(self, sheet):
        from workbook.compute.excel import ExcelPrinter, excel_name
        from workbook.compute.excelsheets import ROW_TOKEN
        from workbook.language import units as un
        from workbook.language.units import header

        data = sheet.table_data("big")
        printer = ExcelPrinter(sheet.typer)
        self.inputs = [
            (excel_name(n), float(q.magnitude), un.pretty(q.units), sheet.spec.inputs[n].note)
            for n, q in sheet.values.items()
        ]
        self.defs = [
            (excel_name(n), printer.formula(sheet.typer.scalar(n), {}), float(sheet.evaluate(n).m))
            for n, d in sheet.spec.definitions.items()
            if not d.is_function
        ]
        self.title = sheet.spec.tables[0].title
        self.heads = [header(c.title, c.unit) for c in data.columns]
        self.x = data.columns[0].values.tolist()
        self.formulas = [
            printer.formula(c.typed, {data.var: f"$A${ROW_TOKEN}"}).split(ROW_TOKEN)
            for c in data.columns[1:]
        ]
        self.values = [c.values.tolist() for c in data.columns[1:]]

    def write(self, path: Path, classic: bool = False) -> None:
        """``classic``: skip xlsxwriter's formula rewriting as the engine does (information)."""
        import xlsxwriter

        from workbook.outputs.xlsx import classic_formulas_as_they_are

        wb = xlsxwriter.Workbook(str(path), {"nan_inf_to_errors": True})
        bold = wb.add_format({"bold": True})
        num = wb.add_format({"num_format": "0.000###"})
        ws = wb.add_worksheet("Inputs")
        for row, (name, value, unit, note) in enumerate(self.inputs, start=1):
            ws.write_string(row, 0, name)
            ws.write_number(row, 1, value)
            ws.write_string(row, 2, unit)
            ws.write_string(row, 3, note)
            wb.define_name(name, f"=Inputs!$B${row + 1}")
        ws = wb.add_worksheet("Definitions")
        for row, (name, formula, value) in enumerate(self.defs, start=1):
            ws.write_string(row, 0, name)
            ws.write_formula(row, 1, formula, None, value)
            wb.define_name(name, f"=Definitions!$B${row + 1}")
        ws = wb.add_worksheet("Listing")
        if classic:
            classic_formulas_as_they_are(ws)
        ws.write_string(0, 0, self.title, bold)
        ws.write_row(1, 0, self.heads, bold)
        n = len(self.x)
        for i, x in enumerate(self.x):
            ws.write_number(2 + i, 0, x)
        for j, (pieces, values) in enumerate(zip(self.formulas, self.values), start=1):
            for i in range(n):
                ws.write_formula(2 + i, j, str(3 + i).join(pieces), num, values[i])
        chart = wb.add_chart({"type": "scatter", "subtype": "straight"})
        chart.add_series(
            {
                "name": "x, mm",
                "categories": ["Listing", 2, 0, n + 1, 0],
                "values": ["Listing", 2, 1, n + 1, 1],
            }
        )
        wb.add_worksheet("Charts").insert_chart(0, 0, chart)
        wb.close()


def run(n: int = 100_000, reps: int = 5) -> list[Result]:
    import workbook

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        (tmp / "write-bench.toml").write_text(template_text(n), encoding="utf-8")
        sheet = workbook.load(tmp / "write-bench.toml")
        raw = Raw(sheet)
        assert len(raw.x) == n and len(raw.formulas) == 4
        engine_path, raw_path = tmp / "engine.xlsx", tmp / "raw.xlsx"

        def engine():
            # a fresh Sheet each time: nothing evaluated is reused between repetitions
            workbook.load(tmp / "write-bench.toml").write_xlsx(engine_path, force=True)

        te, tr = alternate(engine, lambda: raw.write(raw_path), reps=reps)
        sizes = engine_path.stat().st_size, raw_path.stat().st_size
        te2, tc = alternate(engine, lambda: raw.write(raw_path, classic=True), reps=reps)
    return [
        Result(
            f"write {n:,} rows x 4 formula columns + 1 chart: engine / raw xlsxwriter",
            median(te) / median(tr),
            TARGET,
            detail=f"engine {ms(median(te))}, xlsxwriter {ms(median(tr))}, medians of {reps}; "
            f"files {sizes[0] / 2**20:.1f} / {sizes[1] / 2**20:.1f} MiB",
        ),
        Result(
            "  (information) the same against raw xlsxwriter that also skips its formula rewriting",
            median(te2) / median(tc),
            TARGET,
            detail=f"engine {ms(median(te2))}, xlsxwriter {ms(median(tc))}, medians of {reps}",
            info=True,
        ),
    ]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rows", type=int, default=100_000)
    ap.add_argument("--reps", type=int, default=5)
    args = ap.parse_args(argv)
    results = run(args.rows, args.reps)
    return report(results)


if __name__ == "__main__":
    sys.exit(main())
