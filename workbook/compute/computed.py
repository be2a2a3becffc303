"""The computed sheet: every value, table, chart series and check a renderer shows, computed
once after the sheet is loaded and checked.

:func:`compute` is the one stage between evaluation and writing. It evaluates the scalar
definitions (each with its typed tree in the unit it is shown in), the [[solve]] unknowns,
the tables (range tables as :class:`workbook.engine.tabledata.TableData`, block and family
tables as DataFrames), the data of every chart series (and the x column of each over a range), the
check report (printed values, findings, estimate warnings) and, when asked, the workbook's
Excel form (:class:`workbook.compute.excelsheets.ExcelForm`: every cell with its formula or value,
helper cells, live-form notes, charts and defined names, checked by
:mod:`workbook.compute.livecheck`). The renderers (:mod:`workbook.outputs.xlsx`,
:mod:`workbook.outputs.report`,
:mod:`workbook.outputs.notebook`, the CSV writer) read a :class:`ComputedSheet`: they neither type
nor evaluate, and the Sheet is not changed by them.

This module imports no Sheet (it reads the one it is given), and the Excel form reads what it
needs of the charts from the ComputedSheet: the package's import graph has no cycle
(tests/project/test_layers.py).

A value that cannot be computed is kept as its error: the report and the notebook show it,
the workbook raises it where it would have been written.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..engine.tabledata import Column, TableData
from ..errors import InputError
from ..language import expr as ex
from ..language import units as un
from .checks import sheet_report

if TYPE_CHECKING:
    import pandas as pd
    import pint

    from ..engine.sheet import Sheet
    from ..language.spec import ChartSpec, ColumnSpec, SeriesSpec, SheetSpec
    from ..language.typed import T
    from .checks import Report
    from .excelsheets import ExcelForm


@dataclass(frozen=True)
class Scalar:
    """A scalar definition: its typed tree in the unit it is shown in, and its value (a
    quantity, a text, or an array quantity), or the error that stops it."""

    name: str
    typed: T | None
    value: Any = None
    error: BaseException | None = None


@dataclass(frozen=True)
class Unknown:
    """An unknown of a [[solve]] block without parameters: its value and the block's
    solution (error estimates, condition number), or the error."""

    name: str
    value: pint.Quantity | None
    solution: Any = None
    error: BaseException | None = None


@dataclass(frozen=True)
class Series:
    """The data of one chart series: x and y as the engine computes them, and, for a
    series over a range, the table of its columns (the range variable first)."""

    x: np.ndarray
    y: np.ndarray
    data: TableData | None = None


@dataclass
class ComputedSheet:
    """What every renderer reads: a Sheet's values, computed once (see :func:`compute`)."""

    name: str
    file: str
    spec: SheetSpec
    full_spec: SheetSpec
    parts: Any
    values: dict[str, Any]  # the inputs
    left_out: list[str]
    scalars: dict[str, Scalar] = field(default_factory=dict)
    function_units: dict[str, pint.Unit | None] = field(default_factory=dict)
    unknowns: dict[str, Unknown] = field(default_factory=dict)
    # range tables as TableData, block and family tables as DataFrames, or the error
    tables: dict[str, Any] = field(default_factory=dict)
    series: dict[tuple[str, int], Series | BaseException] = field(default_factory=dict)
    # the x column of each series over a range (None: x is the range variable itself)
    x_columns: dict[tuple[str, int], ColumnSpec | None] = field(default_factory=dict)
    report: Report | BaseException | None = None
    excel: ExcelForm | None = None

    def table(self, name: str):
        """Table ``name`` (TableData of a range table, else a DataFrame); its error is raised."""
        item = self.tables[name]
        if isinstance(item, BaseException):
            raise item
        return item

    def check_report(self) -> Report | None:
        """The check report (None when it was not asked for); its error is raised."""
        if isinstance(self.report, BaseException):
            raise self.report
        return self.report

    def frame(self, name: str) -> pd.DataFrame:
        """Table ``name`` as a pandas DataFrame, the unit in every column header (as
        ``Sheet.table``)."""
        import pandas as pd

        data = self.table(name)
        if isinstance(data, TableData):
            return pd.DataFrame({un.header(c.title, c.unit): c.values for c in data.columns})
        return data


def compute(
    sheet: Sheet,
    *,
    report: Report | None = None,
    check: bool | None = None,
    excel: bool = False,
    command: str | None = None,
    verify: bool = True,
) -> ComputedSheet:
    """Compute what the renderers of ``sheet`` show, once.

    ``check``: run the check report (default: when the sheet has printed values, findings or
    relations; always with ``excel``); a given ``report`` is used as it is. With ``excel`` the
    check runs first (as ``workbook run``, whose Checks sheet lists the findings made before
    writing), otherwise after the values (as the report has it: the estimate warnings of what
    was computed). ``excel`` also lays out the workbook (``command`` is the About sheet's
    regenerate command, ``verify`` runs the live-cell check)."""
    spec = sheet.spec
    out = ComputedSheet(
        name=sheet.name,
        file=sheet.file,
        spec=spec,
        full_spec=sheet.full_spec,
        parts=sheet.parts,
        values=dict(sheet.values),
        left_out=sheet.left_out,
    )
    if check is None or excel:
        check = excel or bool(spec.printed or spec.findings or spec.relations)
    with np.errstate(all="ignore"):  # a value outside its domain is an error or a failed row
        _compute(sheet, out, report, check, excel)
    if excel:
        from .excelform import lay_out

        out.excel = lay_out(out, sheet, command=command, verify=verify)
    return out


