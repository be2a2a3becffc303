"""Optional parts of a worksheet (``[parts]``): read, assigned to the sections that name them,
and chosen for a Sheet (``--part``, ``sheet.with_parts``)."""

from __future__ import annotations

from dataclasses import replace

from ..errors import InputError, TemplateError
from .fields import value_line
from .spec import ALL_PARTS, PartSpec, SheetSpec


def assign_parts(data: dict, parts: dict[str, PartSpec], text: str, *specs: list) -> None:
    """Set ``part`` on every table, chart, printed file and relation that names one (``data``:
    the arrays of tables read, by section). A section
    may name only a declared part, and a chart that draws a block table of a part must be in
    that part (else it would draw a table that was not written)."""
    sections = ("tables", "charts", "printed", "relations")
    for section, items in zip(sections, specs):
        for item, raw in zip(items, data[section]):
            item.part = _part_of(raw, parts, section, text, getattr(item, "line", None))
    for raw in data["findings"]:
        _part_of(raw, parts, "findings", text, None)
    for raw in data["checks"]:
        _part_of(raw, parts, "checks", text, None)
    tables, charts = specs[0], specs[1]
    table_part = {t.name: t.part for t in tables}
    for c in charts:
        for s in c.series:
            if s.table in table_part and table_part[s.table] not in (None, c.part):
                raise TemplateError(
                    f"chart {c.name} draws table {s.table} of part {table_part[s.table]!r}: "
                    f'give the chart part = "{table_part[s.table]}" too',
                    line=c.line,
                    definition=f"chart {c.name}",
                )


def _part_of(raw: dict, parts: dict[str, PartSpec], section: str, text: str, line) -> str | None:
    part = raw.get("part")
    if part is None:
        return None
    if not isinstance(part, str) or part not in parts:
        known = ", ".join(parts) or "none declared"
        raise TemplateError(
            f"[[{section}]] part = {part!r} is not declared in [parts] (parts: {known})",
            line=line or value_line(text, f"part = {part!r}".replace("'", '"')),
        )
    return part


def select_parts(spec: SheetSpec, chosen: frozenset[str]) -> SheetSpec:
    """The spec with only the sections of no part or of a chosen part."""
    if set(spec.parts) <= chosen:
        return spec

    def keep(part) -> bool:
        return part is None or part in chosen

    return replace(
        spec,
        tables=[t for t in spec.tables if keep(t.part)],
        charts=[c for c in spec.charts if keep(c.part)],
        printed=[p for p in spec.printed if keep(p.part)],
        relations=[r for r in spec.relations if keep(r.part)],
        findings=[f for f in spec.findings if keep(f.get("part"))],
        checks=[c for c in spec.checks if keep(c.part)],
    )


def resolve_parts(spec: SheetSpec, parts) -> frozenset[str]:
    """``None`` (the default: no optional part), ``"all"``, a part name, or several names."""
    if parts is None:
        return frozenset()
    names = [parts] if isinstance(parts, str) else list(parts)
    if ALL_PARTS in names:
        return frozenset(spec.parts)
    unknown = [n for n in names if n not in spec.parts]
    if unknown:
        known = ", ".join(spec.parts) or "it has none"
        raise InputError(
            f"{spec.name} has no part {unknown[0]!r} (parts: {known}; or 'all')",
            file=str(spec.path),
        )
    return frozenset(names)
