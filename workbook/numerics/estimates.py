"""Findings about the numerical built-ins' error estimates: a value whose estimate is far above
the sheet's tolerance, and an extremum that rests on an assumption (no feature narrower than
its samples' spacing), are printed by ``run`` and ``check`` (warnings), never kept silent."""

from __future__ import annotations

import numpy as np

from ..functions.numerical import sheet_tolerance

#: An estimate this many times the sheet's tolerance (relative to the value) is reported.
ESTIMATE_LIMIT = 100.0

#: An estimate below this times the larger of the value and 1 (in the unit the built-in
#: computes in) is the rounding of the numbers it works with (a maximum of a difference that
#: is 0 but for rounding), not an uncertainty worth a warning.
ROUNDING = 100 * np.finfo(float).eps

#: Extrema are certified to the tolerance relative to EXPR's size on the interval (a maximum
#: that is 0 is found to within rtol times that size), so their estimates are measured
#: against it; an integral's against its value (a small value by cancellation is warned of)
CERTIFIED_TO_SCALE = frozenset({"maximum", "minimum"})

#: The position of a smooth extremum is known only to about the square root of the rounding
#: of its expression (docs/numerics.md): its estimate is information, not a warning, unless
#: the rounding of EXPR spot-checked beside it (numerics.rounding) makes it more than
#: ESTIMATE_LIMIT times that square root (or the tolerance) of the interval's width.
POSITIONS = frozenset({"argmax", "argmin"})
POSITION_FLOOR = float(np.finfo(float).eps) ** 0.5


def estimate_findings(sheet) -> list:
    """One warning per definition or column whose built-in's largest error estimate, relative
    to its largest value (an extremum's: to the larger of that and EXPR's size on the
    interval), exceeds ESTIMATE_LIMIT times ``[sheet] tolerance``; computed from what the sheet
    has evaluated so far (call it after the values)."""
    from ..findings import Finding

    rtol = sheet_tolerance(sheet.spec.meta).rtol
    worst: dict[tuple[str, str], tuple[float, float, float, str]] = {}
    for builtin, result in sheet.evaluator.records:
        where = result.notes.get("in")
        # a result computed outside a definition or a column (a writer's live form, a report)
        # repeats one of theirs; counting it would make the findings depend on what was
        # written before the check
        if where is None or not np.size(result.error):
            continue
        if builtin in POSITIONS:
            _position(worst, where, builtin, result, rtol)
            continue
        size = float(np.max(np.abs(result.value), initial=0.0))
        scale = float(result.notes.get("scale", 0.0))  # EXPR's size on the interval
        err = float(np.max(np.abs(result.error), initial=0.0))
        # the rounding of the numbers it adds; a linear-algebra estimate is relative already
        floor = max(size, scale) if result.notes.get("relative") else max(size, scale, 1.0)
        if err <= ROUNDING * floor:
            continue
        if builtin in CERTIFIED_TO_SCALE:
            size = max(size, scale)
        relative = err / size if size > 0 else np.inf
        key = (where, builtin)
        if relative > worst.get(key, (-1.0,))[0]:
            worst[key] = (relative, err, size, result.notes.get("named", ""))
    out = assumption_findings(sheet)
    for (where, builtin), (relative, err, size, named) in worst.items():
        if relative <= ESTIMATE_LIMIT * rtol:
            continue
        out.append(
            Finding(
                f"estimate {where}",
                f"{builtin}: error estimate {err:.3g} for a value of size {size:.6g} "
                f"(relative {relative:.2g})" + (f": {named}" if named else ""),
                None,
                "",
                "warning",
                f"over {ESTIMATE_LIMIT:g} times the sheet's tolerance ({rtol:g}): the value is "
                "less certain than asked; docs/numerics.md says what each built-in certifies",
            )
        )
    return out


def _position(worst: dict, where: str, builtin: str, result, rtol: float) -> None:
    """An argmax's or argmin's estimate, relative to the interval's width, where EXPR's
    rounding made it larger than POSITION_FLOOR allows (else no warning: see POSITIONS)."""
    span = float(result.notes.get("span", 0.0))
    if span <= 0:
        return
    err = float(np.max(np.abs(result.error), initial=0.0))
    relative = err / span
    if relative <= ESTIMATE_LIMIT * max(rtol, POSITION_FLOOR):
        return
    if relative > worst.get((where, builtin), (-1.0,))[0]:
        worst[(where, builtin)] = (relative, err, span, "its place, against the interval's width")


def assumption_findings(sheet) -> list:
    """A warning per assumption that maximum, minimum, argmax or argmin values rest on where
    EXPR has a node without an interval extension (the global extremum is then not
    certified): no feature narrower than the samples' spacing h. The values that share one
    h and one cause are named in one warning."""
    from ..findings import Finding

    widest: dict[tuple[str, str], tuple[float, str, str]] = {}
    for builtin, result in sheet.evaluator.records:
        where, h = result.notes.get("in"), result.notes.get("assumes")
        if where is None or h is None:
            continue
        key = (where, builtin)
        if h > widest.get(key, (-1.0,))[0]:
            widest[key] = (h, result.notes.get("unit", ""), result.notes.get("why", ""))
    shared: dict[tuple[float, str, str], list[str]] = {}
    for (where, builtin), same in widest.items():
        shared.setdefault(same, []).append(f"{builtin} {where}")
    out = []
    for (h, unit, why), values in shared.items():
        cause = f"{why} has no interval extension" if why else "no interval extension"
        size = f"{h:.4g} {unit}".rstrip()
        out.append(
            Finding(
                f"assumption {', '.join(values)}",
                f"assumes no feature narrower than h = {size} (the spacing of the samples)",
                None,
                "",
                "warning",
                f"{cause}, so the global extremum is not certified between the samples; more "
                "[sheet] samples narrow h; docs/numerics.md says what each built-in certifies",
            )
        )
    return out
