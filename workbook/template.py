"""Reading a worksheet template (TOML) into a validated specification.

The template is data: TOML parsed by the standard library, expressions parsed by
:mod:`workbook.expr`. Nothing here evaluates anything.
"""

from __future__ import annotations

import math
import re

try:
    import tomllib
except ImportError:  # Python 3.10
    import tomli as tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import pint

from . import expr as ex
from . import units as un
from .builtins import REGISTRY
from .errors import InputError, LimitError, TemplateError, WorkbookError
from .measured import read_data

MAX_RANGE_POINTS = 2_000_000
MAX_TEMPLATE_BYTES = 2_000_000  # a template file larger than this is refused

SECTIONS = {
    "sheet",
    "inputs",
    "arguments",
    "definitions",
    "blocks",
    "tables",
    "charts",
    "printed",
    "relations",
    "findings",
    "sweep",
    "parts",
    "data",
}
ALL_PARTS = "all"
_PART_NAME = re.compile(r"^[a-z][a-z0-9-]{0,39}$")


@dataclass
class Located:
    file: str
    line: int | None


@dataclass
class InputSpec:
    name: str
    value: pint.Quantity | str
    unit: pint.Unit | None  # None for a choice input
    note: str = ""
    options: tuple[str, ...] = ()
    minimum: pint.Quantity | None = None
    maximum: pint.Quantity | None = None
    positive: bool = False
    line: int | None = None
    label: str = ""  # unit shown beside a plain number (e.g. "deg" for Mathcad's Theta = 52)


@dataclass
class ArgumentSpec:
    name: str
    unit: pint.Unit
    note: str = ""
    line: int | None = None
    plain: bool = False  # inside formulas the argument is a plain number in `unit` (Mathcad style)

    @property
    def binding_unit(self) -> pint.Unit:
        return un.registry().dimensionless if self.plain else self.unit


@dataclass
class Branch:
    value: ex.Node
    condition: ex.Node | None  # None: 'otherwise'
    text: str


@dataclass
class Definition:
    name: str
    params: tuple[str, ...]
    body: ex.Node | None
    branches: list[Branch] | None = None
    text: str = ""
    note: str = ""
    unit: pint.Unit | None = None  # display unit, optional
    line: int | None = None

    @property
    def is_function(self) -> bool:
        return bool(self.params)


@dataclass
class PartSpec:
    """An optional part of a worksheet (hand checks, studies): left out unless asked for."""

    name: str
    title: str
    note: str = ""
    line: int | None = None


@dataclass
class RangeSpec:
    var: str
    first: ex.Node
    second: ex.Node | None
    last: ex.Node
    text: str


@dataclass
class ColumnSpec:
    text: str
    node: ex.Node
    unit: pint.Unit | None
    title: str


@dataclass
class TableSpec:
    name: str
    title: str
    range: RangeSpec | None
    columns: list[ColumnSpec]
    sheet: str = "Listing"
    block: str | None = None
    line: int | None = None
    part: str | None = None


@dataclass
class SeriesSpec:
    y: ColumnSpec
    name: str
    line: str = "solid"  # solid | dash | dot | none
    axis: str = "primary"
    marker: bool = False
    x: ColumnSpec | None = None
    range: RangeSpec | None = None
    table: str | None = None  # series read from a block table: column names
    x_column: str | None = None
    y_column: str | None = None


@dataclass
class ChartSpec:
    name: str
    title: str
    range: RangeSpec | None
    x: ColumnSpec | None
    x_title: str
    y_title: str
    y2_title: str = ""
    series: list[SeriesSpec] = field(default_factory=list)
    log_x: bool = False
    log_y: bool = False
    equal_axes: bool = False
    line: int | None = None
    part: str | None = None


@dataclass
class Misprint:
    name: str
    at: float
    note: str
    corrected: float | None = None


@dataclass
class PrintedSpec:
    file: Path
    title: str
    argument: str
    tolerance: float | None = None  # absolute, in the printed unit
    rel_tolerance: float | None = None
    role: str = "check"  # check | information
    misprints: list[Misprint] = field(default_factory=list)
    note: str = ""
    part: str | None = None


