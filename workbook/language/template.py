"""Reading a worksheet template (TOML) into a validated specification.

The template is data: TOML parsed by the standard library, expressions parsed by
:mod:`workbook.language.expr`. Nothing here evaluates anything.
"""

from __future__ import annotations

import re

try:
    import tomllib
except ImportError:  # Python 3.10
    import tomli as tomllib
from dataclasses import replace
from pathlib import Path

import pint

from ..errors import InputError, LimitError, TemplateError, WorkbookError
from . import expr as ex
from . import units as un
from .checkspec import read_check
from .fields import Fields, find_line, nearest, value_line
from .parts import assign_parts
from .ranges import parse_range
from .spec import (
    ALL_PARTS,
    ARGUMENT_KEYS,
    AXIS_KEYS,
    CHART_KEYS,
    COLUMN_KEYS,
    DEFINITION_KEYS,
    FINDING_KEYS,
    INPUT_KEYS,
    MAX_VARY,
    MISPRINT_KEYS,
    PART_KEYS,
    PRINTED_KEYS,
    RELATION_KEYS,
    SECTIONS,
    SERIES_KEYS,
    SHEET_KEYS,
    SWEEP_KEYS,
    TABLE_KEYS,
    ArgumentSpec,
    Branch,
    ChartSpec,
    ColumnSpec,
    Definition,
    InputSpec,
    Limits,
    Misprint,
    PartSpec,
    PrintedSpec,
    RelationSpec,
    SeriesSpec,
    SheetSpec,
    TableSpec,
)

MAX_TEMPLATE_BYTES = 2_000_000  # a template file larger than this is refused


_SIGNATURE = re.compile(r"^\s*([A-Za-z][A-Za-z0-9_]*)\s*(?:\(([^()]*)\))?\s*$")
_IF = re.compile(r"\bif\b")


def parse_branch(text: str, *, what: str) -> Branch:
    """``h1(phi) if 0 <= phi <= 22`` or ``0 otherwise``."""
    if not isinstance(text, str):
        raise TemplateError(f"{what}: each piece must be text like 'h1(phi) if 0 <= phi <= 22'")
    stripped = text.strip()
    if stripped.endswith(" otherwise") or stripped == "otherwise":
        return Branch(ex.parse(stripped[: -len("otherwise")], what=what), None, stripped)
    matches = [m for m in _IF.finditer(stripped) if _depth_at(stripped, m.start()) == 0]
    if len(matches) != 1:
        raise TemplateError(
            f"{what}: piece {text!r} must read 'VALUE if CONDITION' (or 'VALUE otherwise')"
        )
    m = matches[0]
    value, cond = stripped[: m.start()], stripped[m.end() :]
    return Branch(ex.parse(value, what=what), ex.parse(cond, what=what), stripped)


def _depth_at(text: str, pos: int) -> int:
    return text[:pos].count("(") - text[:pos].count(")")


def _limits(f: Fields, name: str) -> Limits | None:
    """A definition's declared limits, or None."""
    if not any(k in f for k in ("positive", "min", "max")):
        return None
    return Limits(f.flag("positive"), _bound(f, "min", name), _bound(f, "max", name))


def _bound(f: Fields, key: str, name: str):
    """An input's ``min`` or ``max``: a quantity; a plain number is in the input's unit."""
    if key not in f:
        return None
    value = f.raw[key]
    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        raise TemplateError(f'input {name}: {key} must be a value like "0 mm", got {value!r}')
    return un.quantity(value, what=f"{name} {key}")


def load_spec(path: Path, name: str | None = None) -> SheetSpec:
    """Read and validate a template file."""
    from ..limits import read_text

    file = str(path)
    try:
        text = read_text(path, what="template", max_bytes=MAX_TEMPLATE_BYTES)
    except InputError as err:  # not UTF-8, not a regular file
        raise TemplateError(err.message, file=file, line=err.line) from None
    except WorkbookError as err:
        raise err.located(file=file) from None
    return parse_spec(text, path, name)


def parse_spec(
    text: str, path: Path, name: str | None = None, data: dict | None = None
) -> SheetSpec:
    """Read and validate a template's text; ``path`` names it in messages and is where
    files it names ([data] CSV) are found. ``data``: what :func:`read_toml` gave for
    ``text``, when the caller has read it already (it is not changed)."""
    file = str(path)
    if data is None:
        data = read_toml(text, file)
    try:
        return _build(path, name or path.stem, text, data)
    except WorkbookError as err:
        raise err.located(file=file) from None


