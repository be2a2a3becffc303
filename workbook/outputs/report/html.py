"""The report as one self-contained HTML document: the calculation as it is handed in.

Title and source, the inputs, then each definition as written by hand (symbol = formula =
the formula with the values put in = the result with its unit), the tables, the charts
(inline SVG), the checks against the printed values, what was left out, and the command
that regenerates the document. Inline CSS, no script, nothing fetched from the network.
A value the engine could not compute is shown with its error.
"""

from __future__ import annotations

import math
import re
from html import escape

import numpy as np
import pint

from ...errors import WorkbookError
from ...functions.complexes import readable
from ...language import expr as ex
from ...language import units as un
from ...language.template import column_node
from ...language.visitor import UnhandledNode
from ...verdicts import NOT_FAILED
from ...version import __version__
from . import mathml as mm
from .mathml import Box, MathML

MAX_ROWS = 1000  # a longer table shows its first and last rows (unless full_tables)
SHOWN_ROWS = 10  # rows shown at each end of a long table
# Width of the A4 text block (182 mm) in the printer's em estimate: 46.9 em of the 11 pt
# formula font, less the 22 % by which the estimate fell short of Chromium's layout (measured)
TEXT_WIDTH_EM = 38.0
MAX_COLUMNS = 7  # a wider table is cut into groups of columns
MIN_SCALE = 0.6  # a formula is scaled down to at most this before it is broken into lines

_MINUS = "\u2212"


def _error_text(err: BaseException) -> str:
    if isinstance(err, WorkbookError):
        return err.message
    return f"{type(err).__name__}: {err}"


class Values:
    """The computed values of a sheet's inputs and scalar definitions, as the report shows
    them."""

    def __init__(self, sheet):
        self.sheet = sheet
        self._results: dict[str, tuple[float, str] | BaseException] = {}

    def result(self, name: str) -> tuple[float, str] | BaseException:
        """A scalar definition's value and unit (its display unit), or the error."""
        if name not in self._results:
            d = self.sheet.spec.definitions[name]
            scalar = self.sheet.scalars[name]
            try:
                if scalar.error is not None:
                    raise scalar.error
                q = scalar.value
                if isinstance(q, str):  # a text: "OK"
                    self._results[name] = q
                    return q
                if d.unit is not None:
                    q = q.to(d.unit)
                mag = q.magnitude
                if not np.ndim(mag):
                    mag = complex(mag) if np.iscomplexobj(mag) else float(mag)
                self._results[name] = (mag, un.pretty(q.units))
            except (WorkbookError, pint.errors.PintError) as err:  # shown, never blank
                self._results[name] = err
        return self._results[name]

    def __call__(self, name: str) -> mm.Value | None:
        """What substitution shows for ``name`` (None: keep the name)."""
        sheet = self.sheet
        if name in sheet.spec.inputs:
            v = sheet.values[name]
            if isinstance(v, str):
                return v
            spec = sheet.spec.inputs[name]
            unit = "" if spec.label else un.pretty(spec.unit)  # a labelled number is plain
            return (float(v.magnitude), unit)
        d = sheet.spec.definitions.get(name)
        if d is not None and not d.is_function:
            r = self.result(name)
            if isinstance(r, BaseException) or (isinstance(r, tuple) and np.ndim(r[0])):
                return None  # an error, or a matrix: the name stays in the formula
            return r
        return None


def _with_errors(column):
    """A table column's values, a failed row as its Excel error value."""
    if not column.failed:
        return column.values
    out = column.values.astype(object)
    for i in column.failed:
        out[i] = column.excel_error(i)
    return out


def num_html(value, digits: int = mm.PRECISION) -> str:
    """A table cell's number: 6 significant digits, a true minus, powers of ten as 10^n."""
    if isinstance(value, (bool, np.bool_)):
        return "yes" if value else "no"
    if isinstance(value, (int, np.integer)):
        return str(int(value)).replace("-", _MINUS)
    if isinstance(value, (complex, np.complexfloating)):  # a + bi
        return escape(readable(value, digits)).replace("-", _MINUS)
    if not isinstance(value, (float, np.floating)):
        return escape(str(value))
    v = float(value)
    if math.isnan(v):
        return "NaN"
    if math.isinf(v):
        return ("\u2212" if v < 0 else "") + "\u221e"
    mant, exp = mm.number_text(abs(v), digits)
    text = mant if exp is None else f"{mant}\u00d710<sup>{str(exp).replace('-', _MINUS)}</sup>"
    return (_MINUS if v < 0 else "") + text


