"""A Sheet in Jupyter: inputs, definitions, functions and tables as HTML.

Jupyter calls the Sheet's ``_repr_html_``, which is :func:`sheet_html`. Tables are pandas
DataFrames with the unit in every header (``sheet.table(name)``). Displaying a sheet does not
compute block tables (ODE histories, studies: they may take long); they are listed with the
call that computes them. A value that fails is shown with its error instead of breaking the
display.
"""

from __future__ import annotations

import html

from . import units as un
from .errors import WorkbookError

MAX_ROWS = 12  # longer tables show their first and last rows


def inputs_frame(sheet):
    """Inputs as a DataFrame: name, value, unit, note."""
    import pandas as pd

    rows = []
    for name, spec in sheet.spec.inputs.items():
        v = sheet.values[name]
        if isinstance(v, str):
            rows.append((name, v, "", _choice_note(spec)))
        else:
            rows.append((name, float(v.magnitude), spec.label or un.pretty(spec.unit), spec.note))
    return pd.DataFrame(rows, columns=["name", "value", "unit", "note"])


def definitions_frame(sheet):
    """Scalar definitions with their values (or the error that stops them)."""
    import pandas as pd

    rows = []
    for name, d in sheet.spec.definitions.items():
        if d.is_function:
            continue
        try:
            q = sheet.evaluate(name)
            unit = d.unit or q.units
            q = q.to(unit)
            value, shown = float(q.magnitude), un.pretty(q.units)
        except WorkbookError as err:
            value, shown = f"error: {err.message}", ""
        except Exception as err:  # a solver block failing in its own way
            value, shown = f"error: {type(err).__name__}: {err}", ""
        rows.append((name, value, shown, d.text, d.note))
    return pd.DataFrame(rows, columns=["name", "value", "unit", "formula", "note"])


def functions_frame(sheet):
    """Functions: signature, unit, formula, note."""
    import pandas as pd

    rows = []
    for name, d in sheet.spec.definitions.items():
        if not d.is_function:
            continue
        try:
            unit = un.pretty(d.unit or sheet.typer.function(name).unit)
        except WorkbookError:
            unit = ""
        rows.append((f"{name}({', '.join(d.params)})", unit, d.text, d.note))
    return pd.DataFrame(rows, columns=["function", "unit", "formula", "note"])


def tables(sheet) -> dict:
    """Every range table as a DataFrame (unit in every header); block tables are skipped."""
    return {t.name: sheet.table(t.name) for t in sheet.spec.tables if not t.block}


def _choice_note(spec) -> str:
    opts = "one of: " + ", ".join(spec.options)
    return f"{spec.note} ({opts})" if spec.note else opts


def _frame_html(df) -> str:
    return df.to_html(
        index=False,
        max_rows=MAX_ROWS,
        float_format=lambda x: f"{x:.6g}",
        border=0,
        classes="workbook-table",
        na_rep="",
    )


def sheet_html(sheet) -> str:
    """HTML of a Sheet for Jupyter: title, source, inputs, definitions, functions, tables."""
    import numpy as np

    with np.errstate(all="ignore"):  # a value that leaves its domain is shown as an error
        return _sheet_html(sheet)


def _sheet_html(sheet) -> str:
    esc = html.escape
    parts = [f"<div class='workbook-sheet'><h3>{esc(sheet.spec.title or sheet.name)}</h3>"]
    if sheet.spec.source:
        parts.append(f"<p><i>{esc(sheet.spec.source)}</i></p>")
    if sheet.spec.description:
        parts.append(f"<p>{esc(sheet.spec.description)}</p>")
    parts.append(f"<p><code>{esc(sheet.file)}</code></p>")
    sections = [
        ("Inputs", lambda: inputs_frame(sheet)),
        ("Definitions", lambda: definitions_frame(sheet)),
        ("Functions", lambda: functions_frame(sheet)),
    ]
    for title, make in sections:
        try:
            df = make()
        except Exception as err:  # the display must not fail
            parts.append(f"<h4>{title}</h4><p>error: {esc(str(err))}</p>")
            continue
        if len(df):
            parts.append(f"<h4>{title}</h4>{_frame_html(df)}")
    for t in sheet.spec.tables:
        head = f"<h4>Table {esc(t.name)}: {esc(t.title)}</h4>"
        if t.block:
            parts.append(
                f"{head}<p>computed by the solver block <code>{esc(t.block)}</code>: "
                f"<code>sheet.table({t.name!r})</code></p>"
            )
            continue
        try:
            df = sheet.table(t.name)
        except WorkbookError as err:
            parts.append(f"{head}<p>error: {esc(err.message)}</p>")
            continue
        except Exception as err:
            parts.append(f"{head}<p>error: {esc(type(err).__name__)}: {esc(str(err))}</p>")
            continue
        parts.append(f"{head}<p>{len(df)} rows</p>{_frame_html(df)}")
    if sheet.spec.charts:
        names = ", ".join(esc(c.title) for c in sheet.spec.charts)
        parts.append(
            f"<p>Charts (in the workbook: <code>sheet.write_xlsx(path)</code>): {names}</p>"
        )
    parts.append("</div>")
    return "\n".join(parts)