def read_toml(text: str, file: str) -> dict:
    """The TOML of a template's text; a syntax error names its line."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        line = getattr(exc, "lineno", None)
        if line is None:
            m = re.search(r"line (\d+)", str(exc))
            line = int(m.group(1)) if m else None
        raise TemplateError(f"TOML syntax: {exc}", file=file, line=line) from None
    except RecursionError:  # tomllib recurses into nested arrays and inline tables
        raise LimitError("TOML arrays or tables nested too deeply", file=file) from None


def spec_from_data(data: dict, path: Path, name: str) -> SheetSpec:
    """A spec from template data already read (a dict as TOML gives), built in memory: errors
    name ``path`` but no line."""
    try:
        return _build(path, name, "", data)
    except WorkbookError as err:
        raise err.located(file=str(path)) from None


def _fields(raw: dict, allowed, what: str, text: str, section: str) -> Fields:
    """Fields of a [section] table; an unknown key's error names its line."""
    try:
        return Fields(raw, allowed, what)
    except TemplateError as err:
        bad = next((k for k in raw if k not in allowed), None)
        raise err.located(line=find_line(text, bad, section) if bad else None) from None


WRITER_SHEETS = ("Inputs", "Definitions", "Charts", "Checks", "About")  # the writer's own


def _check_sheet_names(tables: list[TableSpec]) -> None:
    """Excel compares sheet names ignoring case: a table's sheet may not be one of the
    writer's own sheets, nor another table's sheet spelt with other capitals."""
    seen: dict[str, str] = {}
    for t in tables:
        key = t.sheet.casefold()
        own = next((w for w in WRITER_SHEETS if w.casefold() == key), None)
        if own is not None:
            raise TemplateError(
                f"table {t.name}: sheet {t.sheet!r} is the workbook's own {own} sheet; "
                "choose another name",
                line=t.line,
                definition=f"table {t.name}",
            )
        if seen.setdefault(key, t.sheet) != t.sheet:
            raise TemplateError(
                f"table {t.name}: sheet {t.sheet!r} and {seen[key]!r} are one sheet in Excel "
                "(names ignore case); spell them alike",
                line=t.line,
                definition=f"table {t.name}",
            )


def _table(data: dict, key: str) -> dict:
    value = data.get(key, {})
    if not isinstance(value, dict):
        raise TemplateError(f"[{key}] must be a table")
    return value


def _build(path: Path, name: str, text: str, data: dict) -> SheetSpec:
    unknown = set(data) - SECTIONS
    if unknown:
        key = sorted(unknown)[0]
        raise TemplateError(
            f"unknown section [{key}]{nearest(key, SECTIONS)} "
            f"(known: {', '.join(sorted(SECTIONS))})",
            line=find_line(text, key) or _section_line(text, key),
        )
    sheet = _sheet_section(data, text)
    claim = _Claims()
    inputs = _inputs(data, text, claim)
    arguments = _arguments(data, text)
    blocks = _blocks(data, text, claim)
    definitions = _definitions(data, text, arguments, claim)
    odes = _odes(data, text, arguments, definitions, claim)
    _sheet_options(sheet, text)
    for pname in arguments:
        if pname in inputs or pname in definitions:
            raise TemplateError(
                f"argument '{pname}' has the name of an input or definition",
                line=arguments[pname].line,
                definition=pname,
            )

    from .given_find import read_solves
    from .measured import read_data

    tables = _table(data, "data")
    lines = {t: find_line(text, t, "data") or find_line(text, "file", f"data.{t}") for t in tables}
    measured = {}
    for col in read_data(tables, path, lines):
        claim(col.name, f"data.{col.table}", col.line)
        measured[col.name] = col

    solves = read_solves(_list(data, "solve"), text)
    _claim_solves(solves, arguments, definitions, claim)

    tables = [_table_spec(i, t, text) for i, t in enumerate(_list(data, "tables"))]
    charts = [_chart_spec(i, c, text) for i, c in enumerate(_list(data, "charts"))]
    printed = [_printed_spec(p, path, text) for p in _list(data, "printed")]
    relations = [_relation_spec(r, text) for r in _list(data, "relations")]
    headers = _header_lines(text, "checks")
    checks = [
        read_check(raw, headers[i] if i < len(headers) else None)
        for i, raw in enumerate(_list(data, "checks"))
    ]
    findings = _list(data, "findings")
    for raw in findings:
        f = Fields(raw, FINDING_KEYS, "[[findings]]")
        try:
            f.text("block"), f.text("title"), f.text("part", None)
        except WorkbookError as err:
            raise err.located(
                line=value_line(text, str(raw.get("block", "[[findings]]")))
            ) from None
    _check_sheet_names(tables)
    names_seen = set()
    for t in tables:
        if t.name in names_seen:
            raise TemplateError(f"two tables are named '{t.name}'", line=t.line)
        names_seen.add(t.name)
    parts = _parts(_table(data, "parts"), text)
    arrays = {
        k: _list(data, k)
        for k in ("tables", "charts", "printed", "relations", "findings", "checks")
    }
    assign_parts(arrays, parts, text, tables, charts, printed, relations)

    return SheetSpec(
        name=str(sheet.get("name", name)),
        title=str(sheet.get("title", name)),
        path=path,
        source=str(sheet.get("source", "")),
        description=str(sheet.get("description", "")),
        inputs=inputs,
        arguments=arguments,
        definitions=definitions,
        blocks=blocks,
        tables=tables,
        charts=charts,
        printed=printed,
        relations=relations,
        findings=findings,
        meta=sheet,
        text=text,
        parts=parts,
        data=measured,
        checks=checks,
        solves=solves,
        odes=odes,
        function_names=claim.functions,
    )


