"""Checks declared in the template (``[[checks]]``, read by :mod:`workbook.language.checkspec`)
typed at load and computed: everything in a check is typed when the sheet loads (the value's
unit against ``unit``, ``ok`` a condition, every ``{EXPR}`` or ``{EXPR:UNIT}`` in ``what`` and
``note``, the ``inputs`` it is evaluated at), so a mistake is an error at load that names the
check, never a finding that silently says something else."""

from __future__ import annotations

import math
import re

import numpy as np
import pint

from ..errors import InputError, TemplateError, WorkbookError
from ..findings import Finding
from ..language import cellunit
from ..language import typed as ty
from ..language import units as un
from ..language.checkspec import PERCENT, PLACEHOLDER, CheckSpec, placeholders
from ..language.fields import nearest


# -- load time --------------------------------------------------------------------------------
def type_checks(sheet) -> None:
    """Type every check of the sheet (all parts), so that a mistake is an error at load."""
    for spec in sheet.full_spec.checks:
        try:
            if not isinstance(spec.example_only, bool):
                for name in spec.example_only:
                    if name not in sheet.spec.inputs:
                        known = sheet.spec.inputs
                        raise InputError(
                            f"example_only: '{name}' is not an input{nearest(name, known)}"
                        )
            for name, text in spec.inputs.items():
                try:
                    sheet.with_inputs(**{name: text})
                except WorkbookError as err:  # said at the check, not at the input's line
                    raise type(err)(f"inputs: {err.message}") from None
            _typed_value(sheet, spec)
            _typed_condition(sheet, spec)
            for piece in (spec.what, spec.note):
                for expression, unit in placeholders(piece):
                    _typed_placeholder(sheet, spec, expression, unit)
        except WorkbookError as err:
            raise err.located(file=sheet.file, line=spec.line, definition=spec.label) from None


def _typed_value(sheet, spec: CheckSpec):
    """The typed value and the factor that shows it in its unit (typed at load, then read)."""
    found = sheet.typed.get(spec, "value")
    return (
        found if found is not None else sheet.typed.keep(spec, "value", _value_typed(sheet, spec))
    )


def _value_typed(sheet, spec: CheckSpec):
    if spec.value is None:
        return None, None
    t = sheet.typer.expression(spec.value, {}, spec.label)
    if getattr(t, "text", False) or getattr(t, "boolean", False) or t.shape:
        raise TemplateError("value must be one number")
    shown = un.unit(spec.unit, what=spec.label) if spec.unit is not None else t.unit
    return t, _factor(t, shown, spec.unit)


def _typed_condition(sheet, spec: CheckSpec):
    """The typed condition ``ok`` (typed at load, then read)."""
    found = sheet.typed.get(spec, "ok")
    return (
        found if found is not None else sheet.typed.keep(spec, "ok", _condition_typed(sheet, spec))
    )


def _condition_typed(sheet, spec: CheckSpec):
    if spec.ok is None:
        return None
    t = sheet.typer.expression(spec.ok, {}, spec.label)
    if not getattr(t, "boolean", False) or t.shape:
        raise TemplateError("ok must be a condition (a comparison like 'sigma <= f_y')")
    return t


def _typed_placeholder(sheet, spec: CheckSpec, expression: str, unit: str | None):
    """A placeholder's typed tree, factor and unit shown (typed at load, then read)."""
    key = ("placeholder", expression, unit)
    found = sheet.typed.get(spec, key)
    if found is None:
        found = sheet.typed.keep(spec, key, _placeholder_typed(sheet, spec, expression, unit))
    return found


def _placeholder_typed(sheet, spec: CheckSpec, expression: str, unit: str | None):
    t = sheet.typer.expression(spec.parsed[expression], {}, spec.label)
    if getattr(t, "boolean", False) or t.shape:
        raise TemplateError(f"{{{expression}}} must be one number or a text")
    if getattr(t, "text", False) or getattr(t, "kind", None) == "choice":  # a choice is text
        if unit is not None:
            raise TemplateError(f"{{{expression}}} is a text, it has no unit")
        return t, None, None
    if unit == PERCENT:
        return t, 100 * _factor(t, un.registry().dimensionless, ""), "%"
    shown = un.unit(unit, what=spec.label) if unit is not None else _shown_unit(t)
    return t, _factor(t, shown, unit), shown


def _shown_unit(t):
    return cellunit.stored_unit(t)


def _factor(t, dst, dst_text: str | None) -> float:
    """The factor that shows ``t`` in ``dst`` (a bare number shown in degrees is in degrees,
    as the typer reads it)."""
    if ty.is_bare(t) and un.is_angle(dst):
        return 1.0
    src = t.unit
    try:
        return un.factor(src, dst)
    except (pint.errors.PintError, WorkbookError):  # other dimensions, or an offset (degC)
        raise TemplateError(
            f"cannot show {un.dims(src)} ({un.pretty(src)}) in {dst_text!r}"
        ) from None


# -- evaluation -------------------------------------------------------------------------------
def check_findings(sheet) -> list[Finding]:
    """The findings of the sheet's ``[[checks]]`` (those of its chosen parts)."""
    out = []
    for spec in sheet.spec.checks:
        if spec.example_only and not sheet.at_template_inputs(_example_inputs(sheet, spec)):
            continue
        out.append(_finding(sheet, spec))
    return out


def _example_inputs(sheet, spec: CheckSpec) -> list[str]:
    if spec.example_only is True:
        return [n for n in sheet.spec.inputs if n not in spec.inputs]
    return list(spec.example_only)


def _finding(sheet, spec: CheckSpec) -> Finding:
    # a value that is not finite is an error with its reason (the evaluator says which
    # formula left its domain), so numpy's own warnings would only repeat it
    with np.errstate(all="ignore"):
        return _computed(sheet, spec)


def _computed(sheet, spec: CheckSpec) -> Finding:
    try:
        at = sheet.with_inputs(**spec.inputs) if spec.inputs else sheet
        what = _fill(at, spec, spec.what)
        note = _fill(at, spec, spec.note)
    except WorkbookError as err:
        return Finding(spec.topic, spec.what, None, "", spec.otherwise, err.message)
    try:
        value = None
        t, f = _typed_value(at, spec)
        if t is not None:
            value = _number(at, t) * f
        verdict = "info"
        condition = _typed_condition(at, spec)
        if condition is not None:
            verdict = "ok" if bool(at.evaluator.compile(condition)({})) else spec.otherwise
    except WorkbookError as err:
        return Finding(spec.topic, what, None, "", spec.otherwise, err.message)
    unit = spec.unit if spec.unit is not None else (un.pretty(t.unit) if t is not None else "")
    return Finding(spec.topic, what, value, unit, verdict, note)


def _number(sheet, t) -> float:
    value = np.asarray(sheet.evaluator.compile(t)({}), dtype=float)
    if value.ndim:
        raise InputError("the value is not one number")
    value = float(value)
    if not math.isfinite(value):
        raise InputError(f"the value is not a finite number ({value})")
    return value


def _fill(sheet, spec: CheckSpec, text: str) -> str:
    def one(m: re.Match) -> str:
        if m.group(1) is None:
            return m.group(0)[0]
        expression, unit = placeholders(m.group(0))[0]
        t, f, shown = _typed_placeholder(sheet, spec, expression, unit)
        if shown is None:
            return str(sheet.evaluator.compile(t)({}))
        number = f"{_number(sheet, t) * f:.6g}"
        if isinstance(shown, str):  # "%"
            return number + " %"
        label = un.pretty(shown)
        return f"{number} {label}" if label else number

    return PLACEHOLDER.sub(one, text)