def _fit(box: Box, lead: float = 0.0) -> str:
    """A ``<math>`` element, scaled down when it is wider than the text block."""
    width = box.width + lead
    style = ""
    if width > TEXT_WIDTH_EM:
        scale = max(MIN_SCALE, TEXT_WIDTH_EM / width)
        style = f" style='font-size:{100 * scale:.0f}%'"
    return f"<math{style}>{box.xml}</math>"


def _eq_box(*boxes: Box) -> Box:
    return Box("".join(b.xml for b in boxes), sum(b.width for b in boxes))


_EQ = Box("<mo>=</mo>", 1.2)


def _lines(sym: Box, printer: MathML, node: ex.Node, strict: bool = False) -> list[str] | None:
    """A formula too wide even scaled down: one line per term of its top-level sum (None
    with ``strict`` when a term alone is still too wide)."""
    terms: list[tuple[str, ex.Node]] = []

    def split(n: ex.Node, sign: str) -> None:
        if isinstance(n, ex.Binary) and n.op in "+-":
            split(n.left, sign)
            terms.append((n.op, n.right))
        else:
            terms.append((sign, n))

    split(node, "")
    out = []
    for i, (op, term) in enumerate(terms):
        body = printer.wrap(term, mm.PREC["+"] + (1 if op == "-" else 0))
        if op:
            body = _eq_box(Box(f"<mo>{_MINUS if op == '-' else '+'}</mo>", 1.0), body)
        head = _eq_box(sym, _EQ) if i == 0 else Box("", 0.0)
        lead = 0 if i == 0 else sym.width + 1.2
        line = _eq_box(head, body)
        if strict and _too_wide(line, lead):
            return None
        out.append(_fit(line, lead))
    return out


def _too_wide(box: Box, lead: float = 0.0) -> bool:
    return (box.width + lead) * MIN_SCALE > TEXT_WIDTH_EM


