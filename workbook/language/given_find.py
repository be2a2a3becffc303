"""``[[solve]]`` blocks: Mathcad's Given/Find, a system of equations in named unknowns.

::

    [[solve]]
    unknowns = { x = "1 m", y = "0.5 m" }          # guesses; their units are the unknowns'
    equations = ["x^2 + y^2 == R^2", "y == x*tan(theta)"]

The unknowns are names for the rest of the sheet (references of kind ``solve``). The
equations are typed when the sheet is loaded (each side in the unknowns' units; the two sides
of an equation must agree), and solved when a value is first needed, by
:func:`workbook.engine.solve_blocks.solve_block`. Not converging is an error that lists
every equation's residual. In the workbook the unknowns, and what uses them, are written as
numbers. A block with ``parameters`` (arguments) is a function: each unknown is a definition
of them, solved at each value it is called with.
"""

from __future__ import annotations

from dataclasses import dataclass

import pint

from ..errors import TemplateError, UnitError, WorkbookError
from . import expr as ex
from . import typed as ty
from . import units as un
from .fields import value_line

#: the methods of a block: Powell's hybrid method (the default), Levenberg-Marquardt (Mathcad's
#: Find), or the root nearest the guesses; from the same guess they may reach different roots
#: of a system with several (scipy's method of each: numerics/given.py)
METHODS = ("hybrid", "levenberg-marquardt", "nearest")

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