def _sheet_section(data: dict, text: str) -> dict:
    """[sheet] and [sweep], their keys checked; returns [sheet]."""
    sheet = _table(data, "sheet")
    fields = _fields(sheet, SHEET_KEYS, "[sheet]", text, "sheet")
    for key in ("name", "title", "source", "description", "bench", "export"):
        fields.text(key)
    fields.flag("hand_checks")
    fields.number("samples"), fields.number("tolerance"), fields.number("time_limit")
    for key, value in fields.table("about").items():
        if not isinstance(value, (str, int, float)) or isinstance(value, bool):
            raise TemplateError(
                f"[sheet] about: {key} must be text, got {value!r}",
                line=find_line(text, key, "sheet"),
            )
    sweep = _fields(_table(data, "sweep"), SWEEP_KEYS, "[sweep]", text, "sweep")
    for key in SWEEP_KEYS:
        sweep.table(key)
    if "name" in sheet and not re.match(r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,79}$", str(sheet["name"])):
        raise TemplateError(  # the name becomes reports/NAME.xlsx: no folders, no '..'
            f"[sheet] name {str(sheet['name'])[:80]!r} must be letters, digits, '-', '_', '.'",
            line=find_line(text, "name", "sheet"),
        )
    return sheet


def _sheet_options(sheet: dict, text: str) -> None:
    """[sheet] complex and origin, checked."""
    if sheet.get("complex", "rectangular") not in ("rectangular", "polar"):
        raise TemplateError(
            f'[sheet] complex is "rectangular" (a + bi) or "polar" (r∠phi), got '
            f"{sheet['complex']!r}",
            line=find_line(text, "complex", "sheet"),
        )
    origin = sheet.get("origin", 0)
    if isinstance(origin, bool) or not isinstance(origin, int) or abs(origin) > 1_000_000:
        raise TemplateError(
            f"[sheet] origin is the first index of vectors, an integer (0 or 1), got {origin!r}",
            line=find_line(text, "origin", "sheet"),
        )


class _Claims:
    """The names a worksheet defines, each claimed once by the section that defines it:
    ``claim(key, section, line, function=True)`` refuses a bad name and a name defined twice,
    and keeps a function's name with its line (``functions``: the typer refuses a built-in's)."""

    def __init__(self):
        self.seen: dict[str, str] = {}
        self.functions: dict[str, int | None] = {}  # name -> line

    def __call__(self, key: str, section: str, line, function: bool = True) -> None:
        if not ex.is_identifier(key):
            raise TemplateError(
                f"'{key}' is not a valid name (letters, digits, _)", line=line, definition=key
            )
        if function:  # the typer refuses a built-in function's name (it knows the built-ins)
            self.functions[key] = line
        if key in self.seen:
            raise TemplateError(
                f"'{key}' is defined twice (in [{self.seen[key]}] and [{section}])",
                line=line,
                definition=key,
            )
        self.seen[key] = section


def _inputs(data: dict, text: str, claim: _Claims) -> dict[str, InputSpec]:
    inputs: dict[str, InputSpec] = {}
    for key, raw in _table(data, "inputs").items():
        line = find_line(text, key, "inputs")
        claim(key, "inputs", line, function=False)
        try:
            inputs[key] = _input(key, raw, line)
        except WorkbookError as err:
            raise err.located(line=line, definition=key) from None
    return inputs


