"""Checks of a hand calculation: derivative relations, joins of piecewise functions, domains.

* :func:`relation_results` differentiates the parent of each ``[[relations]]`` entry
  symbolically (:mod:`workbook.numerics.symbolic`) and compares ``factor * d(parent)/d(var)``
  with the hand-derived child over the relation's range (or the hull of the tables that show it).
* :func:`join_results` reads the conditions of every one-argument piecewise function as
  intervals: overlaps, gaps, and at each join the jump in value, first and second derivative.
* :func:`explain_domain` names the sub-expression and the argument interval where a formula
  leaves its domain (sqrt of a negative, division by zero, asin beyond 1); the numpy back end
  calls it when a function is not finite, so no NaN reaches a table or a workbook.

:func:`findings` turns all of them into :class:`workbook.findings.Finding` lines for
``workbook check`` and the Checks sheet. Findings are information; only a relation that
cannot be evaluated has the verdict ``fail``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import WorkbookError
from ..findings import Finding
from ..language import typed as ty
from ..language import units as un
from ..language.expr import PREC
from ..language.typed import children
from ..language.visitor import Visitor
from ..numerics.registry import REGISTRY

#: a relation "holds" when its largest discrepancy is below this fraction of max |child|
HOLDS = 1e-9
DEFAULT_POINTS = 2001


# -- helpers ------------------------------------------------------------------------------
def true_pi_sheet(sheet):
    """The sheet with an input named ``pi`` (a rounded pi such as 3.142) set to the true pi."""
    spec = sheet.spec.inputs.get("pi")
    if spec is None or spec.options or spec.unit.dimensionality:
        return sheet
    if float(sheet.values["pi"].magnitude) == math.pi:
        return sheet
    return sheet.with_inputs(pi=math.pi)


def _range_for(sheet, names: set[str], rng, points: int = DEFAULT_POINTS):
    """Values of ``rng``, or a fine grid over the hull of the tables/charts that show ``names``."""
    if rng is not None:
        return sheet.range_values(rng, "relation"), rng.var
    from ..language import expr as ex
    from ..language.uses import ranged_outputs

    lo, hi, var = math.inf, -math.inf, None
    for r, nodes in ranged_outputs(sheet.spec):
        used = set().union(*(ex.names(n) for n in nodes))
        if used & names:
            x = sheet.range_values(r, "relation")
            lo, hi, var = min(lo, x.min()), max(hi, x.max()), r.var
    if var is None:
        return None, None
    return np.linspace(lo, hi, points), var


def _fmt(x: float) -> str:
    return f"{x:.6g}"


# -- relations ----------------------------------------------------------------------------
@dataclass
class RelationResult:
    text: str
    child: str
    unit: str  # unit of the child (and of the discrepancy)
    var: str
    var_unit: str  # unit the argument is shown in
    max_abs: float | None = None
    at: float | None = None
    rel: float | None = None  # max_abs / max |child|
    child_max: float | None = None
    lo: float | None = None
    hi: float | None = None
    pi_rel: float | None = None  # the same with the sheet's own pi (if it has one)
    error: str = ""
    second: bool = False  # a composed relation (child against factor^2 * d2(grand)/dvar2)

    @property
    def holds(self) -> bool:
        return self.rel is not None and self.rel <= HOLDS

    @property
    def evaluated(self) -> bool:
        return not self.error


def _relation_values(sheet, child, terms, var, x, unit_child):
    """(child values, derivative values) over x; terms: list of (factor node, unit) and parent."""
    from ..numerics import symbolic

    factors, parent, order, var_unit = terms
    typer = sheet.typer
    fval, funit = 1.0, un.registry().dimensionless
    for node in factors:
        t = typer.expression(node, {}, "relation factor")
        fval *= float(sheet.evaluator.compile(t)({}))
        funit = funit * t.unit
    punit = typer.function(parent).unit
    vunit = un.unit(var_unit)
    combined = funit * punit / vunit**order
    if combined.dimensionality != unit_child.dimensionality:
        raise WorkbookError(
            f"units do not work out: factor * d(parent)/d({var}) is {un.dims(combined)} "
            f"({un.pretty(combined)}), {child} is {un.dims(unit_child)} ({un.pretty(unit_child)})"
        )
    conv = un.factor(combined, unit_child)
    fn = _derivative_fn(sheet, parent, var, order)
    scale = symbolic.per_radian(sheet, var, var_unit) ** order
    with np.errstate(all="ignore"):
        deriv = np.asarray(fn(x), dtype=complex) * (scale * fval * conv)
    if np.any(~np.isfinite(deriv)) or np.any(np.abs(deriv.imag) > 0):
        bad = x[~np.isfinite(deriv) | (deriv.imag != 0)]
        raise WorkbookError(
            f"d({parent})/d({var}) is not a finite real number for {var} from "
            f"{bad.min():g} to {bad.max():g}"
        )
    childv = sheet.evaluate(child, **{var: x}).to(unit_child).magnitude
    return np.broadcast_to(childv, x.shape), deriv.real


_DERIVATIVES: dict = {}


def _derivative_fn(sheet, parent: str, var: str, order: int):
    """numpy function of var: d^order(parent)/d(var)^order, cached per sheet and inputs.

    A sheet input named pi stays a symbol, so the sheet as written and the sheet with the
    true pi share one symbolic derivative.
    """
    import sympy as sp

    from ..numerics import symbolic

    own_pi = "pi" in sheet.spec.inputs and not sheet.spec.inputs["pi"].options
    inputs = tuple(sorted((k, str(v)) for k, v in sheet.values.items() if k != "pi"))
    key = (str(sheet.spec.path), sheet.spec.text, inputs, parent, var)
    pi = sp.Symbol("pi_sheet")
    exprs = _DERIVATIVES.setdefault(key, {})
    if 0 not in exprs:
        if len(_DERIVATIVES) > 64:
            _DERIVATIVES.clear()
            exprs = _DERIVATIVES.setdefault(key, {})
        syms = {var: symbolic.symbol(var, real=False)}
        if own_pi:
            syms["pi"] = pi
        exprs[0] = (symbolic.to_sympy(sheet, parent, syms), None)
    x = symbolic.symbol(var, real=False)
    for n in range(1, order + 1):
        if n not in exprs:
            exprs[n] = (sp.diff(exprs[n - 1][0], x), None)
    expr, fn = exprs[order]
    if fn is None:
        fn = sp.lambdify([x, pi], expr, modules="numpy")
        exprs[order] = (expr, fn)
    pval = float(sheet.values["pi"].magnitude) if own_pi else math.pi
    return lambda v: fn(v, pval)


def _measure(sheet, res: RelationResult, child, terms, x, var):
    unit_child = sheet.typer.function(child).unit
    c, d = _relation_values(sheet, child, terms, var, x, unit_child)
    diff = np.abs(c - d)
    i = int(np.argmax(diff))
    cmax = float(np.max(np.abs(c)))
    return (
        float(diff[i]),
        float(x[i]),
        (float(diff[i]) / cmax if cmax > 0 else float(diff[i])),
        cmax,
    )


def relation_results(sheet) -> list[RelationResult]:
    """Every declared relation, and the composed second-derivative ones, measured."""
    specs = sheet.spec.relations
    if not specs:
        return []
    ref = true_pi_sheet(sheet)
    by_child = {r.child: r for r in specs}
    out: list[RelationResult] = []
    for r in specs:
        res = RelationResult(r.text, r.child, "", r.var, "")
        out.append(res)
        try:
            for name in (r.child, r.parent):
                d = sheet.spec.definitions.get(name)
                if d is None or not d.is_function or r.var not in d.params:
                    raise WorkbookError(f"'{name}' is not a function of {r.var} in {sheet.name}")
            res.unit = un.pretty(sheet.typer.function(r.child).unit)
            arg = sheet.spec.arguments[r.var]
            res.var_unit = un.pretty(arg.unit)
            x, var = _range_for(sheet, {r.child, r.parent}, r.range)
            if x is None:
                raise WorkbookError(f'no range: add range = "{r.var} := ..." to the relation')
            res.lo, res.hi = float(x.min()), float(x.max())
            terms = ([r.factor], r.parent, 1, r.var_unit)
            res.max_abs, res.at, res.rel, res.child_max = _measure(ref, res, r.child, terms, x, var)
            if ref is not sheet:
                res.pi_rel = _measure(sheet, res, r.child, terms, x, var)[2]
            grand = by_child.get(r.parent)
            if grand is not None and grand.var == r.var:
                res2 = RelationResult(
                    f"{r.child} = {ex_text(r.factor)}*{ex_text(grand.factor)} * "
                    f"d2({grand.parent})/d({r.var})^2",
                    r.child,
                    res.unit,
                    r.var,
                    res.var_unit,
                    second=True,
                    lo=res.lo,
                    hi=res.hi,
                )
                terms2 = ([r.factor, grand.factor], grand.parent, 2, r.var_unit)
                try:
                    res2.max_abs, res2.at, res2.rel, res2.child_max = _measure(
                        ref, res2, r.child, terms2, x, var
                    )
                except Exception as exc:  # noqa: BLE001 - reported, not raised
                    res2.error = str(exc)
                out.append(res2)
        except Exception as exc:  # noqa: BLE001 - a relation that cannot be evaluated fails
            res.error = str(exc)
    return out


def ex_text(node) -> str:
    from ..language import expr as ex

    return ex.to_text(node)


def relation_findings(sheet) -> list[Finding]:
    out = []
    pi_note = ""
    for res in relation_results(sheet):
        if res.error:
            out.append(
                Finding(
                    "relations",
                    f"{res.text}: cannot be evaluated",
                    None,
                    "",
                    "info" if res.second else "fail",
                    res.error,
                )
            )
            continue
        span = f"{res.var} = {_fmt(res.lo)} .. {_fmt(res.hi)} {res.var_unit}".rstrip()
        if res.holds:
            what = f"{res.text}: holds over {span}"
            verdict = "ok"
        else:
            what = (
                f"{res.text}: does NOT hold; largest discrepancy at {res.var} = "
                f"{_fmt(res.at)} {res.var_unit}".rstrip()
            )
            verdict = "warning"
        note = (
            f"largest |{res.child} - derivative| = {res.max_abs:.3g} {res.unit} at "
            f"{res.var} = {_fmt(res.at)}, {res.rel:.2e} of max |{res.child}| = "
            f"{res.child_max:.6g} {res.unit}"
        )
        if res.pi_rel is not None:
            note += f"; with the sheet's own pi the relative discrepancy is {res.pi_rel:.2e}"
            pi_note = "x"
        out.append(Finding("relations", what, res.max_abs, res.unit, verdict, note))
    if pi_note:
        out.append(
            Finding(
                "relations",
                "relations are measured with the true pi in place of the sheet's pi "
                "(the derivative is per true radian)",
                None,
                "",
                "info",
                "see [pi rounding]",
            )
        )
    return out


# -- pi rounding ----------------------------------------------------------------------------
def pi_findings(sheet) -> list[Finding]:
    """The sheet's own pi against the true pi, and what it moves in the tables."""
    spec = sheet.spec.inputs.get("pi")
    if spec is None or spec.options or spec.unit.dimensionality:
        return []
    p = float(sheet.values["pi"].magnitude)
    out = [
        Finding(
            "pi rounding",
            f"the sheet's pi = {p:g} against the true pi = {math.pi:.10f}",
            p / math.pi - 1,
            "",
            "info",
            "relative: each of the sheet's degrees is this much larger than a true degree",
        )
    ]
    ref = true_pi_sheet(sheet)
    if ref is sheet:
        return out
    for t in sheet.spec.tables:
        if t.range is None:
            continue
        try:
            a, b = sheet.table_data(t.name), ref.table_data(t.name)
        except WorkbookError:
            continue
        for ca, cb in zip(a.columns[1:], b.columns[1:]):
            d = np.abs(ca.values - cb.values)
            i = int(np.argmax(d))
            out.append(
                Finding(
                    "pi rounding",
                    f"table {t.name}: {ca.title} moves by at most {d[i]:.3g} {un.pretty(ca.unit)} "
                    f"with the true pi (at {a.var} = {_fmt(a.columns[0].values[i])})",
                    float(d[i]),
                    un.pretty(ca.unit),
                    "info",
                )
            )
    return out


