"""Where EXPR may have a kink or a jump that only a numerical search finds: the sub-trees
whose zeros are those points (their zeros are located by interval arithmetic,
:func:`workbook.numerics.features.kink_points`). Apart from :mod:`workbook.numerics.kinks`
(the break points read exactly from the tree), since this reads the registry of built-ins
(another built-in's own variable is its own business), which EXPR's mpmath form, built on
the break points, must not import."""

from __future__ import annotations

from ..language import typed as ty


def switching(body: ty.T, var: str) -> list[ty.T]:
    """Typed sub-trees of ``body`` (outside the sheet's functions) that depend on ``var`` and
    whose zeros are where EXPR may have a kink or a jump: the argument of ``abs`` and
    ``sign``, the difference of the two arguments of ``min`` and ``max``, and of the two
    sides of a comparison (a piecewise condition); for a step function (floor, ceil, trunc,
    round, mod), a smooth function zero at its jumps. Each built-in's entry says which (its
    ``jumps`` and ``kinks``). Their zeros are
    found numerically (:func:`workbook.numerics.features.kink_points`); the linear cases
    are also found above, exactly."""
    from .registry import REGISTRY

    found: list[ty.T] = []
    stack = [body]
    while stack:
        t = stack.pop()
        entry = REGISTRY.get(t.func) if isinstance(t, ty.TFunc) else None
        if entry is not None and entry.binds:
            continue  # another built-in's own variable: its own business
        stack.extend(ty.children(t))
        # of an array the call is element by element: no point of its own
        scalar = entry is not None and bool(t.args) and t.args[0].shape is None
        jump = entry.jumps(t) if scalar and entry.jumps is not None else None
        if jump is not None and var in ty.parameters(jump) and jump.shape is None:
            found.append(jump)
            continue
        if scalar and entry.kinks is not None:
            pairs = list(entry.kinks(t))
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