@dataclass
class RelationSpec:
    """A declared derivative relation: child == factor * d(parent)/d(var)."""

    text: str
    child: str
    factor: ex.Node
    parent: str
    var: str
    var_unit: str
    range: RangeSpec | None
    line: int | None = None
    part: str | None = None


@dataclass
class SheetSpec:
    name: str
    title: str
    path: Path
    source: str
    description: str
    inputs: dict[str, InputSpec]
    arguments: dict[str, ArgumentSpec]
    definitions: dict[str, Definition]
    blocks: dict[str, str]
    tables: list[TableSpec]
    charts: list[ChartSpec]
    printed: list[PrintedSpec]
    relations: list[RelationSpec]
    findings: list[dict]
    meta: dict[str, Any]
    text: str
    parts: dict[str, PartSpec] = field(default_factory=dict)
    data: dict[str, Any] = field(default_factory=dict)  # column name -> measured.DataColumn

    def line_of(self, key: str, section: str | None = None) -> int | None:
        return find_line(self.text, key, section)


def find_line(text: str, key: str, section: str | None = None) -> int | None:
    """Line number (1-based) where ``key = ...`` is written, optionally inside [section]."""
    pattern = re.compile(r'^\s*["\']?' + re.escape(key) + r'["\']?\s*=')
    in_section = section is None
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if section is not None and stripped.startswith("["):
            name = stripped.strip("[]").strip()
            in_section = name == section or name.startswith(section + ".")
            continue
        if in_section and pattern.match(line):
            return number
    return None


_SIGNATURE = re.compile(r"^\s*([A-Za-z][A-Za-z0-9_]*)\s*(?:\(([^()]*)\))?\s*$")
_RANGE = re.compile(r"^\s*(?:([A-Za-z][A-Za-z0-9_]*)\s*:=\s*)?(.+?)\s*\.\.\s*(.+?)\s*$")


def parse_range(text: str, *, default_var: str | None = None, what: str = "range") -> RangeSpec:
    """Parse Mathcad's range form ``phi := first, second .. last`` (or ``first .. last``)."""
    if not isinstance(text, str):
        raise TemplateError(f"{what}: expected a range like 'phi := 0, 5 .. 22'")
    m = _RANGE.match(text)
    if not m:
        raise TemplateError(f"{what}: cannot read range {text!r} (expected 'phi := 0, 5 .. 22')")
    var, head, last = m.group(1) or default_var, m.group(2), m.group(3)
    if not var:
        raise TemplateError(f"{what}: range {text!r} names no variable (write 'phi := 0, 5 .. 22')")
    parts = _split_top(head, ",")
    if len(parts) > 2:
        raise TemplateError(f"{what}: range {text!r} has more than two values before '..'")
    first = ex.parse(parts[0], what=what)
    second = ex.parse(parts[1], what=what) if len(parts) == 2 else None
    return RangeSpec(var, first, second, ex.parse(last, what=what), text.strip())


def range_values(first: float, second: float | None, last: float, *, what: str = "range"):
    """Values of a range; the last value is always included (as the paper's listings show)."""
    import numpy as np

    for v in (first, last) + ((second,) if second is not None else ()):
        if not math.isfinite(v):
            raise TemplateError(f"{what}: range bounds must be finite numbers")
    step = (second - first) if second is not None else (1.0 if last >= first else -1.0)
    if step == 0:
        raise TemplateError(f"{what}: range step is zero (first and second value are equal)")
    if (last - first) * step < 0:
        raise TemplateError(
            f"{what}: range step {step:g} goes away from the last value {last:g} "
            f"(first {first:g}); reverse the step's sign"
        )
    span = (last - first) / step * (1 + 1e-12) + 1e-9
    if not span < MAX_RANGE_POINTS:  # also refuses an infinite span (1e308 / 1e-300)
        raise LimitError(
            f"{what}: range has {span + 1:,.0f} points (limit {MAX_RANGE_POINTS:,}); "
            "use a larger step"
        )
    count = math.floor(span) + 1
    values = first + step * np.arange(count, dtype=float)  # first + k*step: no drift
    if abs(values[-1] - last) > 1e-9 * max(1.0, abs(step)):
        values = np.append(values, last)
    else:
        values[-1] = last
    return values