def _arguments(data: dict, text: str) -> dict[str, ArgumentSpec]:
    arguments: dict[str, ArgumentSpec] = {}
    for key, raw in _table(data, "arguments").items():
        line = find_line(text, key, "arguments")
        if not ex.is_identifier(key):
            raise TemplateError(f"'{key}' is not a valid argument name", line=line)
        if isinstance(raw, str):
            raw = {"unit": raw}
        if not isinstance(raw, dict):
            raise TemplateError(
                'an argument is declared as { unit = "deg", note = "..." }',
                line=line,
                definition=key,
            )
        try:
            f = Fields(raw, ARGUMENT_KEYS, f"argument {key}")
            arguments[key] = ArgumentSpec(
                key, un.unit(f.text("unit"), what=key), f.text("note"), line, f.flag("plain")
            )
        except WorkbookError as err:
            raise err.located(line=line, definition=key) from None
    return arguments


def _blocks(data: dict, text: str, claim: _Claims) -> dict[str, str]:
    blocks: dict[str, str] = {}
    for key, raw in _table(data, "blocks").items():
        line = find_line(text, key, "blocks")
        claim(key, "blocks", line)
        if not isinstance(raw, str) or not re.match(r"^[a-z_][a-z0-9_]*\.[a-z_][a-z0-9_]*$", raw):
            raise TemplateError(
                "a block is named as 'module.function' (e.g. 'r0.direct')",
                line=line,
                definition=key,
            )
        blocks[key] = raw
    return blocks


def _definitions(data: dict, text: str, arguments: dict, claim: _Claims) -> dict[str, Definition]:
    definitions: dict[str, Definition] = {}
    for key, raw in _table(data, "definitions").items():
        line = find_line(text, key, "definitions")
        m = _SIGNATURE.match(key)
        if not m:
            raise TemplateError(
                f"cannot read definition name {key!r} (write 'f(x, y)' or 'x')", line=line
            )
        dname = m.group(1)
        params = tuple(p.strip() for p in m.group(2).split(",")) if m.group(2) else ()
        if m.group(2) is not None and not m.group(2).strip():
            params = ()
        claim(dname, "definitions", line, function=m.group(2) is not None)
        for p in params:
            if not ex.is_identifier(p):
                raise TemplateError(f"bad parameter name {p!r}", line=line, definition=dname)
            if p not in arguments:
                raise TemplateError(
                    f"parameter '{p}' has no declared unit: add it to [arguments] "
                    f'(e.g. {p} = {{ unit = "deg" }})',
                    line=line,
                    definition=dname,
                )
        if len(set(params)) != len(params):
            raise TemplateError("a parameter is repeated", line=line, definition=dname)
        try:
            definitions[dname] = _definition(dname, params, raw, line)
        except WorkbookError as err:
            raise err.located(line=line, definition=dname) from None
    return definitions


def _claim_solves(solves, arguments: dict, definitions: dict, claim: _Claims) -> None:
    """Claim the unknowns of the [[solve]] blocks; an unknown of a block with parameters
    becomes a definition, a function of them."""
    for block in solves:
        for name in block.unknowns:
            claim(name, "solve", block.line)
    for block in solves:  # Mathcad's th(a) := Find(x): each unknown a function of the parameters
        for p in block.parameters:
            if p not in arguments:
                raise TemplateError(
                    f"[[solve]] parameter '{p}' has no declared unit: add it to [arguments]",
                    line=block.line,
                    definition=block.what,
                )
        for unknown in block.parameters and block.unknowns:
            definitions[unknown] = Definition(
                unknown,
                block.parameters,
                ex.Name(unknown),
                None,
                f"Find({', '.join(block.unknowns)}) of the [[solve]] block",
                "solved at each value of " + ", ".join(block.parameters),
                line=block.line,
            )


def _odes(data: dict, text: str, arguments, definitions: dict, claim) -> dict:
    """``[[ode]]`` sections; each state becomes a definition, a function of the time."""
    from .odes import parse_spec

    out = {}
    for k, raw in enumerate(_list(data, "ode")):
        name = raw.get("name") if isinstance(raw, dict) else None
        line = _name_line(text, name) if isinstance(name, str) else _section_line(text, "ode")
        try:
            spec = parse_spec(raw, where=f"[[ode]] {k + 1}", line=line)
        except WorkbookError as err:
            raise err.located(line=line) from None
        if spec.name in out:
            raise TemplateError(f"two [[ode]] sections are named '{spec.name}'", line=line)
        if spec.var not in arguments:
            raise TemplateError(
                f"ode '{spec.name}': the time variable '{spec.var}' has no declared unit: "
                f'add it to [arguments] (e.g. {spec.var} = {{ unit = "s" }})',
                line=line,
            )
        if arguments[spec.var].plain:
            raise TemplateError(
                f"ode '{spec.name}': the time variable '{spec.var}' must not be plain",
                line=line,
            )
        for i, st in enumerate(spec.states):
            claim(st.name, f"ode {spec.name}", _name_line(text, st.name) or line)
            definitions[st.name] = Definition(
                st.name,
                (spec.var,),
                None,
                None,
                f"solution of ode '{spec.name}': {st.name}' = {st.derivative_text}",
                f"state of ode '{spec.name}', initial value {st.initial_text}",
                None,
                line,
                ode=(spec.name, i),
            )
        out[spec.name] = spec
    return out


