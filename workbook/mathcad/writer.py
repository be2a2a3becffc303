"""Writing a translation as a worksheet: ``NAME.toml`` and its printed-values CSV files."""

from __future__ import annotations

import csv
import io
import re
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import InputError
from ..language import expr as ex
from ..language.csvcells import csv_text
from .functions import language_functions
from .symbols import Sym
from .tomldoc import Document, is_one_line, one_line
from .translation import Item, Skipped, Translation
from .trees import rename
from .units import PRIME_UNITS_OFF

#: Relative tolerance of the printed values: Mathcad stores full doubles.
REL_TOLERANCE = 1e-9
#: Absolute tolerance (in the printed unit), for results Mathcad stores as exactly 0.
ABS_TOLERANCE = 1e-12


@dataclass
class Rendered:
    name: str
    toml: str
    csv: dict[str, str] = field(default_factory=dict)
    definitions: int = 0
    region_of: dict[str, str] = field(default_factory=dict)  # identifier -> region id
    #: chart name -> (region id, the number of Mathcad's trace of each series in order)
    chart_of: dict[str, tuple[str, list[int]]] = field(default_factory=dict)
    table_of: dict[str, str] = field(default_factory=dict)  # table name -> its range's region


def pretty_unit(text: str) -> str:
    """Unit text in pint's short form (``kN / m ** 2``); as it is if pint cannot read it."""
    from ..language import units as un

    try:
        return format(un.registry().Unit(text), "~")
    except Exception:  # noqa: BLE001 - left as written, the engine reports it at load
        return text


def pretty_quantity(text: str) -> str:
    number, _, unit = text.partition(" ")
    return f"{number} {pretty_unit(unit)}" if unit and "/ (" not in text else text


def assign_identifiers(tr: Translation) -> None:
    """Choose every symbol's identifier: unique, not a built-in, arguments apart from the
    names of inputs and definitions (shared by arguments of the same unit)."""
    from ..functions.constants import CONSTANTS

    reserved = set(language_functions()) | {"pi"}
    # a name left out (untranslated) is never a constant's: its stored results would read
    # the constant (Mathcad's own e is written exp(1))
    constants = set(CONSTANTS)
    taken: dict[str, Sym] = {}
    lower: set[str] = set()
    # (base, candidates) -> the first number not tried by a claim that shares nothing: the
    # numbers before it stay taken (20,000 redefinitions of x tried 2e8 names)
    untried: dict[tuple[str, int], int] = {}

    def claim(sym: Sym, share=None, alt=True) -> None:
        off = reserved | constants if sym.broken else reserved
        base = sym.base if sym.base not in off else sym.base + "_"
        # an argument named like a variable gets a trailing _ first (x and x_), then numbers
        candidates = [base] + ([base + "_"] if share is not None and alt else [])
        if sym.kind == "unit":  # a unit whose name the worksheet uses: kN_unit
            candidates.append(base + "_unit")
        key = (base, len(candidates))
        n, named = 1, set(candidates)
        if share is None and key in untried:  # its candidates were taken then, so are now
            n, candidates = untried[key], []
        while True:
            name = candidates.pop(0) if candidates else f"{base}_{n}"
            other = taken.get(name)
            if other is None and name.lower() not in lower:
                break
            if other is not None and share is not None and share(other):
                break
            n += 1
        if share is None and name not in named:  # a number, after every candidate
            untried[key] = n + 1
        sym.final = name
        taken[name] = sym
        lower.add(name.lower())

    arguments = [s for s in tr.syms if s.kind == "param" or s.is_range]
    for sym in tr.syms:
        if sym.kind in ("var", "func", "helper") and not sym.is_range:
            claim(sym)
    for sym in tr.syms:  # locals: never a name of the sheet; programs share a local's name
        if sym.kind == "local":  # (two locals of one program are two Mathcad names: x.LN, x.LN_)
            claim(
                sym, share=lambda o, s=sym: o.kind == "local" and o.mathcad == s.mathcad, alt=False
            )
    for sym in arguments:
        claim(sym, share=lambda o, s=sym: (o.kind == "param" or o.is_range) and o.unit == s.unit)
    for sym in tr.syms:
        if sym.kind == "unit":
            claim(sym)


def _text(node: ex.Node, mapping: dict[str, str]) -> str:
    return ex.to_text(rename(node, mapping))


