"""What a sheet's outputs use: the one place that lists the expressions a sheet shows.

Tables, charts, printed values (and, for the hand checks, relations, findings, checks,
[[solve]] blocks and [[ode]] sections) are the outputs; :func:`names_used` follows their
expressions through the definitions to the inputs and blocks they need. The writer writes only
those (``excelform.needed_names``), ``Sheet`` reports the inputs nothing uses, and the analysis
finds the ranges that show a function.
"""

from __future__ import annotations

from ..errors import WorkbookError
from . import expr as ex
from .ranges import RangeSpec
from .spec import SheetSpec
from .template import column_node
from .typedsheet import printed_rows


def ranged_outputs(spec: SheetSpec) -> list[tuple[RangeSpec, list[ex.Node]]]:
    """Each range of a table or chart series, with the expressions shown over it."""
    out = []
    for t in spec.tables:
        if t.range is not None:
            out.append((t.range, [column_node(spec, c, t.range.var) for c in t.columns]))
    for c in spec.charts:
        for s in c.series:
            rng = s.range or c.range
            if s.table is not None or rng is None:
                continue
            nodes = [column_node(spec, s.y, rng.var)]
            x = s.x or c.x
            if x is not None:
                nodes.append(column_node(spec, x, rng.var))
            out.append((rng, nodes))
    return out


def output_roots(spec: SheetSpec, *, hand_checks: bool = False, reads=()) -> list[ex.Node]:
    """Expressions the outputs evaluate: columns, series and their range bounds, printed
    values, the names ``reads`` that blocks evaluated through the sheet (``Sheet.reads``); with
    ``hand_checks`` also the columns of block tables and the relations (what the checks read)."""
    roots: list[ex.Node] = [ex.Name(n) for n in sorted(reads)]
    for t in spec.tables:
        if t.range is None and hand_checks:
            roots += [c.node for c in t.columns]
    for rng, nodes in ranged_outputs(spec):
        roots += nodes
        roots += [n for n in (rng.first, rng.second, rng.last, rng.points) if n is not None]
    for p in spec.printed:
        roots += [ex.Name(n) for n in printed_names(p)]
    if hand_checks:  # the check report solves every [[solve]] block and [[ode]]
        for block in spec.solves:
            roots += solve_expressions(block)
        for o in spec.odes.values():
            roots += [ex.Name(s.name) for s in o.states]
        for r in spec.relations:
            roots += [ex.Name(r.child), ex.Name(r.parent), r.factor]
        for c in spec.checks:
            roots += [n for n in (c.value, c.ok) if n is not None]
            roots += [ex.Name(n) for n in c.inputs]
            roots += list(c.parsed.values())  # the placeholders of what and note
    return roots


def names_used(spec: SheetSpec, *, hand_checks: bool = False, reads=()) -> set[str]:
    """Inputs, definitions and blocks the outputs (and ``reads``) need, transitively."""
    roots = output_roots(spec, hand_checks=hand_checks, reads=reads)
    return dependencies_of_all(spec, roots)  # one closure: linear in the definitions


def printed_names(p) -> set[str]:
    """Names of a printed-values file (none if it cannot be read: the checks report that)."""
    try:
        return {row.name for row in printed_rows(p)}
    except WorkbookError:
        return set()


def dependencies(spec: SheetSpec, node: ex.Node, scope=()) -> set[str]:
    """Names of inputs/definitions/blocks an expression needs, transitively."""
    return _closure(spec, [n for n in ex.names(node) if n not in scope])


def dependencies_of_all(spec: SheetSpec, nodes: list[ex.Node]) -> set[str]:
    """Names that any of ``nodes`` needs, transitively (one walk for all of them)."""
    return _closure(spec, [n for node in nodes for n in ex.names(node)])


def _closure(spec: SheetSpec, todo: list[str]) -> set[str]:
    out: set[str] = set()
    while todo:
        n = todo.pop()
        if n in out:
            continue
        out.add(n)
        block = spec.solve_of(n) if n not in spec.inputs else None
        if block is not None:  # an unknown of [[solve]]: what its equations use
            todo.extend(
                m
                for node in solve_expressions(block)
                for m in ex.names(node)
                if m not in block.parameters
            )
        d = spec.definitions.get(n)
        if d is not None:
            todo.extend(direct_names(spec, d))
    return out


def direct_names(spec: SheetSpec, d) -> set[str]:
    """The names definition ``d``'s formulas, program or ODE use (not its own parameters)."""
    local: set[str] = set(d.params)
    if d.program is not None:
        from ..program.statements import names as program_names

        return program_names(d.program) - local
    bodies = d.expressions()
    if d.ode is not None:
        o = spec.odes[d.ode[0]]
        local |= {o.var} | {s.name for s in o.states}
        bodies = o.expressions()
    return {m for body in bodies for m in ex.names(body) if m not in local}


def solve_expressions(block) -> list[ex.Node]:
    """Every expression of a [[solve]] block: both sides of its equations, its conditions."""
    return [x for lhs, rhs, _ in block.equations for x in (lhs, rhs)] + [
        c for c, _ in block.conditions
    ]
