"""Read the inputs back from the Inputs sheet of a generated (and edited) workbook.

The Inputs sheet (written by :mod:`workbook.outputs.xlsx`) holds Name, Value, Unit, Note from row 2.
A user edits values (and may change a unit: ``45`` ``mm`` -> ``4.5`` ``cm``) in Excel or
LibreOffice; :func:`read_inputs` reads them with openpyxl and checks them exactly as
``--set`` does (unknown names, units, bounds, choices).
"""

from __future__ import annotations

import math
from pathlib import Path

from .errors import InputError, LimitError, WorkbookError

MAX_INPUT_ROWS = 10_000


def read_inputs(sheet, path) -> dict:
    """Inputs of ``path`` as ``{name: checked value}`` (quantities in the input's unit)."""
    from .engine.sheet import coerce_input

    rows = _rows(Path(path))
    values = {}
    for row, name, value, unit in rows:
        spec = sheet.spec.inputs.get(name)
        where = f"{path}, Inputs!B{row}"
        if spec is None:
            raise InputError(
                f"{where}: '{name}' is not an input of {sheet.name} "
                f"(inputs: {', '.join(sheet.spec.inputs)})"
            )
        if name in values:
            raise InputError(f"{where}: '{name}' is listed twice")
        raw = _raw(spec, value, unit, where)
        try:
            values[name] = coerce_input(spec, raw)
        except WorkbookError as err:
            raise InputError(f"{where}: {err.message}") from None
    return values


def changed_inputs(sheet, path) -> dict[str, str]:
    """The inputs of ``path`` that differ from ``sheet``'s, as ``--set`` texts ("45.0 mm").

    Every row is checked; only the changed ones are returned, so that the regenerated
    workbook's About sheet names a command that repeats the run without the edited file.
    """
    out = {}
    for name, q in read_inputs(sheet, path).items():
        old = sheet.values[name]
        if isinstance(q, str):
            if q != old:
                out[name] = q
            continue
        if float(q.magnitude) != float(old.to(q.units).magnitude):
            spec = sheet.spec.inputs[name]
            unit = "" if spec.unit.dimensionless and not str(spec.unit) else _unit_text(q)
            out[name] = f"{float(q.magnitude)!r} {unit}".strip()
    return out


def with_inputs_from(sheet, path):
    """A new Sheet with the inputs read from the workbook at ``path``."""
    return sheet.with_inputs(**read_inputs(sheet, path))


def _unit_text(q) -> str:
    from .language import units as un

    return un.pretty(q.units) or str(q.units)


def _rows(path: Path) -> list[tuple[int, str, object, str]]:
    import openpyxl

    from .limits import check_xlsx_archive

    check_xlsx_archive(path, what="--inputs", sheet="Inputs")
    try:
        return _read_rows(openpyxl, path)
    except WorkbookError:
        raise
    except Exception as exc:  # noqa: BLE001 - zip, XML, bad indexes: the file is not readable
        raise InputError(
            f"--inputs {path}: cannot read it as an xlsx workbook ({type(exc).__name__}: {exc})"
        ) from None


def _read_rows(openpyxl, path: Path) -> list[tuple[int, str, object, str]]:
    wb = openpyxl.load_workbook(path, data_only=True, read_only=True)
    try:
        if "Inputs" not in wb.sheetnames:
            raise InputError(
                f"--inputs {path}: no sheet named 'Inputs' (sheets: {', '.join(wb.sheetnames)})"
            )
        ws = wb["Inputs"]
        head = [c for c in next(ws.iter_rows(min_row=1, max_row=1, values_only=True), ())]
        if [str(h).strip() if h is not None else "" for h in head[:3]] != ["Name", "Value", "Unit"]:
            raise InputError(
                f"--inputs {path}: the Inputs sheet must start with the columns Name, Value, Unit"
            )
        out = []
        formulas = None
        for r, cells in enumerate(ws.iter_rows(min_row=2, max_col=3, values_only=True), start=2):
            name, value, unit = (list(cells) + [None] * 3)[:3]
            if name is None or str(name).strip() == "":
                break  # the input table ends at the first empty name
            if value is None:
                formulas = formulas or _formulas(path)
                text = formulas.get(r)
                if text:
                    raise InputError(
                        f"{path}, Inputs!B{r} ({name}) holds the formula {text} without a "
                        "computed value: open the file in Excel or LibreOffice and save it"
                    )
                raise InputError(f"{path}, Inputs!B{r} ({name}) is empty")
            out.append((r, str(name).strip(), value, "" if unit is None else str(unit).strip()))
            if len(out) > MAX_INPUT_ROWS:
                raise LimitError(f"--inputs {path}: more than {MAX_INPUT_ROWS:,} input rows")
        return out
    finally:
        wb.close()


def _formulas(path: Path) -> dict[int, str]:
    import openpyxl

    wb = openpyxl.load_workbook(path, read_only=True)
    try:
        ws = wb["Inputs"]
        return {
            r: str(v)
            for r, (v,) in enumerate(
                ws.iter_rows(min_row=2, min_col=2, max_col=2, values_only=True), 2
            )
            if isinstance(v, str) and v.startswith("=")
        }
    finally:
        wb.close()


def _raw(spec, value, unit: str, where: str):
    """The cell value and unit as the text ``--set`` would get.

    A cell holds a number, or text that the quantity reader accepts ("45.5 mm"); a date, a
    time, a boolean or an error value is refused naming the cell (a date would otherwise be
    read as its year or serial number).
    """
    from .language.quantity import check_unit_text, split_quantity

    if spec.options:
        if not isinstance(value, str):
            raise InputError(f"{where}: {spec.name} is {value!r}, expected one of its choices")
        return value.strip()
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise InputError(
            f"{where}: {spec.name} holds {_cell_kind(value)} ({value!s}), expected a number"
        )
    if isinstance(value, str):
        number, typed_unit = split_quantity(value, what=f"{where} ({spec.name})")
        if typed_unit:  # a value typed with its unit into the cell ("45 mm") is read as it stands
            return value.strip()
    else:
        number = float(value)
    if not math.isfinite(number):
        raise InputError(f"{where}: {spec.name} = {value!r} is not a finite number")
    check_unit_text(unit, what=f"{where} unit of {spec.name}")
    # a plain-number input shown with a label (phi_n: 38 "deg") is the number itself
    if spec.label and unit == spec.label:
        return number
    if unit in ("", "1", "-"):
        # like --set R3=45: a number without a unit is refused for a dimensioned input
        return number if spec.unit.dimensionless else f"{number!r}"
    return f"{number!r} {unit}"


def _cell_kind(value) -> str:
    import datetime

    if isinstance(value, bool):
        return "a TRUE/FALSE value"
    if isinstance(value, (datetime.datetime, datetime.date)):
        return "a date"
    if isinstance(value, (datetime.time, datetime.timedelta)):
        return "a time"
    return f"a {type(value).__name__} value"