# -- joins of piecewise functions -----------------------------------------------------------
@dataclass
class Join:
    function: str
    at: float
    left: str
    right: str
    jumps: tuple  # (value, d1, d2) right minus left; d per var_unit
    units: tuple
    scale: tuple  # typical size of value, d1, d2 (max |.| of both sides at the join)


@dataclass
class PiecewiseResult:
    function: str
    var: str
    var_unit: str
    domain: tuple | None = None
    overlaps: list | None = None  # (piece i, piece j, set text)
    gaps: list | None = None
    joins: list | None = None
    error: str = ""


def _piece_names(t: ty.TPiecewise) -> list[str]:
    names = []
    for v, text in zip(t.values, t.texts):
        names.append(v.name if isinstance(v, ty.TCall) else text.split(" if ")[0].strip())
    return names


def join_results(sheet, var_unit: str = "rad") -> list[PiecewiseResult]:
    """Every one-argument piecewise function: overlaps, gaps and jumps at the joins."""
    out = []
    for name, d in sheet.spec.definitions.items():
        if d.branches is None or len(d.params) != 1:
            continue
        res = PiecewiseResult(name, d.params[0], "")
        try:
            _analyse_piecewise(sheet, name, res, var_unit)
        except Exception as exc:  # noqa: BLE001 - information only
            res.error = f"{type(exc).__name__}: {exc}"
        out.append(res)
    return out