class Document:
    """Builds the report of one computed sheet
    (:class:`workbook.compute.computed.ComputedSheet`)."""

    def __init__(self, sheet, *, command: str | None = None, full_tables: bool = False):
        self.sheet = sheet
        self.spec = sheet.spec
        self.values = Values(sheet)
        self.formula = MathML()
        self.substituted = MathML(self.values)
        self.command = command or regenerate_command(sheet)
        self.full_tables = full_tables
        self.section = 0

    # -- the whole --------------------------------------------------------------------------
    def body(self) -> str:
        parts = [self.header()]
        for title, make in (
            ("Inputs", self.inputs),
            ("Calculation", self.definitions),
            ("Tables", self.tables),
            ("Charts", self.charts),
            ("Checks", self.checks),
            ("About this document", self.about),
        ):
            try:
                inner = make()
            except (WorkbookError, UnhandledNode) as err:  # one section does not hide the others
                inner = f"<p class='error'>error: {escape(_error_text(err))}</p>"
            if inner:
                self.section += 1
                parts.append(
                    f"<section class='{title.split()[0].lower()}'>"
                    f"<h2>{self.section}. {escape(title)}</h2>{inner}</section>"
                )
        return "\n".join(parts)

    def header(self) -> str:
        spec = self.spec
        out = [f"<header><h1>{escape(spec.title or spec.name)}</h1>"]
        if spec.source:
            out.append(f"<p class='source'><b>Source:</b> {escape(spec.source)}</p>")
        if spec.description:
            out.append(f"<p class='description'>{escape(spec.description)}</p>")
        out.append(
            f"<p class='meta'>Worksheet <code>{escape(spec.name)}</code> "
            f"({escape(spec.path.name)}), computed by workbook {escape(__version__)}</p>"
        )
        out.append("</header>")
        return "".join(out)

    # -- inputs -----------------------------------------------------------------------------
    def inputs(self) -> str:
        rows = []
        for name, spec in self.spec.inputs.items():
            v = self.sheet.values[name]
            sym = mm.math_element(mm.name_box(name))
            if isinstance(v, str):
                value = f"\u201c{escape(v)}\u201d"
                unit = ""
                note = _join_note(spec.note, "one of: " + ", ".join(spec.options))
            else:
                value = num_html(float(v.magnitude), 12)
                unit_text = spec.label or un.pretty(spec.unit)
                unit = mm.math_element(mm.unit_box(unit_text)) if unit_text else ""
                note = spec.note
            rows.append(
                f"<tr data-name='{escape(name)}'><td>{sym}</td><td class='num'>{value}</td>"
                f"<td class='unit'>{unit}</td><td>{escape(note)}</td></tr>"
            )
        if not rows:
            return ""
        out = [
            "<table class='inputs'><thead><tr><th>Symbol</th><th>Value</th><th>Unit</th>"
            f"<th>Note</th></tr></thead><tbody>{''.join(rows)}</tbody></table>"
        ]
        args = []
        for name, a in self.spec.arguments.items():
            unit_text = un.pretty(a.unit)
            unit = mm.math_element(mm.unit_box(unit_text)) if unit_text else ""
            note = _join_note(
                a.note, "a plain number in its unit inside formulas" if a.plain else ""
            )
            args.append(
                f"<tr><td>{mm.math_element(mm.name_box(name))}</td><td class='unit'>{unit}</td>"
                f"<td>{escape(note)}</td></tr>"
            )
        if args:
            out.append(
                "<h3>Arguments of the functions</h3><table class='arguments'><thead><tr>"
                "<th>Symbol</th><th>Unit</th><th>Note</th></tr></thead>"
                f"<tbody>{''.join(args)}</tbody></table>"
            )
        return "".join(out)

    # -- definitions ------------------------------------------------------------------------
    def definitions(self) -> str:
        out = [self.given_find(b) for b in self.spec.solves]
        out += [self.definition(d) for d in self.spec.definitions.values()]
        return "".join(out)

    def given_find(self, block) -> str:
        """A [[solve]] block as Mathcad shows one: the guesses, Given, the equations and the
        conditions, then Find and the solution with its error estimate."""
        guesses = ", ".join(f"{n} = {q:~}" for n, q in block.unknowns.items())
        lines = [f"<p class='note'>guesses: {escape(guesses)}</p>", "<p>Given</p>"]
        for lhs, rhs, text in block.equations:
            try:
                eq = _eq_box(self.formula.box(lhs), _EQ, self.formula.box(rhs))
                lines.append(_fit(eq))
            except (UnhandledNode, WorkbookError):  # a node the printer does not know: the text
                lines.append(f"<p>{escape(text)}</p>")
        for node, text in block.conditions:
            try:
                lines.append(_fit(self.formula.box(node)))
            except (UnhandledNode, WorkbookError):
                lines.append(f"<p>{escape(text)}</p>")
        find = f"Find({', '.join(block.unknowns)})"
        if block.parameters:  # a function: solved where it is called
            at = ", ".join(block.parameters)
            calls = ", ".join(f"{n}({at})" for n in block.unknowns)
            return (
                f"<div class='definition given'>{''.join(lines)}<p>{escape(calls)} := "
                f"{escape(find)}, solved at each value of {escape(at)}</p></div>"
            )
        try:
            found = [self.sheet.unknowns[n] for n in block.unknowns]
            error = next((u.error for u in found if u.error is not None), None)
            if error is not None:
                raise error
            values = [u.value for u in found]
            solved = found[0].solution
            shown = "; ".join(
                f"{n} = {num_html(float(q.magnitude))} {escape(un.typeset(q.units))}".rstrip()
                + f" (error estimate {solved.errors.get(n, float('nan')):.2g})"
                for n, q in zip(block.unknowns, values)
            )
            result = f"<p>{escape(find)}: {shown}; condition number {solved.condition:.3g}</p>"
        except WorkbookError as err:
            result = f"<p class='error'>{escape(find)} not computed: {escape(_error_text(err))}</p>"
        return f"<div class='definition given'>{''.join(lines)}{result}</div>"

    def definition(self, d) -> str:
        try:
            if d.is_function:
                call = ex.Call(d.name, tuple(ex.Name(p) for p in d.params))
                sym = self.formula.box(call)
            else:
                sym = mm.name_box(d.name)
            formula = self.formula.pieces(d.branches) if d.branches else self.formula.box(d.body)
        except (UnhandledNode, WorkbookError) as err:  # a node the printer does not know: text
            sym, formula = mm.name_box(d.name), mm.text_box(d.text)
            del err
        pieces: list[str] = []
        first = _eq_box(sym, _EQ, formula)
        if d.body is not None and _too_wide(first) and isinstance(d.body, ex.Binary):
            pieces += _lines(sym, self.formula, d.body)
        else:
            pieces.append(_fit(first))
        notes = [d.note] if d.note else []
        error = ""
        if d.is_function:
            unit = self.sheet.function_units.get(d.name)
            unit = "" if unit is None else un.typeset(unit)
            if unit:
                notes.append(f"in {unit}")
            shown = self._shown_in(d.name)
            if shown:
                notes.append("values in " + ", ".join(shown))
        else:
            if d.body is not None and self._substitutes(d.body):
                subst = self.substituted.box(d.body)
                if not _too_wide(subst, 1.2):
                    pieces.append(_fit(_eq_box(_EQ, subst)))
                else:  # a line per term, or (a term still too wide) not shown
                    lines = _lines(Box("", 0.0), self.substituted, d.body, strict=True)
                    pieces += lines or []
                    if not lines:
                        notes.append("the formula with the values put in is too long to show")
            r = self.values.result(d.name)
            if isinstance(r, BaseException):
                error = f"<p class='error'>not computed: {escape(_error_text(r))}</p>"
                result = mm.text_box("not computed", "error")
            elif isinstance(r, str):
                text = mm.text_box(f"\u201c{r}\u201d")
                result = Box(_named("result-text", d.name, text.xml), text.width)
            elif np.ndim(r[0]):
                box = mm.matrix_box(r[0], r[1])
                result = Box(_named("result-matrix", d.name, box.xml), box.width)
            else:
                attrs = f"class='result' data-name='{escape(d.name)}'"
                result = mm.quantity_box(r[0], r[1], attrs=attrs, polar=self.spec.polar)
            pieces.append(_fit(_eq_box(_EQ, result)))
        blocks = [
            self.spec.blocks[n]
            for n in (ex.names(d.body) if d.body is not None else ())
            if n in self.spec.blocks
        ]
        if blocks:
            notes.append("solver block " + ", ".join(blocks))
        note = f"<p class='note'>{escape('; '.join(notes))}</p>" if notes else ""
        return (
            f"<div class='definition' id='def-{escape(d.name)}'>"
            f"<div class='eq'>{' '.join(pieces)}</div>{note}{error}</div>"
        )

    def _shown_in(self, name: str) -> list[str]:
        """The tables and charts whose columns call function ``name`` directly."""
        out = []
        for t in self.spec.tables:
            if t.range is not None and any(
                name in ex.names(column_node(self.spec, c, t.range.var)) for c in t.columns
            ):
                out.append(f"table {t.name}")
        for c in self.spec.charts:
            rng = c.range
            if any(
                s.table is None
                and (s.range or rng) is not None
                and name in ex.names(column_node(self.spec, s.y, (s.range or rng).var))
                for s in c.series
            ):
                out.append(f"chart {c.name}")
        return out

    def _substitutes(self, node: ex.Node) -> bool:
        """True if the formula has names to put values in (and is not just one name)."""
        if isinstance(node, ex.Name):
            return False
        return any(isinstance(n, ex.Name) and self.values(n.id) is not None for n in ex.walk(node))

    # -- tables -----------------------------------------------------------------------------
    def tables(self) -> str:
        out = []
        for t in self.spec.tables:
            head = f"<h3>Table {escape(t.name)}: {escape(t.title)}</h3>"
            try:
                body = self.computed_table(t) if t.computed else self.range_table(t)
            except WorkbookError as err:
                body = f"<p class='error'>not computed: {escape(_error_text(err))}</p>"
            out.append(f"<div class='table' id='table-{escape(t.name)}'>{head}{body}</div>")
        return "".join(out)

    def range_table(self, t) -> str:
        data = self.sheet.table(t.name)
        rng = t.range
        first = self.formula.box(rng.first)
        if rng.second is not None:
            comma = Box("<mo separator='true'>,</mo>", 0.5)
            first = _eq_box(first, comma, self.formula.box(rng.second))
        if rng.points is not None:  # f := logspace(first, last, points)
            call = ex.Call("logspace", (rng.first, rng.last, rng.points))
            range_math = mm.math_element(
                mm.name_box(rng.var), Box("<mo>:=</mo>", 1.2), self.formula.box(call)
            )
        else:
            range_math = mm.math_element(
                mm.name_box(rng.var),
                Box("<mo>:=</mo>", 1.2),
                first,
                Box("<mo>..</mo>", 1.0),
                self.formula.box(rng.last),
            )
        heads = []
        for i, col in enumerate(data.columns):
            node = ex.Name(rng.var) if i == 0 else column_node(self.spec, t.columns[i - 1], rng.var)
            try:
                sym = mm.math_element(self.formula.box(node))
            except (UnhandledNode, WorkbookError):
                sym = escape(col.text)
            unit = un.pretty(col.unit)
            unit_html = mm.math_element(mm.unit_box(unit)) if unit else ""
            heads.append(f"{sym}<br><span class='unit'>{unit_html}</span>")
        columns = [_with_errors(c) for c in data.columns]
        n = len(columns[0])
        rows = f"{n:,} row{'s' if n != 1 else ''}"
        failed = "".join(
            f"<p class='error'>{escape(c.text)} has no value in {len(c.failed):,} row(s); the "
            f"first: {escape(c.failed[min(c.failed)])}</p>"
            for c in data.columns
            if c.failed
        )
        return f"<p class='range'>{range_math}: {rows}</p>" + self._grid(heads, columns, n) + failed

    def computed_table(self, t) -> str:
        df = self.sheet.table(t.name)
        heads = []
        for name in df.columns:
            m = re.match(r"^(.*?)\s*\[(.*)\]$", str(name))
            label, unit = (m.group(1), m.group(2)) if m else (str(name), "")
            unit_html = f"<br><span class='unit'>{escape(unit)}</span>" if unit else ""
            heads.append(f"{escape(label)}{unit_html}")
        columns = [df[c].to_numpy(dtype=object) for c in df.columns]
        how = (
            f"computed by the solver block <code>{escape(t.block)}</code>"
            if t.block
            else f"the columns at each value of {escape(_varied(t))}"
        )
        return (
            f"<p class='range'>{how}: {len(df):,} row{'s' if len(df) != 1 else ''}</p>"
            + self._grid(heads, columns, len(df))
        )

    def _grid(self, heads: list[str], columns: list, n: int) -> str:
        """A table that fits the page: a table of one or two rows is turned on its side (one
        line per column); a wide one is cut into groups of columns, each repeating the
        first; a long one shows its first and last rows."""
        if n <= 2 and len(heads) > 4:
            body = "".join(
                f"<tr data-col='{j}'><th>{h.replace('<br>', ' ')}</th>"
                + "".join(f"<td class='num'>{num_html(v)}</td>" for v in columns[j])
                + "</tr>"
                for j, h in enumerate(heads)
            )
            return f"<table class='data turned'><tbody>{body}</tbody></table>"
        groups = [list(range(len(heads)))]
        if len(heads) > MAX_COLUMNS:
            rest = list(range(1, len(heads)))
            step = MAX_COLUMNS - 1
            groups = [[0] + rest[i : i + step] for i in range(0, len(rest), step)]
        out = []
        for cols in groups:
            head = "".join(f"<th data-col='{j}'>{heads[j]}</th>" for j in cols)
            body = self._rows(n, lambda k, cols=cols: [columns[j][k] for j in cols], len(cols))
            out.append(
                f"<table class='data'><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"
            )
        return "".join(out)

    def _rows(self, n: int, row, width: int) -> str:
        if n <= MAX_ROWS or self.full_tables:
            shown = list(range(n))
        else:
            shown = list(range(SHOWN_ROWS)) + [None] + list(range(n - SHOWN_ROWS, n))
        out = []
        for k in shown:
            if k is None:
                left = n - 2 * SHOWN_ROWS
                out.append(
                    f"<tr class='skipped'><td colspan='{width}'>\u2026 {left:,} rows not shown "
                    f"(the table has {n:,} rows; <code>--full-tables</code> shows all)</td></tr>"
                )
                continue
            cells = "".join(f"<td class='num'>{num_html(v)}</td>" for v in row(k))
            out.append(f"<tr>{cells}</tr>")
        return "".join(out)

    # -- charts -----------------------------------------------------------------------------
    def charts(self) -> str:
        if not self.spec.charts:
            return ""
        from .charts import chart_svg

        out = []
        for c in self.spec.charts:
            try:
                svg = chart_svg(self.sheet, c)
            except WorkbookError as err:
                svg = f"<p class='error'>not drawn: {escape(_error_text(err))}</p>"
            out.append(
                f"<figure id='chart-{escape(c.name)}'>{svg}"
                f"<figcaption>{escape(c.title)}</figcaption></figure>"
            )
        return "".join(out)

    # -- checks -----------------------------------------------------------------------------
    def checks(self) -> str:
        if not (self.spec.printed or self.spec.findings or self.spec.relations):
            return ""
        report = self.sheet.check_report()
        out = []
        by_source: dict[str, list] = {}
        for r in report.rows:
            by_source.setdefault(r.source, []).append(r)
        for source, rows in by_source.items():
            role = rows[0].role
            good = sum(r.verdict in NOT_FAILED for r in rows)
            kind = "for information" if role == "information" else "checked"
            out.append(
                f"<h3>{escape(source)}</h3><p class='summary'>{kind}: {good} of {len(rows)} "
                "printed values reproduced</p>"
            )
            out.append(self._check_table(rows, rows[0].argument))
        if report.findings:
            out.append("<h3>Findings</h3>" + self._findings(report.findings))
        if report.unused_inputs:
            out.append(
                "<p class='note'>Inputs that no output uses: "
                + escape(", ".join(report.unused_inputs))
                + "</p>"
            )
        bad = report.failed
        verdict = (
            "<p class='verdict pass'>\u2714 all printed values reproduced</p>"
            if not bad
            else f"<p class='verdict fail'>\u2718 {len(bad)} printed value(s) NOT reproduced</p>"
        )
        return verdict + "".join(out)

    def _check_table(self, rows, argument: str) -> str:
        from ...compute.checks import tolerances

        body = []
        for r in rows:
            at = "" if r.at is None else num_html(r.at)
            comp = "not computed" if r.computed is None else num_html(r.computed)
            abs_err = "" if r.abs_error is None else num_html(r.abs_error, 2)
            rel_err = "" if r.rel_error is None else num_html(100 * r.rel_error, 2) + " %"
            bound, rel = tolerances(r.printed, r.tolerance, r.rel_tolerance)
            tol = []
            if bound is not None:
                tol.append(num_html(r.tolerance if r.tolerance is not None else bound))
            if rel is not None:
                tol.append(num_html(100 * rel) + " %")
            body.append(
                f"<tr class='{_VERDICT_CLASS.get(r.verdict, '')}' data-name='{escape(r.name)}'>"
                f"<td>{mm.math_element(mm.name_box(r.name))}</td><td class='num'>{at}</td>"
                f"<td class='unit'>{_unit_math(r.unit)}</td>"
                f"<td class='num'>{num_html(r.printed, 12)}</td>"
                f"<td class='num computed'>{comp}</td>"
                f"<td class='num'>{abs_err}</td><td class='num'>{rel_err}</td>"
                f"<td class='num'>{' or '.join(tol)}</td>"
                f"<td class='verdict'>{_mark(r.verdict)}</td><td>{escape(r.note)}</td></tr>"
            )
        return (
            "<table class='data checks'><thead><tr><th>Name</th>"
            f"<th>{mm.math_element(mm.name_box(argument)) if argument else ''}</th><th>Unit</th>"
            "<th>Printed</th><th>Computed</th><th>Abs. error</th><th>Rel. error</th>"
            "<th>Tolerance</th><th>Verdict</th><th>Note</th></tr></thead>"
            f"<tbody>{''.join(body)}</tbody></table>"
        )

    def _findings(self, findings) -> str:
        body = []
        for f in findings:
            value = "" if f.value is None else num_html(float(f.value))
            body.append(
                f"<tr class='{_VERDICT_CLASS.get(f.verdict, '')}'><td>{escape(f.topic)}</td>"
                f"<td>{escape(f.what)}</td><td class='num'>{value}</td>"
                f"<td class='unit'>{_unit_math(f.unit)}</td>"
                f"<td class='verdict'>{_mark(f.verdict)}</td>"
                f"<td>{escape(f.note)}</td></tr>"
            )
        return (
            "<table class='data findings'><thead><tr><th>Topic</th><th>What</th><th>Value</th>"
            "<th>Unit</th><th>Verdict</th><th>Note</th></tr></thead>"
            f"<tbody>{''.join(body)}</tbody></table>"
        )

    # -- the end ----------------------------------------------------------------------------
    def about(self) -> str:
        out = []
        full = self.sheet.full_spec
        left = self.sheet.left_out
        if left:
            items = "".join(
                f"<li><b>{escape(n)}</b>: {escape(full.parts[n].title)}"
                f"{' (' + escape(full.parts[n].note) + ')' if full.parts[n].note else ''}; "
                f"add it with <code>--part {escape(n)}</code></li>"
                for n in left
            )
            out.append(f"<p>Optional parts left out (not computed):</p><ul>{items}</ul>")
        included = [p for p in self.sheet.parts if p in full.parts]
        if included:
            names = ", ".join(f"{n} ({full.parts[n].title})" for n in included)
            out.append(f"<p>Optional parts included: {escape(names)}.</p>")
        out.append(
            "<p>Regenerate this document with:</p>"
            f"<pre class='command'>{escape(self.command)}</pre>"
            f"<p class='meta'>Worksheet file: <code>{escape(self.spec.path.name)}</code>; "
            f"workbook {escape(__version__)}. Every number is the engine's, shown to "
            f"{mm.PRECISION} significant digits.</p>"
        )
        return "".join(out)


