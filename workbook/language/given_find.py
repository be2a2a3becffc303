"""``[[solve]]`` blocks: Mathcad's Given/Find, a system of equations in named unknowns.

::

    [[solve]]
    unknowns = { x = "1 m", y = "0.5 m" }          # guesses; their units are the unknowns'
    equations = ["x^2 + y^2 == R^2", "y == x*tan(theta)"]

The unknowns are names for the rest of the sheet (references of kind ``solve``). The
equations are typed when the sheet is loaded (each side in the unknowns' units; the two sides
of an equation must agree), and solved when a value is first needed, by
:func:`workbook.numerics.given.solve`. Not converging is an error that lists every equation's
residual. In the workbook the unknowns, and what uses them, are written as numbers. A block
with ``parameters`` (arguments) is a function: each unknown is a definition of them, solved at
each value it is called with (:func:`solved_at`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pint

from ..errors import TemplateError, UnitError, WorkbookError
from . import expr as ex
from . import typed as ty
from . import units as un
from .fields import value_line

#: most unknowns of one block
MAX_UNKNOWNS = 50


@dataclass(frozen=True, eq=False)
class SolveSpec:
    """One [[solve]] block as written: unknowns with guesses, equations as (lhs, rhs, text)."""

    index: int
    unknowns: dict[str, pint.Quantity]
    equations: tuple[tuple[ex.Node, ex.Node, str], ...]
    line: int | None
    method: str = "hybrid"  # or "levenberg-marquardt" (Mathcad's Find)
    conditions: tuple[tuple[ex.Node, str], ...] = ()  # inequalities the root must meet
    parameters: tuple[str, ...] = ()  # arguments: the unknowns are functions of them

    @property
    def what(self) -> str:
        return f"solve {', '.join(self.unknowns)}"


def read_solves(raw: list, text: str) -> list[SolveSpec]:
    """The [[solve]] blocks of a template (equations parsed, not typed); ``text`` is the
    template's, for the lines of errors (the reader of the template claims the unknowns)."""
    out = []
    for i, block in enumerate(raw):
        if not isinstance(block, dict) or not (
            {"unknowns", "equations"}
            <= set(block)
            <= {"unknowns", "equations", "method", "conditions", "parameters"}
        ):
            raise TemplateError(
                '[[solve]] needs unknowns = { x = "1 m", ... } and equations = ["... == ...", ...]'
                ' (and optionally method = "hybrid", "levenberg-marquardt" or "nearest")'
            )
        from ..numerics.given import METHODS

        method = block.get("method", "hybrid")
        if method not in METHODS:
            raise TemplateError(
                f"[[solve]] method {str(method)!r}: one of {', '.join(METHODS)}",
                line=value_line(text, str(method)),
            )
        unknowns, equations = block["unknowns"], block["equations"]
        line = value_line(text, str(equations[0])) if equations else None
        what = f"solve {', '.join(map(str, unknowns))}"
        try:
            if not isinstance(unknowns, dict) or not unknowns or len(unknowns) > MAX_UNKNOWNS:
                raise TemplateError(f"[[solve]] unknowns: 1 to {MAX_UNKNOWNS} names with guesses")
            fewer = method != "hybrid"  # least squares: fewer equations than unknowns
            if not (
                isinstance(equations, list)
                and equations
                and (len(equations) <= len(unknowns) if fewer else len(equations) == len(unknowns))
            ):
                raise TemplateError(
                    f"[[solve]] has {len(unknowns)} unknown(s) and "
                    f"{len(equations) if isinstance(equations, list) else 0} equation(s): give "
                    "one equation per unknown"
                    + ("" if fewer else ' (or fewer, with method = "levenberg-marquardt")')
                )
            guesses = {}
            for name, guess in unknowns.items():
                guesses[name] = un.quantity(str(guess), None, what=name)
            eqs = tuple(_equation(e) for e in equations)
            conditions = block.get("conditions", [])
            if not isinstance(conditions, list):
                raise TemplateError('[[solve]] conditions = ["x > 0", ...] (a list)')
            conds = tuple(_condition(c) for c in conditions)
            params = block.get("parameters", [])
            if not isinstance(params, list) or not all(
                isinstance(q, str) and ex.is_identifier(q) for q in params
            ):
                raise TemplateError('[[solve]] parameters = ["th2", ...] (argument names)')
        except WorkbookError as err:
            raise err.located(line=line, definition=what) from None
        out.append(SolveSpec(i, guesses, eqs, line, method, conds, tuple(params)))
    return out


def _condition(text) -> tuple[ex.Node, str]:
    """An inequality the root must meet (Mathcad's ``x > 3`` beside the equations)."""
    node = ex.parse(str(text), what="condition")
    if not (isinstance(node, ex.Compare) and set(node.ops) <= {"<", "<=", ">", ">="}):
        raise TemplateError(f"a condition is written LEFT < RIGHT (or <=, >, >=), got {text!r}")
    return node, str(text)


