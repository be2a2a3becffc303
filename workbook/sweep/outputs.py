"""Sweep outputs: ``NAME = EXPR`` or ``NAME = REDUCTION of EXPR over RANGE``."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np
import pint

from ..errors import InputError, TemplateError, WorkbookError
from ..language import expr as ex
from ..language import typed as ty
from ..language import units as un

REDUCTIONS = ("max", "min", "mean", "argmax", "argmin")
_REDUCE = re.compile(r"^\s*(max|min|mean|argmax|argmin)\s+of\s+(.+?)\s+over\s+(.+?)\s*$", re.S)


@dataclass
class Output:
    """One sweep output: ``name = EXPR`` or ``name = REDUCTION of EXPR over RANGE``."""

    name: str
    text: str
    node: ex.Node
    reduction: str | None = None
    range: object | None = None  # ranges.RangeSpec
    unit_text: str | None = None

    @classmethod
    def parse(cls, name: str, text: str, unit: str | None = None) -> Output:
        """Read ``text`` as an expression or a reduction over a range."""
        from ..language.ranges import parse_range

        if not ex.is_identifier(name):
            raise InputError(f"sweep output name {name!r} is not a valid name (letters, digits, _)")
        what = f"sweep output {name}"
        m = _REDUCE.match(text)
        if m:
            reduction, body, rng = m.groups()
            return cls(
                name,
                text,
                ex.parse(body, what=what),
                reduction,
                parse_range(rng, what=what, log=True),
                unit,
            )
        if re.match(r"^\s*(max|min|mean|argmax|argmin)\s+of\b", text):
            raise InputError(
                f"{what}: write a reduction as 'max of EXPR over VAR := FIRST, SECOND .. LAST'"
            )
        return cls(name, text, ex.parse(text, what=what), None, None, unit)


def parse_output_option(item: str) -> Output:
    """``--output NAME=EXPR`` or ``--output NAME[unit]=EXPR``."""
    head, sep, text = item.partition("=")
    if not sep or not head.strip() or not text.strip():
        raise InputError(
            f"--output {item!r}: write NAME=EXPR, e.g. "
            '--output "v_peak=max of v(phi) over phi := 0 .. 104"'
        )
    m = re.match(r"^\s*([A-Za-z_]\w*)\s*(?:\[(.*)\])?\s*$", head)
    if not m:
        raise InputError(f"--output {item!r}: cannot read the name {head!r}")
    return Output.parse(m.group(1), text.strip(), m.group(2))


def template_outputs(spec) -> dict[str, Output]:
    """Outputs declared in the template's ``[sweep]`` section (empty if none)."""
    try:
        import tomllib
    except ImportError:  # Python 3.10
        import tomli as tomllib

    data = tomllib.loads(spec.text).get("sweep", {})
    if not isinstance(data, dict):
        raise TemplateError("[sweep] must be a table", file=str(spec.path))
    outs = data.get("outputs", {})
    units = data.get("units", {})
    if not isinstance(outs, dict) or not isinstance(units, dict):
        raise TemplateError(
            '[sweep] outputs = { v_peak = "max of v(phi) over phi := 0 .. 104" }',
            file=str(spec.path),
        )
    result = {}
    for name, raw in outs.items():
        unit = units.get(name)
        if isinstance(raw, dict):
            unit = raw.get("unit", unit)
            raw = raw.get("expr", "")
        try:
            result[name] = Output.parse(name, str(raw), None if unit is None else str(unit))
        except WorkbookError as err:
            raise err.located(file=str(spec.path), definition=f"[sweep] {name}") from None
    return result


@dataclass
class TypedOutput:
    """An output typed against the sheet, with the unit and factor it is shown in."""

    out: Output
    t: ty.T
    unit: object  # pint.Unit shown
    factor: float  # typed magnitude -> shown unit
    var_unit: object | None = None


