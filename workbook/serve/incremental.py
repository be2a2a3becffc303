"""Incremental compute for the live page: after an edit of the file or of an input, only
what is downstream of the change is computed again.

A :class:`LiveSheet` holds the last good load of one worksheet (its text, the TOML it parses
to, the Sheet and the computed sheet) and the values that Sheet computed. On an edit it
compares the TOML entries of the new text with the old, names what changed (inputs,
definitions), follows the dependency graph (:func:`workbook.language.uses.dependencies`)
to everything downstream, and hands the values of everything else to the new Sheet
(:class:`ReusingSheet`): scalar definitions, ``[[solve]]`` solutions, range tables and block
tables whose formulas read nothing that changed, and the values its checks asked for. When
only inputs and definitions changed, the typing of what the edit does not reach is taken over
too (:func:`seeded_typer`, :func:`seeded_trees`). An edit outside the sections it can follow
(``[sheet]``, ``[arguments]``, ``[blocks]``, ``[[solve]]``, ``[[ode]]``, ``[data]``, ...) is
computed in full. Charts whose data did not change are not drawn again, nor definitions the
edit does not reach rendered again (:class:`LiveDocument`). The language server loads its
texts through :func:`successor` as well.
"""

from __future__ import annotations

import hashlib
import re
import threading
import time
from dataclasses import dataclass, field
from html import escape
from pathlib import Path
from typing import Any

import numpy as np

from ..compute.computed import compute
from ..engine.sheet import Sheet
from ..errors import WorkbookError
from ..language import expr as ex
from ..language.checkspec import placeholders
from ..language.template import column_node, parse_spec, read_toml
from ..language.typecheck import Typer
from ..language.typedsheet import TypedSheet, printed_rows
from ..language.uses import dependencies, solve_expressions
from ..numerics.registry import BUILTINS
from ..outputs.report.charts import chart_svg
from ..outputs.report.html import Document
from ..program.statements import names as program_names
from .watch import stamp

#: Top-level sections whose entries are compared one by one; an edit anywhere else is
#: computed in full.
FOLLOWED = {"inputs", "definitions", "tables", "charts", "printed", "checks", "relations"}
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
#: The charts' section of the report's body (sections are not nested; an SVG holds none).
_CHARTS = re.compile(r"(<section class='charts'><h2>[^<]*</h2>).*?(</section>)", re.S)


_MISSING = object()


class ReusingSheet(Sheet):
    """A Sheet that takes the values of unchanged definitions, solutions and tables from the
    Sheet before an edit (``reuse``) and remembers what it computes (``seen``), for the next."""

    def __init__(self, spec, values=None, typer=None, parts=None, *, reuse=None, retype=None):
        self.reused: dict[Any, Any] = dict(reuse or {})
        self.seen: dict[Any, Any] = {}
        self.known: dict[str, Any] = {}  # definition name -> its value, once known
        # each file of printed values as it was before this Sheet read it (:func:`.watch.stamp`)
        self.printed_stamps = {p.file: stamp(p.file) for p in spec.printed}
        if typer is not None or retype is None:
            super().__init__(spec, values, typer, parts)
            return
        old, dirty = retype  # the Sheet before the edit, and what the edit reaches
        units = {n: (None if i.options else i.unit) for n, i in spec.inputs.items()}
        typer = seeded_typer(old.typer, Typer(spec, units, BUILTINS), dirty)
        super().__init__(spec, values, typer, parts, seeded_trees(old, spec, dirty))
        self.check_units()  # a Sheet given a typer does not: the unchanged are looked up

    def evaluate(self, name, *args, **kwargs):
        """As :meth:`Sheet.evaluate`; the value of a definition (a check's printed value of
        a function at an argument, among others) reused when nothing it reads changed."""
        if not isinstance(name, str) or name not in self.spec.definitions:
            return super().evaluate(name, *args, **kwargs)
        try:
            key = ("evaluate", (name, args, tuple(sorted(kwargs.items()))))
            hash(key)
        except TypeError:  # an array argument: computed
            return super().evaluate(name, *args, **kwargs)
        if self.recording:
            self.reads.add(name)
        return self._take(key, lambda: Sheet.evaluate(self, name, *args, **kwargs))

    def _take(self, key, make):
        if key in self.reused:
            value = self.reused[key]
        else:
            value = make()
        self.seen[key] = value
        return value

    def scalar_value(self, name: str, kind: str):
        """As :meth:`Sheet.scalar_value`; a definition's value reused when it did not change.
        (Called for every reference a formula makes, by an ODE's right-hand side at every
        step: kept to a lookup once the value is known.)"""
        if kind != "definition":
            return Sheet.scalar_value(self, name, kind)
        value = self.known.get(name, _MISSING)
        if value is _MISSING:
            key = ("value", name)
            value = self.reused[key] if key in self.reused else Sheet.scalar_value(self, name, kind)
            self.seen[key] = self.known[name] = value
        return value

    def solution(self, block):
        """As :meth:`Sheet.solution`; reused when nothing its equations read changed."""
        return self._take(("solve", block.index), lambda: Sheet.solution(self, block))

    def table_data(self, table):
        """As :meth:`Sheet.table_data`; a template table reused when its formulas did not
        change."""
        if not isinstance(table, str) and table not in self.spec.tables:
            return super().table_data(table)  # a chart's data: computed from the columns
        name = table if isinstance(table, str) else table.name
        return self._take(("table", name), lambda: Sheet.table_data(self, table))

    def computed_table(self, name: str):
        """As :meth:`Sheet.computed_table`; reused when nothing the sheet reads changed."""
        return self._take(("computed table", name), lambda: Sheet.computed_table(self, name))


