"""The live Excel forms of the numerical built-ins, and what they compute in numpy.

A root of a scalar definition with a bracket is written as BISECTION_STEPS bisection steps
in helper cells (in a table column, one chain a table row on 'Solver rows'); an extremum as
EXPR at 4 x samples + 1 points, the first best one, then GOLDEN_STEPS golden-section steps;
an integral as an EXCEL_NODES-point Gauss-Legendre sum; a product written out; diff as its
formula. :func:`bisection`, :func:`golden` and :func:`live_chain` compute the same steps in
numpy (the numpy hooks inside :func:`workbook.functions.numerical.live_forms`, and the cached
values of the step cells).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import NotLive, WorkbookError
from ..functions.numerical import chains
from ..language import typed as ty
from ..language.expr import PREC

ATOM = PREC["atom"]
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


# -- the steps in numpy ------------------------------------------------------------------------
def bisection(f, a, b, idx) -> dict[str, np.ndarray]:
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


def live_chain(of, a, b, steps_of) -> dict[str, np.ndarray]:
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


def golden(f, a, b, idx, kind: str, of) -> dict:
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


# -- Excel -------------------------------------------------------------------------------------
def root_excel(body, args, consts) -> tuple[str, int]:
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
    engine's same steps (``bisection``); #N/A when f(A) and f(B) have the same sign."""
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
    as the best to SAME (as ``golden``): m less the largest of (m - j) over the samples j
    that are."""
    near = _not_worse(kind, samples, f"{kind.upper()}({samples})")
    countdown = ",".join(str(m - j) for j in range(m + 1))
    return f"{m}-SUMPRODUCT(MAX(({near})*{{{countdown}}}))"


def _not_worse(kind: str, p: str, q: str) -> str:
    """Excel's test that EXPR at p is at least as good as at q, to SAME (as ``golden``)."""
    diff = f"{p}-{q}" if kind == "max" else f"{q}-{p}"
    same = repr(SAME).replace("e", "E")
    return f"{diff}>=-{same}*(ABS({p})+ABS({q}))"


def extremum_excel(name: str):
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


def integral_excel(body, args, consts) -> tuple[str, int]:
    """A live integral: the EXCEL_NODES-point Gauss-Legendre rule on [A, B] over constant
    arrays of nodes and weights (EXPR printed once, over the node array; see gauss.py)."""
    from . import gauss

    a, b = args
    return gauss.excel_form(body, a, b, EXCEL_NODES, body.scope), PREC["*"]


def product_excel(body, args, consts) -> tuple[str, int]:
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


def diff_excel(body, args, consts) -> tuple[str, int]:
    """The derivative's formula, live like any other (found at first use)."""
    from .derivative import formula

    order = int(consts[0]) if consts else 1
    return body.tree(formula(body.defs, body.typed, body.var_param, order))