def _split_top(text: str, sep: str) -> list[str]:
    """Split at ``sep`` outside parentheses."""
    parts, depth, cur = [], 0, []
    for ch in text:
        if ch == "(":
            depth += 1
        elif ch == ")":
            depth -= 1
        if ch == sep and depth == 0:
            parts.append("".join(cur))
            cur = []
        else:
            cur.append(ch)
    parts.append("".join(cur))
    return [p.strip() for p in parts]


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


def _quantity_or_none(value, what: str):
    return None if value is None else un.quantity(value, what=what)


def load_spec(path: Path, name: str | None = None) -> SheetSpec:
    """Read and validate a template file."""
    file = str(path)
    try:
        if path.stat().st_size > MAX_TEMPLATE_BYTES:
            raise LimitError(
                f"template is {path.stat().st_size:,} bytes (limit {MAX_TEMPLATE_BYTES:,})",
                file=file,
            )
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise TemplateError(f"cannot read template: {exc.strerror}", file=file) from None
    except UnicodeDecodeError:
        raise TemplateError("template is not UTF-8 text", file=file) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        line = getattr(exc, "lineno", None)
        if line is None:
            m = re.search(r"line (\d+)", str(exc))
            line = int(m.group(1)) if m else None
        raise TemplateError(f"TOML syntax: {exc}", file=file, line=line) from None
    except RecursionError:  # tomllib recurses into nested arrays and inline tables
        raise LimitError("TOML arrays or tables nested too deeply", file=file) from None
    try:
        return _build(path, name or path.stem, text, data)
    except WorkbookError as err:
        raise err.located(file=file) from None


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
            f"unknown section [{key}] (known: {', '.join(sorted(SECTIONS))})",
            line=find_line(text, key) or _section_line(text, key),
        )
    sheet = _table(data, "sheet")
    if "name" in sheet and not re.match(r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,79}$", str(sheet["name"])):
        raise TemplateError(  # the name becomes reports/NAME.xlsx: no folders, no '..'
            f"[sheet] name {str(sheet['name'])[:80]!r} must be letters, digits, '-', '_', '.'",
            line=find_line(text, "name", "sheet"),
        )
    seen: dict[str, str] = {}

    def claim(key: str, section: str, line):
        if not ex.is_identifier(key):
            raise TemplateError(
                f"'{key}' is not a valid name (letters, digits, _)", line=line, definition=key
            )
        if key in REGISTRY:
            raise TemplateError(
                f"'{key}' shadows the built-in function {key}(); choose another name",
                line=line,
                definition=key,
            )
        if key in seen:
            raise TemplateError(
                f"'{key}' is defined twice (in [{seen[key]}] and [{section}])",
                line=line,
                definition=key,
            )
        seen[key] = section

    inputs: dict[str, InputSpec] = {}
    for key, raw in _table(data, "inputs").items():
        line = find_line(text, key, "inputs")
        claim(key, "inputs", line)
        try:
            inputs[key] = _input(key, raw, line)
        except WorkbookError as err:
            raise err.located(line=line, definition=key) from None

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
            arguments[key] = ArgumentSpec(
                key,
                un.unit(raw.get("unit", ""), what=key),
                str(raw.get("note", "")),
                line,
                bool(raw.get("plain", False)),
            )
        except WorkbookError as err:
            raise err.located(line=line, definition=key) from None

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
        claim(dname, "definitions", line)
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

    for pname in arguments:
        if pname in inputs or pname in definitions:
            raise TemplateError(
                f"argument '{pname}' has the name of an input or definition",
                line=arguments[pname].line,
                definition=pname,
            )

    measured = read_data(
        _table(data, "data"), path, lambda key, sec: find_line(text, key, sec), claim
    )

    tables = [_table_spec(i, t, text) for i, t in enumerate(_list(data, "tables"))]
    charts = [_chart_spec(i, c, text) for i, c in enumerate(_list(data, "charts"))]
    printed = [_printed_spec(p, path, text) for p in _list(data, "printed")]
    relations = [_relation_spec(r, text) for r in _list(data, "relations")]
    findings = _list(data, "findings")
    names_seen = set()
    for t in tables:
        if t.name in names_seen:
            raise TemplateError(f"two tables are named '{t.name}'", line=t.line)
        names_seen.add(t.name)
    parts = _parts(_table(data, "parts"), text)
    _assign_parts(data, parts, text, tables, charts, printed, relations)

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
    )


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
        parts[key] = PartSpec(key, str(value.get("title", key)), str(value.get("note", "")), line)
    return parts