def _section_line(text: str, key: str) -> int | None:
    for number, line in enumerate(text.splitlines(), start=1):
        if line.strip().strip("[]").strip() == key:
            return number
    return None


def _header_lines(text: str, key: str) -> list[int]:
    """The lines of the ``[[key]]`` headers, in order (the i-th entry of an array of tables)."""
    pattern = re.compile(r"^\s*\[\[\s*" + re.escape(key) + r"\s*\]\]")
    return [n for n, line in enumerate(text.splitlines(), start=1) if pattern.match(line)]


def _list(data: dict, key: str) -> list:
    value = data.get(key, [])
    if isinstance(value, dict):
        value = [value]
    if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
        raise TemplateError(
            f"[[{key}]] must be an array of tables", line=_section_line(text="", key=key)
        )
    return value


def _input(key: str, raw, line) -> InputSpec:
    if isinstance(raw, (str, int, float)) and not isinstance(raw, bool):
        raw = {"value": raw}
    if not isinstance(raw, dict) or "value" not in raw:
        raise TemplateError(
            'an input is written  R1 = "20 mm"  or  R1 = { value = "20 mm", note = "..." }'
        )
    f = Fields(raw, INPUT_KEYS, f"input {key}")
    options = f.texts("options")
    note = f.text("note")
    if options:
        value = f.text("value")
        if value not in options:
            raise InputError(f"value {value!r} is not one of {', '.join(options)}")
        for other in ("unit", "min", "max", "positive", "label"):
            if other in f:
                raise TemplateError(f"input {key}: a choice input takes no {other}")
        return InputSpec(key, value, None, note, options, line=line)
    if isinstance(raw["value"], (list, dict)):
        raise TemplateError(f'input {key}: value must be one number with its unit ("20 mm")')
    q = un.quantity(raw["value"], what=key)
    if "unit" in f:  # show the input in a declared unit
        target = un.unit(f.text("unit"), what=key)
        try:
            q = q.to(target)
        except pint.DimensionalityError:
            raise InputError(
                f"value {raw['value']!r} is {un.dims(q.units)}, and cannot be shown in "
                f"{raw['unit']!r} ({un.dims(target)})"
            ) from None
    spec = InputSpec(
        key,
        q,
        q.units,
        note,
        minimum=_bound(f, "min", key),
        maximum=_bound(f, "max", key),
        positive=f.flag("positive"),
        line=line,
        label=f.text("label"),
    )
    check_input_value(spec, q)
    return spec


def check_input_value(spec: InputSpec, q: pint.Quantity) -> None:
    """Refuse NaN/inf and values outside the template's declared bounds."""
    import numpy as np

    mag = np.asarray(q.magnitude, dtype=float)
    if not np.all(np.isfinite(mag)):
        raise InputError(f"{spec.name} = {q:~} is not a finite number", definition=spec.name)
    if spec.positive and np.any(mag <= 0):
        raise InputError(f"{spec.name} = {q:~} must be positive", definition=spec.name)
    for bound, ok, word in (
        (spec.minimum, lambda a, b: a >= b, "at least"),
        (spec.maximum, lambda a, b: a <= b, "at most"),
    ):
        if bound is None:
            continue
        try:
            b = bound.to(q.units).magnitude
        except pint.DimensionalityError:
            raise InputError(f"{spec.name}: bound {bound:~} has other units than {q:~}") from None
        if not np.all(ok(mag, b)):
            hint = ""  # a bare number for a radian input: say so if it fits read as degrees
            if str(q.units) == "radian" and np.ndim(mag) == 0 and ok(np.radians(mag), b):
                hint = f" (a bare number is read as radians; for degrees write '{mag:g} deg')"
            raise InputError(
                f"{spec.name} = {q:~} must be {word} {bound:~}{hint}", definition=spec.name
            )


