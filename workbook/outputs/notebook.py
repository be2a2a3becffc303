"""A Sheet in Jupyter: the report's rendering, and its parts as DataFrames.

Jupyter calls the Sheet's ``_repr_html_``, which is :func:`sheet_html`: what ``workbook
report`` writes (:mod:`workbook.outputs.report`). Tables are pandas DataFrames with the unit in
every header (``sheet.table(name)``, :func:`tables`). A value that fails is shown with its error
instead of breaking the display. Each function reads a computed sheet
(:class:`workbook.compute.computed.ComputedSheet`, ``sheet.computed()``): none computes."""

from __future__ import annotations

import html
from typing import TYPE_CHECKING

from ..errors import WorkbookError
from ..language import units as un

if TYPE_CHECKING:
    from ..compute.computed import ComputedSheet


def inputs_frame(sheet: ComputedSheet):
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


def definitions_frame(sheet: ComputedSheet):
    """Scalar definitions with their values (or the error that stops them)."""
    import pandas as pd

    rows = []
    for name, d in sheet.spec.definitions.items():
        if d.is_function:
            continue
        try:
            scalar = sheet.scalars[name]
            if scalar.error is not None:
                raise scalar.error
            q = scalar.value
            q = q.to(d.unit or q.units)
            value, shown = float(q.magnitude), un.pretty(q.units)
        except WorkbookError as err:
            value, shown = f"error: {err.message}", ""
        except Exception as err:  # noqa: BLE001 - a solver block failing in its own way
            value, shown = f"error: {type(err).__name__}: {err}", ""
        rows.append((name, value, shown, d.text, d.note))
    return pd.DataFrame(rows, columns=["name", "value", "unit", "formula", "note"])


def functions_frame(sheet: ComputedSheet):
    """Functions: signature, unit, formula, note."""
    import pandas as pd

    rows = []
    for name, d in sheet.spec.definitions.items():
        if not d.is_function:
            continue
        unit = sheet.function_units.get(name)
        unit = "" if unit is None else un.pretty(unit)
        rows.append((f"{name}({', '.join(d.params)})", unit, d.text, d.note))
    return pd.DataFrame(rows, columns=["function", "unit", "formula", "note"])


def tables(sheet: ComputedSheet) -> dict:
    """Every range table as a DataFrame (unit in every header); block tables are skipped."""
    return {t.name: sheet.frame(t.name) for t in sheet.spec.tables if not t.block}


def _choice_note(spec) -> str:
    opts = "one of: " + ", ".join(spec.options)
    return f"{spec.note} ({opts})" if spec.note else opts


def sheet_html(sheet: ComputedSheet) -> str:
    """HTML of a computed sheet for Jupyter: the same rendering as ``workbook report``
    (formulas as MathML, the values put in, tables, charts, checks), as a fragment with its
    own style."""
    from .report import fragment

    try:
        return fragment(sheet)
    except WorkbookError as err:
        return error_html(sheet.name, err)


def error_html(name: str, err: WorkbookError) -> str:
    """A worksheet's error as Jupyter shows it in place of the sheet (a bug raises: IPython
    shows it)."""
    return f"<p>{html.escape(name)}: error: {html.escape(str(err))}</p>"