def _assign_parts(data: dict, parts: dict[str, PartSpec], text: str, *specs: list) -> None:
    """Set ``part`` on every table, chart, printed file and relation that names one. A section
    may name only a declared part, and a chart that draws a block table of a part must be in
    that part (else it would draw a table that was not written)."""
    sections = ("tables", "charts", "printed", "relations")
    for section, items in zip(sections, specs):
        for item, raw in zip(items, _list(data, section)):
            item.part = _part_of(raw, parts, section, text, getattr(item, "line", None))
    for raw in _list(data, "findings"):
        _part_of(raw, parts, "findings", text, None)
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
            line=line or _value_line(text, f"part = {part!r}".replace("'", '"')),
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


def _section_line(text: str, key: str) -> int | None:
    for number, line in enumerate(text.splitlines(), start=1):
        if line.strip().strip("[]").strip() == key:
            return number
    return None


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
    options = tuple(str(o) for o in raw.get("options", ()))
    note = str(raw.get("note", ""))
    if options:
        value = str(raw["value"])
        if value not in options:
            raise InputError(f"value {value!r} is not one of {', '.join(options)}")
        return InputSpec(key, value, None, note, options, line=line)
    q = un.quantity(raw["value"], what=key)
    if "unit" in raw:  # show the input in a declared unit
        target = un.unit(str(raw["unit"]), what=key)
        try:
            q = q.to(target)
        except pint.DimensionalityError:
            raise InputError(f"value {raw['value']!r} cannot be shown in {raw['unit']!r}") from None
    spec = InputSpec(
        key,
        q,
        q.units,
        note,
        minimum=_quantity_or_none(raw.get("min"), key),
        maximum=_quantity_or_none(raw.get("max"), key),
        positive=bool(raw.get("positive", False)),
        line=line,
        label=str(raw.get("label", "")),
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
        note = str(raw.get("note", ""))
        unit_text = raw.get("unit")
        if "expr" in raw:
            raw = raw["expr"]
        elif "pieces" in raw:
            raw = raw["pieces"]
        else:
            raise TemplateError(
                'a definition with a note is written { expr = "...", note = "..." }'
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
        raw = [{"expr": k, "unit": v} for k, v in raw.items()]
    if not isinstance(raw, list):
        raise TemplateError(f'{what}: columns are {{ h1 = "mm", v1 = "m/s" }}')
    for item in raw:
        if isinstance(item, str):
            item = {"expr": item}
        if not isinstance(item, dict) or "expr" not in item:
            raise TemplateError(f'{what}: a column is {{ expr = "h1", unit = "mm" }}')
        cols.append(
            _column(
                str(item["expr"]), item.get("unit"), default_var, what, str(item.get("title", ""))
            )
        )
    return cols


def _table_spec(index: int, raw: dict, text: str) -> TableSpec:
    name = str(raw.get("name", f"table{index + 1}"))
    line = find_line(text, "name") if False else _name_line(text, name)
    try:
        rng = parse_range(raw["range"], what=f"table {name}") if "range" in raw else None
        cols = _columns(raw.get("columns", []), rng.var if rng else None, f"table {name}")
        if not raw.get("block") and rng is None:
            raise TemplateError(f"table {name} needs a range (or a block)")
        return TableSpec(
            name,
            str(raw.get("title", name)),
            rng,
            cols,
            str(raw.get("sheet", "Listing")),
            raw.get("block"),
            line,
        )
    except WorkbookError as err:
        raise err.located(line=line, definition=f"table {name}") from None


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
        rng = parse_range(raw["range"], what=what) if "range" in raw else None
        x_raw = raw.get("x", rng.var if rng else None)
        x_title = ""
        if isinstance(x_raw, dict):
            x_title = str(x_raw.get("title", ""))
            x = _column(str(x_raw["expr"]), x_raw.get("unit"), None, what, x_title)
        elif x_raw is not None:
            x = _column(str(x_raw), None, None, what)
        else:
            x = None
        series = []
        for s in raw.get("series", []):
            if not isinstance(s, dict):
                raise TemplateError(f'{what}: a series is {{ y = "h", unit = "mm" }}')
            if "table" in s:
                series.append(
                    SeriesSpec(
                        y=_column("0", None, None, what),
                        name=str(s.get("name", s.get("y", ""))),
                        line=str(s.get("line", "solid")),
                        axis=str(s.get("axis", "primary")),
                        marker=bool(s.get("marker", False)),
                        table=str(s["table"]),
                        x_column=str(s.get("x", "")),
                        y_column=str(s.get("y", "")),
                    )
                )
                continue
            y = _column(str(s["y"]), s.get("unit"), None, what, str(s.get("name", s["y"])))
            srange = parse_range(s["range"], what=what) if "range" in s else None
            sx = _column(str(s["x"]), s.get("x_unit"), None, what) if "x" in s else None
            series.append(
                SeriesSpec(
                    y,
                    str(s.get("name", s["y"])),
                    str(s.get("line", "solid")),
                    str(s.get("axis", "primary")),
                    bool(s.get("marker", False)),
                    sx,
                    srange,
                )
            )
        if not series:
            raise TemplateError(f"{what} has no series")
        for s in series:
            if s.line not in ("solid", "dash", "dot", "none"):
                raise TemplateError(f"{what}: line must be solid, dash, dot or none")
            if s.axis not in ("primary", "secondary"):
                raise TemplateError(f"{what}: axis must be primary or secondary")
        return ChartSpec(
            name,
            str(raw.get("title", name)),
            rng,
            x,
            x_title or str(raw.get("x_title", "")),
            str(raw.get("y_title", "")),
            str(raw.get("y2_title", "")),
            series,
            bool(raw.get("log_x", False)),
            bool(raw.get("log_y", False)),
            bool(raw.get("equal_axes", False)),
            line,
        )
    except WorkbookError as err:
        raise err.located(line=line, definition=what) from None


def _printed_spec(raw: dict, path: Path, text: str) -> PrintedSpec:
    if "file" not in raw:
        raise TemplateError('[[printed]] needs file = "...csv"')
    misprints = [
        Misprint(
            str(m["name"]),
            float(m["at"]),
            str(m.get("note", "")),
            float(m["corrected"]) if "corrected" in m else None,
        )
        for m in raw.get("misprints", [])
    ]
    rel = Path(str(raw["file"]))
    if rel.is_absolute() or ".." in rel.parts:
        raise TemplateError(  # a worksheet reads only files in its own folder
            f"[[printed]] file {str(raw['file'])!r} must be a file name beside the template",
            line=_value_line(text, str(raw["file"])),
        )
    role = str(raw.get("role", "check"))
    if role not in ("check", "information"):
        raise TemplateError("[[printed]] role is 'check' or 'information'")
    return PrintedSpec(
        path.parent / str(raw["file"]),
        str(raw.get("title", raw["file"])),
        str(raw.get("argument", "")),
        float(raw["tolerance"]) if "tolerance" in raw else None,
        float(raw["rel_tolerance"]) if "rel_tolerance" in raw else None,
        role,
        misprints,
        str(raw.get("note", "")),
    )


_RELATION = re.compile(
    r"^\s*([A-Za-z]\w*)\s*=\s*(.*?)\s*\*?\s*d\(\s*([A-Za-z]\w*)\s*\)\s*/\s*d\(\s*([A-Za-z]\w*)\s*\)\s*$"
)


def _relation_spec(raw: dict, text: str) -> RelationSpec:
    rel = raw.get("relation")
    if not isinstance(rel, str):
        raise TemplateError('[[relations]] needs relation = "v1 = omega * d(h1)/d(phi)"')
    line = find_line(text, "relation") if False else _value_line(text, rel)
    m = _RELATION.match(rel)
    if not m:
        raise TemplateError(
            f"cannot read relation {rel!r} (write 'v1 = omega * d(h1)/d(phi)')", line=line
        )
    factor = m.group(2).strip().rstrip("*").strip() or "1"
    rng = parse_range(raw["range"], what=rel) if "range" in raw else None
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


def _value_line(text: str, value: str) -> int | None:
    for number, line in enumerate(text.splitlines(), start=1):
        if value in line:
            return number
    return None
