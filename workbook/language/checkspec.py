"""Checks declared in the template (``[[checks]]``): a value, a condition, a line of the
report; read and typed at load here, computed by :mod:`workbook.compute.declared_checks`.

A check is a finding written in the worksheet rather than in a solver block::

    [[checks]]
    topic = "stress"
    what = "bending stress at {F:kN} ({sigma/f_y:%} of the yield stress)"
    value = "sigma"
    unit = "MPa"
    ok = "sigma <= f_y"
    otherwise = "fail"

Everything in it is typed when the sheet loads (the value's unit against ``unit``, ``ok`` a
condition, every ``{EXPR}`` or ``{EXPR:UNIT}`` in ``what`` and ``note``, the ``inputs`` it is
evaluated at), so a mistake is an error at load that names the check, never a finding that
silently says something else.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import pint

from ..errors import InputError, TemplateError, WorkbookError
from ..verdicts import FINDING_VERDICTS
from . import cellunit
from . import expr as ex
from . import typed as ty
from . import units as un
from .fields import Fields, nearest

CHECK_KEYS = (
    "topic",
    "what",
    "value",
    "unit",
    "ok",
    "otherwise",
    "note",
    "inputs",
    "example_only",
    "part",
)
# {EXPR} or {EXPR:UNIT}; {{ and }} are literal braces
PLACEHOLDER = re.compile(r"\{\{|\}\}|\{([^{}]+)\}")
PERCENT = "%"


@dataclass
class CheckSpec:
    """One ``[[checks]]`` entry, parsed (not yet typed)."""

    topic: str
    what: str
    value: ex.Node | None
    unit: str | None
    ok: ex.Node | None
    otherwise: str
    note: str
    inputs: dict[str, str] = field(default_factory=dict)
    # the check is for the template's own inputs (a listed worked example): all of them but
    # those the check sets itself (True), or the ones named
    example_only: bool | tuple[str, ...] = False
    part: str | None = None
    line: int | None = None
    # the expression of every placeholder of ``what`` and ``note``, parsed: text -> node
    parsed: dict[str, ex.Node] = field(default_factory=dict)

    @property
    def label(self) -> str:
        return f"check {self.what}"


def read_check(raw: dict, line: int | None) -> CheckSpec:
    """A ``[[checks]]`` table as a :class:`CheckSpec` (a bad key or value names the line)."""
    what = raw.get("what", "[[checks]]") if isinstance(raw, dict) else "[[checks]]"
    try:
        f = Fields(raw, CHECK_KEYS, f"[[checks]] {what!r}")
        text = f.required_text("what", '"largest stress over the yield stress"')
        value, ok = f.text("value", None), f.text("ok", None)
        if value is None and ok is None:
            raise TemplateError(f"check {text!r} needs value = EXPR, ok = CONDITION or both")
        otherwise = f.text("otherwise", "fail")
        if otherwise not in FINDING_VERDICTS or otherwise == "ok":
            choices = ", ".join(v for v in FINDING_VERDICTS if v != "ok")
            raise TemplateError(
                f"check {text!r}: otherwise = {otherwise!r} is not one of {choices}"
            )
        inputs = {str(k): _input_text(text, k, v) for k, v in f.table("inputs").items()}
        spec = CheckSpec(
            topic=f.text("topic", "checks"),
            what=text,
            value=ex.parse(value, what=f"check {text!r}") if value is not None else None,
            unit=f.text("unit", None),
            ok=ex.parse(ok, what=f"check {text!r}") if ok is not None else None,
            otherwise=otherwise,
            note=f.text("note", ""),
            inputs=inputs,
            example_only=_example_only(f, text),
            part=f.text("part", None),
            line=line,
        )
        for piece in (spec.what, spec.note):
            for expression, _ in placeholders(piece):
                spec.parsed[expression] = ex.parse(expression, what=f"check {text!r}")
        if spec.unit is not None:
            un.unit(spec.unit, what=f"check {text!r}")
    except WorkbookError as err:
        raise err.located(line=line) from None
    return spec


def _example_only(f: Fields, what: str) -> bool | tuple[str, ...]:
    value = f.raw.get("example_only", False)
    if isinstance(value, bool):
        return value
    names = f.texts("example_only")
    if not names:
        raise TemplateError(f"check {what!r}: example_only is true, false or a list of inputs")
    return names


def _input_text(what: str, name, value) -> str:
    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        raise TemplateError(f'check {what!r}: inputs.{name} must be a value like "40 mm"')
    return str(value)


def placeholders(text: str) -> list[tuple[str, str | None]]:
    """The ``(EXPR, UNIT or None)`` of every ``{...}`` in ``text``."""
    out = []
    for m in PLACEHOLDER.finditer(text):
        if m.group(1) is None:
            continue
        body = m.group(1)
        expression, _, unit = body.rpartition(":") if ":" in body else (body, "", "")
        out.append((expression.strip(), unit.strip() or None))
    return out


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
            typed_value(sheet, spec)
            typed_condition(sheet, spec)
            for piece in (spec.what, spec.note):
                for expression, unit in placeholders(piece):
                    typed_placeholder(sheet, spec, expression, unit)
        except WorkbookError as err:
            raise err.located(file=sheet.file, line=spec.line, definition=spec.label) from None


def _kept(sheet, spec: CheckSpec, key, make, *args):
    # made here rather than passed down to the typed sheet as a callback: the typed sheet only
    # stores, it never calls back up into this stage
    found = sheet.typed.get(spec, key)
    return found if found is not None else sheet.typed.keep(spec, key, make(*args))


def typed_value(sheet, spec: CheckSpec):
    """The typed value and the factor that shows it in its unit (typed at load, then read)."""
    return _kept(sheet, spec, "value", _value_typed, sheet, spec)


def _value_typed(sheet, spec: CheckSpec):
    if spec.value is None:
        return None, None
    t = sheet.typer.expression(spec.value, {}, spec.label)
    if getattr(t, "text", False) or getattr(t, "boolean", False) or t.shape:
        raise TemplateError("value must be one number")
    shown = un.unit(spec.unit, what=spec.label) if spec.unit is not None else t.unit
    return t, _factor(t, shown, spec.unit)


def typed_condition(sheet, spec: CheckSpec):
    """The typed condition ``ok`` (typed at load, then read)."""
    return _kept(sheet, spec, "ok", _condition_typed, sheet, spec)


def _condition_typed(sheet, spec: CheckSpec):
    if spec.ok is None:
        return None
    t = sheet.typer.expression(spec.ok, {}, spec.label)
    if not getattr(t, "boolean", False) or t.shape:
        raise TemplateError("ok must be a condition (a comparison like 'sigma <= f_y')")
    return t


def typed_placeholder(sheet, spec: CheckSpec, expression: str, unit: str | None):
    """A placeholder's typed tree, factor and unit shown (typed at load, then read)."""
    key = ("placeholder", expression, unit)
    return _kept(sheet, spec, key, _placeholder_typed, sheet, spec, expression, unit)


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