_VERDICT_CLASS = {
    "pass": "pass",
    "ok": "pass",
    "FAIL": "fail",
    "fail": "fail",
    "error": "fail",
    "misprint": "misprint",
    "warning": "misprint",
    "info": "info",
}


def _mark(verdict: str) -> str:
    sign = {
        "pass": "\u2714",
        "ok": "\u2714",
        "FAIL": "\u2718",
        "fail": "\u2718",
        "error": "\u2718",
        "misprint": "\u26a0",
        "warning": "\u26a0",
        "info": "\u2139",
    }.get(verdict, "")
    return f"{sign} {escape(verdict)}".strip()


def _unit_math(text: str) -> str:
    """A unit written in a check or finding (``m/s^2``) as MathML, or as it is if pint does
    not read it."""
    if not text:
        return ""
    try:
        shown = un.pretty(un.unit(text))
    except WorkbookError:
        return escape(text)
    return mm.math_element(mm.unit_box(shown)) if shown else escape(text)


def _join_note(*parts: str) -> str:
    return "; ".join(p for p in parts if p)


def regenerate_command(sheet, sets: dict[str, str] | None = None) -> str:
    """``workbook report NAME --part ... --set ...`` for this sheet."""
    from ...data import list_templates

    installed = list_templates().get(sheet.name)
    same = installed is not None and installed.resolve() == sheet.spec.path.resolve()
    parts = ["workbook", "report", sheet.name if same else str(sheet.spec.path)]
    parts += [f"--part {p}" for p in sheet.parts if p in sheet.full_spec.parts]
    changed = sets
    if changed is None:
        changed = {}
        for name, spec in sheet.full_spec.inputs.items():
            v = sheet.values.get(name)
            if v is not None and str(v) != str(spec.value):
                changed[name] = v if isinstance(v, str) else f"{v.magnitude:g} {un.pretty(v.units)}"
    for name, value in changed.items():
        value = str(value).strip()
        parts.append(f'--set {name}="{value}"' if " " in value else f"--set {name}={value}")
    return " ".join(parts)


