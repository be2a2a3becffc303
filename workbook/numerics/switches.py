"""Where EXPR may have a kink or a jump that only a numerical search finds: the sub-trees
whose zeros are those points (their zeros are located by interval arithmetic,
:func:`workbook.numerics.features.kink_points`). Apart from :mod:`workbook.numerics.kinks`
(the break points read exactly from the tree), since this reads the registry of built-ins
(another built-in's own variable is its own business), which EXPR's mpmath form, built on
the break points, must not import."""

from __future__ import annotations

from ..language import typed as ty


def _jumps(t: ty.T) -> ty.T | None:
    """A smooth sub-tree whose zeros are the jumps of ``t``, if ``t`` is a step function:
    sin(pi u) for floor(u), ceil(u), trunc(u) (0 at every integer), cos(pi u) for round(u)
    (0 at every half-integer), sin(pi a/m) for mod(a, m)."""
    import math

    from ..language import units as un

    if not isinstance(t, ty.TFunc) or not t.args or t.args[0].shape is not None:
        return None
    one = un.registry().dimensionless
    if t.func in ("floor", "ceil", "trunc") and len(t.args) == 1:
        u, wave = t.args[0], "sin"
    elif t.func == "round" and len(t.args) == 1:
        u, wave = t.args[0], "cos"
    elif t.func == "mod" and len(t.args) == 2 and t.args[1].shape is None:
        u, wave = ty.TBinary(one, op="/", left=t.args[0], right=t.args[1]), "sin"
    else:
        return None
    return ty.TFunc(one, func=wave, args=(ty.TScale(one, child=u, factor=math.pi),))


def switching(body: ty.T, var: str) -> list[ty.T]:
    """Typed sub-trees of ``body`` (outside the sheet's functions) that depend on ``var`` and
    whose zeros are where EXPR may have a kink or a jump: the argument of ``abs`` and
    ``sign``, the difference of the two arguments of ``min`` and ``max``, and of the two
    sides of a comparison (a piecewise condition); for a step function (floor, ceil, trunc,
    round, mod), a smooth function zero at its jumps (:func:`_jumps`). Their zeros are
    found numerically (:func:`workbook.numerics.features.kink_points`); the linear cases
    are also found above, exactly."""
    from ..functions.registry import REGISTRY

    found: list[ty.T] = []
    stack = [body]
    while stack:
        t = stack.pop()
        entry = REGISTRY.get(t.func) if isinstance(t, ty.TFunc) else None
        if entry is not None and entry.binds:
            continue  # another built-in's own variable: its own business
        stack.extend(ty.children(t))
        jump = _jumps(t)
        if jump is not None and var in ty.parameters(jump) and jump.shape is None:
            found.append(jump)
            continue
        if isinstance(t, ty.TFunc) and t.func in ("abs", "sign") and len(t.args) == 1:
            pairs = [(t.args[0], None)]
        elif isinstance(t, ty.TFunc) and t.func in ("min", "max") and len(t.args) == 2:
            pairs = [(t.args[0], t.args[1])]
        elif isinstance(t, ty.TCompare):
            pairs = list(zip(t.operands, t.operands[1:]))
        else:
            continue
        for x, y in pairs:
            if x.shape is not None or (y is not None and y.shape is not None):
                continue
            u = x if y is None else ty.TBinary(x.unit, op="-", left=x, right=y)
            if var in ty.parameters(u):
                found.append(u)
    return found