def type_output(sheet, out: Output) -> TypedOutput:
    """Type ``out`` against ``sheet`` (a mistake is one error for the whole sweep)."""
    what = f"sweep output {out.name}"
    scope = {}
    if out.range is not None:
        spec = sheet.spec.arguments.get(out.range.var)
        if spec is None:
            raise TemplateError(
                f"{what}: the range variable '{out.range.var}' is not declared in [arguments]"
            )
        scope = {out.range.var: spec.binding_unit}
    t = sheet.typer.expression(out.node, scope, what)
    if isinstance(t, ty.TText) or getattr(t, "text", False) or getattr(t, "boolean", False):
        # a text (a design check's "OK") failed every case with a raw ValueError, exit 0
        raise TemplateError(f"{what}: the output must be a number, not a text or a condition")
    if t.complex:  # a column of the sweep's table holds real numbers
        raise TemplateError(f"{what}: the output is complex; sweep abs(z), arg(z), Re(z) or Im(z)")
    if out.reduction in ("argmax", "argmin"):
        shown = sheet.spec.arguments[out.range.var].unit
        return TypedOutput(out, t, shown, 1.0, shown)
    shown = un.unit(out.unit_text, what=what) if out.unit_text is not None else t.unit
    if "absolute" in (un.temperature_kind(t.unit), un.temperature_kind(shown)):
        # degC, degF: not a factor; the typer's conversion adds the offset (or refuses)
        return TypedOutput(out, sheet.typer.convert(t, shown, what), shown, 1.0)
    try:
        f = un.factor(t.unit, shown)
    except (pint.errors.PintError, WorkbookError):  # other dimensions, or an offset (degC)
        raise InputError(
            f"{what}: cannot show {un.dims(t.unit)} ({un.pretty(t.unit)}) in {out.unit_text!r}"
        ) from None
    return TypedOutput(out, t, shown, f)


def reduce_values(kind: str, values: np.ndarray, grid: np.ndarray, axis: int = -1):
    """max, min, mean of ``values`` along ``axis``, or the ``grid`` value at argmax/argmin."""
    if kind == "max":
        return values.max(axis=axis)
    if kind == "min":
        return values.min(axis=axis)
    if kind == "mean":
        return values.mean(axis=axis)
    idx = values.argmax(axis=axis) if kind == "argmax" else values.argmin(axis=axis)
    return grid[idx]


def evaluate_outputs(sheet, outputs: list[Output]) -> dict[str, float]:
    """The outputs of one sheet (one case), each a float in its shown unit."""
    result = {}
    with sheet.evaluator.sharing():  # subtrees shared by the outputs computed once
        for out in outputs:
            result[out.name] = _output_value(sheet, out)
    return result


def _output_value(sheet, out: Output) -> float:
    """One output of one case, a float in its shown unit."""
    typed = type_output(sheet, out)
    fn = sheet.evaluator.compile(typed.t)
    if out.range is None:
        value = np.asarray(fn({}), dtype=float)
        if value.ndim:
            raise InputError(f"sweep output {out.name} is not one number")
        value = float(value)
    else:
        grid = sheet.range_values(out.range, f"sweep output {out.name}")
        vals = np.broadcast_to(np.asarray(fn({out.range.var: grid}), dtype=float), grid.shape)
        bad = ~np.isfinite(vals)
        if bad.any():
            raise InputError(
                f"sweep output {out.name}: not a finite number at "
                f"{out.range.var} = {grid[bad][0]:g}"
            )
        value = float(reduce_values(out.reduction, vals, grid))
    value *= typed.factor
    if not math.isfinite(value):
        raise InputError(f"sweep output {out.name} is not a finite number ({value})")
    return value


def as_outputs(sheet, outputs) -> list[Output]:
    """The outputs from a list, a dict ``{name: text or None}`` or the template's ``[sweep]``."""
    if outputs is None:
        found = list(template_outputs(sheet.spec).values())
        if not found:
            raise InputError(
                f"{sheet.name} declares no sweep outputs: add [sweep] outputs = {{ ... }} "
                "to the template or give --output NAME=EXPR"
            )
        return found
    if isinstance(outputs, dict):
        declared = template_outputs(sheet.spec)
        out = []
        for name, text in outputs.items():
            if text is None and name in declared:
                out.append(declared[name])
            else:
                out.append(Output.parse(name, str(text)))
        return out
    return list(outputs)
