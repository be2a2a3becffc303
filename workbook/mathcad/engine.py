"""The translated worksheet as the engine reads it: typed once, in memory, and what the engine
refuses left out of the translation.

:func:`refusals` builds the worksheet's spec from the document's data (no TOML text, no file)
and types every element with one :class:`~workbook.language.typecheck.Typer` in the order the engine
checks a worksheet at load (solve blocks, definitions, table columns, chart series, functions
typed by their calls), then computes every chart series as ``workbook run`` will. An element
the engine refuses gives its region and the engine's reason; what needs a refused definition
is not typed (it is left out with it). :func:`leave_out` marks the refused regions
untranslated in the translation, and everything that uses them, with the reason.
:class:`AtImport` gives the unit and the value of an expression while the translation is
built (a range's values, a guess, a size), with the same typer and evaluator.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import WorkbookError
from ..language import expr as ex
from ..language import typecheck as tc
from ..language import typed as ty
from ..language.uses import dependencies, solve_expressions
from ..numerics.registry import BUILTINS
from .symbols import Unknown
from .translation import Item, Result, Skipped, Translation, uses
from .trees import rename
from .writer import Rendered


def refusals(data: dict, rendered: Rendered, folder: Path, results=()) -> dict[str, str]:
    """Region id (or ``"REGION/trace N"`` for one trace of a plot) -> why the engine refuses
    it, for the worksheet ``data`` (a TOML document's data) rendered as ``rendered``."""
    from ..language.template import spec_from_data

    path = folder / f"{rendered.name}.toml"
    spec = spec_from_data(data, path, rendered.name)
    check = _Refusals(spec, rendered)
    check.solve_blocks()
    later = check.definitions()
    check.tables()
    traces = check.chart_types()
    check.functions(later)
    check.chart_values(traces)
    _mark_misfits(spec, check.typer, results, check.bad)
    return check.refused


class _Refusals:
    """The engine's refusals of a translated worksheet, region by region: each part typed
    (and a chart's traces computed) as `workbook run` will, unless it reads a part refused."""

    def __init__(self, spec, rendered: Rendered) -> None:
        from ..engine.sheet import Sheet

        self.spec, self.rendered = spec, rendered
        input_units = {n: (None if i.options else i.unit) for n, i in spec.inputs.items()}
        self.sheet = Sheet(
            spec, typer=tc.Typer(spec, input_units, BUILTINS)
        )  # typed element by element
        self.typer = self.sheet.typer
        self.refused: dict[str, str] = {}
        self.bad: set[str] = set()  # definitions and unknowns refused

    def _region_of(self, err: WorkbookError, fallback: str | None) -> str:
        name = err.definition or ""
        if name.startswith("solve "):  # a [[solve]] block: the region of its first unknown
            name = name[len("solve ") :].split(",")[0].strip()
        region = self.rendered.region_of.get(name, fallback)
        if region is None:
            raise WorkbookError(f"the translated worksheet does not load: {err.message}")
        return region

    def _refuse(self, err: WorkbookError, fallback: str | None, names=()) -> None:
        region = self._region_of(err, fallback)
        self.refused.setdefault(region, f"the engine refuses it: {err.message}")
        self.bad.update(n for n, r in self.rendered.region_of.items() if r == region)
        self.bad.update(names)

    def _needs_refused(self, *nodes: ex.Node) -> bool:
        return bool(self.bad) and any(
            dependencies(self.spec, n) & self.bad for n in nodes if n is not None
        )

    def _series_nodes(self, s, var: str) -> list[ex.Node]:
        return [self.sheet.column_node(col, var) for col in (s.x, s.y) if col is not None]

    def solve_blocks(self) -> None:
        from ..language.given_find import type_block

        for block in self.spec.solves:
            if self._needs_refused(*solve_expressions(block)):
                continue
            try:
                self.sheet.check_not_circular(block)
                type_block(self.typer, block)
            except WorkbookError as err:
                unknowns = list(block.unknowns)  # a dict of the unknowns, in order
                self._refuse(err, self.rendered.region_of.get(unknowns[0]), unknowns)

    def definitions(self) -> list[str]:
        """Type every definition; the functions refused at first, to type again last."""
        later = []
        for name, d in self.spec.definitions.items():
            if name in self.bad or self._needs_refused(ex.Name(name)):
                continue
            try:
                self.typer.function(name) if d.is_function else self.typer.scalar(name)
            except WorkbookError as err:
                if d.is_function:
                    later.append(name)
                else:
                    self._refuse(err, self.rendered.region_of.get(name), [name])
            except RecursionError:
                self._refuse(
                    WorkbookError("definitions and expressions nested too deeply for the engine"),
                    self.rendered.region_of.get(name),
                    [name],
                )
        return later

    def tables(self) -> None:
        for t in self.spec.tables:
            for col in t.columns if t.range is not None else []:
                node = self.sheet.column_node(col, t.range.var)
                if self._needs_refused(node):
                    continue
                try:
                    self.sheet.typed_column(col, t.range.var, f"table {t.name}")
                except WorkbookError as err:
                    self._refuse(err, self.rendered.table_of.get(t.name))

    def chart_types(self) -> list[tuple]:
        """Type every trace; the (chart, series, range, region, trace number) to draw."""
        traces: list[tuple] = []
        for c in self.spec.charts:
            region, numbers = self.rendered.chart_of[c.name]
            for s, n in zip(c.series, numbers, strict=True):
                rng = s.range or c.range
                if self._needs_refused(*self._series_nodes(s, rng.var)):
                    continue
                try:
                    typed = [
                        self.sheet.typed_column(col, rng.var, f"chart {c.name}")
                        for col in (s.x, s.y)
                        if col is not None
                    ]
                    if any(t.complex for t in typed):
                        # `workbook run` draws no points of complex values: the trace is
                        # left out with that reason
                        self.refused[f"{region}/trace {n}"] = (
                            "the engine cannot draw it: a series of complex values"
                        )
                        continue
                except WorkbookError as err:
                    if err.definition in self.rendered.region_of:
                        self._refuse(err, None)
                    else:
                        self.refused[f"{region}/trace {n}"] = (
                            f"the engine refuses it: {err.message}"
                        )
                    continue
                traces.append((c, s, rng, region, n))
        return traces

    def functions(self, later: list[str]) -> None:
        """The functions typed at numbers, or by a call with vectors or matrices."""
        for name in later:
            if self._needs_refused(ex.Name(name)):
                continue
            try:
                self.typer.function(name)
            except WorkbookError as err:
                self._refuse(err, self.rendered.region_of.get(name), [name])

    def chart_values(self, traces: list[tuple]) -> None:
        """Each trace computed as `workbook run` will draw it."""
        for c, s, rng, region, n in traces:
            if self._needs_refused(*self._series_nodes(s, rng.var)):
                continue
            try:
                values = self.sheet.range_values(rng, f"chart {c.name}")
                for col in (s.x, s.y):
                    if col is not None:
                        self.sheet.column(col, rng.var, values, f"chart {c.name}")
            except WorkbookError as err:
                self.refused[f"{region}/trace {n}"] = f"the engine cannot draw it: {err.message}"


def _mark_misfits(spec, typer, results: list[Result], bad: set[str]) -> None:
    """Give each stored result (of ``results``) whose unit does not fit what the translation
    computes its ``misfit``: its values stay, not computable, and the rest is compared."""
    for res in results:
        if res.sym is not None and res.rows and not res.misfit and res.sym.final not in bad:
            res.misfit = _misfit(spec, typer, res)


def _misfit(spec, typer, res: Result) -> str:
    """Why the stored values of ``res`` cannot be compared with the translation's (a unit of
    another dimension), or ''."""
    import pint

    from ..language import units as un

    if all(isinstance(v, str) for _, v in res.rows):
        return ""
    name = res.sym.final
    try:
        printed = un.unit(res.unit or "")
        if name in spec.inputs:
            ours = spec.inputs[name].unit
            if ours is None:
                return ""
        elif name not in spec.definitions:
            return ""  # not defined: not computable as it is
        elif spec.definitions[name].is_function:
            ours = typer.function(name).unit
        else:
            ours = typer.scalar(name).unit
    except (WorkbookError, pint.PintError, AttributeError, TypeError):
        return ""  # the check says why
    if ours.dimensionality == printed.dimensionality:
        return ""
    return (
        f"Mathcad stored it in {un.pretty(printed) or 'a plain number'} "
        f"({un.dims(printed)}), the translation computes {un.dims(ours)}"
    )


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
    place = {s.token(): k for k, s in enumerate(tr.syms)}

    def first_broken(trees):
        """The first name (in the translation's order, so every import names the same one)
        the trees use that is left out, or None."""
        at = [place[n] for t in trees for n in ex.names(t) if n in place]
        broken = [k for k in at if tr.syms[k].broken]
        return tr.syms[min(broken)] if broken else None

    changed = True
    while changed:  # in Mathcad's order what an item uses is before it; cycles are settled
        changed = False
        for item in tr.items:
            broken = first_broken(_trees(item))
            if broken is None:
                continue
            if item.kind == "chart":
                continue  # a trace's own names are looked at below
            for sym in _defined(item):
                if not sym.broken:
                    sym.broken = uses(broken)
                    changed = True
                    skip(item.region, what.get(item.region, "a region"), uses(broken))
    for item in tr.items:  # a trace over a name left out: that trace is left out
        if item.kind != "chart" or not item.chart:
            continue
        for x, y, rng, _, n in list(item.chart):
            trees = [x, y, *(t for t in rng.range if t is not None)]
            broken = first_broken(trees)
            if broken is not None:
                _drop_trace(tr, item.region, n, uses(broken), skip)
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


class AtImport:
    """The unit and the value of an expression of the translation so far, as the engine
    gives them: the inputs, units and definitions it needs (nothing else) are written as a
    worksheet in memory by the writer, typed by the language's typer and computed by its
    evaluator. A name that is not known at import is :class:`Unknown`: an argument of a
    function (typed by its calls at the end), a local of a program, a function of the sheet
    (its arguments' units are not known yet), an unknown of a solve block, a definition the
    translation left out or written as a program; a range variable is known by its unit only
    (``ranges=True``).

    A definition the engine typed once (or computed) stands in the next worksheet as an input
    of that unit (or value), and one it refused is refused again without typing: a chain of
    definitions each asked about (``x2 := x1/2`` divides an angle?) is typed once, not once
    per link."""

    def __init__(self, translator) -> None:
        self.translator = translator
        self.out = translator.out
        self.items: dict[str, Item] = {}
        self.syms: dict[str, object] = {}
        self.order: dict[int, int] = {}  # id of a symbol -> its place in the translation
        self.seen = (0, 0)
        # token of a scalar definition -> (its value or None, its unit); None: refused
        self.known: dict[str, tuple | None] = {}
        # arguments whose unit the end of the translation gave (argument_units): an
        # expression of them is known by its unit
        self.settled: set[int] = set()
        # what a worksheet holds -> (spec, typer, identifier of each token, its Sheet or None)
        self.worksheets: dict[frozenset, list] = {}

    def _update(self) -> None:
        """The symbols and their items so far (the translation only grows)."""
        items, syms = self.out.items, self.out.syms
        for item in items[self.seen[0] :]:
            if item.sym is not None:
                self.items[item.sym.token()] = item
        for k, sym in enumerate(syms[self.seen[1] :], self.seen[1]):
            self.syms[sym.token()] = sym
            self.order[id(sym)] = k
        self.seen = (len(items), len(syms))

    def _needs(self, node: ex.Node, ranges: bool, values: bool):
        """The items and symbols ``node`` needs (a definition known before as an input in
        its place), and the range variables it uses."""
        self._update()
        items: list[Item] = []
        syms: set = set()
        range_syms: list = []
        stack, seen = list(ex.names(node)), set()
        while stack:
            name = stack.pop()
            if name in seen or not name.startswith("\x00"):  # a built-in: the engine's
                continue
            seen.add(name)
            sym = self.syms.get(name)
            if sym is None or sym.broken:
                raise Unknown(name)
            if sym.kind == "unit":
                syms.add(sym)
                continue
            if sym.kind == "param":  # a bound variable (a free one the typer refuses)
                if not sym.unit and (sym.hint is not None or sym.hint_sym is not None):
                    raise Unknown(name)  # its unit is given at the end
                syms.add(sym)
                if ranges and id(sym) in self.settled:  # known by its unit, as a range's
                    range_syms.append(sym)
                continue
            item = self.items.get(name)
            if item is None:
                raise Unknown(name)
            if item.kind == "range" and ranges and sym.is_range:
                syms.add(sym)
                range_syms.append(sym)
                continue
            if item.kind == "definition" and name in self.known:
                known = self.known[name]
                if known is None:
                    raise Unknown(name)
                if known[0] is not None or not values:
                    items.append(Item("input", sym=sym, value=_quantity_text(*known)))
                    syms.add(sym)
                    continue
            if item.kind == "input" or (item.kind == "definition" and item.program is None):
                items.append(item)
                syms.add(sym)
                trees = [item.body] if item.body is not None else []
                trees += [t for piece in item.pieces or [] for t in piece if t is not None]
                for tree in trees:
                    stack += ex.names(tree)
                continue
            raise Unknown(name)
        return items, syms, range_syms

    def _sizes(self, node: ex.Node) -> ex.Node:
        """``node`` with the sizes (rows, cols, length: a built-in that reads only the size
        of its argument, whatever the origin) of a matrix written out in the translation (by
        name) as numbers. Kept from the tree, not computed: an element of M may call a
        function of the sheet, whose arguments' units are only known at the end."""
        entry = BUILTINS.functions.get(node.func) if isinstance(node, ex.Call) else None
        if entry is not None and entry.sizes and len(node.args) == 1:
            tree = self.translator.written_out(node.args[0]) or node.args[0]
            if isinstance(tree, ex.Matrix):
                shape = (len(tree.rows), len(tree.rows[0]))
                try:  # at origins 0 and 1: one that depends on the origin (last) stays
                    at = {float(entry.numpy(np.zeros(shape), o, shapes=[shape])) for o in (0, 1)}
                except WorkbookError:  # the length of a matrix: typed, and refused, as written
                    at = set()
                if len(at) == 1:
                    return ex.Number(at.pop())
        return ex.map_children(node, self._sizes)

    def _typed(self, node: ex.Node, what: str, ranges: bool, values: bool):
        """(key of the worksheet of what ``node`` needs, typed tree, token of each identifier);
        the worksheet is written, read and given a typer once for the same needs."""
        from ..language.template import spec_from_data
        from .writer import document

        node = self._sizes(node)
        items, syms, range_syms = self._needs(node, ranges, values)
        # an argument's unit is given at the end of the translation: part of the key
        key = frozenset((id(s), s.unit) if s.kind == "param" else id(s) for s in syms) | {
            (id(i.sym), i.value if i.kind == "input" else id(i)) for i in items
        }
        try:
            if key not in self.worksheets:  # the same needs (a range over n, again): reused
                part = Translation(
                    items=items,
                    syms=sorted(syms, key=lambda s: self.order[id(s)]),
                    origin=self.out.origin,  # the worksheet's indices count from its origin
                )
                doc, _ = document(part, "at-import", Path("at-import.xmcd"))
                spec = spec_from_data(doc.data, Path("at-import.toml"), "at-import")
                input_units = {n: (None if i.options else i.unit) for n, i in spec.inputs.items()}
                mapping = {s.token(): s.final for s in part.syms}
                self.worksheets[key] = [spec, tc.Typer(spec, input_units, BUILTINS), mapping, None]
            spec, typer, mapping, _ = self.worksheets[key]
            finals = [mapping[s.token()] for s in range_syms]
            scope = {f: spec.arguments[f].binding_unit for f in finals}
            t = typer.expression(rename(node, mapping), scope, what)
        except (WorkbookError, RecursionError) as err:
            if isinstance(node, ex.Name) and node.id in self.items:
                self.known.setdefault(node.id, None)  # refused wherever it is used
            raise Unknown(str(err)) from None
        tokens = {final: token for token, final in mapping.items()}
        for name, typed in typer.scalars.items():
            if _number(typed):
                self.known.setdefault(tokens[name], (None, typed.unit))
        return key, t, tokens

    def unit(self, node: ex.Node):
        """The pint unit of ``node`` (of each element of a vector or matrix; a range variable
        by its unit), or None: not known at import, a text, a condition or an array of
        arrays."""
        known = self.known.get(node.id) if isinstance(node, ex.Name) else None
        if known is not None:
            return known[1]
        try:
            t = self._typed(node, "an expression at import", True, False)[1]
        except Unknown:
            return None
        return None if t.text or t.boolean or ty.is_runtime(t.shape) else t.unit

    def shape(self, node: ex.Node) -> tuple[int, int] | None:
        """(rows, columns) of ``node`` as the engine types it, or None: a number, not known
        at import, or an array whose size is known only when it is computed."""
        try:
            t = self._typed(node, "an expression at import", True, False)[1]
        except Unknown:
            return None
        if t.text or t.boolean or t.shape is None or ty.is_runtime(t.shape):
            return None
        return tuple(t.shape)

    def quantity(self, node: ex.Node):
        """The value of ``node`` (a number) as a pint quantity; :class:`Unknown` if it is not
        one known at import."""
        import numpy as np

        from ..engine.sheet import Sheet
        from ..language import units as un
        from ..limits import matrix_work

        known = self.known.get(node.id) if isinstance(node, ex.Name) else None
        if known is not None and known[0] is not None:
            return un.registry().Quantity(*known)
        key, t, tokens = self._typed(node, "an expression at import", False, True)
        if not _number(t):
            raise Unknown("not a number")
        worksheet = self.worksheets[key]
        spec, typer = worksheet[:2]
        try:
            if worksheet[3] is None:  # the evaluator of what it needs
                worksheet[3] = Sheet(spec, typer=typer)
            sheet = worksheet[3]
            with matrix_work():
                value = sheet.evaluator.compile(t)({})
        except (WorkbookError, RecursionError) as err:
            raise Unknown(str(err)) from None
        if isinstance(value, str) or np.ndim(value) != 0:
            raise Unknown("not a number")
        for name, typed in typer.scalars.items():  # the definitions computed on the way
            if _number(typed):
                try:
                    v = sheet.scalar_value(name, "definition")  # remembered: not computed again
                except WorkbookError:
                    continue
                if isinstance(v, float):
                    self.known[tokens[name]] = (v, typed.unit)
        return un.registry().Quantity(float(value), t.unit)


def _number(t) -> bool:
    """Is the typed tree ``t`` one number (not a vector, a text or a condition)?"""
    return t.shape is None and not t.text and not t.boolean


def _quantity_text(value: float | None, unit) -> str:
    """An input's value: ``value`` (1 if None) in ``unit``."""
    number = repr(float(1.0 if value is None else value))
    return number if str(unit) in ("", "dimensionless") else f"{number} {unit}"
