"""The case grid: swept inputs (``--vary R3=40mm..60mm:21``) and their Cartesian product."""

from __future__ import annotations

import itertools
import math
import re
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..language import units as un

_VARY = re.compile(r"^\s*(.+?)\s*\.\.\s*(.+?)\s*:\s*(\d+)\s*$")
MAX_CASES = 100_000  # 100,000 cases of a formula: 12 s to an xlsx; 10^6 took 148 s


@dataclass
class Vary:
    """One swept input and its values (magnitudes in ``unit``, or words for a choice)."""

    name: str
    values: list
    unit: str = ""  # pint unit text of the magnitudes ('' for a choice or dimensionless)

    def header(self, sheet) -> str:
        """The table's column header: the name and the input's unit."""
        spec = sheet.spec.inputs[self.name]
        if spec.options:
            return self.name
        shown = spec.label or un.pretty(spec.unit)
        return f"{self.name} [{shown}]" if shown else self.name


def parse_vary(item: str, sheet) -> Vary:
    """``R3=40mm..60mm:21`` (21 values, ends included), ``R3=40mm,45mm,50mm`` or a choice list."""
    name, sep, text = item.partition("=")
    name, text = name.strip(), text.strip()
    if not sep or not name or not text:
        raise InputError(f"--vary {item!r}: write NAME=FIRST..LAST:COUNT, e.g. R3=40mm..60mm:21")
    spec = sheet.spec.inputs.get(name)
    if spec is None:
        raise InputError(
            f"--vary {item!r}: '{name}' is not an input of {sheet.name} "
            f"(inputs: {', '.join(sheet.spec.inputs)})"
        )
    if spec.options:
        words = [w.strip() for w in text.split(",") if w.strip()]
        for w in words:
            if w not in spec.options:
                raise InputError(f"--vary {name}: {w!r} is not one of {', '.join(spec.options)}")
        return Vary(name, words)
    unit_text = str(spec.unit)
    m = _VARY.match(text)
    if m:
        first, last, count = m.group(1), m.group(2), int(m.group(3))
        if count < 1:
            raise InputError(f"--vary {name}: the count must be at least 1")
        if count > MAX_CASES:
            raise InputError(f"--vary {name}: {count:,} values is more than {MAX_CASES:,}")
        a = _magnitude(spec, first, name)
        b = _magnitude(spec, last, name)
        values = [a] if count == 1 else np.linspace(a, b, count).tolist()
    else:
        values = [_magnitude(spec, v, name) for v in text.split(",") if v.strip()]
        if not values:
            raise InputError(f"--vary {name}: no values")
    return Vary(name, values, unit_text)


def _magnitude(spec, text: str, name: str) -> float:
    """A value in the input's unit; units are checked here, bounds per case (a case error)."""
    import pint

    text = text.strip()
    if ".." in text:
        raise InputError(f"--vary {name}: cannot read {text!r}; write FIRST..LAST:COUNT")
    # "40mm" reads as 40 mm; a bare number is taken in the input's own unit
    try:
        q = un.registry().Quantity(float(text), spec.unit)
    except ValueError:
        q = un.quantity(text, str(spec.unit) if spec.unit.dimensionless else None, what=name)
    try:
        value = float(q.to(spec.unit).magnitude)
    except pint.DimensionalityError:
        raise InputError(
            f"--vary {name}: {text} is {un.dims(q.units)}, but {name} is "
            f"{un.dims(spec.unit)} ({un.pretty(spec.unit) or 'dimensionless'})"
        ) from None
    if not math.isfinite(value):
        raise InputError(f"--vary {name}: {text} is not a finite number")
    return value


def grid(varies: list[Vary]) -> list[dict]:
    """Cartesian product of the swept values; the first input varies slowest."""
    total = math.prod(len(v.values) for v in varies)
    if total > MAX_CASES:
        raise InputError(f"the sweep has {total:,} cases (limit {MAX_CASES:,})")
    return [
        {v.name: (val, v.unit) for v, val in zip(varies, combo)}
        for combo in itertools.product(*[v.values for v in varies])
    ]


def as_varies(sheet, vary) -> list[Vary]:
    """The swept inputs from a list of Vary or a dict ``{name: values or 'FIRST..LAST:N'}``."""
    if isinstance(vary, dict):
        out = []
        for name, values in vary.items():
            if isinstance(values, str):
                out.append(parse_vary(f"{name}={values}", sheet))
            else:
                out.append(parse_vary(f"{name}=" + ",".join(_text(v) for v in values), sheet))
        vary = out
    if not vary:
        raise InputError("nothing to vary: give --vary NAME=FIRST..LAST:COUNT")
    names = [v.name for v in vary]
    if len(set(names)) != len(names):
        raise InputError("an input is varied twice")
    return list(vary)


def _text(v) -> str:
    import pint

    if isinstance(v, pint.Quantity):
        return f"{v.magnitude!r} {v.units}"
    return str(v)