@dataclass
class Update:
    """What one edit gave: the report's body, or the error that stopped it (the body is then
    the last good one), and how long each stage took (seconds)."""

    html: str | None
    error: WorkbookError | None
    seconds: dict[str, float] = field(default_factory=dict)
    recomputed: set[str] | None = None  # None: everything (a full compute)


class LiveDocument(Document):
    """The report's Document, its charts drawn again only when their data changed. With
    ``drawn`` (chart name -> the SVG shown last) a changed chart is not drawn: the last
    drawing is shown, marked as being redrawn, and ``pending`` says so (the numbers reach the
    page first, the drawing follows)."""

    def __init__(self, sheet, charts: dict, drawn: dict | None = None, **options):
        super().__init__(sheet, **options)
        self.cache = charts
        self.drawn = drawn
        self.pending = False
        self.shown: dict[str, str] = {}
        # the last rendering's pieces: a definition's (by name) and the checks' (by the
        # report they show); ``dirty``: the definitions an edit reaches (None: all)
        self.last: dict[str, Any] = {}
        self.dirty: set[str] | None = None
        self.made: dict[str, Any] = {}

    def definition(self, d) -> str:
        """As :meth:`Document.definition`; the last rendering's when the edit did not reach
        ``d`` (its text, and the values it shows, are as they were)."""
        key = ("definition", d.name)
        if self.dirty is not None and d.name not in self.dirty and key in self.last:
            out = self.last[key]
        else:
            out = super().definition(d)
        self.made[key] = out
        return out

    def checks(self) -> str:
        """As :meth:`Document.checks`; the last rendering's when the report is the same."""
        try:
            key = ("checks", repr(self.sheet.check_report()))
        except WorkbookError:
            return super().checks()
        out = self.last[key] if key in self.last else super().checks()
        self.made[key] = out
        return out

    def charts(self) -> str:
        if not self.spec.charts:
            return ""
        out = []
        for c in self.spec.charts:
            key = _chart_key(self.sheet, c)
            svg = self.cache.get(key) if key else None
            stale = ""
            if svg is None and self.drawn is not None and c.name in self.drawn:
                svg, stale, self.pending = self.drawn[c.name], " class='wb-stale'", True
            elif svg is None:
                try:
                    svg = chart_svg(self.sheet, c)
                    if key:
                        self.cache[key] = svg
                except WorkbookError as err:
                    svg = f"<p class='error'>not drawn: {escape(err.message)}</p>"
            self.shown[c.name] = svg
            out.append(
                f"<figure id='chart-{escape(c.name)}'{stale}>{svg}"
                f"<figcaption>{escape(c.title)}</figcaption></figure>"
            )
        return "".join(out)