def _analyse_piecewise(sheet, name, res: PiecewiseResult, var_unit: str):
    import sympy as sp

    from ..numerics import symbolic

    body = sheet.typer.function(name).body
    if not isinstance(body, ty.TPiecewise):
        res.error = "not a piecewise body"
        return
    var = res.var
    arg = sheet.spec.arguments[var]
    res.var_unit = un.pretty(arg.unit)
    x = symbolic.symbol(var, real=False)  # no assumptions: much faster to differentiate
    conv = symbolic.SympyConverter(sheet)
    env = {var: x}
    names = _piece_names(body)
    sets, exprs = [], []
    for cond, val in zip(body.conditions, body.values):
        c = sp.true if cond is None else conv.convert(cond, env)
        sets.append(_as_set(c, x))
        exprs.append(conv.convert(val, env))
    union = sp.Union(*sets)
    lo, hi = union.inf, union.sup
    res.domain = (float(lo), float(hi))
    hull = sp.Interval(lo, hi)
    taken = sp.S.EmptySet
    res.overlaps = []
    for i in range(len(sets)):
        for j in range(i + 1, len(sets)):
            common = sp.Intersection(sets[i], sets[j])
            if common is not sp.S.EmptySet:
                res.overlaps.append((names[i], names[j], str(common)))
        taken = sp.Union(taken, sets[i])
    gaps = sp.Complement(hull, union)
    res.gaps = [] if gaps is sp.S.EmptySet else [str(gaps)]
    # joins: boundaries inside the hull
    points = set()
    for s in sets:
        for b in s.boundary if s is not sp.S.Reals else []:
            if lo < b < hi:
                points.add(b)
    per = symbolic.per_radian(sheet, var, var_unit)
    unit = sheet.typer.function(name).unit
    res.joins = []
    for p in sorted(points, key=float):
        eps = sp.Rational(1, 10**9)

        def piece_at(v):
            for k, s in enumerate(sets):
                if s.contains(v) is sp.true:
                    return k
            return None

        left, right = piece_at(p - eps), piece_at(p + eps)
        if left is None or right is None or left == right:
            continue
        jumps, scale = [], []
        for order in range(3):
            a, b = (_piece_derivative(sheet, body, exprs, k, order, x, p) for k in (left, right))
            f = per**order
            jumps.append(float(b - a) * f)
            scale.append(max(abs(float(a)), abs(float(b))) * f)
        units = tuple(
            un.pretty(unit / un.unit(var_unit) ** k) if k else un.pretty(unit) for k in range(3)
        )
        res.joins.append(
            Join(name, float(p), names[left], names[right], tuple(jumps), units, tuple(scale))
        )


