"""Two slips of Mathcad users with angles, found in the typed formulas and reported as
warnings (``run`` prints them; they are not errors, the formula may mean it):

- an angle already in degrees multiplied by ``pi/180`` (``sin(theta*pi/180)`` with theta in
  deg): the engine converts degrees itself, so this takes the sine of theta/57.3;
- a bare number above 2*pi given to sin, cos or tan in a worksheet whose angles are in degrees
  (``sin(90)``): a plain number there is radians (the documented rule), which is rarely what
  such a sheet means.
"""

from __future__ import annotations

import math

from ..findings import Finding
from ..language import typed as ty
from ..language.units import angle_in
from ..numerics.registry import REGISTRY


def angle_findings(sheet) -> list[Finding]:
    """The warnings for the two slips, one per formula and kind."""
    typer = sheet.typer
    degrees = _sheet_uses_degrees(sheet)
    bodies = [(name, t) for name, t in typer.scalars.items()]
    bodies += [(key.split("@", 1)[0], f.body) for key, f in typer.functions.items()]
    out, seen = [], set()
    for name, body in bodies:
        for call in _trig_calls(body):
            arg = call.args[0]
            if (name, "pi/180") not in seen and _degrees_times_pi_over_180(arg):
                seen.add((name, "pi/180"))
                out.append(
                    Finding(
                        "angles",
                        f"'{name}': {call.func}() of an angle in degrees multiplied by pi/180",
                        None,
                        "",
                        "warning",
                        "an angle in deg is already an angle: write sin(theta), not "
                        "sin(theta*pi/180), which takes the sine of theta/57.3",
                    )
                )
            bare = _bare(arg)
            if (
                degrees
                and bare is not None
                and abs(bare) > 2 * math.pi
                and (name, bare) not in seen
            ):
                seen.add((name, bare))
                out.append(
                    Finding(
                        "angles",
                        f"'{name}': {call.func}({bare:g}) reads {bare:g} as radians",
                        None,
                        "",
                        "warning",
                        f"a plain number given to {call.func}() is in radians; this worksheet's "
                        f"angles are in degrees: for degrees write {call.func}({bare:g} deg)",
                    )
                )
    return out


def _sheet_uses_degrees(sheet) -> bool:
    units = [u for u in sheet.typer.input_units.values() if u is not None]
    units += [a.unit for a in sheet.spec.arguments.values()]
    return any(angle_in(u) == "deg" for u in units)


def takes_angle(name: str) -> bool:
    """True for a built-in whose argument is an angle (sin, cos, tan: the entry says)."""
    entry = REGISTRY.get(name)
    return entry is not None and entry.angle


def _trig_calls(t: ty.T):
    """The calls of sin, cos and tan (the built-ins that take an angle) in ``t`` (not inside
    the bodies of called functions)."""
    stack = [t]
    while stack:
        n = stack.pop()
        if isinstance(n, ty.TFunc) and n.args and takes_angle(n.func):
            yield n
        stack.extend(ty.children(n))


def _bare(t: ty.T) -> float | None:
    while isinstance(t, ty.TScale) and t.factor == 1.0:
        t = t.child
    return t.value if ty.is_bare(t) and not t.complex else None  # sin(2 + 1i) is no angle


def _degrees_times_pi_over_180(t: ty.T) -> bool:
    """True when a product in ``t`` has pi and an angle in degrees over 180."""
    stack = [t]
    while stack:
        n = stack.pop()
        if isinstance(n, ty.TBinary) and n.op in "*/":
            top, bottom = _factors(n)
            has_pi = any(
                isinstance(f, ty.TRef) and f.kind == "builtin" and f.name == "pi" for f in top
            )
            has_180 = any(ty.is_bare(f) and f.value == 180 for f in bottom)
            has_degrees = any(angle_in(f.unit) == "deg" for f in top)
            if has_pi and has_180 and has_degrees:
                return True
        if not isinstance(n, ty.TCall):
            stack.extend(ty.children(n))
    return False


def _factors(t: ty.T) -> tuple[list[ty.T], list[ty.T]]:
    """The factors of a product or quotient: (numerator, denominator)."""
    if isinstance(t, ty.TScale) and t.factor == 1.0:
        return _factors(t.child)
    if isinstance(t, ty.TBinary) and t.op in "*/":
        (a, b), (c, d) = _factors(t.left), _factors(t.right)
        return (a + c, b + d) if t.op == "*" else (a + d, b + c)
    return [t], []