def _chart_key(computed, chart) -> str | None:
    """A digest of what a chart shows: its spec and the data of its series (None when a
    series failed: it is drawn, and its error shown, every time)."""
    h = hashlib.sha256(repr(chart).encode())
    for i in range(len(chart.series)):
        s = computed.series.get((chart.name, i))
        if s is None or isinstance(s, BaseException):
            return None
        h.update(np.ascontiguousarray(s.x, dtype=float).tobytes())
        h.update(np.ascontiguousarray(s.y, dtype=float).tobytes())
        if s.data is not None:
            h.update(repr([str(c.unit) for c in s.data.columns]).encode())
    return h.hexdigest()


def render_body(
    computed, charts: dict, drawn: dict | None = None, last: dict | None = None, dirty=None
) -> LiveDocument:
    """The report of a computed sheet as the live page shows it: the document (its ``text``
    the body; see :class:`LiveDocument` for ``drawn``, ``last`` and ``dirty``)."""
    doc = LiveDocument(computed, charts, drawn)
    doc.last, doc.dirty = last or {}, dirty
    with np.errstate(all="ignore"):
        doc.text = doc.body()
    return doc


def _entries(raw: dict, section: str) -> dict:
    """The entries of one section of the TOML: a table's keys, or an array's items by index."""
    value = raw.get(section, {})
    if isinstance(value, list):
        return dict(enumerate(value))
    return dict(value) if isinstance(value, dict) else {}


def _data_digest(spec) -> str:
    h = hashlib.sha256()
    for name in sorted(spec.data):
        h.update(name.encode())
        h.update(np.ascontiguousarray(spec.data[name].values, dtype=float).tobytes())
    return h.hexdigest()


def changed_names(old_raw: dict, new_raw: dict, old_values: dict, new_values: dict):
    """The inputs and definitions an edit changed, or None when it changed what cannot be
    followed (a section outside :data:`FOLLOWED`)."""
    keys = set(old_raw) | set(new_raw)
    if any(old_raw.get(k) != new_raw.get(k) for k in keys - FOLLOWED):
        return None
    out: set[str] = set()
    for section in ("inputs", "definitions"):
        old, new = _entries(old_raw, section), _entries(new_raw, section)
        for key in set(old) | set(new):
            if old.get(key) != new.get(key):
                out.add(str(key).split("(", 1)[0].strip().strip("\"'"))
    for name in set(old_values) | set(new_values):
        if str(old_values.get(name)) != str(new_values.get(name)):
            out.add(name)
    return out


def only_entries_changed(old_raw: dict, new_raw: dict) -> bool:
    """Did an edit change inputs and definitions only (what the typing of the unchanged
    definitions can be taken over for)?"""
    keys = (set(old_raw) | set(new_raw)) - {"inputs", "definitions"}
    return all(old_raw.get(k) == new_raw.get(k) for k in keys)


def stopped_by(spec, err) -> list[str]:
    """The definitions of ``spec`` an error stops: its own and every one that reads it."""
    name = getattr(err, "definition", None)
    if spec is None or name not in spec.definitions:
        return []
    return sorted(n for n in downstream(spec, {name}) if n in spec.definitions)


def downstream(spec, changed: set[str]) -> set[str]:
    """Every input and definition that reads (transitively) one of ``changed`` (the reads of
    each name found once, then followed backwards from ``changed``)."""
    names = [*spec.inputs, *spec.definitions]
    nodes = names + [u for block in spec.solves for u in block.unknowns]
    readers: dict[str, set[str]] = {}
    out = set(changed)
    for name in nodes:
        try:
            reads = direct_reads(spec, name)
        except (WorkbookError, RecursionError):
            out.add(name)  # cannot be followed: taken as reached
            continue
        for m in reads:
            readers.setdefault(m, set()).add(name)
    todo = list(out)
    while todo:
        for r in readers.get(todo.pop(), ()):
            if r not in out:
                out.add(r)
                todo.append(r)
    known = set(names)
    return {n for n in out if n in known or n in changed}


def direct_reads(spec, name: str) -> set[str]:
    """The names that the entry ``name`` reads itself (one step of
    :func:`workbook.language.uses.dependencies`): a definition's formulas, program or
    ODE, an unknown's [[solve]] equations."""
    out: set[str] = set()
    block = spec.solve_of(name) if name not in spec.inputs else None
    if block is not None:
        out |= {
            m
            for node in solve_expressions(block)
            for m in ex.names(node)
            if m not in block.parameters
        }
    d = spec.definitions.get(name)
    if d is None:
        return out
    local: set[str] = set(d.params)
    if d.program is not None:
        return out | (program_names(d.program) - local)
    bodies = d.expressions()
    if d.ode is not None:
        o = spec.odes[d.ode[0]]
        local |= {o.var} | {st.name for st in o.states}
        bodies = o.expressions()
    for body in bodies:
        out |= {m for m in ex.names(body) if m not in local}
    return out