def _piece_derivative(sheet, body, exprs, k, order, x, p) -> float:
    """d^order of piece k at p: via the cached derivative when the piece is f(var)."""
    import sympy as sp

    val = body.values[k]
    if (
        isinstance(val, ty.TCall)
        and len(val.args) == 1
        and isinstance(val.args[0], ty.TParam)
        and val.args[0].name == str(x)
    ):
        return float(_derivative_fn(sheet, val.name, str(x), order)(float(p)))
    return float(sp.diff(exprs[k], x, order).evalf(30, subs={x: p}))


def _as_set(cond, x):
    """The set of x where a condition holds: fast for comparisons of x with numbers."""
    import sympy as sp

    if cond is sp.true:
        return sp.S.Reals
    if cond is sp.false:
        return sp.S.EmptySet
    if isinstance(cond, sp.And):
        return sp.Intersection(*[_as_set(a, x) for a in cond.args])
    if isinstance(cond, sp.Or):
        return sp.Union(*[_as_set(a, x) for a in cond.args])
    if isinstance(cond, sp.core.relational.Relational) and cond.rhs.is_number and cond.lhs == x:
        b, op = cond.rhs, cond.rel_op
    elif isinstance(cond, sp.core.relational.Relational) and cond.lhs.is_number and cond.rhs == x:
        b, op = cond.lhs, cond.reversed.rel_op
    else:
        return cond.as_set()
    oo = sp.oo
    return {
        "<": sp.Interval.open(-oo, b),
        "<=": sp.Interval(-oo, b),
        ">": sp.Interval.open(b, oo),
        ">=": sp.Interval(b, oo),
        "==": sp.FiniteSet(b),
        "!=": sp.Union(sp.Interval.open(-oo, b), sp.Interval.open(b, oo)),
    }[op]


