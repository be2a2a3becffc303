"""What the language server answers about a loaded worksheet (:mod:`.document`): hover,
completion, go to definition and the outline, as Language Server Protocol values."""

from __future__ import annotations

import re

import numpy as np
from lsprotocol import types as lsp

from ..errors import WorkbookError
from ..functions.constants import CONSTANTS
from ..language import spec as tp
from ..language import units as un
from ..numerics.registry import REGISTRY
from .document import Document, Span, section_at, word_at

#: The keys of each section's entries, as the template reader accepts them.
SECTION_KEYS = {
    "sheet": tp.SHEET_KEYS,
    "inputs": tp.INPUT_KEYS,
    "arguments": tp.ARGUMENT_KEYS,
    "definitions": tp.DEFINITION_KEYS,
    "parts": tp.PART_KEYS,
    "tables": tp.TABLE_KEYS,
    "charts": tp.CHART_KEYS,
    "printed": tp.PRINTED_KEYS,
    "relations": tp.RELATION_KEYS,
    "findings": tp.FINDING_KEYS,
    "sweep": tp.SWEEP_KEYS,
}
#: Sections written as arrays of tables (``[[tables]]``).
ARRAY_SECTIONS = ("tables", "charts", "printed", "relations", "findings", "checks", "solve", "ode")
_NUMBER_BEFORE = re.compile(r"\d\s+[A-Za-z_]*$")
_UNIT_KEY = re.compile(r"\b(unit|x_unit|value|min|max)\s*=\s*\"[^\"]*$")


def to_range(span: Span) -> lsp.Range:
    return lsp.Range(lsp.Position(span.line, span.start), lsp.Position(span.end_line, span.end))


def diagnostics(problems) -> list[lsp.Diagnostic]:
    return [
        lsp.Diagnostic(
            range=to_range(p.span),
            message=p.message,
            severity=lsp.DiagnosticSeverity.Error,
            source="workbook",
            code=p.kind,
        )
        for p in problems
    ]


# -- hover ------------------------------------------------------------------------------------
def hover(doc: Document, line: int, character: int) -> lsp.Hover | None:
    lines = doc.lines
    if line >= len(lines):
        return None
    found = word_at(lines[line], character)
    if found is None:
        return None
    name, start, end = found
    text = describe(doc, name)
    if text is None:
        return None
    return lsp.Hover(
        contents=lsp.MarkupContent(kind=lsp.MarkupKind.Markdown, value=text),
        range=lsp.Range(lsp.Position(line, start), lsp.Position(line, end)),
    )


def describe(doc: Document, name: str) -> str | None:
    """What the hover shows for ``name``: an input's value, a definition's value with its
    unit and error estimate, a function's signature and units, a built-in's doc line."""
    sheet = doc.sheet
    spec = sheet.spec if sheet is not None else None
    if spec is not None and name in spec.inputs:
        i = spec.inputs[name]
        value = sheet.values[name]
        shown = f'"{value}"' if isinstance(value, str) else _quantity(value)
        out = f"**{name}** = {shown} (input)"
        if i.options:
            out += f"\n\none of: {', '.join(i.options)}"
        return out + (f"\n\n{i.note}" if i.note else "")
    if spec is not None and name in spec.definitions:
        d = spec.definitions[name]
        if d.is_function:
            return _function(sheet, d)
        return _scalar(doc, d)
    if spec is not None and name in spec.arguments:
        a = spec.arguments[name]
        unit = un.pretty(a.unit) or "dimensionless"
        plain = " (a plain number in it inside formulas)" if a.plain else ""
        return f"**{name}**: argument in {unit}{plain}" + (f"\n\n{a.note}" if a.note else "")
    if name in REGISTRY:
        return f"**{name}** (built-in): {REGISTRY[name].doc}"
    if name in CONSTANTS:
        c = CONSTANTS[name]
        return f"**{name}** (built-in constant) = {c.value:.12g} {un.pretty(c.unit)}".rstrip()
    return None


def _quantity(q) -> str:
    mag = q.magnitude
    if np.ndim(mag):
        return f"{np.array2string(np.asarray(mag), precision=6)} {un.pretty(q.units)}".rstrip()
    return f"{float(mag):.6g} {un.pretty(q.units)}".rstrip()


