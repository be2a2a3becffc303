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

from ..errors import NotLive, NotSymbolic, TemplateError, UnitError
from ..functions.entry import Builtin, register
from ..functions.numerical import (
    NumericsError,
    Result,
    chains,
    live,
    reference,
    reference_methods,
    reference_values,
    sheet_tolerance,
)
from ..language import typed as ty
from ..language import units as un
from ..language.expr import PREC
from .excelforms import (
    EXCEL_NODES,
    bisection,
    diff_excel,
    extremum_excel,
    golden,
    integral_excel,
    live_chain,
    product_excel,
    root_excel,
)

ATOM = PREC["atom"]
#: rows solved at once (a bracket's samples take rows x samples memory)
CHUNK = 20_000
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
    from .symbolic import refusal

    why = refusal(ctx, body)
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


def _root_numpy(of, a, b=None):
    from . import odestates, roots

    tol, var, unit = of.tolerance, of.var, of.unit_text
    if live() and b is not None:
        return _out(live_chain(of, a, b, bisection)["root"])
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


#: a call of more rows than this is searched for poles on POLE_PROBE rows spread over it
#: first, and entirely only when one of them has one (as the features of an integrand)
POLE_ROWS, POLE_PROBE = 2_000, 32


def _poles_located(of, shape, a, b) -> list[np.ndarray]:
    """Points where a singular sub-tree of EXPR (a denominator, tan's cosine, ...) is 0 inside
    [A, B], located as the kinks are; a point whose sub-tree is not 0 there (the middle of an
    unresolved box beside a touching zero) is left out (the row's lower bound instead)."""
    pairs = of.poles(shape)
    if not pairs:
        return []
    a, b = (np.broadcast_to(np.asarray(v, dtype=float), shape).reshape(-1) for v in (a, b))
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    if lo.size > POLE_ROWS:
        sel = np.unique(np.linspace(0, lo.size - 1, POLE_PROBE).astype(np.intp))
        probe = _poles_at(pairs, lo[sel], hi[sel], sel)
        if not any(np.any((p > lo[sel]) & (p < hi[sel])) for p in probe):
            return []
    return [p.reshape(shape) for p in _poles_at(pairs, lo, hi, np.arange(lo.size))]


def _poles_at(pairs, lo, hi, rows) -> list[np.ndarray]:
    """:func:`_poles_located` on the flat rows ``rows`` of the call (lo, hi: theirs)."""
    from .features import kink_points

    span = np.maximum(np.abs(lo), np.abs(hi))
    min_width = np.maximum(1e-6 * (hi - lo), 64 * np.spacing(span))
    at_rows = np.arange(lo.size, dtype=float)
    out = []
    for g, h in pairs:

        def enclose(p, q, r, g=g):
            return g(p, q, rows[np.asarray(r).astype(np.intp)])

        def value(x, r, h=h):
            return h(x, rows[np.asarray(r).astype(np.intp)])

        for p in kink_points(enclose, value, lo, hi, min_width):
            with np.errstate(all="ignore"):
                there = np.abs(np.broadcast_to(np.asarray(value(p, at_rows), float), p.shape))
                size = np.max(
                    [
                        np.abs(np.broadcast_to(np.asarray(value(x, at_rows), float), p.shape))
                        for x in (lo, (lo + hi) / 2, hi)
                    ],
                    axis=0,
                )
            size = np.where(np.isfinite(size), size, 0.0)
            keep = (there <= POLE_ZERO * size) & (size > 0)  # not a sub-tree 0 throughout
            out.append(np.where(keep, p, lo))
    return out


def _extremum_numpy(name: str):
    kind = "max" if name.endswith("max") or name == "maximum" else "min"
    where = name.startswith("arg")

    def hook(of, a, b):
        from . import extrema, odestates

        if live():  # what the workbook's samples and golden-section steps compute
            steps = live_chain(of, a, b, lambda f, a, b, idx: golden(f, a, b, idx, kind, of))
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

    convert.refusal = why  # read by workbook.numerics.symbolic.refusal, without SymPy
    return convert


register(
    Builtin(
        "root",
        (3, 4),
        _root_unit,
        _root_numpy,
        root_excel,
        _no_sympy("root"),
        doc="root(EXPR, X, A, B): the X in [A, B] where EXPR changes sign; "
        "root(EXPR, X, GUESS): a root near GUESS",
        binds=(0, 1),
        estimate="iterative",
        live_note="60 bisection steps on the sheet 'Solver steps' (in a table, a chain per table "
        "row on 'Solver rows'; #N/A when f(A) and f(B) have the same sign; with more than one "
        "root in [A, B] it may find another one than the engine)",
        mathcad=("root",),
    )
)
register(
    Builtin(
        "integral",
        4,
        _integral_unit,
        _integral_numpy,
        integral_excel,
        _integral_sympy,
        doc="integral(EXPR, X, A, B): the definite integral of EXPR for X from A to B",
        binds=(0, 1),
        estimate="iterative",
        live_note="a 20-point Gauss-Legendre sum (SUMPRODUCT over constant nodes)",
        mathml="<msubsup><mo>\u222b</mo>{2}{3}</msubsup>{0:group}<mo>\u2062</mo>"
        "<mi mathvariant='normal'>d</mi>{1}",
        mathcad_operator="integral",
    )
)


def _extremum_note(name: str) -> str:
    """How the live Excel form of an extremum computes (said beside its cell)."""
    return (
        "samples at 4 x samples + 1 points and 60 golden-section steps around the best "
        "one, on the sheet 'Solver steps' or, in a table, 'Solver rows' (with two peaks "
        "nearly as high it may find another one than the engine)"
        + (
            "; where the extremum is, the workbook finds to about 1e-6 relative (values of "
            "EXPR within 1e-12 count as equal in its steps, so that another spreadsheet's "
            "rounding takes the same steps; the function is flat there), the engine to "
            "about 1e-8"
            if name.startswith("arg")
            else ""
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
            extremum_excel(_name),
            _no_sympy(_name),
            doc=f"{_name}(EXPR, X, A, B): {_text} (the global one: see docs/numerics.md)",
            binds=(0, 1),
            estimate="iterative",
            live_note=_extremum_note(_name),
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
        diff_excel,
        _diff_sympy,
        doc="diff(EXPR, X) or diff(EXPR, X, N): the (N-th) derivative of EXPR in X, "
        "found symbolically at first use (a formula like any other)",
        binds=(0, 1),
        estimate="iterative",
        mathml="<mfrac><mi mathvariant='normal'>d</mi><mrow><mi mathvariant='normal'>d</mi>{1}"
        "</mrow></mfrac>{0:group}",
        mathcad_operator="derivative",
    )
)
register(
    Builtin(
        "product",
        4,
        _product_unit,
        _product_numpy,
        product_excel,
        _product_sympy,
        doc="product(EXPR, I, A, B): EXPR multiplied over the integers I = A..B (1 if B < A)",
        binds=(0, 1),
        estimate="iterative",
        mathml="<munderover><mo>\u220f</mo><mrow>{1}<mo>=</mo>{2}</mrow>{3}</munderover>{0:group}",
        mathcad_operator="product",
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
            mathcad=(_name,),
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
        mathcad=("interp",),
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
            mathcad=(_name,),
        )
    )
