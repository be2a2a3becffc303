"""The translated worksheet as the engine reads it: typed once, in memory, and what the engine
refuses left out of the translation.

:func:`refusals` builds the worksheet's spec from the document's data (no TOML text, no file)
and types every element with one :class:`~workbook.typecheck.Typer` in the order the engine
checks a worksheet at load (solve blocks, definitions, table columns, chart series, functions
typed by their calls), then computes every chart series as ``workbook run`` will. An element
the engine refuses gives its region and the engine's reason; what needs a refused definition
is not typed (it is left out with it). :func:`leave_out` marks the refused regions
untranslated in the translation, and everything that uses them, with the reason.
"""

from __future__ import annotations

from pathlib import Path

from .. import expr as ex
from .. import typecheck as tc
from ..errors import WorkbookError
from .translate import Item, Skipped, Translation, _uses
from .writer import Rendered


def refusals(data: dict, rendered: Rendered, folder: Path) -> dict[str, str]:
    """Region id (or ``"REGION/trace N"`` for one trace of a plot) -> why the engine refuses
    it, for the worksheet ``data`` (a TOML document's data) rendered as ``rendered``."""
    from ..sheet import Sheet
    from ..template import spec_from_data

    path = folder / f"{rendered.name}.toml"
    spec = spec_from_data(data, path, rendered.name)
    input_units = {n: (None if i.options else i.unit) for n, i in spec.inputs.items()}
    sheet = Sheet(spec, typer=tc.Typer(spec, input_units))  # typed here, element by element
    typer = sheet.typer
    refused: dict[str, str] = {}
    bad: set[str] = set()  # definitions and unknowns refused

    def region_of(err: WorkbookError, fallback: str | None) -> str:
        name = err.definition or ""
        if name.startswith("solve "):  # a [[solve]] block: the region of its first unknown
            name = name[len("solve ") :].split(",")[0].strip()
        region = rendered.region_of.get(name, fallback)
        if region is None:
            raise WorkbookError(f"the translated worksheet does not load: {err.message}")
        return region

    def refuse(err: WorkbookError, fallback: str | None, names=()) -> None:
        region = region_of(err, fallback)
        refused.setdefault(region, f"the engine refuses it: {err.message}")
        bad.update(n for n, r in rendered.region_of.items() if r == region)
        bad.update(names)

    def needs_refused(*nodes: ex.Node) -> bool:
        return bool(bad) and any(tc.dependencies(spec, n) & bad for n in nodes if n is not None)

    def series_nodes(s, var: str) -> list[ex.Node]:
        return [sheet.column_node(col, var) for col in (s.x, s.y) if col is not None]

    for block in spec.solves:
        if needs_refused(*tc.solve_expressions(block)):
            continue
        try:
            from ..given_find import typed_equations

            sheet._check_not_circular(block)
            typed_equations(typer, block)
        except WorkbookError as err:
            refuse(err, rendered.region_of.get(block.unknowns[0]), block.unknowns)
    later = []
    for name, d in spec.definitions.items():
        if name in bad or needs_refused(ex.Name(name)):
            continue
        try:
            typer.function(name) if d.is_function else typer.scalar(name)
        except WorkbookError as err:
            if d.is_function:
                later.append(name)
            else:
                refuse(err, rendered.region_of.get(name), [name])
        except RecursionError:
            refuse(
                WorkbookError("definitions and expressions nested too deeply for the engine"),
                rendered.region_of.get(name),
                [name],
            )
    for t in spec.tables:
        for col in t.columns if t.range is not None else []:
            node = sheet.column_node(col, t.range.var)
            if needs_refused(node):
                continue
            try:
                sheet.typed_column(col, t.range.var, f"table {t.name}")
            except WorkbookError as err:
                refuse(err, rendered.table_of.get(t.name))
    traces: list[tuple] = []  # (chart, series, region, trace number) to draw
    for c in spec.charts:
        region, numbers = rendered.chart_of[c.name]
        for s, n in zip(c.series, numbers, strict=True):
            rng = s.range or c.range
            what = f"chart {c.name}"
            if needs_refused(*series_nodes(s, rng.var)):
                continue
            try:
                sheet.typed_column(s.y, rng.var, what)
            except WorkbookError as err:
                if err.definition in rendered.region_of:
                    refuse(err, None)
                else:
                    refused[f"{region}/trace {n}"] = f"the engine refuses it: {err.message}"
                continue
            traces.append((c, s, rng, region, n))
    for name in later:  # typed at numbers, or by a call with vectors or matrices
        if needs_refused(ex.Name(name)):
            continue
        try:
            typer.function(name)
        except WorkbookError as err:
            refuse(err, rendered.region_of.get(name), [name])
    for c, s, rng, region, n in traces:  # computed as `workbook run` will draw them
        if needs_refused(*series_nodes(s, rng.var)):
            continue
        try:
            values = sheet.range_values(rng, f"chart {c.name}")
            for col in (s.x, s.y):
                if col is not None:
                    sheet.column(col, rng.var, values, f"chart {c.name}")
        except WorkbookError as err:
            refused[f"{region}/trace {n}"] = f"the engine cannot draw it: {err.message}"
    return refused