def _definition(name: str, params: tuple[str, ...], raw, line) -> Definition:
    note, unit_text = "", None
    if isinstance(raw, dict):
        f = Fields(raw, DEFINITION_KEYS, f"definition {name}")
        note = f.text("note")
        unit_text = f.text("unit", None)
        limits = _limits(f, name)
        if limits is not None:  # the rest of the definition as it would be without them
            rest = {k: v for k, v in raw.items() if k not in ("positive", "min", "max")}
            d = _definition(name, params, rest, line)
            return replace(d, limits=limits)
        if "expr" in f and "pieces" in f:
            raise TemplateError("a definition has either expr or pieces, not both")
        if "expr" in f:
            raw = raw["expr"]
        elif "pieces" in f:
            raw = raw["pieces"]
        elif "program" in raw:
            from ..program.parse import parse as parse_program

            body = parse_program(raw["program"], what=f"program of '{name}'")
            display = un.unit(unit_text, what=name) if unit_text is not None else None
            text = raw["program"].strip()
            return Definition(name, params, None, None, text, note, display, line, body)
        else:
            raise TemplateError(
                'a definition with a note is written { expr = "...", note = "..." } '
                '(or { program = """...""" })'
            )
    display = un.unit(unit_text, what=name) if unit_text is not None else None
    what = name
    if isinstance(raw, list):
        if not raw:
            raise TemplateError("a piecewise definition needs at least one piece")
        branches = [parse_branch(b, what=what) for b in raw]
        for b in branches[:-1]:
            if b.condition is None:
                raise TemplateError("'otherwise' must be the last piece")
        return Definition(
            name, params, None, branches, " | ".join(b.text for b in branches), note, display, line
        )
    if isinstance(raw, (int, float)) and not isinstance(raw, bool):
        raw = repr(raw)
    if not isinstance(raw, str):
        raise TemplateError("a definition is an expression in quotes")
    return Definition(name, params, ex.parse(raw, what=what), None, raw, note, display, line)


def _printed_spec(raw: dict, path: Path, text: str) -> PrintedSpec:
    if "file" not in raw:
        raise TemplateError('[[printed]] needs file = "...csv"')
    line = value_line(text, str(raw["file"]))
    try:
        return _printed_fields(raw, path, text)
    except WorkbookError as err:
        raise err.located(line=line, definition=f"printed {raw['file']}") from None


def _printed_fields(raw: dict, path: Path, text: str) -> PrintedSpec:
    f = Fields(raw, PRINTED_KEYS, "[[printed]]")
    f.text("part", None)
    misprints = []
    for m in f.tables("misprints"):
        fm = Fields(m, MISPRINT_KEYS, "[[printed]] misprint")
        misprints.append(
            Misprint(
                fm.required_text("name", 'name = "h1"'),
                fm.number("at") if fm.required("at", "at = 20") is not None else None,
                fm.text("note"),
                fm.number("corrected"),
            )
        )
    rel = Path(f.text("file"))
    if rel.is_absolute() or ".." in rel.parts:
        raise TemplateError(  # a worksheet reads only files in its own folder
            f"[[printed]] file {str(raw['file'])!r} must be a file name beside the template",
            line=value_line(text, str(raw["file"])),
        )
    role = f.text("role", "check")
    if role not in ("check", "information"):
        raise TemplateError("[[printed]] role is 'check' or 'information'")
    tolerance, rel_tolerance = f.number("tolerance"), f.number("rel_tolerance")
    for key, value in (("tolerance", tolerance), ("rel_tolerance", rel_tolerance)):
        if value is not None and value < 0:
            raise TemplateError(f"[[printed]] {key} must not be negative, got {value:g}")
    return PrintedSpec(
        path.parent / f.text("file"),
        f.text("title", f.text("file")),
        f.text("argument"),
        tolerance,
        rel_tolerance,
        role,
        misprints,
        f.text("note"),
        folder=path.parent,
    )


_SHEET_NAME_BAD = re.compile(r"[\[\]:*?/\\']")


def sheet_name(name: str, what: str) -> str:
    """A worksheet name Excel accepts: 1 to 31 characters, none of ``[]:*?/\\``, no leading or
    trailing apostrophe (the writer quotes names in formulas)."""
    if not name.strip() or len(name) > 31 or _SHEET_NAME_BAD.search(name):
        raise TemplateError(
            f"{what}: sheet name {name!r} must be 1 to 31 characters without [ ] : * ? / \\ '"
        )
    return name