def _reads(raw_entry, dirty: set[str]) -> bool:
    """Does a TOML entry (a table, a chart) name, directly or through the definitions it
    uses, anything in ``dirty``? Every word of its text counts as a name (over-approximate)."""
    words = set(_NAME.findall(repr(raw_entry)))
    return bool(words & dirty)


def reusable(
    old: ReusingSheet, new_spec, new_raw, old_raw, changed: set[str], dirty: set[str] | None = None
) -> dict:
    """The values of ``old`` that the Sheet of ``new_spec`` may take as they are (``dirty``:
    what is downstream of ``changed``, when known)."""
    dirty = downstream(new_spec, changed) if dirty is None else dirty
    out = {}
    old_tables = _entries(old_raw, "tables")
    new_tables = _entries(new_raw, "tables")
    # what ``old`` computed, and what it was given and did not come to ask for (the values
    # a language server had not finished when the next change came): both hold for it
    # (copies: another thread may be adding to them)
    for key, value in {**dict(old.reused), **dict(old.seen)}.items():
        kind, name = key
        if kind == "value":
            if name in dirty or name not in new_spec.definitions:
                continue
            if name not in old.spec.definitions or isinstance(value, BaseException):
                continue
        elif kind == "evaluate":
            if name[0] in dirty or name[0] not in new_spec.definitions:
                continue
        elif kind == "solve":
            block = next((b for b in new_spec.solves if b.index == name), None)
            if block is None or any(n in dirty for n in _solve_reads(new_spec, block)):
                continue
        elif kind in ("table", "computed table"):
            index = next((i for i, t in enumerate(new_spec.tables) if t.name == name), None)
            if index is None or old_tables.get(index) != new_tables.get(index):
                continue
            if kind == "computed table" and (changed or new_spec.tables[index].vary):
                continue  # a block reads the sheet as it likes: reused only when nothing changed
            if _reads(new_tables.get(index), dirty):
                continue
        out[key] = value
    return out


def seeded_typer(old: Typer, new: Typer, dirty: set[str]) -> Typer:
    """``new`` with the typed definitions of ``old`` that the edit does not reach: their
    text, and the text and units of everything they read, are as they were."""
    spec = new.spec
    for name, body in dict(old.scalars).items():  # copies: values may be typing more
        if name not in dirty and name in spec.definitions:
            new.scalars[name] = body
    for key, f in dict(old.functions).items():
        name = key.split("@", 1)[0]  # a specialization (``f@2x1``) belongs to its function
        if name not in dirty and name in spec.definitions:
            new.functions[key] = f
            if key in old.recursive:
                new.recursive.add(key)
    new.derivatives.update(dict(old.derivatives))  # by the typed tree they were found for
    return new


def seeded_trees(old, spec, dirty: set[str]) -> TypedSheet:
    """The trees :class:`Sheet` types at load besides the definitions' (a scalar in the unit
    it is shown in, a printed value's formula), taken from ``old`` where the edit does not
    reach them."""
    trees = TypedSheet()
    for name, d in spec.definitions.items():
        if name not in dirty and not d.is_function and name in old.full_spec.definitions:
            key = ("scalar", name)
            t = old.typed.get(None, key)
            if t is not None:
                trees.keep(None, key, t)
    for p, new_p in zip(old.full_spec.printed, spec.printed):
        if p.read is not None and stamp(p.file) == old.printed_stamps.get(p.file):
            new_p.read = p.read  # the file of printed values is as it was read
        try:
            rows = printed_rows(p)
        except WorkbookError:
            continue
        for row in rows:
            if row.name in dirty or row.name not in spec.definitions:
                continue
            at = None if np.isnan(row.at) else row.at
            key = ("printed", row.name, at, bool(p.argument), row.unit)
            t = old.typed.get(None, key)
            if t is not None:
                trees.keep(None, key, t)
    for (col, var), new_col in _column_pairs(old.full_spec, spec):  # tables' and charts'
        if ex.names(column_node(spec, new_col, var)) & dirty:
            continue
        t = old.typed.get(col, ("column", var))
        if t is not None:
            trees.keep(new_col, ("column", var), t)
    for c, new_c in zip(old.full_spec.checks, spec.checks):  # [[checks]] as they were
        pieces = [(e, u) for text in (c.what, c.note) for e, u in placeholders(text)]
        nodes = [c.value, c.ok, *(c.parsed.get(e) for e, _ in pieces)]
        if any(n is not None and ex.names(n) & dirty for n in nodes):
            continue
        for key in ("value", "ok", *(("placeholder", e, u) for e, u in pieces)):
            t = old.typed.get(c, key)
            if t is not None:
                trees.keep(new_c, key, t)
    return trees


