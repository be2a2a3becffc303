"""The global error of ODE states inside EXPR, in a built-in's estimate.

A built-in over ``y(t)`` of an [[ode]] (a root of a logistic state, an integral of a
velocity) computes with the run's states, whose global error is far above the built-in's own
tolerance (rtol 1e-6 of the run against 1e-10 of a root). EXPR is evaluated again with the
states of the run's error-estimate reference (the same method at tolerances 1000 times
tighter, :meth:`workbook.engine.ode.Solution.reference`): the difference at the points the
built-in used is what the states' error moves EXPR by; a root's error is twice that over
the slope (the reference's own error).
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

import numpy as np

from ..errors import WorkbookError
from ..language import typed as ty

#: the difference from the reference is the run's error only to within the reference's own
#: (a root of a logistic state: 1.047e-6 for an error of 1.057e-6): it counts twice
SAFETY = 2.0


def ode_names(of) -> set[str]:
    """The [[ode]] sections whose states EXPR reads (also through the sheet's functions)."""
    defs = of.evaluator.defs
    found: set[str] = set()
    stack, seen = [of.body], set()
    while stack:
        n = stack.pop()
        if isinstance(n, ty.TOde):
            found.add(n.ode)
        if isinstance(n, ty.TCall) and n.name not in seen:
            seen.add(n.name)
            stack.append(defs.function(n.name).body)
        stack.extend(ty.children(n))
    return found


@contextlib.contextmanager
def reference_states(of, names: set[str]) -> Iterator[bool]:
    """Inside: the evaluator's solutions of ``names`` are their references (yields False,
    and changes nothing, where one has none)."""
    cache = of.evaluator.__dict__.get("_odes", {})
    kept = {}
    try:
        for name in names:
            sol = cache.get(name)
            ref = None if sol is None or isinstance(sol, Exception) else sol.reference()
            if ref is None:
                yield False
                return
            kept[name] = sol
        for name in names:
            cache[name] = kept[name].reference()
        yield True
    finally:
        for name, sol in kept.items():
            cache[name] = sol


def moved(of, shape, xs: np.ndarray) -> np.ndarray | None:
    """[row, k]: |EXPR with the reference states - EXPR| at ``xs[row, k]`` (None: EXPR reads
    no ODE state, or a state has no reference)."""
    names = ode_names(of)
    if not names:
        return None
    f = of.over(shape)
    rows = np.repeat(np.arange(xs.shape[0]), xs.shape[1]).astype(float)
    try:
        with np.errstate(all="ignore"):
            here = np.asarray(f(xs.ravel(), rows), dtype=float)
            with reference_states(of, names) as ok:
                if not ok:
                    return None
                there = np.asarray(f(xs.ravel(), rows), dtype=float)
    except WorkbookError:  # a point past a blow-up of the reference: no estimate here
        return None
    diff = np.abs(np.broadcast_to(there, here.shape) - here).reshape(xs.shape)
    return np.where(np.isfinite(diff), diff, np.inf)


def root_error(of, shape, x: np.ndarray) -> np.ndarray | None:
    """Per row: the states' error moved into the root ``x``: |EXPR_ref - EXPR| at the root
    over |EXPR'| there (a central difference)."""
    x = np.asarray(x, dtype=float).reshape(-1)
    d = moved(of, shape, x[:, None])
    if d is None:
        return None
    h = 1e-6 * np.maximum(np.abs(x), 1e-3)
    f = of.over(shape)
    rows = np.arange(x.size, dtype=float)
    with np.errstate(all="ignore"):
        slope = (np.asarray(f(x + h, rows), float) - np.asarray(f(x - h, rows), float)) / (2 * h)
        return np.where(slope != 0, SAFETY * d[:, 0] / np.abs(slope), np.inf)


def add_root_error(of, shape, result) -> None:
    """Add the states' error to the roots' estimate (in place), where EXPR reads a state."""
    from ..functions.numerical import live, reference

    if live() or reference() or not ode_names(of):
        return
    e = root_error(of, shape, result.value)
    if e is not None:
        result.error = np.asarray(result.error, dtype=float) + e.reshape(np.shape(result.error))


#: interior nodes at which an integral's EXPR is compared with the reference states
NODES = 16


def add_integral_error(of, shape, a, b, result) -> None:
    """Add the states' error to an integral's estimate (in place): twice the integral of the
    difference (the width times its mean at NODES interior points), where EXPR reads a
    state."""
    from ..functions.numerical import live, reference

    if live() or reference() or not ode_names(of):
        return
    a, b = (np.broadcast_to(np.asarray(v, dtype=float), shape).reshape(-1) for v in (a, b))
    t = (np.arange(NODES) + 0.5) / NODES
    d = moved(of, shape, a[:, None] + (b - a)[:, None] * t[None, :])
    if d is not None:
        add = SAFETY * np.abs(b - a) * d.mean(axis=1)
        result.error = np.asarray(result.error, dtype=float) + add.reshape(np.shape(result.error))


def add_value_error(of, shape, where, result) -> None:
    """Add the states' error to a maximum's or minimum's estimate (in place): twice the
    difference where it is, where EXPR reads a state."""
    from ..functions.numerical import live, reference

    if live() or reference() or where is None or not ode_names(of):
        return
    d = moved(of, shape, np.asarray(where, dtype=float).reshape(-1, 1))
    if d is not None:
        add = SAFETY * d[:, 0]
        result.error = np.asarray(result.error, dtype=float) + add.reshape(np.shape(result.error))