def _column(
    text: str, unit_text, default_var: str | None, what: str, title: str = ""
) -> ColumnSpec:
    node = ex.parse(text, what=what)
    return ColumnSpec(
        text, node, un.unit(unit_text, what=what) if unit_text is not None else None, title or text
    )


def _columns(raw, default_var, what) -> list[ColumnSpec]:
    cols = []
    if isinstance(raw, dict):
        for k, v in raw.items():
            if not isinstance(v, str):
                raise TemplateError(
                    f'{what}: column {k!r}: its unit must be text like "mm", got {v!r}'
                )
        raw = [{"expr": k, "unit": v} for k, v in raw.items()]
    if not isinstance(raw, list):
        raise TemplateError(f'{what}: columns are {{ h1 = "mm", v1 = "m/s" }}')
    for item in raw:
        if isinstance(item, str):
            item = {"expr": item}
        if not isinstance(item, dict) or "expr" not in item:
            raise TemplateError(f'{what}: a column is {{ expr = "h1", unit = "mm" }}')
        f = Fields(item, COLUMN_KEYS, f"{what}, column {item['expr']!r}")
        cols.append(
            _column(f.text("expr"), f.text("unit", None), default_var, what, f.text("title"))
        )
    return cols


def _table_spec(index: int, raw: dict, text: str) -> TableSpec:
    name = str(raw.get("name", f"table{index + 1}"))
    line = _name_line(text, name)
    try:
        f = Fields(raw, TABLE_KEYS, f"table {name}")
        f.text("name"), f.text("part", None)
        rng = parse_range(f.text("range"), what=f"table {name}", log=True) if "range" in f else None
        cols = _columns(raw.get("columns", []), rng.var if rng else None, f"table {name}")
        shown = [(c.title, None if c.unit is None else str(c.unit)) for c in cols]
        twice = next((c for c, k in zip(cols, shown) if shown.count(k) > 1), None)
        if twice is not None:
            raise TemplateError(
                f"table {name}: column {twice.title!r} is listed twice in the same unit"
            )
        block = f.text("block", None)
        if not block and rng is None:
            raise TemplateError(f"table {name} needs a range (or a block)")
        vary = _vary(f, name)
        if vary and (block or not cols):
            raise TemplateError(f"table {name}: vary needs a range and columns (not a block)")
        return TableSpec(
            name,
            f.text("title", name),
            rng,
            cols,
            sheet_name(f.text("sheet", "Listing"), f"table {name}"),
            block,
            line,
            vary=vary,
        )
    except WorkbookError as err:
        raise err.located(line=line, definition=f"table {name}") from None


def _vary(f: Fields, name: str) -> dict[str, tuple[str, ...]]:
    """``vary = { c1 = ["1500 N/m", "3000 N/m"] }``: one input and its values (checked
    against the input when the sheet loads)."""
    raw = f.table("vary")
    if len(raw) > 1:
        raise TemplateError(
            f"table {name}: vary takes one input (a family of curves), got {len(raw)}"
        )
    out = {}
    for key, values in raw.items():
        if (
            not isinstance(values, list)
            or not values
            or not all(isinstance(v, (str, int, float)) and not isinstance(v, bool) for v in values)
        ):
            raise TemplateError(
                f'table {name}: vary.{key} must be a list of values like ["1500 N/m", "3000 N/m"]'
            )
        if len(values) > MAX_VARY:
            raise LimitError(
                f"table {name}: vary.{key} has {len(values)} values (limit {MAX_VARY})"
            )
        out[str(key)] = tuple(str(v) for v in values)
    return out


def _name_line(text: str, name: str) -> int | None:
    pattern = re.compile(r'^\s*name\s*=\s*["\']' + re.escape(name) + r'["\']')
    for number, line in enumerate(text.splitlines(), start=1):
        if pattern.match(line):
            return number
    return None


