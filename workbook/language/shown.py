"""Reading what a worksheet shows besides its values: ``[[tables]]`` (their columns and
``vary``), ``[[charts]]`` and ``[[relations]]``, each into its spec; the Excel sheet names
the tables become."""

from __future__ import annotations

import re

from ..errors import LimitError, TemplateError, WorkbookError
from . import expr as ex
from . import units as un
from .fields import Fields, value_line
from .ranges import parse_range
from .spec import (
    AXIS_KEYS,
    CHART_KEYS,
    COLUMN_KEYS,
    MAX_VARY,
    RELATION_KEYS,
    SERIES_KEYS,
    TABLE_KEYS,
    ChartSpec,
    ColumnSpec,
    RelationSpec,
    SeriesSpec,
    SheetSpec,
    TableSpec,
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


def table_spec(index: int, raw: dict, text: str) -> TableSpec:
    name = str(raw.get("name", f"table{index + 1}"))
    line = name_line(text, name)
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


def name_line(text: str, name: str) -> int | None:
    pattern = re.compile(r'^\s*name\s*=\s*["\']' + re.escape(name) + r'["\']')
    for number, line in enumerate(text.splitlines(), start=1):
        if pattern.match(line):
            return number
    return None


def chart_spec(index: int, raw: dict, text: str) -> ChartSpec:
    name = str(raw.get("name", f"chart{index + 1}"))
    line = name_line(text, name)
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


def relation_spec(raw: dict, text: str) -> RelationSpec:
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