def leave_out(tr: Translation, refused: dict[str, str], what: dict[str, str]) -> None:
    """Mark the ``refused`` regions of ``tr`` untranslated with the engine's reason (``what``:
    region id -> what the region is, for the list), then every item that uses a name left
    out, until nothing more is. The list of untranslated regions stays in the order of
    ``what``."""
    whole = {r: why for r, why in refused.items() if "/trace " not in r}
    before = list(tr.skipped)
    sound = {s for s in tr.syms if not s.broken}
    listed: set[str] = set()

    def skip(region: str, kind: str, why: str) -> None:
        if region not in listed:
            listed.add(region)
            tr.skipped.append(Skipped(region, kind, why))

    traces: dict[str, list[str]] = {}
    for key, why in refused.items():
        if "/trace " in key:
            region, n = key.split("/trace ")
            traces.setdefault(region, []).append(n)
            _drop_trace(tr, region, int(n), why, skip)
    for item in tr.items:
        why = whole.get(item.region)
        if why is None:
            continue
        if item.kind == "solve":
            for sym, _ in item.solve[0]:
                sym.broken = why
            for rid in item.solve[2]:
                skip(rid, "a region of a solve block (Given ... Find)", why)
        elif item.kind == "chart":
            item.chart = []
            skip(item.region, "a plot", why)
        elif item.sym is not None:
            item.sym.broken = item.sym.broken or why
            skip(item.region, what.get(item.region, "a region"), why)
    by_token = {s.token(): s for s in tr.syms}
    changed = True
    while changed:  # in Mathcad's order what an item uses is before it; cycles are settled
        changed = False
        for item in tr.items:
            used = [by_token[n] for t in _trees(item) for n in ex.names(t) if n in by_token]
            broken = next((s for s in used if s.broken), None)
            if broken is None:
                continue
            if item.kind == "chart":
                continue  # a trace's own names are looked at below
            for sym in _defined(item):
                if not sym.broken:
                    sym.broken = _uses(broken)
                    changed = True
                    skip(item.region, what.get(item.region, "a region"), _uses(broken))
    for item in tr.items:  # a trace over a name left out: that trace is left out
        if item.kind != "chart" or not item.chart:
            continue
        for x, y, rng, _, n in list(item.chart):
            trees = [x, y, *(t for t in rng.range if t is not None)]
            used = [by_token[m] for t in trees for m in ex.names(t) if m in by_token]
            broken = next((s for s in used if s.broken), None)
            if broken is not None:
                _drop_trace(tr, item.region, n, _uses(broken), skip)
    for res in tr.results:  # stored values of what is left out: kept, listed as values
        if res.sym in sound and res.sym.broken:
            res.rows = [(None, v) for _, v in res.rows]
            res.argument = None
    _in_order(tr, len(before), {region: k for k, region in enumerate(what)})


def _in_order(tr: Translation, kept: int, order: dict[str, int]) -> None:
    """Move each entry of ``tr.skipped`` after the first ``kept`` (the translator's, in its
    order) before the first of those of a later region."""
    listed, added = tr.skipped[:kept], tr.skipped[kept:]
    for entry in sorted(added, key=lambda s: order.get(s.region, len(order))):
        at = order.get(entry.region, len(order))
        k = next(
            (i for i, s in enumerate(listed) if s.region in order and order[s.region] > at),
            len(listed),
        )
        listed.insert(k, entry)
    tr.skipped[:] = listed


def _drop_trace(tr: Translation, region: str, n: int, why: str, skip) -> None:
    """Leave trace ``n`` out of the plot of ``region`` (the plot, if it was its last)."""
    for item in tr.items:
        if item.kind != "chart" or item.region != region:
            continue
        item.chart = [t for t in item.chart if t[4] != n]
        if item.chart:
            tr.skipped.append(Skipped(region, "a plot (traces left out)", f"trace {n}: {why}"))
        else:
            skip(region, "a plot", f"trace {n}: {why}")


def _trees(item: Item) -> list[ex.Node]:
    """The expressions an item is made of."""
    out = [item.body] if item.body is not None else []
    out += [t for piece in item.pieces or [] for t in piece if t is not None]
    out += [p for _, parts in item.program or [] for p in parts if not isinstance(p, str)]
    out += [t for t in item.range or () if t is not None]
    if item.solve is not None:
        out += list(item.solve[1]) + list(item.solve[3])
    return out


def _defined(item: Item) -> list:
    if item.kind == "solve":
        return [sym for sym, _ in item.solve[0]]
    return [item.sym] if item.sym is not None else []