def _wrapped(text: str, width: int = 96) -> list[str]:
    """A paragraph text as comment lines of at most ``width`` characters."""
    lines = []
    for para in text.splitlines():
        words, cur = para.split(), ""
        for w in words:
            if cur and len(cur) + len(w) + 1 > width:
                lines.append(cur)
                cur = w
            else:
                cur = f"{cur} {w}".strip()
        if cur:
            lines.append(cur)
    return lines


class _Section:
    """The entries of one table, written after the others are known (comments that precede
    an entry go with it)."""

    def __init__(self, name: str) -> None:
        self.name = name
        self.entries: list[tuple] = []

    def comment(self, text: str) -> None:
        self.entries.append(("comment", text))

    def pair(self, key: str, value, *, multiline: bool = False) -> None:
        self.entries.append(("pair", key, value, multiline))

    def write(self, doc: Document) -> None:
        if not self.entries:
            return
        doc.table(self.name)
        for entry in self.entries:
            if entry[0] == "comment":
                doc.comment(entry[1])
            else:
                doc.pair(entry[1], entry[2], multiline=entry[3])
        doc.blank()


def render(tr: Translation, name: str, src: Path) -> Rendered:
    """The worksheet text and its CSV files."""
    doc, out = document(tr, name, src)
    out.toml = doc.text()
    return out


def document(tr: Translation, name: str, src: Path) -> tuple[Document, Rendered]:
    """The worksheet as a TOML document (its data, not yet written as text) and its CSV files;
    the document's text is left to :meth:`Document.text`, once the engine has typed it."""
    assign_identifiers(tr)
    _list_unknown_units(tr)
    mapping = {s.token(): s.final for s in tr.syms}
    out = Rendered(name, "")
    doc = Document()
    _header(tr, src, doc)
    doc.blank()
    doc.table("sheet")
    doc.pair("name", name)
    doc.pair("title", tr.title or name)
    doc.pair("source", "Mathcad worksheet " + src.name)
    if tr.origin:
        doc.pair("origin", int(tr.origin))
    doc.blank()
    solves, charts = _definitions(tr, mapping, out, doc)
    for item in solves:
        _solve(item, mapping, out, doc)
    printed, tables = _printed_files(tr, name, mapping, out)
    for table in tables:
        _write_table(table, doc)
        out.table_of[table["name"]] = table["region"]
    for item in charts:
        _chart(item, mapping, doc, out)
    for fname, title, arg, from_solve, absolute in printed:
        doc.blank()
        doc.array_table("printed")
        doc.pair("file", fname)
        doc.pair("title", title)
        if arg:
            doc.pair("argument", arg)
        # Mathcad's solver stops at its TOL: its roots are that close
        doc.pair("rel_tolerance", tr.solve_tolerance if from_solve else REL_TOLERANCE)
        doc.pair("tolerance", absolute)
    return doc, out


def _header(tr: Translation, src: Path, doc: Document) -> None:
    """The comments that open the worksheet: where it came from, what was not translated or
    left out, and the names that changed."""
    doc.comment(
        f"Imported from {src.name} by `workbook import`: Mathcad's definitions in order, its"
    )
    doc.comment("text regions as comments, and every result Mathcad stored as a printed value")
    doc.comment("(`workbook check` compares them with the engine).")
    if tr.skipped:
        doc.comment()
        doc.comment(
            f"Not translated ({len({s.region for s in tr.skipped})} regions; their results "
            "count as not reproduced):"
        )
        shown = {s.token(): s.mathcad for s in tr.syms}
        for s in tr.skipped:  # a symbol's token in a reason is shown as Mathcad's name
            why = re.sub("\x00\\d+", lambda m: shown.get(m.group(), "?"), s.why)
            doc.comment(f"  region {s.region}: {s.what}: {why}")
    if tr.ignored:
        doc.comment()
        for line in _wrapped(
            "Regions that define and show nothing in Mathcad (a name or an expression without "
            ":= or =), left out: " + ", ".join(tr.ignored)
        ):
            doc.comment(line)
    renamed = sorted(
        {
            (s.mathcad, s.final)
            for s in tr.syms
            if s.mathcad != s.final and s.kind != "helper" and not s.generated
        }
    )
    if renamed:
        doc.comment()
        doc.comment("Names (Mathcad -> worksheet):")
        line = " "
        for mathcad, final in renamed:
            piece = f" {mathcad} -> {final};"
            if len(line) + len(piece) > 94:
                doc.comment(line)
                line = " "
            line += piece
        doc.comment(line)