def join_findings(sheet) -> list[Finding]:
    out = []
    for res in join_results(sheet):
        if res.error:
            out.append(
                Finding(
                    "joins", f"{res.function}: pieces not analysed", None, "", "info", res.error
                )
            )
            continue
        u = res.var_unit
        for a, b, common in res.overlaps:
            point = common.startswith("{")
            out.append(
                Finding(
                    "joins",
                    f"{res.function}: conditions of {a} and {b} overlap on {common} {u}".rstrip(),
                    None,
                    "",
                    "info" if point else "warning",
                    "the first true piece wins" + ("" if point else ": the later piece is hidden"),
                )
            )
        for g in res.gaps:
            out.append(
                Finding(
                    "joins",
                    f"{res.function}: no piece applies on {g} {u} inside "
                    f"{_fmt(res.domain[0])} .. {_fmt(res.domain[1])}",
                    None,
                    "",
                    "warning",
                )
            )
        if not res.overlaps and not res.gaps:
            out.append(
                Finding(
                    "joins",
                    f"{res.function}: pieces cover {_fmt(res.domain[0])} .. "
                    f"{_fmt(res.domain[1])} {u} without gaps or overlaps".rstrip(),
                    None,
                    "",
                    "ok",
                )
            )
        for j in res.joins:
            for order, label in enumerate(("value", "first derivative", "second derivative")):
                jump, scale = j.jumps[order], j.scale[order]
                cont = abs(jump) <= 1e-9 * max(scale, 1e-300)
                verdict = "ok" if cont else ("info" if order == 2 else "warning")
                d = "" if order == 0 else f" d{'' if order == 1 else '2'}/d{res.var}"
                out.append(
                    Finding(
                        "joins",
                        f"{res.function} at {res.var} = {_fmt(j.at)} {u} ({j.left} -> {j.right}): "
                        f"jump in {label}{d}",
                        jump,
                        j.units[order],
                        verdict,
                        "continuous" if cont else f"{abs(jump) / scale:.2%} of the larger side",
                    )
                )
    return out


