"""Where an integrand may be singular, read from its typed tree.

A denominator, the base of a power whose exponent is negative or not whole, the
argument of ``sqrt``, ``ln`` and ``log10``, and the cosine of ``tan``'s argument are
singular where they are 0 (the function or
one of its derivatives is unbounded there). Such a zero just outside an interval (or just
inside a piece, past a break point) is what tanh-sinh's error estimate misses: it stops at
its first levels with an estimate far below its error (1/sqrt(t + 1e-3) over [0, 0.79]:
4.5e-11 for 6e-8). Sheet functions called with the variable in an argument are read with
their parameters replaced by the arguments of the call; an inner integral whose bound
depends on the variable contributes its integrand's singular sub-trees at that bound (the
derivative of the integral in its bound is the integrand there).
"""

from __future__ import annotations

from ..language import typed as ty
from .kinks import substitute

#: a sheet function nested deeper than this is not read
_MAX_DEPTH = 20


def singular_arguments(defs, body: ty.T, var: str) -> list[ty.T]:
    """Typed sub-trees of ``body`` that depend on ``var`` and whose zeros are singular points
    of EXPR (a denominator, a power's base, and what each built-in's entry says: the argument
    of sqrt, ln, log10, the cosine of tan's)."""
    from .registry import REGISTRY

    found: list[ty.T] = []
    stack = [(body, 0)]
    while stack:
        t, depth = stack.pop()
        if isinstance(t, ty.TFunc):
            entry = REGISTRY.get(t.func)
            if t.func == "integral" and len(t.args) == 4:
                # d/db of integral(g, t, a, b) is g at t = b: g's singular points, at the
                # bounds, are the inner integral's in the variable
                inner, bound_var = t.args[0], t.args[1].name
                for u in singular_arguments(defs, inner, bound_var):
                    for end in t.args[2:]:
                        _keep(substitute(u, {bound_var: end}), var, found)
                continue
            if entry is not None and entry.binds:
                continue  # another built-in's own variable: its own business
            if entry is not None and entry.singular is not None:  # sqrt: its argument
                for u in entry.singular(t):
                    _keep(u, var, found)
        elif isinstance(t, ty.TBinary) and t.left.shape is None and t.right.shape is None:
            if t.op == "/":
                _keep(t.right, var, found)
            elif t.op == "^" and not _whole_positive(t.right):
                _keep(t.left, var, found)
        elif isinstance(t, ty.TCall) and depth < _MAX_DEPTH and t.name not in defs.recursive:
            f = defs.function(t.name)
            stack.append((substitute(f.body, dict(zip(f.params, t.args))), depth + 1))
            continue  # its arguments are inside the substituted body
        stack.extend((c, depth) for c in ty.children(t))
    return found


def _whole_positive(t: ty.T) -> bool:
    return isinstance(t, ty.TConst) and t.value >= 0 and float(t.value).is_integer()


def _keep(u: ty.T, var: str, found: list[ty.T]) -> None:
    if u.shape is None and not u.text and var in ty.parameters(u):
        found.append(u)