def _definitions(tr: Translation, mapping: dict, out: Rendered, doc: Document):
    """The [inputs], [arguments] and [definitions] sections, written to ``doc`` in Mathcad's
    order, with the text regions as comments; the solve blocks and charts, to write after."""
    inputs, definitions = _Section("inputs"), _Section("definitions")
    arguments = _Section("arguments")
    notes: list[str] = []
    for sym in tr.syms:
        if sym.kind == "unit":
            value = {"value": "1 " + pretty_unit(sym.unit), "note": f"the unit {sym.mathcad}"}
            inputs.pair(sym.final, value)
    seen_args: set[str] = set()
    for sym in tr.syms:
        if (sym.kind == "param" or sym.is_range) and not sym.broken:
            if sym.final in seen_args:
                continue
            seen_args.add(sym.final)
            arguments.pair(sym.final, {"unit": pretty_unit(sym.unit)})
    solves: list = []
    charts: list = []
    for item in tr.items:
        if item.kind == "note":
            notes += _wrapped(item.value)
            continue
        if item.kind == "solve":
            solves.append(item)
            continue
        if item.kind == "chart":
            charts.append(item)
            continue
        if item.sym is None or item.sym.broken:
            continue
        out.region_of[item.sym.final] = item.region
        target = inputs if item.kind == "input" else definitions
        if item.kind == "range":
            target = arguments
        for note in notes:
            target.comment(note)
        notes = []
        note = f"{item.sym.mathcad} (region {item.region})"
        if item.kind == "input":
            value = {"value": pretty_quantity(item.value)}
            if item.unit:
                value["unit"] = pretty_unit(item.unit)
            value["note"] = note
            target.pair(item.sym.final, value)
            out.definitions += 1
        elif item.kind == "range":
            target.comment(
                f"{item.sym.final} := {_range_text(item, mapping)} (region {item.region})"
            )
        else:
            key = item.sym.final
            if item.params:
                key = f"{key}({', '.join(p.final for p in item.params)})"
            value, multiline = _definition_value(item, mapping)
            if item.unit:
                value["unit"] = pretty_unit(item.unit)
            value["note"] = note
            target.pair(key, value, multiline=multiline)
            out.definitions += 1
    for note in notes:
        definitions.comment(note)
    for section in (inputs, arguments, definitions):
        section.write(doc)
    return solves, charts


def _definition_value(item, mapping: dict) -> tuple[dict, bool]:
    """A definition's value table (a program, pieces or an expression), and whether it is
    written over several lines."""
    if item.program is not None:
        lines = []
        for indent, parts in item.program:
            text = "".join(p if isinstance(p, str) else _text(p, mapping) for p in parts)
            lines.append(" " * indent + text)
        return {"program": "\n".join(lines) + "\n"}, True
    if item.pieces is not None:
        pieces = [
            f"{_text(v, mapping)} if {_text(c, mapping)}"
            if c is not None
            else f"{_text(v, mapping)} otherwise"
            for v, c in item.pieces
        ]
        return {"pieces": pieces}, False
    return {"expr": _text(item.body, mapping)}, False