# -- domains --------------------------------------------------------------------------------
def _pure(t: ty.T) -> bool:
    """True if the tree calls no solver block (cheap to evaluate on a grid)."""
    if isinstance(t, (ty.TBlock,)) or type(t).__name__ == "TAggregate":
        return False
    return all(_pure(c) for c in children(t))


def restricted(t: ty.T):
    """Yield (kind, argument node, test) for every sub-expression with a restricted domain."""
    for item in _restricted(t):
        if _pure(item[1]):
            yield item


def _restricted(t: ty.T):
    if isinstance(t, ty.TFunc):
        for d in REGISTRY[t.func].domain:
            yield d.kind, t.args[d.arg], d.bad, d.shown
    elif isinstance(t, ty.TBinary):
        if t.op == "/":
            yield "division by zero", t.right, lambda v: v == 0, "1/({})"
        elif t.op == "^" and isinstance(t.right, ty.TConst):
            n = t.right.value
            if not float(n).is_integer():
                shown = "({})^" + f"{n:g}"
                yield f"power {n:g} of a negative number", t.left, lambda v: v < 0, shown
            elif n < 0:
                shown = "({})^" + f"{n:g}"
                yield "division by zero (negative power of 0)", t.left, lambda v: v == 0, shown
    for child in children(t):
        yield from _restricted(child)


class TypedText(Visitor):
    """The typed tree back as worksheet text (unit conversions are implicit).

    ``visit(t)`` returns (text, precedence level of :data:`workbook.language.expr.PREC`).
    """

    def text(self, t: ty.T, parent: int = 0) -> str:
        s, p = self.visit(t)
        return f"({s})" if p < parent else s

    def visit_TConst(self, t: ty.TConst) -> tuple[str, int]:
        v = t.value
        if isinstance(v, complex):  # 3+4i, as written
            return f"({v.real:.6g}{v.imag:+.6g}i)", PREC["atom"]
        s = repr(int(v)) if float(v).is_integer() and abs(v) < 1e15 else f"{v:.6g}"
        return s, PREC["atom"]

    def visit_TParam(self, t) -> tuple[str, int]:
        return t.name, PREC["atom"]

    visit_TRef = visit_TParam

    def visit_TText(self, t: ty.TText) -> tuple[str, int]:
        return f'"{t.value}"', PREC["atom"]

    def visit_TScale(self, t: ty.TScale) -> tuple[str, int]:
        return self.visit(t.child)

    def visit_TUnary(self, t: ty.TUnary) -> tuple[str, int]:
        if t.op == "not":
            return "not " + self.text(t.child, PREC["not"]), PREC["not"]
        return "-" + self.text(t.child, PREC["neg"]), PREC["neg"]

    def visit_TBinary(self, t: ty.TBinary) -> tuple[str, int]:
        op = {"@": "*", "@^": "^"}.get(t.op, t.op)  # matrix product and power
        p = PREC[op]
        if op == "^":
            return f"{self.text(t.left, p + 1)}^{self.text(t.right, p)}", p
        return f"{self.text(t.left, p)} {op} {self.text(t.right, p + 1)}", p

    def visit_TCompare(self, t: ty.TCompare) -> tuple[str, int]:
        p = PREC["cmp"]
        parts = [self.text(t.operands[0], p + 1)]
        for op, o in zip(t.ops, t.operands[1:]):
            parts += [op, self.text(o, p + 1)]
        return " ".join(parts), p

    def visit_TLogic(self, t: ty.TLogic) -> tuple[str, int]:
        p = PREC[t.op]
        return f" {t.op} ".join(self.text(v, p + 1) for v in t.values), p

    def visit_TFunc(self, t: ty.TFunc) -> tuple[str, int]:
        return f"{t.func}({', '.join(self.text(a) for a in t.args)})", PREC["atom"]

    def visit_TCall(self, t) -> tuple[str, int]:
        return f"{t.name}({', '.join(self.text(a) for a in t.args)})", PREC["atom"]

    visit_TBlock = visit_TCall

    def visit_TAggregate(self, t: ty.TAggregate) -> tuple[str, int]:
        return f"{t.func}_over({t.table}, {t.column})", PREC["atom"]

    def visit_TPiecewise(self, t: ty.TPiecewise) -> tuple[str, int]:
        return "; ".join(t.texts), PREC["or"] - 1

    def visit_TMatrix(self, t: ty.TMatrix) -> tuple[str, int]:
        rows = ["[" + ", ".join(self.text(e) for e in row) + "]" for row in t.rows]
        return "[" + ", ".join(rows) + "]", PREC["atom"]

    def visit_TIndex(self, t: ty.TIndex) -> tuple[str, int]:
        inner = ", ".join(self.text(i) for i in t.indices)
        return f"{self.text(t.target, PREC['atom'])}[{inner}]", PREC["atom"]

    def visit_TProgram(self, t: ty.TProgram) -> tuple[str, int]:
        return f"the program of {t.name}", PREC["atom"]

    def visit_TOde(self, t: ty.TOde) -> tuple[str, int]:
        return f"{t.name}({', '.join(self.text(a) for a in t.args)})", PREC["atom"]