CSS = """
.workbook-report { font: 10pt/1.45 "DejaVu Sans", "Liberation Sans", Arial, sans-serif;
  color: #111; max-width: 182mm; }
.workbook-report h1 { font-size: 16pt; margin: 0 0 .4em; line-height: 1.25; }
.workbook-report h2 { font-size: 13pt; margin: 1.2em 0 .5em; border-bottom: 1px solid #999;
  break-after: avoid; }
.workbook-report h3 { font-size: 10.5pt; margin: 1em 0 .3em; break-after: avoid; }
.workbook-report p { margin: .3em 0; }
.workbook-report .meta, .workbook-report .note, .workbook-report .range { color: #444;
  font-size: 9pt; }
.workbook-report math { font-family: "TeX Gyre Termes Math", "DejaVu Math TeX Gyre",
  "Latin Modern Math", "STIX Two Math", math; font-size: 11pt; math-style: normal; }
.workbook-report .definition { break-inside: avoid; margin: .35em 0 .5em; }
.workbook-report .eq { line-height: 2.1; }
.workbook-report .eq math { margin-right: .25em; }
.workbook-report mtd { text-align: left; padding: .1em .6em .1em 0; }
.workbook-report mfrac > *, .workbook-report mtable { math-style: normal; }
.workbook-report .error { color: #b00020; }
.workbook-report mtext.error { color: #b00020; }
.workbook-report table { border-collapse: collapse; margin: .3em 0 .8em; font-size: 8.5pt; }
.workbook-report tr { break-inside: avoid; }
.workbook-report thead { display: table-header-group; }
.workbook-report th { background: #eee; border-bottom: 1px solid #888; padding: 2px 6px;
  text-align: center; vertical-align: bottom; font-weight: 600; }
.workbook-report table.inputs th:last-child, .workbook-report table.arguments th:last-child,
.workbook-report table.checks th:last-child, .workbook-report table.findings th:nth-child(2),
.workbook-report table.findings th:last-child { text-align: left; }
.workbook-report table.checks, .workbook-report table.findings { width: 100%; }
.workbook-report td.verdict { white-space: nowrap; }
.workbook-report td { border-bottom: 1px solid #ddd; padding: 1px 6px; vertical-align: top; }
.workbook-report td.num { text-align: right; font-variant-numeric: tabular-nums;
  white-space: nowrap; }
.workbook-report table.inputs td, .workbook-report table.arguments td { font-size: 9pt; }
.workbook-report table math { font-size: 10pt; }
.workbook-report th .unit { font-weight: normal; }
.workbook-report tr.skipped td { text-align: center; color: #555; font-style: italic; }
.workbook-report tr.fail td.verdict, .workbook-report .verdict.fail { color: #b00020;
  font-weight: 700; }
.workbook-report tr.pass td.verdict, .workbook-report .verdict.pass { color: #1b7d2b;
  font-weight: 700; }
.workbook-report tr.misprint td.verdict { color: #a05a00; font-weight: 700; }
.workbook-report tr.info td.verdict { color: #555; }
.workbook-report table.checks td:last-child, .workbook-report table.findings td:nth-child(2),
.workbook-report table.findings td:last-child { font-size: 8pt; }
.workbook-report figure { break-inside: avoid; margin: .6em 0 1em; }
.workbook-report figure svg { width: 100%; max-width: 170mm; height: auto; display: block; }
.workbook-report figcaption { font-size: 9pt; color: #333; text-align: center; }
.workbook-report pre.command { background: #f4f4f4; padding: .4em .6em; white-space: pre-wrap;
  word-break: break-all; }
.workbook-report code { font-size: 9pt; }
"""