def _column_pairs(old_spec, spec):
    """Each column of a range table and each series' x and y over a range in ``old_spec``
    with its range variable, beside the same one of ``spec`` (whose tables and charts have
    the same text)."""
    for t_old, t_new in zip(old_spec.tables, spec.tables):
        if t_old.range is not None:
            for a, b in zip(t_old.columns, t_new.columns):
                yield (a, t_old.range.var), b
    for c_old, c_new in zip(old_spec.charts, spec.charts):
        for s_old, s_new in zip(c_old.series, c_new.series):
            rng = s_old.range or c_old.range
            if s_old.table is not None or rng is None:
                continue
            yield (s_old.y, rng.var), s_new.y
            x_old, x_new = s_old.x or c_old.x, s_new.x or c_new.x
            if x_old is not None and x_new is not None:
                yield (x_old, rng.var), x_new


def _solve_reads(spec, block) -> set[str]:
    names: set[str] = set()
    for lhs, rhs, _ in block.equations:
        names |= ex.names(lhs) | ex.names(rhs)
    for c, _ in block.conditions:
        names |= ex.names(c)
    deps = set(names)
    for n in names:
        if n in spec.definitions or n in spec.inputs:
            deps |= dependencies(spec, ex.Name(n))
    return deps


def successor(old: ReusingSheet | None, old_raw: dict, spec, raw: dict | None, values, typer=None):
    """The Sheet of ``spec`` (its TOML ``raw``, its input ``values``) after an edit of the
    one that gave ``old`` (None: none to reuse), taking from it what the edit does not reach;
    with ``typer``, the same text with other input values. Returns the Sheet, what the edit
    reached (None: everything) and, when the typing of the rest was taken over (or kept),
    the same set (else None)."""
    reuse, changed, dirty, retype = {}, None, None, None
    if old is not None and raw is not None:
        old_values = {n: str(v) for n, v in old.values.items()}
        new_values = {n: str(v) for n, v in values.items()}
        changed = changed_names(old_raw, raw, old_values, new_values)
        if changed is not None:
            dirty = downstream(spec, changed)
            reuse = reusable(old, spec, raw, old_raw, changed, dirty)
            if typer is None and only_entries_changed(old_raw, raw):
                retype = (old, dirty)
    sheet = ReusingSheet(spec, values, typer, reuse=reuse, retype=retype)
    return sheet, dirty, dirty if retype is not None or typer is not None else None