def _printed_files(tr: Translation, name: str, mapping: dict, out: Rendered):
    """Mathcad's stored results as printed-value CSV files in ``out`` (one per argument, per
    solve-block dependence and per round-off size): each file's [[printed]] entry and the
    tables over the arguments."""
    groups: dict[tuple[str, bool, str], list[list[str]]] = {}
    solved = _from_solve_blocks(tr)
    for res in tr.results:
        arg = res.argument.final if res.argument is not None else ""
        from_solve = res.sym is not None and res.sym.token() in solved
        # values that are round-off of a larger size: a file of their own, within it
        own = res.region if res.round_off and not from_solve else ""
        rows = groups.setdefault((arg, from_solve, own), [])
        sym_name = res.sym.final if res.sym is not None else f"result_{res.region}"
        texts = [v for _, v in res.rows if isinstance(v, str)]
        if not res.rows or not all(is_one_line(t) for t in texts):
            why = "cannot be read" if not res.rows else "is a text of several lines"
            rows.append([f"# region {res.region}: {res.name}: the stored result {why}"])
            # under a name no worksheet defines: counted, and not computable (never compared)
            rows.append([f"unreadable result of region {res.region}", "", "(unreadable)", ""])
            continue
        if res.misfit:
            rows += _misfit_rows(res)
            continue
        rows.append([f"# region {res.region}: {res.name}"])
        for at, value in res.rows:
            at_text = "" if at is None else repr(float(at))
            val = csv_text(value) if isinstance(value, str) else repr(float(value))
            rows.append([sym_name, at_text, val, pretty_unit(res.unit) if res.unit else ""])
    printed: list[tuple] = []
    tables: list = []
    round_off = {r.region: r.round_off for r in tr.results if r.round_off}
    for (arg, from_solve, own), rows in groups.items():
        kind = ".solve" if from_solve else (f".round-off-{own}" if own else "")
        fname = f"{name}.mathcad{kind}{'.' + arg if arg else ''}.csv"
        title = "Mathcad results" + (" over " + arg if arg else "")
        if from_solve:
            title += f" that depend on a solve block (Mathcad's TOL = {tr.solve_tolerance:g})"
        absolute = tr.solve_tolerance if from_solve else ABS_TOLERANCE  # TOL near 0 too
        if own:
            absolute, why = round_off[own]
            title += f" of {why}: their round-off"
        out.csv[fname] = _csv_text(rows)
        printed.append((fname, title, arg, from_solve, absolute))
        table = _table_for(tr, arg, mapping)
        if table:
            tables.append(table)
    return printed, tables


def _misfit_rows(res) -> list[list[str]]:
    """The stored values of a result that does not fit the translation, under a name no
    worksheet defines: each counted, and not computable."""
    rows = [[f"# region {res.region}: {res.name}: not computable: {res.misfit}"]]
    for at, value in res.rows:
        at_text = "" if at is None else repr(float(at))
        val = csv_text(value) if isinstance(value, str) else repr(float(value))
        rows.append([f"not computable result of region {res.region}", at_text, val, ""])
    return rows


def _list_unknown_units(tr: Translation) -> None:
    """A stored result in a unit the engine does not know costs that result (listed, not
    computable), never the check of the whole worksheet."""
    from ..language import units as un

    for res in tr.results:
        if not res.unit or not res.rows or res.misfit:
            continue
        off = [w for u, w in PRIME_UNITS_OFF.items() if re.search(rf"\b{u}\b", res.unit)]
        if off and tr.generator == "Mathcad Prime":
            tr.skipped.append(Skipped(res.region, f"the result of {res.name}", off[0]))
            res.misfit = off[0]
            continue
        try:
            un.unit(res.unit)  # the language's reading: its names and its powers
        except Exception:  # noqa: BLE001 - pint's parse and definition errors alike
            tr.skipped.append(
                Skipped(
                    res.region,
                    f"the result of {res.name}",
                    f"its unit {res.unit!r} is not a unit the engine knows",
                )
            )
            res.misfit = f"its unit {res.unit!r} is not a unit the engine knows"


def _csv_text(rows: list[list[str]]) -> str:
    """A printed-values CSV: a one-cell row starting with '#' is a comment line; every cell
    is one line (the reader reads the file line by line)."""
    buffer = io.StringIO()
    buffer.write("# Mathcad's stored results (imported by `workbook import`)\n")
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(["name", "argument", "value", "unit"])
    for row in rows:
        if len(row) == 1 and row[0].startswith("#"):
            buffer.write(one_line(row[0]) + "\n")
        else:
            writer.writerow([one_line(c) for c in row])
    return buffer.getvalue()


def _from_solve_blocks(tr: Translation) -> set[str]:
    """Tokens of the names whose value comes from a solve block (its unknowns, and what uses
    them): their stored values are as close as Mathcad's solver went (TOL)."""
    found = {sym.token() for i in tr.items if i.kind == "solve" for sym, _ in i.solve[0]}
    for item in tr.items:  # in Mathcad's order: what an item uses is before it
        if item.sym is None or item.kind not in ("definition", "function"):
            continue
        trees = [item.body] if item.body is not None else []
        trees += [t for piece in item.pieces or [] for t in piece if t is not None]
        trees += [p for _, parts in item.program or [] for p in parts if not isinstance(p, str)]
        if any(ex.names(t) & found for t in trees):
            found.add(item.sym.token())
    return found