def _scalar(doc: Document, d) -> str:
    sheet = doc.sheet
    value = doc.values.get(d.name)
    if value is None:
        with doc.lock:
            try:
                value = sheet.scalar_quantity(d.name)
            except WorkbookError as err:
                value = err
        doc.values[d.name] = value
    if isinstance(value, BaseException):
        shown = f"not computed: {getattr(value, 'message', value)}"
    elif isinstance(value, str):
        shown = f'"{value}"'
    else:
        with doc.lock:
            shown = _quantity(value) + _estimate(sheet, d.name)
    out = f"**{d.name}** = {shown}\n\n`{d.name} = {d.text}`"
    return out + (f"\n\n{d.note}" if d.note else "")


def _estimate(sheet, name: str) -> str:
    """`` ± E`` from the error estimates of the numerical built-ins the value used."""
    worst: tuple[float, str] | None = None
    for builtin, result in list(sheet.evaluator.records):
        if result.notes.get("in") != name or not np.size(result.error):
            continue
        err = float(np.max(np.abs(result.error)))
        if worst is None or err > worst[0]:
            worst = (err, builtin)
    if worst is None:
        return ""
    return f" ± {worst[0]:.2g} (error estimate of {worst[1]}, in the unit it computes in)"


def _function(sheet, d) -> str:
    spec = sheet.spec
    params = []
    for p in d.params:
        a = spec.arguments.get(p)
        params.append(f"{p} [{un.pretty(a.unit) or '1'}]" if a is not None else p)
    try:
        unit = d.unit or sheet.typer.function(d.name).unit
        result = f" -> {un.pretty(unit) or 'dimensionless'}"
    except WorkbookError:
        result = ""
    out = f"**{d.name}({', '.join(params)})**{result}\n\n`{d.name}({', '.join(d.params)}) = "
    out += f"{d.text}`"
    return out + (f"\n\n{d.note}" if d.note else "")


# -- completion -------------------------------------------------------------------------------
def completion(doc: Document, line: int, character: int) -> list[lsp.CompletionItem]:
    lines = doc.lines
    text = lines[line][:character] if line < len(lines) else ""
    stripped = text.lstrip()
    if stripped.startswith("["):
        return _sections(stripped)
    section = section_at(lines, line)
    in_string = text.count('"') % 2 == 1
    if not in_string:
        head = text.rsplit("{", 1)[-1].rsplit(",", 1)[-1]
        if "=" not in head:  # a key: of the section, or of an entry's inline table
            keys = SECTION_KEYS.get(section or "", ())
            if "{" not in text and section in ("inputs", "definitions", "arguments"):
                return _names(doc)  # an entry's name: the sheet's own
            return [_item(k, lsp.CompletionItemKind.Property, f"[{section}] key") for k in keys]
        return []
    if _NUMBER_BEFORE.search(text) or _UNIT_KEY.search(text):
        return _units()
    return _names(doc) + _builtins()


def _item(label: str, kind, detail: str) -> lsp.CompletionItem:
    return lsp.CompletionItem(label=label, kind=kind, detail=detail)


def _sections(typed: str) -> list[lsp.CompletionItem]:
    double = typed.startswith("[[")
    out = []
    for s in sorted(tp.SECTIONS):
        array = s in ARRAY_SECTIONS
        if double and not array:
            continue
        label = f"[[{s}]]" if array else f"[{s}]"
        out.append(
            lsp.CompletionItem(
                label=label,
                kind=lsp.CompletionItemKind.Module,
                detail="section",
                insert_text=label[len(typed) :] if label.startswith(typed) else label,
            )
        )
    return out


def _names(doc: Document) -> list[lsp.CompletionItem]:
    sheet = doc.sheet
    if sheet is None:
        return []
    spec = sheet.spec
    out = [_item(n, lsp.CompletionItemKind.Variable, "input") for n in spec.inputs]
    for n, d in spec.definitions.items():
        if d.is_function:
            out.append(_item(n, lsp.CompletionItemKind.Function, f"{n}({', '.join(d.params)})"))
        else:
            out.append(_item(n, lsp.CompletionItemKind.Constant, "definition"))
    out += [_item(n, lsp.CompletionItemKind.TypeParameter, "argument") for n in spec.arguments]
    return out


def _builtins() -> list[lsp.CompletionItem]:
    out = [
        _item(n, lsp.CompletionItemKind.Function, b.doc.split(":")[0][:80])
        for n, b in sorted(REGISTRY.items())
    ]
    out += [_item(n, lsp.CompletionItemKind.Constant, "built-in constant") for n in CONSTANTS]
    return out


