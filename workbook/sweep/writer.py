"""Writing a sweep: a CSV table, or an xlsx workbook (table, charts, About)."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np

from ..compute import style
from ..errors import InputError
from .driver import SweepResult


def write(result: SweepResult, path: Path, *, force: bool = False, command: str = "") -> Path:
    """Write the sweep: ``.csv`` (the table) or ``.xlsx`` (table, chart, about), atomically."""
    from ..outputs.atomic import check_target, replacing, write_csv

    path = Path(path)
    kind = "csv" if path.suffix.lower() == ".csv" else "xlsx"
    if kind == "xlsx" and path.suffix.lower() != ".xlsx":
        raise InputError(f"sweep output {path}: write a .xlsx or a .csv file")
    check_target(path, kind=kind, force=force)
    with replacing(path) as tmp:
        if kind == "csv":
            write_csv(result.table, tmp)
        else:
            _write_xlsx(result, tmp, command)
    return path


def _write_xlsx(result: SweepResult, path: Path, command: str) -> None:
    import xlsxwriter

    from ..compute.excelsheets import chart_label, write_labels
    from ..version import __version__

    df = result.table
    wb = xlsxwriter.Workbook(
        str(path),
        {"nan_inf_to_errors": True, "strings_to_formulas": False, "strings_to_urls": False},
    )
    fmt = style.add_formats(wb)
    head, num, bad = fmt["header"], fmt["number"], fmt["fail"]
    ws = wb.add_worksheet("Sweep")
    write_labels(ws, 0, 0, [str(c) for c in df.columns], head)
    for i, row in enumerate(df.itertuples(index=False), start=1):
        for j, v in enumerate(row):
            if v is None or (isinstance(v, float) and math.isnan(v)):
                continue
            if isinstance(v, (int, float, np.floating, np.integer)):
                ws.write_number(i, j, float(v), num)
            else:
                ws.write_string(i, j, str(v), bad if df.columns[j] == "error" else None)
    ws.set_column(0, len(df.columns) - 2, 14)
    ws.set_column(len(df.columns) - 1, len(df.columns) - 1, 60)
    ws.freeze_panes(1, 0)
    n = len(df)
    nv = len(result.varies)
    charts = wb.add_worksheet("Charts")
    # x is the last swept input (it varies fastest, so each series is a block of rows);
    # one series per combination of the other swept inputs
    x = result.varies[-1]
    xcol = nv - 1
    row = 0
    label_row = 0

    def literal(text: str):
        nonlocal label_row
        label, label_row = chart_label(charts, "Charts", text, label_row, head)
        return label

    if x.unit or all(isinstance(v, (int, float)) for v in x.values):
        groups = _series_groups(result)
        for k, out in enumerate(result.outputs):
            col = nv + k
            c = style.scatter_chart(wb, markers=True)
            for label, first, last in groups:
                c.add_series(
                    {
                        "name": literal(label or out.name),
                        "categories": ["Sweep", first, xcol, last, xcol],
                        "values": ["Sweep", first, col, last, col],
                        "marker": style.MARKER,
                    }
                )
            unit = result.output_units[out.name]
            c.set_title({"name": literal(f"{out.name} over {x.name} ({result.sheet_name})")})
            c.set_x_axis(style.axis(literal(str(df.columns[xcol]))))
            c.set_y_axis(style.axis(literal(f"{out.name}, {unit}" if unit else out.name)))
            row = style.place_chart(charts, row, c, legend=len(groups) > 1)
    about = wb.add_worksheet("About")
    about.set_column(0, 0, 20)
    about.set_column(1, 1, 100)
    rows = [
        ("Worksheet", result.sheet_name),
        ("Swept", ", ".join(f"{v.name} ({len(v.values)} values)" for v in result.varies)),
        ("Outputs", "; ".join(f"{o.name} = {o.text}" for o in result.outputs)),
        ("Cases", f"{n} ({result.failed} failed)"),
        ("Ran as", f"{result.mode}, {result.seconds:.2f} s"),
        ("Engine", f"workbook {__version__}"),
        ("Regenerate with", command),
        ("Values", "numbers computed by the engine (a sweep is not live)"),
    ]
    for i, (k, v) in enumerate(rows):
        about.write_string(i, 0, k, head)
        about.write_string(i, 1, v)
    wb.close()


def _series_groups(result: SweepResult) -> list[tuple[str, int, int]]:
    """(label, first row, last row) of each series; rows are 0-based sheet rows."""
    n_last = len(result.varies[-1].values)
    rest = result.varies[:-1]
    combos = list(itertools.product(*[v.values for v in rest])) if rest else [()]
    groups = []
    for j, combo in enumerate(combos):
        label = ", ".join(
            f"{v.name} = {val:g}" if isinstance(val, float) else f"{v.name} = {val}"
            for v, val in zip(rest, combo)
        )
        groups.append((label, 1 + j * n_last, j * n_last + n_last))
    return groups
