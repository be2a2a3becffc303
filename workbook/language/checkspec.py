"""Checks declared in the template (``[[checks]]``), as written: a value, a condition, a line
of the report; typed at load and computed by :mod:`workbook.compute.declared_checks`.

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

from ..errors import TemplateError, WorkbookError
from ..verdicts import FINDING_VERDICTS
from . import expr as ex
from . import units as un
from .fields import Fields

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
