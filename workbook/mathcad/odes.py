"""Mathcad's ODE solvers: ``rkfixed(y, x1, x2, npoints, D)``, the classical fourth-order
Runge-Kutta method at fixed steps, written out as a program of the language.

Mathcad gives the matrix of ``npoints + 1`` rows: the value of x in the first column (x1,
then x1 + h, ... added step by step, as its stored column shows: 0.30000000000000004 at the
third step of 0.1), the states in the others; ``D(x, y)`` is the vector of the derivatives
(a scalar initial value is a state vector of one). The program computes the same steps in
the same order, so its values are Mathcad's to round-off; the adaptive solvers (Rkadapt,
Odesolve) are not translated, as their steps are Mathcad's own.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..language import expr as ex
from .symbols import Untranslatable
from .symbols import key as _key
from .translation import Item

if TYPE_CHECKING:
    from .context import ExpressionContext
    from .reader import MNode


def rkfixed(et: ExpressionContext, args: list[MNode]) -> ex.Node:
    """The matrix of rkfixed(y, x1, x2, npoints, D): a definition of its own, a program."""
    tr = et.tr
    if len(args) != 5:
        raise Untranslatable(f"rkfixed() with {len(args)} arguments")
    if et.local:
        raise Untranslatable("rkfixed() inside a function or program")
    if tr.origin != tr.sheet_origin:
        raise Untranslatable("rkfixed() where ORIGIN differs from the worksheet's origin")
    d = args[4]
    dsym = tr.scope.get(_key(d)) if d.tag == "id" else None
    if dsym is None or dsym.kind != "func" or dsym.broken:
        raise Untranslatable("rkfixed() of a derivative that is not a function of the worksheet")
    y0, x1, x2, n = (et.value(a) for a in args[:4])
    if et.ranges:
        raise Untranslatable("rkfixed() over a range variable")
    if not _is_vector(tr, y0):
        try:
            start = tr.quantity(args[0])
        except Exception:  # noqa: BLE001 - not known at import
            raise Untranslatable("rkfixed() of an initial value not known at import") from None
        if getattr(start.magnitude, "ndim", 0) == 0:
            y0 = ex.Matrix(((y0,),))  # a scalar: a state vector of one
    names = {w: tr.new_sym("local", w, w) for w in ("h", "y", "x", "out", "k", "j")}
    slopes = [tr.new_sym("local", f"k{i}", f"k{i}") for i in range(1, 5)]
    h, y, x, out, k, j = (ex.Name(names[w].token()) for w in ("h", "y", "x", "out", "k", "j"))
    k1, k2, k3, k4 = (ex.Name(s.token()) for s in slopes)
    o = ex.Number(float(tr.sheet_origin))
    half = ex.Binary("/", h, ex.Number(2.0))

    def plus(a: ex.Node, b: ex.Node) -> ex.Node:
        if isinstance(b, ex.Number) and b.value == 0:
            return a
        return ex.Binary("+", a, b)

    def times(a: ex.Node, b: ex.Node) -> ex.Node:
        return ex.Binary("*", a, b)

    def slope(at: ex.Node, state: ex.Node) -> ex.Node:
        return ex.Call(dsym.token(), (at, state))

    row = plus(k, o)
    weighted = plus(plus(plus(k1, times(ex.Number(2.0), k2)), times(ex.Number(2.0), k3)), k4)
    last_state = ex.Binary("-", ex.Call("rows", (y,)), ex.Number(1.0))
    lines = [
        (0, [h, " := ", ex.Binary("/", ex.Binary("-", x2, x1), n)]),
        (0, [y, " := ", y0]),
        (0, [x, " := ", x1]),
        (0, ["for ", k, " in ", ex.Number(0.0), " .. ", n]),
        (4, [ex.Index(out, (row, o)), " := ", x]),
        (4, ["for ", j, " in ", ex.Number(0.0), " .. ", last_state]),
        (
            8,
            [
                ex.Index(out, (row, plus(plus(j, o), ex.Number(1.0)))),
                " := ",
                ex.Index(y, (plus(j, o),)),
            ],
        ),
        (4, [k1, " := ", slope(x, y)]),
        (4, [k2, " := ", slope(plus(x, half), plus(y, times(half, k1)))]),
        (4, [k3, " := ", slope(plus(x, half), plus(y, times(half, k2)))]),
        (4, [k4, " := ", slope(plus(x, h), plus(y, times(h, k3)))]),
        (4, [y, " := ", plus(y, times(ex.Binary("/", h, ex.Number(6.0)), weighted))]),
        (4, [x, " := ", plus(x, h)]),
        (0, [out]),
    ]
    helper = tr.new_sym(
        "var", f"{dsym.base}_rkfixed", f"rkfixed of {dsym.mathcad}", tr.region, generated=True
    )
    tr.out.items.append(Item("definition", tr.region, sym=helper, program=lines))
    tr.calls.setdefault(dsym, []).append((x1, y0))
    return ex.Name(helper.token())


def _is_vector(tr, tree: ex.Node) -> bool:
    """Whether the initial value is a vector as the import sees it (written, or a name of
    one)."""
    if isinstance(tree, ex.Matrix):
        return True
    return isinstance(tree, ex.Name) and tr.is_array(tree.id)