class LiveSheet:
    """One worksheet as the live page shows it: the last good load and rendering, updated
    by :meth:`refresh` (the file changed) and :meth:`set_inputs` (the form changed)."""

    def __init__(self, path: Path, *, incremental: bool = True):
        self.path = Path(path)
        self.incremental = incremental
        self.text: str | None = None
        self.raw: dict = {}
        self.sheet: ReusingSheet | None = None
        self.computed = None
        self.html: str = ""
        self.error: WorkbookError | None = None
        self.overrides: dict[str, str] = {}  # input name -> the text the form gave
        self.charts: dict[str, str] = {}  # chart digest -> its SVG
        self.drawn: dict[str, str] = {}  # chart name -> the SVG on the page
        self.pieces: dict = {}  # the last rendering's pieces (:class:`LiveDocument`)
        self.seconds: dict[str, float] = {}
        self.pending = False  # a chart on the page is the last drawing, to be drawn again
        self.version = 0
        self.lock = threading.Lock()  # one computation at a time

    @property
    def name(self) -> str:
        return self.path.stem

    def refresh(self, force: bool = False) -> Update | None:
        """Read the file again; None when its text did not change."""
        try:
            text = self.path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            return self._failed(WorkbookError(f"cannot read {self.path}: {exc}"))
        if text == self.text and not force:
            return None
        self.text = text
        return self.rebuild(text, dict(self.overrides))

    def set_inputs(self, changes: dict[str, str]) -> Update:
        """Compute again with inputs changed by the form (the file is not touched); a value
        that is refused (unit, bounds, choices) changes nothing and is returned as the error."""
        overrides = {**self.overrides, **changes}
        if self.text is None or self.sheet is None:
            return self.rebuild(self.text or "", overrides)
        try:  # a refused value is said at its field; the page stays as it is
            _input_values(self.sheet.full_spec, changes, self.path)
        except WorkbookError as err:
            return Update(None, err)
        return self.rebuild(self.text, overrides, typer_from=self.sheet)

    def rebuild(self, text: str, overrides: dict[str, str], typer_from=None) -> Update:
        """Load ``text`` with ``overrides`` and compute what changed; on an error the last
        good rendering stays and the error is returned beside it."""
        seconds: dict[str, float] = {}
        t0 = time.perf_counter()
        try:
            if typer_from is not None:  # the same text: its TOML is the one read last
                spec, typer, raw = typer_from.full_spec, typer_from.typer, self.raw
            else:
                raw = read_toml(text, str(self.path))  # read once: the spec is built from it
                spec, typer = parse_spec(text, self.path, self.path.stem, raw), None
                if raw is not None and self.raw:  # an input edited in the file: its value wins
                    old, new = _entries(self.raw, "inputs"), _entries(raw, "inputs")
                    overrides = {n: v for n, v in overrides.items() if old.get(n) == new.get(n)}
            values = _input_values(spec, overrides, self.path)
            seconds["parse"] = time.perf_counter() - t0
            t1 = time.perf_counter()
            old = self.sheet if self.incremental else None
            sheet, dirty, kept = successor(old, self.raw, spec, raw, values, typer)
            seconds["type"] = time.perf_counter() - t1
            t2 = time.perf_counter()
            computed = compute(sheet)
            seconds["compute"] = time.perf_counter() - t2
            t3 = time.perf_counter()
            drawn = self.drawn if self.incremental and self.drawn else None
            last = self.pieces if self.incremental else {}
            doc = render_body(computed, self.charts if self.incremental else {}, drawn, last, kept)
            html = doc.text
            seconds["render"] = time.perf_counter() - t3
        except WorkbookError as err:
            return self._failed(err, seconds)
        except RecursionError:
            from ..errors import LimitError

            return self._failed(LimitError("the worksheet is nested too deeply"), seconds)
        if len(self.charts) > 64:
            self.charts.clear()
        self.raw, self.sheet, self.computed, self.html = raw or {}, sheet, computed, html
        self.drawn, self.pending, self.pieces = doc.shown, doc.pending, doc.made
        self.overrides = overrides
        self.error = None
        self.seconds = seconds  # how long the last good update's stages took
        self.version += 1
        recomputed = dirty
        return Update(html, None, seconds, recomputed)

    def draw_charts(self) -> Update | None:
        """Draw the charts the last rendering left as they were (None: none is pending)."""
        if not self.pending or self.computed is None:
            return None
        t0 = time.perf_counter()
        doc = LiveDocument(self.computed, self.charts)
        with np.errstate(all="ignore"):
            inner = doc.charts()
        # only the charts' section is made again: the rest of the page is as it was
        self.html = _CHARTS.sub(lambda m: m.group(1) + inner + m.group(2), self.html, count=1)
        self.drawn, self.pending = doc.shown, False
        self.version += 1
        return Update(self.html, None, {"render": time.perf_counter() - t0}, set())

    def _failed(self, err: WorkbookError, seconds=None) -> Update:
        self.error = err.located(file=str(self.path))
        self.version += 1
        return Update(None, self.error, seconds or {})


def _input_values(spec, overrides: dict[str, str], path: Path) -> dict:
    """The inputs of ``spec`` with the form's ``overrides`` (checked: unit, bounds, choices);
    an override of an input that is no longer there is dropped."""
    from ..engine.sheet import coerce_input

    values = {n: i.value for n, i in spec.inputs.items()}
    for name, text in overrides.items():
        i = spec.inputs.get(name)
        if i is None:
            continue
        try:
            values[name] = coerce_input(i, text, file=str(path))
        except WorkbookError as err:
            raise err.located(file=str(path), line=i.line, definition=name) from None
    return values
