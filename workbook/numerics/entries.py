"""Registry entries of the numerical built-ins: root, integral, maximum/minimum/argmax/argmin,
product, diff, and linterp/cspline over [data] columns (one
:class:`workbook.functions.builtins.Builtin` each; ``sum`` is in builtins.py).

Each binds its variable (``binds=(0, 1)``): the unit rule checks the bounds or the guess
against the variable's unit at load; the numpy hook receives EXPR as a
:class:`workbook.engine.numeric.Bound` and solves every row of a table in one vectorised call of
:mod:`workbook.numerics`. SciPy is imported only when a hook runs.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import NotLive, NotSymbolic, TemplateError, UnitError, WorkbookError
from ..functions.entry import Builtin, register
from ..language import typed as ty
from ..language import units as un
from ..language.expr import PREC
from ._common import (
    NumericsError,
    Result,
    chains,
    live,
    reference,
    reference_methods,
    reference_values,
    sheet_tolerance,
)

ATOM = PREC["atom"]
#: rows solved at once (a bracket's samples take rows x samples memory)
CHUNK = 20_000
#: bisection steps of a root's live Excel form (a bracket halves 60 times: full precision)
BISECTION_STEPS = 60
#: golden-section steps of an extremum's live Excel form (after sampling, around the best sample)
GOLDEN_STEPS = 60
#: an extremum is live only where its live form is this close (relative) to the engine's value
LIVE_EXTREMUM = 1e-9
#: two values of EXPR this close (relative) count as equal in the live extremum's comparisons,
#: so that rounding (which LibreOffice or Excel may do differently) does not choose the side
SAME = 1e-12
#: the golden ratio's inverse, as the workbook's formulas write it
GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0
#: nodes of the Gauss-Legendre rule of an integral's live Excel form
EXCEL_NODES = 20
#: highest order of diff(EXPR, X, N)
MAX_ORDER = 10


# -- unit rules ---------------------------------------------------------------------------------
def _variable(name: str, body: ty.T, var: ty.TParam) -> None:
    if body.boolean:
        raise TemplateError(f"{name}(): the expression is a condition, not a number")


def _in_var_unit(ctx, t: ty.T, var: ty.TParam, name: str, what: str) -> ty.T:
    """A bound or guess in the variable's unit; a mismatch names both units. For a
    ``plain = true`` argument (a plain number of its declared unit, Mathcad's phi*deg) a
    bound with a unit is converted to the declared unit and a plain number is taken as
    already in it, as range bounds are."""
    arg = ctx.spec.arguments.get(var.name)
    if arg is not None and arg.plain and (t.unit.dimensionality or t.unit != ctx.dimensionless):
        if t.unit.dimensionality != arg.unit.dimensionality and not _zero(t):
            raise UnitError(
                f"{name}(): {what} is {un.dims(t.unit)} ({un.pretty(t.unit) or '1'}), but the "
                f"variable {var.name} is {un.dims(arg.unit)} ({un.pretty(arg.unit) or '1'})"
            )
        t = ctx.convert(t, arg.unit, f"{name}(): {what}")
        return ty.TScale(var.unit, child=t, factor=1.0)
    if t.unit.dimensionality != var.unit.dimensionality and not _zero(t):
        raise UnitError(
            f"{name}(): {what} is {un.dims(t.unit)} ({un.pretty(t.unit) or '1'}), but the "
            f"variable {var.name} is {un.dims(var.unit)} ({un.pretty(var.unit) or '1'})"
        )
    # a bare number bounding an angle in degrees is in degrees, as range bounds are
    # (180 for phi in deg was 180 rad); an expression with pi (pi/2) stays in radians
    return ctx.convert(t, var.unit, f"{name}(): {what}")


def _zero(t: ty.T) -> bool:
    return isinstance(t, ty.TConst) and t.value == 0.0 and not t.unit.dimensionality


def _root_unit(ctx, name: str, args: tuple) -> ty.T:
    body, var, *rest = args
    _variable(name, body, var)
    sheet_tolerance(ctx.spec.meta)
    whats = ("the guess",) if len(rest) == 1 else ("the lower bound A", "the upper bound B")
    rest = [_in_var_unit(ctx, t, var, name, w) for t, w in zip(rest, whats)]
    return ty.TFunc(var.unit, func=name, args=(body, var, *rest))


def _integral_unit(ctx, name: str, args: tuple) -> ty.T:
    body, var, a, b = args
    _variable(name, body, var)
    sheet_tolerance(ctx.spec.meta)
    a = _in_var_unit(ctx, a, var, name, "the lower bound A")
    b = _in_var_unit(ctx, b, var, name, "the upper bound B")
    # over a temperature in degC the variable's steps are differences (delta_degC)
    step = un.difference_unit(var.unit)
    return ty.TFunc(body.unit * step, func=name, args=(body, var, a, b))


def _extremum_unit(ctx, name: str, args: tuple) -> ty.T:
    body, var, a, b = args
    _variable(name, body, var)
    sheet_tolerance(ctx.spec.meta)
    a = _in_var_unit(ctx, a, var, name, "the lower bound A")
    b = _in_var_unit(ctx, b, var, name, "the upper bound B")
    unit = var.unit if name.startswith("arg") else body.unit
    return ty.TFunc(unit, func=name, args=(body, var, a, b))


def _diff_unit(ctx, name: str, args: tuple) -> ty.T:
    """diff's unit, EXPR's over X's to the N: no SymPy at load. What can be refused without
    SymPy is refused here (the order, a variable not in scope, EXPR with a part that has no
    formula); the derivative itself is found at first use (workbook.numerics.derivative)."""
    from .derivative import pending

    body, var, *rest = args
    _variable(name, body, var)
    order = 1
    if rest:
        n = rest[0]
        ok = isinstance(n, ty.TConst) and not n.unit.dimensionality and n.value == int(n.value)
        if not ok or not 1 <= n.value <= MAX_ORDER:
            raise TemplateError(
                f"diff(): the order N must be a whole number from 1 to {MAX_ORDER} written as "
                "a number"
            )
        order = int(n.value)
    if var.name not in ctx.scope:
        raise TemplateError(
            f"diff(): the derivative is a function of {var.name}, which is not an argument "
            f'here: make {var.name} an argument of the definition ("NAME({var.name})")'
        )
    why = ctx.symbolic_refusal(body)
    if why:
        raise TemplateError(f"diff(): {why}")
    unit = body.unit / un.difference_unit(var.unit) ** order  # per delta_degC, not per degC
    pending(ctx, body, var, order, unit)
    return ty.TFunc(unit, func=name, args=args)


def _product_unit(ctx, name: str, args: tuple) -> ty.T:
    body, var, a, b = args
    _variable(name, body, var)
    if var.unit.dimensionality or var.unit != ctx.dimensionless:
        raise UnitError(f"{name}(): the index {var.name} must be a plain number (integers A..B)")
    if body.unit.dimensionality:
        raise UnitError(
            f"{name}(): the factors must be plain numbers (the unit of a product would depend "
            f"on the number of factors), got {un.dims(body.unit)}"
        )
    a = ctx.plain(a, f"{name}(): the first index")
    b = ctx.plain(b, f"{name}(): the last index")
    return ty.TFunc(body.unit, func=name, args=(body, var, a, b))


# -- numpy hooks --------------------------------------------------------------------------------
def _solve(of, solve, *bounds) -> Result:
    """``solve(f, *bounds, idx, label)`` for every row of the call, ``CHUNK`` rows at a time
    (the samples of a bracket take rows x samples memory); one Result in the call's shape.

    The rows are the broadcast of the expression's arrays and the bounds; ``f(x, idx)`` is
    EXPR at the flat rows ``idx`` (scipy passes them compressed to the unconverged rows)."""
    shape = np.broadcast_shapes(of.shape, *(np.shape(b) for b in bounds))
    f, label = of.over(shape), of.describe_row(shape)
    flat = [np.broadcast_to(np.asarray(b, dtype=float), shape).reshape(-1) for b in bounds]
    n = math.prod(shape)
    idx = np.arange(n, dtype=float)
    parts = []
    for lo in range(0, max(n, 1), CHUNK):
        sl = slice(lo, lo + CHUNK)
        parts.append(solve(f, *[b[sl] for b in flat], idx[sl], lambda i, lo=lo: label(i + lo)))
    first = parts[0]

    def join(attr):
        if getattr(first, attr) is None:
            return None
        return np.concatenate([np.ravel(getattr(r, attr)) for r in parts]).reshape(shape)

    return Result(
        join("value"),
        join("error"),
        join("where"),
        join("where_error"),
        evaluations=max(r.evaluations for r in parts),
        notes=_joined_notes(parts),
    )


def _joined_notes(parts: list[Result]) -> dict:
    """The notes of the chunks of one call: the widest assumption and the largest size of
    EXPR of them all."""
    notes = dict(parts[0].notes)
    for key in ("assumes", "scale"):
        found = [r.notes[key] for r in parts if key in r.notes]
        if found:
            notes[key] = max(found)
    return notes


def _bisection(f, a, b, idx) -> dict[str, np.ndarray]:
    """What the workbook's bisection steps compute, row by row: f(A), f(B), then lo, hi and
    f(mid) of every step (f(lo) keeps the sign of f(A), so only f(mid) is evaluated); the
    root is the last (lo + hi)/2, NaN where f(A) and f(B) have the same sign (#N/A)."""
    lo, hi = a.copy(), b.copy()
    fa = np.asarray(f(lo, idx), dtype=float)
    fb = np.asarray(f(hi, idx), dtype=float)
    out = {"fa": fa, "fb": fb, "lo": [lo], "hi": [hi], "fm": []}
    for _ in range(BISECTION_STEPS):
        mid = (lo + hi) / 2
        fm = np.asarray(f(mid, idx), dtype=float)
        left = fa * fm <= 0
        lo, hi = np.where(left, lo, mid), np.where(left, mid, hi)
        out["lo"].append(lo)
        out["hi"].append(hi)
        out["fm"].append(fm)
    out["root"] = np.where(fa * fb > 0, np.nan, (lo + hi) / 2)
    return out


def _live_chain(of, a, b, steps_of) -> dict[str, np.ndarray]:
    """``steps_of(f, a, b, idx)`` (the cells of a live form) over every row, in the call's
    shape; the chain is kept when the writer records (the cached values of the cells)."""
    shape = np.broadcast_shapes(of.shape, np.shape(a), np.shape(b))
    f = of.over(shape)
    flat = [np.broadcast_to(np.asarray(v, dtype=float), shape).reshape(-1) for v in (a, b)]
    idx = np.arange(math.prod(shape), dtype=float)
    with np.errstate(all="ignore"):
        steps = steps_of(f, *flat, idx)
    kept = chains()
    if kept is not None:
        kept.setdefault(id(of.body), []).append((of.body, steps))
    return {k: v.reshape(shape) if k in ("root", "value", "where") else v for k, v in steps.items()}


def _golden(f, a, b, idx, kind: str, of) -> dict:
    """What the workbook's live extremum computes, row by row: EXPR at the 4 x samples + 1
    points A + (B-A)*j/m, the first sample k as good as the best to SAME, then GOLDEN_STEPS
    golden-section steps on [x(k-1), x(k+1)] (c = hi - (hi-lo)*g, d = lo + (hi-lo)*g, the
    side of the better of f(c), f(d) kept, the left one when they are within SAME of each
    other); the result is f at the middle of the last bracket, or the best sample where that
    is better by more than SAME."""
    m = 4 * of.tolerance.samples
    sign = 1.0 if kind == "max" else -1.0
    width = b - a
    xs = [a + width * j / m for j in range(m + 1)]
    fs = [np.broadcast_to(np.asarray(f(x, idx), dtype=float), a.shape) for x in xs]
    values = np.vstack(fs)
    top = np.max(sign * values, axis=0) * sign  # the best sample's value
    # the first sample as good as the best to SAME (the workbook's samples, computed by
    # another program, break a tie of two equal peaks the same way)
    near = sign * (values - top) >= -SAME * (np.abs(values) + np.abs(top))
    k = np.argmax(near, axis=0)
    best = np.take_along_axis(values, k[None], axis=0)[0]
    lo = a + width * np.maximum(k - 1, 0) / m
    hi = a + width * np.minimum(k + 1, m) / m
    out = {"samples": fs, "k": k.astype(float), "lo": [lo], "hi": [hi], "fc": [], "fd": []}
    for _ in range(GOLDEN_STEPS):
        c, d = hi - (hi - lo) * GOLDEN, lo + (hi - lo) * GOLDEN
        fc = np.asarray(f(c, idx), dtype=float)
        fd = np.asarray(f(d, idx), dtype=float)
        left = sign * (fc - fd) >= -SAME * (np.abs(fc) + np.abs(fd))
        lo, hi = np.where(left, lo, c), np.where(left, d, hi)
        out["lo"].append(lo)
        out["hi"].append(hi)
        out["fc"].append(fc)
        out["fd"].append(fd)
    x = (lo + hi) / 2
    fx = np.asarray(f(x, idx), dtype=float)
    better = sign * (fx - best) >= -SAME * (np.abs(fx) + np.abs(best))
    out["fx"] = fx
    out["value"] = np.where(better, fx, best)
    out["where"] = np.where(better, x, a + width * k / m)
    return out


def _root_numpy(of, a, b=None):
    from . import odestates, roots

    tol, var, unit = of.tolerance, of.var, of.unit_text
    if live() and b is not None:
        return _out(_live_chain(of, a, b, _bisection)["root"])
    if reference():
        from . import mpref
        from . import reference as ref

        values = mpref.root(of, a, b)
        if values is None and b is None:
            values = _solve(of, lambda f, a, idx, label: ref.root_near(f, a, (idx,)), a).value
        elif values is None:
            values = _solve(
                of, lambda f, a, b, idx, label: ref.root_in(f, a, b, (idx,)), a, b
            ).value
        return _merged(values, _root_numpy, of, a, b)
    if b is None:
        res = _solve(
            of,
            lambda f, a, idx, label: roots.root_near(
                f, a, (idx,), tol, var=var, unit=unit, label=label
            ),
            a,
        )
    else:
        enclose = of.enclosure(np.broadcast_shapes(of.shape, np.shape(a), np.shape(b)))
        res = _solve(
            of,
            lambda f, a, b, idx, label: roots.root_in(
                f, a, b, (idx,), tol, var=var, unit=unit, label=label, enclose=enclose
            ),
            a,
            b,
        )
    # a root hidden within the rounding of EXPR (a multiple root): polished in mpmath
    from .mpref import polish_roots

    shape = np.broadcast_shapes(of.shape, np.shape(a), *(() if b is None else (np.shape(b),)))
    polish_roots(of, res, shape, tol)
    from .rounding import root_rounding

    # EXPR's rounding over the slope, where the polish did not certify the row
    root_rounding(of, shape, res, np.abs(np.asarray(b, dtype=float) - a) if b is not None else a)
    odestates.add_root_error(of, shape, res)  # the states' global error, over the slope
    of.record("root", res)
    return _out(res.value)


def _integral_numpy(of, a, b):
    from . import gauss, odestates, quadrature, rounding

    if live():  # what the workbook's SUMPRODUCT computes
        res = _solve(
            of,
            lambda f, a, b, idx, label: Result(
                gauss.pieces_value(f, np.vstack([a, b]), EXCEL_NODES, (idx,)), np.zeros(a.shape)
            ),
            a,
            b,
        )
        return _out(res.value)
    shape = np.broadcast_shapes(of.shape, np.shape(a), np.shape(b))
    breaks = of.breaks(shape) + _kinks_located(of, shape, a, b)
    poles = _poles_located(of, shape, a, b)
    if reference():
        from . import mpref
        from . import reference as ref

        values = mpref.integral(of, a, b, breaks + poles)
        if values is None:
            values = _solve(
                of,
                lambda f, a, b, *rest: ref.integral(f, a, b, (rest[-2],), rest[:-2]),
                a,
                b,
                *breaks,
            ).value
        return _merged(values, _integral_numpy, of, a, b)
    tol, var, unit = of.tolerance, of.var, of.unit_text
    enclose, singular = of.enclosure(shape), of.singular(shape)
    res = _solve(
        of,
        lambda f, a, b, *rest: quadrature.integrate(
            f,
            a,
            b,
            (rest[-2],),
            tol,
            breaks=rest[: len(breaks)],
            poles=rest[len(breaks) : -2],
            var=var,
            unit=unit,
            label=rest[-1],
            enclose=enclose,
            singular=singular,
        ),
        a,
        b,
        *breaks,
        *poles,
    )
    rounding.integral_rounding(of, shape, a, b, res)  # EXPR's own rounding joins the estimate
    odestates.add_integral_error(of, shape, a, b, res)  # and the ODE states' global error
    of.record("integral", res)
    return _out(res.value)


def _kinks_located(of, shape, a, b, switches=None) -> list[np.ndarray]:
    """Break points where a sub-tree whose zeros are kinks of EXPR (abs(sin(x)), min of two
    curves) is 0, found by interval arithmetic (numerics.features.kink_points); or, given
    ``switches`` (:meth:`Bound.poles`), where a singular sub-tree is."""
    from .features import kink_points

    switches = of.switches(shape) if switches is None else switches
    if not switches:
        return []
    a, b = (np.broadcast_to(np.asarray(v, dtype=float), shape).reshape(-1) for v in (a, b))
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    # boxes of a millionth of the bracket at least: a root box is refined by find_root, an
    # unresolved one (a curve that touches zero) is split at its middle
    span = np.maximum(np.abs(lo), np.abs(hi))
    min_width = np.maximum(1e-6 * (hi - lo), 64 * np.spacing(span))
    out = []
    for g, h in switches:
        out += [p.reshape(shape) for p in kink_points(g, h, lo, hi, min_width)]
    return out


#: a located zero of a singular sub-tree is a pole where |the sub-tree| there is below this
#: share of its largest |value| at the ends and middle (not a touching zero's estimate)
POLE_ZERO = 1e-10


def _poles_located(of, shape, a, b) -> list[np.ndarray]:
    """Points where a singular sub-tree of EXPR (a denominator, tan's cosine, ...) is 0 inside
    [A, B], located as the kinks are; a point whose sub-tree is not 0 there (the middle of an
    unresolved box beside a touching zero) is left out (the row's lower bound instead)."""
    pairs = of.poles(shape)
    if not pairs:
        return []
    lo, hi = (np.broadcast_to(np.asarray(v, dtype=float), shape).reshape(-1) for v in (a, b))
    rows = np.arange(lo.size, dtype=float)
    out = []
    for g, h in pairs:
        for p in _kinks_located(of, shape, a, b, [(g, h)]):
            p = np.ravel(p)
            with np.errstate(all="ignore"):
                at = np.abs(np.broadcast_to(np.asarray(h(p, rows), float), p.shape))
                size = np.max(
                    [
                        np.abs(np.broadcast_to(np.asarray(h(x, rows), float), p.shape))
                        for x in (lo, (lo + hi) / 2, hi)
                    ],
                    axis=0,
                )
            size = np.where(np.isfinite(size), size, 0.0)
            keep = (at <= POLE_ZERO * size) & (size > 0)  # not a sub-tree that is 0 throughout
            out.append(np.where(keep, p, np.minimum(lo, hi)).reshape(shape))
    return out


def _extremum_numpy(name: str):
    kind = "max" if name.endswith("max") or name == "maximum" else "min"
    where = name.startswith("arg")

    def hook(of, a, b):
        from . import extrema, odestates

        if live():  # what the workbook's samples and golden-section steps compute
            steps = _live_chain(of, a, b, lambda f, a, b, idx: _golden(f, a, b, idx, kind, of))
            return _out(steps["where" if where else "value"])
        if reference():
            from . import mpref
            from . import reference as ref

            values = mpref.extremum_of(of, a, b, kind, where)
            if values is None:
                res = _solve(
                    of,
                    lambda f, a, b, idx, label: ref.extremum(f, a, b, (idx,), kind, where),
                    a,
                    b,
                )
                values = res.where if where else res.value
            return _merged(values, hook, of, a, b)
        tol, var, unit = of.tolerance, of.var, of.unit_text
        enclose = of.enclosure(np.broadcast_shapes(of.shape, np.shape(a), np.shape(b)))
        res = _solve(
            of,
            lambda f, a, b, idx, label: extrema.extremum(
                f,
                a,
                b,
                (idx,),
                tol,
                kind=kind,
                need_where=where,
                var=var,
                unit=unit,
                label=label,
                enclose=enclose,
            ),
            a,
            b,
        )
        from .rounding import extremum_rounding

        shape = np.broadcast_shapes(of.shape, np.shape(a), np.shape(b))
        if where:
            res = Result(
                res.where, res.where_error, res.where, evaluations=res.evaluations, notes=res.notes
            )
        extremum_rounding(of, shape, a, b, res, where)  # EXPR's own rounding near it
        if where:
            res.where = None
        else:  # the states' global error where the extremum is
            odestates.add_value_error(of, np.shape(res.value), res.where, res)
        if "assumes" in res.notes:
            res.notes["why"] = of.no_enclosure
        of.record(name, res)
        kept = chains()
        if kept is not None:  # the writer compares the live form with it
            kept.setdefault(("engine", id(of.body)), []).append(np.ravel(res.value))
        return _out(res.value)

    return hook


def _diff_numpy(of, order=1):
    """The derivative's formula where diff() is, checked (numerics.slopes)."""
    from .slopes import derivative_values

    return derivative_values(of, int(order))


def _product_numpy(of, a, b):
    from . import series

    var = of.var
    res = _solve(
        of,
        lambda f, a, b, idx, label: series.reduce(f, a, b, (idx,), kind="product", var=var),
        a,
        b,
    )
    series.record_series(of, a, b, res.value, 0.0, None, kind="product")
    return _out(res.value)


def _merged(ref: np.ndarray, hook, of, *bounds):
    """The reference's values, and the engine's where the reference left a row out (NaN)."""
    reference_values(of.body, ref)
    if not np.isnan(ref).any():
        return _out(ref)
    with reference_methods(False):
        engine = np.broadcast_to(np.asarray(hook(of, *bounds), dtype=float), np.shape(ref))
    return _out(np.where(np.isnan(ref), engine, ref))


def _out(v: np.ndarray):
    return float(v) if np.ndim(v) == 0 else v


# -- Excel --------------------------------------------------------------------------------------
def _root_excel(body, args, consts) -> tuple[str, int]:
    """A live root of a scalar definition: BISECTION_STEPS bisection steps in helper cells
    (lo, hi, mid, f(lo), f(mid) a row, each with its cached value); #N/A when f(A) and f(B)
    have the same sign. In a table column: one chain a table row (:func:`_root_rows`)."""
    from . import gauss

    gauss.refuse_in_integral("root", (*body.scope, *args), EXCEL_NODES)
    helpers = getattr(body, "helpers", None)
    if getattr(helpers, "per_row", False):
        return _root_rows(body, args, helpers)
    free = helpers is not None and len(args) == 2
    free = (
        free
        and not (ty.parameters(body.typed) - {body.var})
        and not any(ty.parameters(a) for a in body.rest)
    )
    if not free:
        raise NotLive(
            "root() is computed by find_root (scipy.optimize.elementwise) to the sheet's "
            "tolerance; its value is written as a number (a live root is written for a scalar "
            "definition with a bracket, as bisection steps)"
        )
    a, b = args
    if max(len(body(a)), len(body(b))) > 2000:
        raise NotLive("root(): the expression is too long for bisection steps in helper cells")

    def f(x: float) -> float:
        return helpers.value(body.typed, {body.var: x})

    try:  # the cached values: the same steps in the engine, before any cell is written
        rows = []
        lo, hi = (helpers.value(t, {}) for t in body.rest)
        for _ in range(BISECTION_STEPS + 1):
            mid = (lo + hi) / 2
            flo, fmid = f(lo), f(mid)
            rows.append((lo, hi, mid, flo, fmid))
            lo, hi = (lo, mid) if flo * fmid <= 0 else (mid, hi)
    except WorkbookError as err:
        raise NotLive(
            f"root(): the bisection steps leave the expression's domain ({err.message})"
        ) from None
    headers = ["lo", "hi", "mid", "f(lo)", "f(mid)"]
    block = helpers("root() by bisection", BISECTION_STEPS + 1, headers)
    r = block.ref
    for k, (lo, hi, mid, flo, fmid) in enumerate(rows):
        if k:
            left = f"{r(k - 1, 3)}*{r(k - 1, 4)}<=0"
            block.write(k, 0, f"=IF({left},{r(k - 1, 0)},{r(k - 1, 2)})", lo)
            block.write(k, 1, f"=IF({left},{r(k - 1, 2)},{r(k - 1, 1)})", hi)
        else:
            block.write(0, 0, f"={a}", lo)
            block.write(0, 1, f"={b}", hi)
        block.write(k, 2, f"=({r(k, 0)}+{r(k, 1)})/2", mid)
        block.write(k, 3, "=" + body(r(k, 0)), flo)
        block.write(k, 4, "=" + body(r(k, 2)), fmid)
    same_sign = f"{r(0, 3)}*({body(r(0, 1))})>0"
    return f"IF({same_sign},NA(),{r(BISECTION_STEPS, 2)})", ATOM


def _root_rows(body, args, helpers) -> tuple[str, int]:
    """A live root in a table column: BISECTION_STEPS bisection steps for every table row, in
    a block of the sheet 'Solver rows' whose row i is the table's row i (f(A), f(B), then
    lo, hi and f(mid) of each step; f(lo) keeps the sign of f(A)). The cached values are the
    engine's same steps (``_bisection``); #N/A when f(A) and f(B) have the same sign."""
    if len(args) != 2:
        raise NotLive(
            "root() from a guess is computed by find_root (scipy.optimize.elementwise) to the "
            "sheet's tolerance; its values are written as numbers (a bracketed root is live)"
        )
    a, b = args
    if max(len(body(f"({a})")), len(body(f"({b})"))) > 2000:
        raise NotLive("root(): the expression is too long for bisection steps in helper cells")
    n = BISECTION_STEPS
    headers = ["f(A)", "f(B)"]
    for k in range(n + 1):
        headers += [f"lo {k}", f"hi {k}"] + ([f"f(mid) {k}"] if k < n else [])
    block = helpers.block("root() by bisection, one row per table row", headers)  # the limit
    steps = helpers.chain(body.typed)
    r = block.ref
    fa, fb = r(0), r(1)

    def lo(k: int) -> str:
        return r(2 + 3 * k)

    def hi(k: int) -> str:
        return r(3 + 3 * k)

    block.write(0, "=" + body(f"({a})"), steps["fa"])
    block.write(1, "=" + body(f"({b})"), steps["fb"])
    for k in range(n + 1):
        if k:
            left = f"{fa}*{r(4 + 3 * (k - 1))}<=0"
            mid = f"({lo(k - 1)}+{hi(k - 1)})/2"
            block.write(2 + 3 * k, f"=IF({left},{lo(k - 1)},{mid})", steps["lo"][k])
            block.write(3 + 3 * k, f"=IF({left},{mid},{hi(k - 1)})", steps["hi"][k])
        else:
            block.write(2, f"={a}", steps["lo"][0])
            block.write(3, f"={b}", steps["hi"][0])
        if k < n:
            block.write(4 + 3 * k, "=" + body(f"(({lo(k)}+{hi(k)})/2)"), steps["fm"][k])
    return f"IF({fa}*{fb}>0,NA(),({lo(n)}+{hi(n)})/2)", ATOM


def _cells(helpers, title: str, headers: list[str]):
    """One row of helper cells, in a scalar definition's block or a table row's block:
    (ref(j), write(j, formula, value or values))."""
    if getattr(helpers, "per_row", False):
        block = helpers.block(title, headers)
        return block.ref, block.write
    block = helpers(title, 1, headers)
    return (lambda j: block.ref(0, j)), (
        lambda j, f, v: block.write(0, j, f, float(np.ravel(v)[0]))
    )


def _close_to_engine(name: str, steps: dict) -> None:
    """NotLive unless the live form is within LIVE_EXTREMUM of the engine's value in every
    row (a peak at a kink, or the position of a flat one, is not)."""
    live = np.ravel(steps["where" if name.startswith("arg") else "value"])
    engine = steps.get("engine")
    if engine is None or np.shape(engine) not in ((1,), live.shape):
        raise NotLive(f"{name}(): the engine's value to compare the live form with is unknown")
    diff = float(np.max(np.abs(live - engine)))
    scale = float(np.max(np.abs(engine))) or 1.0
    if diff > LIVE_EXTREMUM * scale:
        raise NotLive(
            f"{name}() is computed by sampling and find_minimum (scipy.optimize.elementwise); "
            f"its live form (samples and golden-section steps) would differ from the engine's "
            f"value by {diff:.2g} ({diff / scale:.1g} relative, more than {LIVE_EXTREMUM:g}), "
            "so the value is written as a number"
        )


def _first_best(kind: str, samples: str, m: int) -> str:
    """Excel's position (from 0) of the first of the m + 1 samples (a row of cells) as good
    as the best to SAME (as ``_golden``): m less the largest of (m - j) over the samples j
    that are."""
    near = _not_worse(kind, samples, f"{kind.upper()}({samples})")
    countdown = ",".join(str(m - j) for j in range(m + 1))
    return f"{m}-SUMPRODUCT(MAX(({near})*{{{countdown}}}))"


def _not_worse(kind: str, p: str, q: str) -> str:
    """Excel's test that EXPR at p is at least as good as at q, to SAME (as ``_golden``)."""
    diff = f"{p}-{q}" if kind == "max" else f"{q}-{p}"
    same = repr(SAME).replace("e", "E")
    return f"{diff}>=-{same}*(ABS({p})+ABS({q}))"


def _extremum_excel(name: str):
    kind = "max" if name.endswith("max") or name == "maximum" else "min"

    def excel(body, args, consts) -> tuple[str, int]:
        """A live extremum: EXPR at 4 x samples + 1 points of [A, B], the first best one
        (MATCH), then GOLDEN_STEPS golden-section steps around it, in helper cells (a row of
        the sheet 'Solver steps'; in a table, one row per table row on 'Solver rows')."""
        from . import gauss

        gauss.refuse_in_integral(name, (*body.scope, *args), EXCEL_NODES)
        helpers = getattr(body, "helpers", None)
        if helpers is None or not hasattr(helpers, "chain"):
            raise NotLive(
                f"{name}() is computed by sampling and find_minimum (scipy.optimize."
                "elementwise); its value is written as a number (live as samples and "
                "golden-section steps in a scalar definition or a table column)"
            )
        a, b = args
        steps = helpers.chain(body.typed)
        _close_to_engine(name, steps)
        m, n = len(steps["samples"]) - 1, GOLDEN_STEPS
        headers = [f"f(x{j})" for j in range(m + 1)] + ["best"]
        for s in range(n + 1):
            headers += [f"lo {s}", f"hi {s}"] + ([f"f(c) {s}", f"f(d) {s}"] if s < n else [])
        headers.append("f(x)")
        ref, write = _cells(helpers, f"{name}() by samples and golden section", headers)

        def x(j: str) -> str:
            return f"(({a})+(({b})-({a}))*{j}/{m})"

        for j in range(m + 1):
            write(j, "=" + body(x(str(j))), steps["samples"][j])
        samples = f"{ref(0)}:{ref(m).split('!')[1]}"
        k = ref(m + 1)
        write(m + 1, "=" + _first_best(kind, samples, m), steps["k"])
        best = f"INDEX({samples},1,{k}+1)"
        g = repr(GOLDEN)
        col = m + 2
        for s in range(n + 1):
            lo, hi = ref(col), ref(col + 1)
            if s:
                plo, phi, fc, fd = (ref(col - 4 + i) for i in range(4))
                c, d = f"({phi}-({phi}-{plo})*{g})", f"({plo}+({phi}-{plo})*{g})"
                keep = _not_worse(kind, fc, fd)
                write(col, f"=IF({keep},{plo},{c})", steps["lo"][s])
                write(col + 1, f"=IF({keep},{d},{phi})", steps["hi"][s])
            else:
                write(col, f"={x(f'MAX({k}-1,0)')}", steps["lo"][0])
                write(col + 1, f"={x(f'MIN({k}+1,{m})')}", steps["hi"][0])
            if s < n:
                c, d = f"({hi}-({hi}-{lo})*{g})", f"({lo}+({hi}-{lo})*{g})"
                write(col + 2, "=" + body(c), steps["fc"][s])
                write(col + 3, "=" + body(d), steps["fd"][s])
                col += 4
        mid = f"(({ref(col)}+{ref(col + 1)})/2)"
        fx = ref(col + 2)
        write(col + 2, "=" + body(mid), steps["fx"])
        better = _not_worse(kind, fx, best)
        if name.startswith("arg"):
            return f"IF({better},{mid},{x(k)})", ATOM
        return f"IF({better},{fx},{best})", ATOM

    return excel


def _integral_excel(body, args, consts) -> tuple[str, int]:
    """A live integral: the EXCEL_NODES-point Gauss-Legendre rule on [A, B] over constant
    arrays of nodes and weights (EXPR printed once, over the node array; see gauss.py)."""
    from . import gauss

    a, b = args
    return gauss.excel_form(body, a, b, EXCEL_NODES, body.scope), PREC["*"]


def _product_excel(body, args, consts) -> tuple[str, int]:
    from ..functions.builtins import MAX_EXCEL_TERMS, live_terms, sum_index

    lo, hi = consts
    if lo is None or hi is None:  # bounds that follow the inputs
        return live_terms(body, args[0], args[1], "*", "1"), ATOM
    lo, hi = sum_index(lo, "first"), sum_index(hi, "last")
    if hi < lo:
        return "1", ATOM
    if hi - lo + 1 > MAX_EXCEL_TERMS:
        raise NotLive(f"product() of {hi - lo + 1} factors (written out up to {MAX_EXCEL_TERMS})")
    terms = [body(str(i) if i >= 0 else f"({i})") for i in range(lo, hi + 1)]
    return "(" + ")*(".join(terms) + ")", PREC["*"]


def _diff_excel(body, args, consts) -> tuple[str, int]:
    """The derivative's formula, live like any other (found at first use)."""
    from .derivative import formula

    order = int(consts[0]) if consts else 1
    return body.tree(formula(body.typer, body.typed, body.var_param, order))


# -- sympy --------------------------------------------------------------------------------------
def _integral_sympy(sp, body, var, a, b):
    return sp.Integral(body, (var, a, b))


def _product_sympy(sp, body, var, a, b):
    return sp.Product(body, (var, a, b)).doit()


def _diff_sympy(sp, body, var, order=1):
    return sp.diff(body, var, int(order))


def _no_sympy(name: str):
    why = f"{name}() is solved numerically: it has no formula to differentiate"

    def convert(sp, body, var, *rest):
        raise NotSymbolic(why)

    convert.refusal = why  # read by workbook.engine.symbolic.refusal, without SymPy
    return convert


register(
    Builtin(
        "root",
        (3, 4),
        _root_unit,
        _root_numpy,
        _root_excel,
        _no_sympy("root"),
        doc="root(EXPR, X, A, B): the X in [A, B] where EXPR changes sign; "
        "root(EXPR, X, GUESS): a root near GUESS",
        binds=(0, 1),
    )
)
register(
    Builtin(
        "integral",
        4,
        _integral_unit,
        _integral_numpy,
        _integral_excel,
        _integral_sympy,
        doc="integral(EXPR, X, A, B): the definite integral of EXPR for X from A to B",
        binds=(0, 1),
        mathml="<msubsup><mo>\u222b</mo>{2}{3}</msubsup>{0:group}<mo>\u2062</mo>"
        "<mi mathvariant='normal'>d</mi>{1}",
    )
)
for _name, _text, _shown in (
    ("maximum", "the largest value of EXPR for X in [A, B]", "max"),
    ("minimum", "the smallest value of EXPR for X in [A, B]", "min"),
    ("argmax", "the X in [A, B] where EXPR is largest", "arg\u2009max"),
    ("argmin", "the X in [A, B] where EXPR is smallest", "arg\u2009min"),
):
    register(
        Builtin(
            _name,
            4,
            _extremum_unit,
            _extremum_numpy(_name),
            _extremum_excel(_name),
            _no_sympy(_name),
            doc=f"{_name}(EXPR, X, A, B): {_text} (the global one: see docs/numerics.md)",
            binds=(0, 1),
            mathml=f"<munder><mi>{_shown}</mi><mrow>{{1}}<mo>\u2208</mo><mrow><mo>[</mo>{{2}}"
            "<mo separator='true'>,</mo>{3}<mo>]</mo></mrow></mrow></munder>{0:group}",
        )
    )
register(
    Builtin(
        "diff",
        (2, 3),
        _diff_unit,
        _diff_numpy,
        _diff_excel,
        _diff_sympy,
        doc="diff(EXPR, X) or diff(EXPR, X, N): the (N-th) derivative of EXPR in X, "
        "found symbolically at first use (a formula like any other)",
        binds=(0, 1),
        mathml="<mfrac><mi mathvariant='normal'>d</mi><mrow><mi mathvariant='normal'>d</mi>{1}"
        "</mrow></mfrac>{0:group}",
    )
)
register(
    Builtin(
        "product",
        4,
        _product_unit,
        _product_numpy,
        _product_excel,
        _product_sympy,
        doc="product(EXPR, I, A, B): EXPR multiplied over the integers I = A..B (1 if B < A)",
        binds=(0, 1),
        mathml="<munderover><mo>\u220f</mo><mrow>{1}<mo>=</mo>{2}</mrow>{3}</munderover>{0:group}",
    )
)


# -- interpolation in [data] columns ------------------------------------------------------------
def _interp_unit(ctx, name: str, args: tuple) -> ty.T:
    from .interpolate import check_data

    xs, ys, x = args
    if not (isinstance(xs, ty.TRef) and xs.kind == "data") or not (
        isinstance(ys, ty.TRef) and ys.kind == "data"
    ):
        return _interp_vectors(ctx, name, args)
    cx, cy = ctx.spec.data[xs.name], ctx.spec.data[ys.name]
    if cx.table != cy.table:
        raise TemplateError(
            f"{name}(): {xs.name} is a column of '{cx.table}' and {ys.name} of '{cy.table}': "
            "give two columns of one data table"
        )
    check_data(cx.values, cy.values, f"{name}({xs.name}, {ys.name}, ...) in {cx.file.name}")
    if x.unit.dimensionality != xs.unit.dimensionality and not _zero(x):
        raise UnitError(
            f"{name}(): x is {un.dims(x.unit)} ({un.pretty(x.unit) or '1'}), but the data "
            f"column {xs.name} is {un.dims(xs.unit)} ({un.pretty(xs.unit) or '1'})"
        )
    x = ctx.convert(x, xs.unit, f"{name}(): x")  # a bare 45 in data in deg is 45 deg
    return ty.TFunc(ys.unit, func=name, args=(xs, ys, x))


def _interp_vectors(ctx, name: str, args: tuple) -> ty.T:
    """linterp(vx, vy, x) of two vectors (of the sheet, or of a program): their lengths are
    checked at load when known, else when they run."""
    xs, ys, x = args
    for k, v in ((1, xs), (2, ys)):
        if v.shape is None:
            raise TemplateError(f"{name}(): argument {k} must be a vector or a [data] column")
        if not ty.is_runtime(v.shape) and v.shape[1] != 1:
            shown = ty.shape_text(v.shape)
            raise TemplateError(f"{name}(): argument {k} is a {shown}, not a vector")
    if not ty.is_runtime(xs.shape) and not ty.is_runtime(ys.shape) and xs.shape != ys.shape:
        raise TemplateError(
            f"{name}(): x and y need the same number of values ({ty.shape_text(xs.shape)} and "
            f"{ty.shape_text(ys.shape)})"
        )
    if x.shape is not None and not ty.is_runtime(x.shape):
        raise TemplateError(f"{name}(): x is a vector or matrix; give a number")
    x = ctx.convert(x, xs.unit, f"{name}(): x")
    return ty.TFunc(ys.unit, func=name, args=(xs, ys, x))


def _interp_numpy(kind: str):
    def hook(xs, ys, x):
        from .interpolate import check_data, interpolate

        what = f"{_KINDS[kind]}()"
        if np.ndim(xs) == 2:  # vectors (columns), not [data] columns: checked as they run
            xs = _data_vector(xs, what)
            ys = _data_vector(ys, what)
            check_data(xs, ys, what)
        return _out(interpolate(xs, ys, x, kind=kind, what=what))

    return hook


def _data_vector(v, what: str) -> np.ndarray:
    v = np.asarray(v)
    if v.ndim != 2 or v.shape[1] != 1 or v.dtype == object:
        raise NumericsError(f"{what}: the data must be vectors of numbers")
    return v[:, 0].astype(float)


_KINDS = {"linear": "linterp", "cubic": "cspline"}


def _interp_excel(args) -> tuple[str, int]:
    raise NotLive("interpolation in a [data] table: its values are written as numbers")


def _points(ctx, v: ty.T, name: str, k: int) -> int:
    """The number of points of a [data] column or a vector known at load."""
    if isinstance(v, ty.TRef) and v.kind == "data":
        return len(ctx.spec.data[v.name].values)
    if v.shape is None or ty.is_runtime(v.shape) or v.shape[1] != 1:
        shown = "a number" if v.shape is None else "not a vector of a length known at load"
        raise TemplateError(
            f"{name}(): argument {k} must be a vector or a [data] column, got {shown}"
        )
    return v.shape[0]


def _spline_unit(ctx, name: str, args: tuple) -> ty.T:
    """lspline/pspline/cspline(vx, vy): the second derivatives at the points, in vy's unit
    over vx's squared."""
    if len(args) == 3:
        return _interp_unit(ctx, name, args)
    xs, ys = args
    n, m = _points(ctx, xs, name, 1), _points(ctx, ys, name, 2)
    if n != m:
        raise TemplateError(f"{name}(vx, vy): vx has {n} points and vy {m}")
    return ty.TFunc(ys.unit / xs.unit**2, func=name, args=(xs, ys), shape=(n, 1))


def _spline_numpy(ends: str):
    def hook(xs, ys, x=None):
        from .splines import checked, second_derivatives

        if x is not None:  # cspline(X, Y, x)
            return _interp_numpy("cubic")(xs, ys, x)
        xs, ys = checked(xs, ys, f"{_SPLINES[ends]}()")
        return second_derivatives(xs, ys, ends)[:, None]

    return hook


def _spline_value_unit(ctx, name: str, args: tuple) -> ty.T:
    vs, xs, ys, x = args
    n, m = _points(ctx, xs, name, 2), _points(ctx, ys, name, 3)
    k = _points(ctx, vs, name, 1)
    if not n == m == k:
        raise TemplateError(f"interp(vs, vx, vy, x): vs, vx and vy have {k}, {n} and {m} points")
    vs = ctx.convert(vs, ys.unit / xs.unit**2, "interp(vs, vx, vy, x): vs (a spline of vx, vy)")
    if x.shape is not None and not ty.is_runtime(x.shape):
        raise TemplateError("interp(vs, vx, vy, x): x is a vector or matrix; give a number")
    x = ctx.convert(x, xs.unit, "interp(vs, vx, vy, x): x")
    return ty.TFunc(ys.unit, func=name, args=(vs, xs, ys, x))


def _spline_value_numpy(vs, xs, ys, x):
    from .splines import checked, evaluate

    xs, ys = checked(xs, ys, "interp()")
    ms = np.asarray(vs, dtype=float).reshape(-1)
    return _out(evaluate(ms, xs, ys, x, "interp()"))


_SPLINES = {"linear": "lspline", "parabolic": "pspline", "cubic": "cspline"}

for _ends, _name in _SPLINES.items():
    if _name == "cspline":
        continue  # one entry with cspline(X, Y, x), below
    register(
        Builtin(
            _name,
            2,
            _spline_unit,
            _spline_numpy(_ends),
            _interp_excel,
            _no_sympy(_name),
            doc=f"{_name}(vx, vy): the second derivatives at the points of a cubic spline "
            f"through them with {_ends} ends, for interp (Mathcad's {_name})",
            data_args=(0, 1),
        )
    )
register(
    Builtin(
        "interp",
        4,
        _spline_value_unit,
        _spline_value_numpy,
        _interp_excel,
        _no_sympy("interp"),
        doc="interp(vs, vx, vy, x): the spline of lspline, pspline or cspline(vx, vy) at x "
        "(Mathcad's interp)",
        data_args=(1, 2),
    )
)

for _kind, _name in _KINDS.items():
    cubic = _kind == "cubic"
    register(
        Builtin(
            _name,
            (2, 3) if cubic else 3,
            _spline_unit if cubic else _interp_unit,
            _spline_numpy("cubic") if cubic else _interp_numpy(_kind),
            _interp_excel,
            _no_sympy(_name),
            doc=f"{_name}(X, Y, x): y at x, "
            + (
                "linear between the data points (Mathcad's linterp)"
                if _kind == "linear"
                else "on a cubic spline through the data points (Mathcad's interp(cspline(...))); "
                "cspline(vx, vy): that spline's second derivatives at the points, for interp"
            ),
            data_args=(0, 1),
        )
    )
