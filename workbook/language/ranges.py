"""Range variables: Mathcad's ``phi := first, second .. last`` read, and its values."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import pint

from ..errors import LimitError, TemplateError
from . import expr as ex

MAX_RANGE_POINTS = 2_000_000


@dataclass
class RangeSpec:
    """A range variable as written: ``var := first, second .. last`` (second may be None)."""

    var: str
    first: ex.Node
    second: ex.Node | None
    last: ex.Node
    text: str
    # the unit of a bound written as a quantity ("25 N"): its node is then the number
    units: tuple[pint.Unit | None, ...] = (None, None, None)
    # a log-spaced range, ``var := logspace(first, last, points)``: the number of points
    points: ex.Node | None = None


_RANGE = re.compile(r"^\s*(?:([A-Za-z][A-Za-z0-9_]*)\s*:=\s*)?(.+?)\s*\.\.\s*(.+?)\s*$")


_LOGSPACE = re.compile(r"^\s*(?:([A-Za-z][A-Za-z0-9_]*)\s*:=\s*)?logspace\s*\((.*)\)\s*$", re.S)


def parse_range(
    text: str, *, default_var: str | None = None, what: str = "range", log: bool = False
) -> RangeSpec:
    """Parse Mathcad's range form ``phi := first, second .. last`` (or ``first .. last``);
    with ``log``, also a log-spaced range ``f := logspace(first, last, points)``."""
    if not isinstance(text, str):
        raise TemplateError(f"{what}: expected a range like 'phi := 0, 5 .. 22'")
    m = _LOGSPACE.match(text)
    if m:
        return _log_range(m, text, default_var, what, log)
    m = _RANGE.match(text)
    if not m:
        raise TemplateError(f"{what}: cannot read range {text!r} (expected 'phi := 0, 5 .. 22')")
    var, head, last = m.group(1) or default_var, m.group(2), m.group(3)
    if not var:
        raise TemplateError(f"{what}: range {text!r} names no variable (write 'phi := 0, 5 .. 22')")
    parts = split_top(head, ",")
    if len(parts) > 2:
        raise TemplateError(f"{what}: range {text!r} has more than two values before '..'")
    texts = [parts[0], parts[1] if len(parts) == 2 else None, last]
    bounds = [None if t is None else _bound_node(t, what) for t in texts]
    nodes = [None if b is None else b[0] for b in bounds]
    units = tuple(None if b is None else b[1] for b in bounds)
    return RangeSpec(var, nodes[0], nodes[1], nodes[2], text.strip(), units)


def _log_range(m, text: str, default_var, what: str, allowed: bool) -> RangeSpec:
    if not allowed:
        raise TemplateError(
            f"{what}: a log-spaced range (logspace) is for tables, charts and sweep outputs; "
            "write 'first, second .. last' here"
        )
    var = m.group(1) or default_var
    if not var:
        raise TemplateError(f"{what}: range {text!r} names no variable (f := logspace(...))")
    args = split_top(m.group(2), ",")
    if len(args) != 3 or not all(args):
        raise TemplateError(
            f"{what}: write logspace(first, last, points), e.g. 'f := logspace(1 Hz, 1 kHz, 31)'"
        )
    (first, u1), (last, u2) = (_bound_node(a, what) for a in args[:2])
    return RangeSpec(
        var, first, None, last, text.strip(), (u1, None, u2), ex.parse(args[2], what=what)
    )


def log_range_values(first: float, last: float, points: float, *, what: str = "range"):
    """``points`` values from ``first`` to ``last`` (both included), evenly spaced on a log
    scale (Mathcad's logspace): both bounds above zero, at least 2 points."""
    import numpy as np

    if not (math.isfinite(first) and math.isfinite(last)) or first <= 0 or last <= 0:
        raise TemplateError(
            f"{what}: the bounds of a log-spaced range are above zero (got {first:g}, {last:g})"
        )
    if not float(points).is_integer() or points < 2:
        raise TemplateError(f"{what}: a log-spaced range has a whole number >= 2 of points")
    if points > MAX_RANGE_POINTS:
        raise LimitError(f"{what}: range has {points:,.0f} points (limit {MAX_RANGE_POINTS:,})")
    values = np.geomspace(first, last, int(points))
    values[0], values[-1] = first, last
    return values


_QUANTITY_BOUND = re.compile(r"^[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?\s*[^\W\d]")


def _bound_node(text: str, what: str) -> tuple[ex.Node, pint.Unit | None]:
    """A range bound: an expression (``25 N`` and ``360 deg * turns`` are expressions with a
    quantity in them, whose unit a space ends), or else a quantity the expression language
    does not read (``1e3 1/s``): its number and unit."""
    try:
        return ex.parse(text, what=what), None
    except TemplateError:
        if not _QUANTITY_BOUND.match(text.strip()):
            raise
    from . import units as un

    q = un.quantity(text, what=f"{what}: range bound")
    return ex.Number(float(q.magnitude)), q.units


def range_values(first: float, second: float | None, last: float, *, what: str = "range"):
    """Values of a range variable; the last value is always included (as the paper's listings
    show: ``0, 5 .. 22`` is 0, 5, 10, 15, 20, 22)."""
    import numpy as np

    values, on_step = _steps(first, second, last, what)
    return values if on_step else np.append(values, last)


def loop_values(first: float, second: float | None, last: float, *, what: str = "loop"):
    """Values of a program's ``for`` loop, as Mathcad runs it: first, first + step, ... never
    beyond the last value (``for k in 1, 3 .. 10`` is 1, 3, 5, 7, 9)."""
    return _steps(first, second, last, what)[0]


def _steps(first: float, second: float | None, last: float, what: str):
    """(first + k*step up to ``last``, whether ``last`` is one of them); refuses a zero step,
    a step away from ``last`` and more than MAX_RANGE_POINTS values."""
    import numpy as np

    for v in (first, last) + ((second,) if second is not None else ()):
        if not math.isfinite(v):
            raise TemplateError(f"{what}: range bounds must be finite numbers")
    step = (second - first) if second is not None else (1.0 if last >= first else -1.0)
    if step == 0:
        raise TemplateError(f"{what}: range step is zero (first and second value are equal)")
    if (last - first) * step < 0:
        raise TemplateError(
            f"{what}: range step {step:g} goes away from the last value {last:g} "
            f"(first {first:g}); reverse the step's sign"
        )
    span = (last - first) / step * (1 + 1e-12) + 1e-9
    if not span < MAX_RANGE_POINTS:  # also refuses an infinite span (1e308 / 1e-300)
        raise LimitError(
            f"{what}: range has {span + 1:,.0f} points (limit {MAX_RANGE_POINTS:,}); "
            "use a larger step"
        )
    count = math.floor(span) + 1
    values = first + step * np.arange(count, dtype=float)  # first + k*step: no drift
    if abs(values[-1] - last) > 1e-9 * max(1.0, abs(step)):
        return values, False
    values[-1] = last
    return values, True


def split_top(text: str, sep: str) -> list[str]:
    """Split at ``sep`` outside parentheses."""
    parts, depth, cur = [], 0, []
    for ch in text:
        if ch == "(":
            depth += 1
        elif ch == ")":
            depth -= 1
        if ch == sep and depth == 0:
            parts.append("".join(cur))
            cur = []
        else:
            cur.append(ch)
    parts.append("".join(cur))
    return [p.strip() for p in parts]