def typed_text(t: ty.T, parent: int = 0) -> str:
    """The typed tree back as worksheet text (unit conversions are implicit)."""
    return TypedText().text(t, parent)


def _squares(t: ty.T):
    """Bases of a product of squares (k^2*sin(x)^2 -> [k, sin(x)]), else None."""
    if isinstance(t, ty.TScale) and t.factor == 1.0:
        return _squares(t.child)
    if isinstance(t, ty.TBinary) and t.op == "^" and isinstance(t.right, ty.TConst):
        return [t.left] if t.right.value == 2 else None
    if isinstance(t, ty.TBinary) and t.op == "*":
        a, b = _squares(t.left), _squares(t.right)
        return a + b if a is not None and b is not None else None
    return None


def meaning(kind: str, node: ty.T) -> str:
    """What leaving the domain means in the sheet's terms: 1 - X^2 < 0 is |X| > 1."""
    if not (kind.startswith("sqrt") or kind.startswith("power")):
        return ""
    t = node.child if isinstance(node, ty.TScale) and node.factor == 1.0 else node
    if (
        isinstance(t, ty.TBinary)
        and t.op == "-"
        and isinstance(t.left, ty.TConst)
        and t.left.value == 1
    ):
        bases = _squares(t.right)
        if bases:
            return " (|" + "*".join(typed_text(b, 6) for b in bases) + "| > 1)"
    return ""


def _runs(x: np.ndarray, mask: np.ndarray) -> list[tuple[float, float]]:
    """Contiguous runs of True in mask, as (first x, last x)."""
    out, start = [], None
    for i, m in enumerate(mask):
        if m and start is None:
            start = i
        if not m and start is not None:
            out.append((float(x[start]), float(x[i - 1])))
            start = None
    if start is not None:
        out.append((float(x[start]), float(x[len(mask) - 1])))
    return out


