"""Checks declared in the template (``[[checks]]``, read and typed at load by
:mod:`workbook.language.checkspec`) computed: each is a finding of the check report."""

from __future__ import annotations

import math
import re

import numpy as np

from ..errors import InputError, WorkbookError
from ..findings import Finding
from ..language import units as un
from ..language.checkspec import (
    PLACEHOLDER,
    CheckSpec,
    placeholders,
    typed_condition,
    typed_placeholder,
    typed_value,
)


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
        t, f = typed_value(at, spec)
        if t is not None:
            value = _number(at, t) * f
        verdict = "info"
        condition = typed_condition(at, spec)
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
        t, f, shown = typed_placeholder(sheet, spec, expression, unit)
        if shown is None:
            return str(sheet.evaluator.compile(t)({}))
        number = f"{_number(sheet, t) * f:.6g}"
        if isinstance(shown, str):  # "%"
            return number + " %"
        label = un.pretty(shown)
        return f"{number} {label}" if label else number

    return PLACEHOLDER.sub(one, text)