def page_css(title: str) -> str:
    """The print page: A4, margins, the worksheet name and the page number in the footer."""
    label = title.replace("\\", "").replace('"', "'")
    if len(label) > 70:
        label = label[:67] + "..."
    return (
        "@page { size: A4; margin: 15mm 14mm 17mm;"
        f' @bottom-left {{ content: "{label}"; font: 8pt sans-serif; color: #555; }}'
        ' @bottom-right { content: "page " counter(page) " of " counter(pages);'
        " font: 8pt sans-serif; color: #555; } }\n"
        "html, body { margin: 0; } body { padding: 0; }\n"
        "@media screen { body { padding: 12mm; } }\n"
    )


def render(sheet, *, command: str | None = None, full_tables: bool = False) -> str:
    """The report of ``sheet`` (a :class:`workbook.compute.computed.ComputedSheet`) as a complete
    HTML document (inline CSS, no script)."""
    doc = Document(sheet, command=command, full_tables=full_tables)
    with np.errstate(all="ignore"):
        body = doc.body()
    title = sheet.spec.title or sheet.name
    return (
        "<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'>"
        f"<meta name='generator' content='workbook report {escape(__version__)}'>"
        f"<title>{escape(title)}</title><style>{page_css(sheet.name)}{CSS}</style></head>\n"
        f"<body><main class='workbook-report'>\n{body}\n</main></body></html>\n"
    )


def fragment(sheet, *, full_tables: bool = False) -> str:
    """The same report of a computed sheet as an HTML fragment with its scoped style (for
    notebooks)."""
    doc = Document(sheet, full_tables=full_tables)
    with np.errstate(all="ignore"):
        body = doc.body()
    return f"<div class='workbook-report'><style>{CSS}</style>\n{body}\n</div>"


def _varied(t) -> str:
    """``c1 = 1500 N/m, 3000 N/m``: the input a family table varies, and its values."""
    ((name, values),) = t.vary.items()
    return f"{name} = {', '.join(values)}"


def _named(cls: str, name: str, xml: str) -> str:
    """A result that is a text or a matrix, marked with the definition it is the value of."""
    return f"<mrow class='{cls}' data-name='{escape(name)}'>{xml}</mrow>"