def _compute(sheet: Sheet, out: ComputedSheet, report, check: bool, excel: bool) -> None:
    spec = sheet.spec
    out.report = report
    if report is None and check and excel:
        out.report = sheet_report(sheet)
    for name, d in spec.definitions.items():
        if d.is_function:
            if not excel:  # the report's and the notebook's (the workbook shows none)
                out.function_units[name] = _function_unit(sheet, name, d)
        else:
            out.scalars[name] = _scalar(sheet, name)
    for block in spec.solves:
        if not block.parameters:
            for name in block.unknowns:
                out.unknowns[name] = _unknown(sheet, block, name)
    for t in spec.tables:
        out.tables[t.name] = _table(sheet, t)
    for chart in spec.charts:
        for i, s in enumerate(chart.series):
            if s.table is None:
                out.x_columns[(chart.name, i)] = x_column(chart, s, s.range or chart.range)
            out.series[(chart.name, i)] = _series(sheet, out.tables, chart, s)
    if out.report is None and check:
        try:
            out.report = sheet_report(sheet)
        except Exception as err:  # noqa: BLE001 - shown in the report's Checks section
            out.report = err


def _function_unit(sheet: Sheet, name: str, d) -> pint.Unit | None:
    """A function's unit (declared, else typed), None when it has none to show."""
    if d.unit is not None:
        return d.unit
    try:
        return sheet.defs.function(name).unit
    except Exception:  # noqa: BLE001 - a function typed only by its calls: no unit shown
        return None


def _scalar(sheet: Sheet, name: str) -> Scalar:
    try:
        typed = sheet.scalar_typed(name)
    except Exception as err:  # noqa: BLE001 - kept; the workbook raises it, the report shows it
        return Scalar(name, None, error=err)
    try:
        with sheet.evaluator.sharing():
            value = sheet.scalar_quantity(name)
    except Exception as err:  # noqa: BLE001 - as above (a solver block failing its own way)
        return Scalar(name, typed, error=err)
    return Scalar(name, typed, value)


def _unknown(sheet: Sheet, block, name: str) -> Unknown:
    try:
        value = sheet.evaluate(name)
        return Unknown(name, value, sheet.solution(block))
    except Exception as err:  # noqa: BLE001 - kept; the workbook and the report show it
        return Unknown(name, None, error=err)


def _table(sheet: Sheet, t):
    try:
        return sheet.computed_table(t.name) if t.computed else sheet.table_data(t)
    except Exception as err:  # noqa: BLE001 - kept; the workbook raises it, the report shows it
        return err


def x_column(chart: ChartSpec, s: SeriesSpec, rng):
    """The series' x column, or None when x is the range variable itself."""
    x = s.x or chart.x
    if x is None or (isinstance(x.node, ex.Name) and x.node.id == rng.var and x.unit is None):
        return None
    return x


def _series(sheet: Sheet, tables: dict, chart: ChartSpec, s: SeriesSpec) -> Series | Exception:
    try:
        if s.table is not None:
            df = tables.get(s.table)
            if df is None:
                df = sheet.computed_table(s.table)
            if isinstance(df, BaseException):
                raise df
            x = np.asarray(df[s.x_column], dtype=float)
            return Series(x, np.asarray(df[s.y_column], dtype=float))
        data = _series_table(sheet, tables, chart, s)
        x = data.columns[1].values if len(data.columns) == 3 else data.columns[0].values
        if any(c.typed is not None and c.typed.complex for c in data.columns):
            raise InputError(
                f"chart {chart.name}: a series of complex values has no points; plot abs(z), "
                "arg(z), Re(z) or Im(z)"
            )
        return Series(x, data.columns[-1].values, data)
    except Exception as err:  # noqa: BLE001 - kept; the workbook raises it, the report shows it
        return err


def _series_table(sheet: Sheet, tables: dict, chart: ChartSpec, s: SeriesSpec) -> TableData:
    """The range variable, x (unless it is the variable) and y of a series over a range: the
    columns of a range table over the same range when one has them (same text and unit),
    else computed."""
    rng = s.range or chart.range
    what = f"chart {chart.name}"
    x = x_column(chart, s, rng)
    wanted = [s.y] if x is None else [x, s.y]
    units = [str(sheet.typed_column(c, rng.var, what).unit) for c in wanted]
    for t in sheet.spec.tables:
        data = tables.get(t.name)
        if not isinstance(data, TableData) or t.range is None or t.range.text != rng.text:
            continue
        found = [
            next((col for col in data.columns[1:] if (col.text, str(col.unit)) == key), None)
            for key in zip((c.text for c in wanted), units)
        ]
        if all(found):
            return TableData(
                data.name, data.title, data.var, data.var_unit, [data.columns[0]] + found
            )
    xs = sheet.range_values(rng, what)
    arg = sheet.spec.arguments.get(rng.var)
    var_unit = arg.unit if arg else un.registry().dimensionless
    with sheet.evaluator.sharing():
        cols = [sheet.column(c, rng.var, xs, what) for c in wanted]
    return TableData(
        f"{chart.name}",
        f"Data of {chart.title}: {s.name}",
        rng.var,
        var_unit,
        [Column(rng.var, var_unit, xs, None, rng.var), *cols],
    )


def is_error(item) -> bool:
    """Is a computed item an error kept in place of its value?"""
    return isinstance(item, BaseException)