def _solve(item: Item, mapping, out: Rendered, doc: Document) -> None:
    """A [[solve]] block: Mathcad's Given, its equations and Find."""
    unknowns, equations, regions, conditions = item.solve
    if any(sym.broken for sym, _ in unknowns):
        return
    for sym, _ in unknowns:
        out.region_of[sym.final] = item.region
    tag = f"(region {item.region})"
    doc.array_table("solve", f"Given ... Find, regions {', '.join(regions)} {tag}")
    doc.pair("unknowns", {sym.final: g for sym, g in unknowns}, tag)
    doc.pair("equations", [_text(e, mapping) for e in equations], tag)
    if item.value:
        doc.pair("method", item.value)
    if conditions:
        doc.pair("conditions", [_text(c, mapping) for c in conditions])
    doc.blank()


def _chart(item: Item, mapping, doc: Document, out: Rendered) -> None:
    """A [[charts]] entry: Mathcad's X-Y plot, one series per trace over its range."""
    series = [t for t in item.chart if not t[2].sym.broken]
    if not series:
        return
    tag = f"(region {item.region})"
    polar = item.value == "polar"
    kind = "Mathcad polar plot" if polar else "Mathcad plot"
    first = series[0][2]
    first_text = first.sym.final + " := " + _range_text(first, mapping)
    entries, comments = [], []
    for x, y, rng, points, n in series:
        entry = {"x": _text(x, mapping), "y": _text(y, mapping)}
        text = rng.sym.final + " := " + _range_text(rng, mapping)
        if text != first_text:
            entry["range"] = text
        if points:  # Mathcad draws the points of vectors, or a single point
            entry.update(line="none", marker=True)
        entries.append(entry)
        comments.append(f"(region {item.region}, trace {n})")
    x_title = ", ".join(dict.fromkeys(_text(t[0], mapping) for t in series))
    y_title = ", ".join(dict.fromkeys(_text(t[1], mapping) for t in series))
    doc.blank()
    doc.array_table("charts", f"Mathcad's plot {tag}")
    doc.pair("name", "plot_" + item.region, tag)
    out.chart_of["plot_" + item.region] = (item.region, [n for *_, n in series])
    doc.pair("title", kind + ", region " + item.region)
    if polar:
        doc.pair("equal_axes", True)
    doc.pair("range", first_text)
    doc.pair("x_title", x_title)
    doc.pair("y_title", y_title)
    doc.array("series", entries, comments)


def _range_text(item: Item, mapping) -> str:
    first, second, last = item.range
    head = _text(first, mapping)
    if second is not None:
        head += ", " + _text(second, mapping)
    return f"{head} .. {_text(last, mapping)}"


def _table_for(tr: Translation, arg: str, mapping) -> dict | None:
    """A table over the range variable `arg` listing what Mathcad listed over it."""
    ranges = [i for i in tr.items if i.kind == "range" and i.sym.final == arg and not i.sym.broken]
    if not ranges:
        return None
    item = ranges[-1]
    funcs = []
    for res in tr.results:
        if res.argument is not None and res.argument.final == arg and res.sym is not None:
            if not res.sym.broken and res.sym.final not in funcs:
                funcs.append(res.sym.final)
    if not funcs:
        return None
    return {
        "comment": f"what Mathcad listed over {item.sym.mathcad} (region {item.region})",
        "name": "table_" + arg,
        "region": item.region,
        "range": arg + " := " + _range_text(item, mapping),
        "columns": {f"{f}({arg})": "" for f in funcs},
    }


def _write_table(table: dict, doc: Document) -> None:
    doc.blank()
    doc.array_table("tables", table["comment"])
    for key in ("name", "range", "columns"):
        doc.pair(key, table[key])


def write(rendered: Rendered, out_dir: Path, *, force: bool) -> list[Path]:
    """Write the worksheet and its CSV files; an existing file needs --force."""
    if out_dir.exists() and not out_dir.is_dir():
        raise InputError(f"--out {out_dir} is a file, not a folder: name the folder to write into")
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"--out {out_dir}: cannot make the folder ({exc.strerror})") from None
    targets = [out_dir / f"{rendered.name}.toml"] + [out_dir / f for f in rendered.csv]
    if not force:
        existing = [p for p in targets if p.exists()]
        if existing:
            raise InputError(f"{existing[0]} exists; use --force to replace it")
    from ..outputs.atomic import replacing

    for path, text in zip(targets, [rendered.toml, *rendered.csv.values()]):
        with replacing(path) as tmp:
            Path(tmp).write_text(text, encoding="utf-8")
    return targets