def explain_domain(evaluator, typed: ty.TypedFunction, env: dict, units: dict | None = None) -> str:
    """Which sub-expression leaves its domain, and for which argument values ('' if unknown)."""
    parts = []
    try:
        (param,) = typed.params
        x = np.asarray(env[param], dtype=float)
    except (ValueError, KeyError, TypeError):
        return ""
    if x.ndim == 0:
        x = x.reshape(1)
    order = np.argsort(x, kind="stable")
    unit = (units or {}).get(param, "")
    seen = set()
    for kind, node, bad, shown in restricted(typed.body):
        try:
            with np.errstate(all="ignore"):
                v = np.broadcast_to(np.asarray(evaluator.compile(node)({param: x})), x.shape)
                mask = np.asarray(bad(v), dtype=bool)
        except Exception:  # noqa: BLE001 - the explanation must never hide the error
            continue
        if not mask.any():
            continue
        text = shown.format(typed_text(node))
        if (kind, text) in seen:
            continue
        seen.add((kind, text))
        runs = _runs(x[order], mask[order])
        where = ", ".join(
            f"{param} = {_fmt(a)}" if a == b else f"{param} from {_fmt(a)} to {_fmt(b)}"
            for a, b in runs[:4]
        )
        if len(runs) > 4:
            where += f" and {len(runs) - 4} more interval(s)"
        parts.append(f"{kind}: {text}{meaning(kind, node)} for {where} {unit}".rstrip())
    return "; ".join(parts)


def domain_margins(sheet) -> list[Finding]:
    """For each function shown in a range table: how far its restricted sub-expressions are
    from leaving their domain over the table's range, and where they would leave it."""
    out = []
    seen = set()
    for t in sheet.spec.tables:
        if t.range is None:
            continue
        try:
            x = sheet.range_values(t.range, t.name)
        except WorkbookError:
            continue
        var = t.range.var
        for col in t.columns:
            node = sheet.column_node(col, var)
            fname = getattr(node, "func", None)
            d = sheet.spec.definitions.get(fname or "")
            if d is None or len(d.params) != 1 or fname in seen:
                continue
            seen.add(fname)
            typed = sheet.typer.function(fname)
            lo, hi = float(x.min()), float(x.max())
            fine = np.linspace(lo, hi, 4001)
            ext = np.linspace(lo, lo + 4 * max(hi - lo, 1.0), 40001)
            unit = un.pretty(sheet.spec.arguments[var].unit)
            for kind, node_, bad, shown in restricted(typed.body):
                try:
                    with np.errstate(all="ignore"):
                        fn = sheet.evaluator.compile(node_)
                        inside = np.asarray(bad(np.broadcast_to(fn({var: fine}), fine.shape)))
                        outside = np.asarray(bad(np.broadcast_to(fn({var: ext}), ext.shape)))
                except Exception:  # noqa: BLE001
                    continue
                if inside.any():
                    runs = _runs(fine, inside)
                    out.append(
                        Finding(
                            "domains",
                            f"{fname}: {kind}: {shown.format(typed_text(node_))} for {var} from "
                            f"{_fmt(runs[0][0])} to {_fmt(runs[0][1])} {unit}",
                            None,
                            "",
                            "warning",
                            f"inside the range of table {t.name}",
                        )
                    )
                elif outside.any():
                    first = float(ext[np.argmax(outside)])
                    out.append(
                        Finding(
                            "domains",
                            f"{fname}: {shown.format(typed_text(node_))} is valid over "
                            f"{_fmt(lo)} .. {_fmt(hi)} {unit}; it leaves its domain at "
                            f"{var} ~ {_fmt(first)} {unit}",
                            first,
                            unit,
                            "ok",
                            f"{kind}{meaning(kind, node_)} beyond that angle",
                        )
                    )
    return out


# -- all --------------------------------------------------------------------------------------
def findings(sheet) -> list[Finding]:
    """Relations, joins, domain margins and pi rounding of a sheet (empty if it has none)."""
    out = relation_findings(sheet)
    try:
        out += join_findings(sheet)
        out += domain_margins(sheet)
        out += pi_findings(sheet)
    except WorkbookError as exc:  # a value the analysis needs cannot be computed: said, loud
        out.append(Finding("analysis", "analysis stopped", None, "", "warning", str(exc)))
    return out