_UNITS: list[lsp.CompletionItem] = []
#: Prefixed units offered beside the registry's own names (pint makes them on demand).
_PREFIXES = ("k", "M", "G", "m", "u", "n", "c", "d")
_PREFIXED = ("m", "g", "s", "N", "Pa", "W", "J", "Hz", "V", "A", "L", "rad", "bar", "Wh")


def _units() -> list[lsp.CompletionItem]:
    if not _UNITS:
        reg = un.registry()
        names = set(reg) | {p + u for p in _PREFIXES for u in _PREFIXED if (p + u) in reg}
        _UNITS.extend(_item(u, lsp.CompletionItemKind.Unit, "unit") for u in sorted(names))
    return _UNITS


# -- go to definition and the outline ---------------------------------------------------------
def definition_line(doc: Document, name: str) -> int | None:
    """The 1-based line where ``name`` is declared (input, definition, argument, table,
    chart), or None."""
    sheet = doc.sheet
    if sheet is not None:
        spec = sheet.spec
        for table in (spec.inputs, spec.definitions, spec.arguments):
            if name in table and table[name].line:
                return table[name].line
        for t in [*spec.tables, *spec.charts]:
            if t.name == name and t.line:
                return t.line
        for block in spec.solves:
            if name in block.unknowns and block.line:
                return block.line
    pattern = re.compile(r'^\s*["\']?' + re.escape(name) + r"(\(|[\"']?\s*=)")
    for i, text in enumerate(doc.lines, start=1):
        if pattern.match(text):
            return i
    return None


def definition(doc: Document, uri: str, line: int, character: int) -> lsp.Location | None:
    lines = doc.lines
    if line >= len(lines):
        return None
    found = word_at(lines[line], character)
    if found is None:
        return None
    target = definition_line(doc, found[0])
    if target is None:
        return None
    row = target - 1
    width = len(lines[row]) if row < len(lines) else 0
    return lsp.Location(uri, lsp.Range(lsp.Position(row, 0), lsp.Position(row, width)))


_HEADER = re.compile(r"^\s*\[\[?\s*([A-Za-z_.]+)\s*\]\]?")
_KEY = re.compile(r"^\s*\"?([A-Za-z_][A-Za-z0-9_]*)(\([^)]*\))?\"?\s*=")
_SYMBOL_KINDS = {
    "inputs": lsp.SymbolKind.Variable,
    "arguments": lsp.SymbolKind.TypeParameter,
    "definitions": lsp.SymbolKind.Constant,
}


def outline(doc: Document) -> list[lsp.DocumentSymbol]:
    """The sections of the text, each with its entries (inputs, arguments, definitions) or
    the name of its item (a table, a chart), read from the text itself so that an outline is
    there while the sheet does not load."""
    lines = doc.lines
    out: list[lsp.DocumentSymbol] = []
    current: lsp.DocumentSymbol | None = None
    section = None

    def span(row: int) -> lsp.Range:
        return lsp.Range(lsp.Position(row, 0), lsp.Position(row, len(lines[row])))

    for row, text in enumerate(lines):
        m = _HEADER.match(text)
        if m:
            section = m.group(1).split(".")[0]
            current = lsp.DocumentSymbol(
                name=text.strip(),
                kind=lsp.SymbolKind.Namespace,
                range=span(row),
                selection_range=span(row),
                children=[],
            )
            out.append(current)
            continue
        k = _KEY.match(text)
        if not k or current is None:
            continue
        if section in _SYMBOL_KINDS:
            kind = _SYMBOL_KINDS[section]
            if section == "definitions" and k.group(2):
                kind = lsp.SymbolKind.Function
            name = k.group(1) + (k.group(2) or "")
        elif k.group(1) == "name" and section in ARRAY_SECTIONS:
            value = text.split("=", 1)[1].strip().strip("\"'")
            current.name = f"{current.name} {value}"
            continue
        else:
            continue
        current.children.append(
            lsp.DocumentSymbol(name=name, kind=kind, range=span(row), selection_range=span(row))
        )
    for s in out:  # a section's range covers its entries
        if s.children:
            s.range = lsp.Range(s.range.start, s.children[-1].range.end)
    return out