def _chart_spec(index: int, raw: dict, text: str) -> ChartSpec:
    name = str(raw.get("name", f"chart{index + 1}"))
    line = _name_line(text, name)
    what = f"chart {name}"
    try:
        f = Fields(raw, CHART_KEYS, what)
        f.text("name"), f.text("part", None)
        rng = parse_range(f.text("range"), what=what, log=True) if "range" in f else None
        x_raw = raw.get("x", rng.var if rng else None)
        x_title = ""
        if isinstance(x_raw, dict):
            fx = Fields(x_raw, AXIS_KEYS, f"{what}, x")
            x_title = fx.text("title")
            expr = fx.required_text("expr", 'x = { expr = "phi" }')
            x = _column(expr, fx.text("unit", None), None, what, x_title)
        elif x_raw is not None:
            x = _column(Fields({"x": x_raw}, ("x",), what).text("x"), None, None, what)
        else:
            x = None
        series = []
        for raw_s in f.tables("series"):
            label = raw_s.get("name", raw_s.get("y", len(series) + 1))
            s = Fields(raw_s, SERIES_KEYS, f"{what}, series {label!r}")
            y_text = s.required_text("y", 'y = "h1"')
            common = dict(
                name=s.text("name", y_text),
                line=s.text("line", "solid"),
                axis=s.text("axis", "primary"),
                marker=s.flag("marker"),
            )
            if "table" in s:
                series.append(
                    SeriesSpec(
                        y=_column("0", None, None, what),
                        table=s.text("table"),
                        x_column=s.text("x"),
                        y_column=y_text,
                        **common,
                    )
                )
                continue
            y = _column(y_text, s.text("unit", None), None, what, common["name"])
            srange = parse_range(s.text("range"), what=what, log=True) if "range" in s else None
            sx = _column(s.text("x"), s.text("x_unit", None), None, what) if "x" in s else None
            series.append(SeriesSpec(y, x=sx, range=srange, **common))
        if not series:
            raise TemplateError(f"{what} has no series")
        for s in series:
            if s.line not in ("solid", "dash", "dot", "none"):
                raise TemplateError(f"{what}: line must be solid, dash, dot or none")
            if s.axis not in ("primary", "secondary"):
                raise TemplateError(f"{what}: axis must be primary or secondary")
        return ChartSpec(
            name,
            f.text("title", name),
            rng,
            x,
            x_title or f.text("x_title"),
            f.text("y_title"),
            f.text("y2_title"),
            series,
            f.flag("log_x"),
            f.flag("log_y"),
            f.flag("equal_axes"),
            line,
        )
    except WorkbookError as err:
        raise err.located(line=line, definition=what) from None


_RELATION = re.compile(
    r"^\s*([A-Za-z]\w*)\s*=\s*(.*?)\s*\*?\s*d\(\s*([A-Za-z]\w*)\s*\)\s*/\s*d\(\s*([A-Za-z]\w*)\s*\)\s*$"
)


def _relation_spec(raw: dict, text: str) -> RelationSpec:
    rel = raw.get("relation")
    if not isinstance(rel, str):
        raise TemplateError('[[relations]] needs relation = "v1 = omega * d(h1)/d(phi)"')
    line = value_line(text, rel)
    try:
        f = Fields(raw, RELATION_KEYS, f"relation {rel!r}")
        f.text("part", None), f.text("range"), f.text("unit")
    except WorkbookError as err:
        raise err.located(line=line) from None
    m = _RELATION.match(rel)
    if not m:
        raise TemplateError(
            f"cannot read relation {rel!r} (write 'v1 = omega * d(h1)/d(phi)')", line=line
        )
    factor = m.group(2).strip().rstrip("*").strip() or "1"
    try:
        rng = parse_range(raw["range"], what=rel) if "range" in raw else None
        un.unit(f.text("unit", "rad"), what=rel)
    except WorkbookError as err:
        raise err.located(line=line) from None
    return RelationSpec(
        rel,
        m.group(1),
        ex.parse(factor, what=rel),
        m.group(3),
        m.group(4),
        str(raw.get("unit", "rad")),
        rng,
        line,
    )


def column_node(spec: SheetSpec, col, var: str) -> ex.Node:
    """A bare one-argument function name as a column means that function of the range variable."""
    node = col.node
    if isinstance(node, ex.Name):
        d = spec.definitions.get(node.id)
        if d is not None and d.is_function and len(d.params) == 1:
            return ex.Call(node.id, (ex.Name(var),))
    return node


_PART_NAME = re.compile(r"^[a-z][a-z0-9-]{0,39}$")


def _parts(raw: dict, text: str) -> dict[str, PartSpec]:
    parts = {}
    for key, value in raw.items():
        line = find_line(text, key, "parts")
        if not _PART_NAME.match(key) or key == ALL_PARTS:
            raise TemplateError(
                f"part name {key!r}: lowercase letters, digits and '-' (and not 'all')", line=line
            )
        if isinstance(value, str):
            value = {"title": value}
        if not isinstance(value, dict):
            raise TemplateError(
                'a part is declared as { title = "...", note = "..." }', line=line, definition=key
            )
        try:
            f = Fields(value, PART_KEYS, f"part {key}")
            parts[key] = PartSpec(key, f.text("title", key), f.text("note"), line)
        except WorkbookError as err:
            raise err.located(line=line, definition=key) from None
    return parts