def scope_of(typer, block: SolveSpec) -> dict:
    """The names in scope in a block's equations: the unknowns, and its parameters."""
    scope = {n: q.units for n, q in block.unknowns.items()}
    for name in block.parameters:
        arg = typer.spec.arguments.get(name)
        if arg is None:
            raise TemplateError(
                f"[[solve]] parameter '{name}' has no declared unit: add it to [arguments]"
            )
        scope[name] = arg.binding_unit
    return scope


def typed_conditions(typer, block: SolveSpec) -> list[tuple[ty.T, str]]:
    """The conditions, typed with the unknowns in scope (units checked at load)."""
    scope = scope_of(typer, block)
    return [(typer.expression(node, scope, block.what), text) for node, text in block.conditions]


def _equation(text) -> tuple[ex.Node, ex.Node, str]:
    node = ex.parse(str(text), what="equation")
    if not (isinstance(node, ex.Compare) and node.ops == ("==",)):
        raise TemplateError(f"an equation is written LEFT == RIGHT, got {str(text)!r}")
    return node.operands[0], node.operands[1], str(text)


def typed_equations(typer, block: SolveSpec) -> list[tuple[ty.T, ty.T]]:
    """Both sides of every equation, typed with the unknowns in scope (rhs in lhs's unit)."""
    scope = scope_of(typer, block)
    out = []
    for lhs, rhs, text in block.equations:
        left = typer.expression(lhs, scope, block.what)
        right = typer.expression(rhs, scope, block.what)
        zero = [
            isinstance(s, ty.TConst) and s.value == 0 and not s.unit.dimensionality
            for s in (left, right)
        ]
        if zero[0] and not zero[1]:  # 0 == x: zero in the other side's unit
            left = ty.TConst(right.unit, value=0.0)
        if left.unit.dimensionality != right.unit.dimensionality and not zero[1]:
            raise UnitError(
                f"equation {text!r}: the left side is {un.dims(left.unit)} "
                f"({un.pretty(left.unit) or '1'}), the right side {un.dims(right.unit)} "
                f"({un.pretty(right.unit) or '1'})"
            )
        out.append((left, typer.convert(right, left.unit, f"equation {text!r}")))
    return out


@dataclass(frozen=True)
class TypedSolve:
    """A [[solve]] block's trees, typed once when the sheet is loaded: both sides of every
    equation (the right in the left's unit), every condition, and every comparison of the
    conditions as (smaller side, larger side) in one unit."""

    equations: tuple[tuple[ty.T, ty.T], ...]
    conditions: tuple[tuple[ty.T, str], ...]
    comparisons: tuple[tuple[ty.T, ty.T], ...]


def type_block(typer, block: SolveSpec) -> TypedSolve:
    """Type a [[solve]] block's equations and conditions (units checked: load time)."""
    scope = scope_of(typer, block)
    comparisons = []
    for node, text in block.conditions:
        sides = [typer.expression(o, scope, block.what) for o in node.operands]
        for op, a, b in zip(node.ops, sides, sides[1:]):
            b = typer.convert(b, a.unit, f"condition {text!r}")
            comparisons.append((a, b) if op in ("<", "<=") else (b, a))
    return TypedSolve(
        tuple(typed_equations(typer, block)),
        tuple(typed_conditions(typer, block)),
        tuple(comparisons),
    )


def typed_block(sheet, block: SolveSpec) -> TypedSolve:
    """The block's trees typed at load (kept in ``sheet.typed``), typed now if they were not."""
    found = sheet.typed.get(block, "solve")
    return (
        found
        if found is not None
        else sheet.typed.keep(block, "solve", type_block(sheet.typer, block))
    )


def _violations(sheet, block: SolveSpec, names: list[str], at: dict):
    """x -> how far x is outside each condition (0 inside), relative to the size of the two
    sides at the guess: residuals for the solvers that honour the conditions while solving."""
    pairs = [  # (smaller side, larger side) of every comparison of a chain
        (sheet.evaluator.compile(lo), sheet.evaluator.compile(hi))
        for lo, hi in typed_block(sheet, block).comparisons
    ]
    guess = dict(zip(names, (q.magnitude for q in block.unknowns.values())), **at)
    with np.errstate(all="ignore"):
        sizes = [abs(float(lo(guess))) + abs(float(hi(guess))) for lo, hi in pairs]
    sizes = [z if np.isfinite(z) and z else 1.0 for z in sizes]

    def violations(x):
        env = dict(zip(names, (float(v) for v in x)), **at)
        return np.array(
            [max(float(lo(env)) - float(hi(env)), 0.0) / z for (lo, hi), z in zip(pairs, sizes)]
        )

    return violations


class Solved(dict):
    """The unknowns' values of a solved block, with ``errors`` (their estimates, same units)
    and ``condition`` (the condition number of the relative residuals' Jacobian)."""

    errors: dict[str, float]
    condition: float


#: Most points at which a block with parameters is solved in one evaluation.
MAX_POINTS = 100_000


