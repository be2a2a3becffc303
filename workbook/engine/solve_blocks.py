"""Solving ``[[solve]]`` blocks (Mathcad's Given/Find) of a loaded sheet: the block's trees
typed at load (:func:`workbook.language.given_find.typed_block`) compiled and handed to
:func:`workbook.numerics.given.solve`; a block with parameters solved at each point it is
called with, and the findings of the solved blocks."""

from __future__ import annotations

import numpy as np

from ..errors import LimitError, WorkbookError
from ..findings import Finding
from ..functions.numerical import NumericsError, current, sheet_tolerance
from ..language import units as un
from ..language.given_find import SolveSpec, typed_block
from ..numerics.given import solve


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
            at = ", ".join(f"{n} = {v:.6g}" for n, v in found.items())
            raise NumericsError(
                f"the root found from the guesses ({at}) does not meet the condition {text!r}; "
                "try other guesses"
            )
    return found