def solved_at(sheet, block: SolveSpec, name: str, env: dict):
    """Unknown ``name`` of a block with parameters at the parameters' values in ``env``
    (numbers or arrays, broadcast): the block solved at each distinct point, once per sheet."""
    values = np.broadcast_arrays(*[np.asarray(env[p], dtype=float) for p in block.parameters])
    shape = values[0].shape
    if values[0].size > MAX_POINTS:
        from ..errors import LimitError

        raise LimitError(
            f"{block.what}: {values[0].size:,} points to solve at (limit {MAX_POINTS:,})"
        )
    out = np.empty(shape)
    memo = sheet.solutions_at(block)
    for ix in np.ndindex(shape):
        point = tuple(float(v[ix]) for v in values)
        if point not in memo:
            try:
                memo[point] = solve_block(sheet, block, dict(zip(block.parameters, point)))
            except WorkbookError as err:
                where = ", ".join(f"{p} = {v:g}" for p, v in zip(block.parameters, point))
                raise type(err)(f"{err.message} (at {where})") from None
        out[ix] = memo[point][name]
    return float(out) if out.ndim == 0 else out


def solve_findings(sheet) -> list:
    """A finding per solved [[solve]] block: its solution, each unknown's error estimate and
    the condition number; a warning when an estimate exceeds the sheet's tolerance relative
    to its unknown (a block that fails is a failed value, not listed here)."""
    from ..compute.findings import Finding
    from ..numerics import sheet_tolerance

    rtol = sheet_tolerance(sheet.spec.meta).rtol
    out = []
    for block in sheet.spec.solves:
        if block.parameters:  # a function: each point's estimate is not listed
            continue
        try:
            sheet.evaluate(next(iter(block.unknowns)))
        except WorkbookError:
            continue
        solved = sheet.solution(block)
        parts, worst = [], 0.0
        for name, q in block.unknowns.items():
            v, e = solved[name], solved.errors.get(name, float("nan"))
            unit = f" {un.pretty(q.units)}" if un.pretty(q.units) else ""
            step = un.pretty(un.difference_unit(q.units))  # an error is a difference: delta_degC
            step = f" {step}" if step else ""
            parts.append(f"{name} = {v:.10g}{unit} (error estimate {e:.2g}{step})")
            rel = e / abs(v) if v else e
            worst = max(worst, rel) if np.isfinite(rel) else float("inf")
        what = "; ".join(parts)
        note = f"condition number {solved.condition:.3g} of the equations' Jacobian"
        if worst > rtol:
            note += (
                f"; an estimate exceeds the sheet's tolerance {rtol:g} relative: the equations "
                "are ill-conditioned (nearly dependent), the solution is known only to the "
                "estimate"
            )
        out.append(Finding(block.what, what, None, "", "warning" if worst > rtol else "info", note))
    return out


def solve_block(sheet, block: SolveSpec, at: dict | None = None) -> dict[str, float]:
    """The unknowns' values (magnitudes in their guesses' units); ``at``: the values of the
    block's parameters (magnitudes in their binding units)."""
    at = dict(at or {})
    from ..numerics import current, sheet_tolerance
    from ..numerics.given import solve

    names = list(block.unknowns)
    typed = typed_block(sheet, block)
    sides = [
        (sheet.evaluator.compile(lhs), sheet.evaluator.compile(rhs)) for lhs, rhs in typed.equations
    ]

    def values(x):
        env = dict(zip(names, (float(v) for v in x)), **at)
        return [(float(left(env)), float(right(env))) for left, right in sides]

    guess = [q.magnitude for q in block.unknowns.values()]
    # each residual relative to the size of its two sides at the guess: a fixed scale keeps
    # the residuals smooth (a scale that moves with x makes `expr == 0` a step, +-1)
    with np.errstate(all="ignore"):
        start = values(guess)
    scales = [abs(a) + abs(b) if np.isfinite(abs(a) + abs(b)) else 0.0 for a, b in start]
    scales = [s or 1.0 for s in scales]

    def residuals(x):
        return np.array([(a - b) / s for (a, b), s in zip(values(x), scales)])

    result = solve(
        residuals,
        guess,
        guess,
        current(sheet_tolerance(sheet.spec.meta)),
        names=names,
        equations=[text for _, _, text in block.equations],
        method=block.method,
        violations=_violations(sheet, block, names, at) if block.conditions else None,
    )
    found = Solved(zip(names, (float(v) for v in result.value)))
    found.errors = dict(zip(names, (float(e) for e in result.error)))
    found.condition = float(result.notes.get("condition", float("nan")))
    for cond, text in typed.conditions:
        if not bool(sheet.evaluator.compile(cond)(dict(found, **at))):
            from ..numerics import NumericsError

            at = ", ".join(f"{n} = {v:.6g}" for n, v in found.items())
            raise NumericsError(
                f"the root found from the guesses ({at}) does not meet the condition {text!r}; "
                "try other guesses"
            )
    return found
