"""``[[ode]]`` sections read and typed: states (unit, initial value, derivative expression),
the time range, the method and the tolerances, as written (:func:`parse_spec`) and typed with
the sheet's typer at load (:func:`type_ode`); solving them is :mod:`workbook.engine.ode`."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..errors import LimitError, TemplateError
from . import expr as ex

METHODS = ("auto", "RK45", "DOP853", "Radau", "BDF", "LSODA")
MAX_STATES = 1000
MAX_TIME = 30.0  # wall-clock budget of one run, seconds
MAX_STEPS = 1_000_000


Setting = float | ex.Node  # a number, or an expression of the sheet


@dataclass(frozen=True)
class StateSpec:
    name: str
    unit: str
    initial: ex.Node
    derivative: ex.Node
    initial_text: str
    derivative_text: str
    atol: ex.Node | None = None  # this state's absolute tolerance (in its unit)


@dataclass(frozen=True)
class OdeSpec:
    name: str
    var: str
    first: ex.Node
    last: ex.Node
    time_text: str
    states: tuple[StateSpec, ...]
    method: str | ex.Node = "auto"  # one of METHODS, or an expression giving one
    rtol: Setting = 1e-6
    atol: Setting = 1e-9
    max_time: Setting = MAX_TIME
    max_steps: int = MAX_STEPS
    note: str = ""
    line: int | None = None

    def expressions(self) -> list[ex.Node]:
        """Every expression of the section (what it depends on)."""
        out = [self.first, self.last]
        out += [x for s in self.states for x in (s.initial, s.derivative, s.atol) if x]
        settings = (self.method, self.rtol, self.atol, self.max_time)
        return out + [x for x in settings if isinstance(x, ex.Node)]


_KEYS = {"name", "time", "states", "method", "rtol", "atol", "max_time", "max_steps", "note"}
_STATE_KEYS = {"name", "unit", "initial", "derivative", "atol", "note"}


def parse_spec(raw: dict, *, where: str, line: int | None = None) -> OdeSpec:
    """Read one ``[[ode]]`` table (raises TemplateError naming the key)."""
    from .ranges import parse_range

    if not isinstance(raw, dict):
        raise TemplateError(f"{where}: an [[ode]] entry is a table", line=line)
    extra = set(raw) - _KEYS
    if extra:
        raise TemplateError(
            f"{where}: unknown key(s) {', '.join(sorted(extra))} "
            f"(known: {', '.join(sorted(_KEYS))})",
            line=line,
        )
    name = raw.get("name")
    if not isinstance(name, str) or not ex.is_identifier(name):
        raise TemplateError(f'{where}: name = "..." (a plain name) is required', line=line)
    where = f"ode '{name}'"
    if "time" not in raw:
        raise TemplateError(f'{where}: time = "t := 0 .. t_end" is required', line=line)
    rng = parse_range(raw["time"], what=f"{where}: time")
    if rng.second is not None:
        raise TemplateError(f"{where}: time is 'VAR := FIRST .. LAST' (no step)", line=line)
    method = raw.get("method", "auto")
    if not isinstance(method, str):
        raise TemplateError(f"{where}: method is one of {', '.join(METHODS)}", line=line)
    if method not in METHODS:
        method = ex.parse(method, what=f"{where}: method")
    rtol, atol = _setting(raw, "rtol", 1e-6, where), _setting(raw, "atol", 1e-9, where)
    if isinstance(rtol, float) and rtol < 1e-13:
        raise TemplateError(f"{where}: rtol {rtol:g} is below what doubles resolve (1e-13)")
    max_time = _setting(raw, "max_time", MAX_TIME, where)
    max_steps = int(_positive(raw, "max_steps", MAX_STEPS, where))
    # a worksheet may lower its budget, never raise it past the engine's
    if isinstance(max_time, float):
        check_budget(where, "max_time", max_time, line)
    check_budget(where, "max_steps", max_steps, line)
    states = raw.get("states")
    if not isinstance(states, list) or not states:
        raise TemplateError(
            f'{where}: states = [{{ name = "x", unit = "m", initial = "...", '
            'derivative = "..." }, ...] is required',
            line=line,
        )
    if len(states) > MAX_STATES:
        raise LimitError(f"{where}: {len(states)} states (limit {MAX_STATES})", line=line)
    out, seen = [], set()
    for k, s in enumerate(states):
        sw = f"{where}, state {k + 1}"
        if not isinstance(s, dict):
            raise TemplateError(f"{sw}: a state is a table {{ name = ..., ... }}", line=line)
        extra = set(s) - _STATE_KEYS
        missing = {"name", "initial", "derivative"} - set(s)
        if extra or missing:
            raise TemplateError(
                f"{sw}: keys are name, unit, initial, derivative (and atol, note); "
                + (f"unknown: {', '.join(sorted(extra))}" if extra else "")
                + (f"missing: {', '.join(sorted(missing))}" if missing else ""),
                line=line,
            )
        sname = s["name"]
        if not isinstance(sname, str) or not ex.is_identifier(sname) or sname in seen:
            raise TemplateError(f"{sw}: name {sname!r} is not a new plain name", line=line)
        seen.add(sname)
        unit = s.get("unit", "")
        if not isinstance(unit, str):
            raise TemplateError(f'{sw}: unit is text like "m/s"', line=line)
        init, der = s["initial"], s["derivative"]
        init = repr(init) if isinstance(init, (int, float)) and not isinstance(init, bool) else init
        der = repr(der) if isinstance(der, (int, float)) and not isinstance(der, bool) else der
        out.append(
            StateSpec(
                sname,
                unit,
                ex.parse(init, what=f"{sw}: initial"),
                ex.parse(der, what=f"{sw}: derivative"),
                init,
                der,
                _expression(s["atol"], f"{sw}: atol") if "atol" in s else None,
            )
        )
    if rng.var in seen:
        raise TemplateError(f"{where}: the time variable '{rng.var}' is also a state", line=line)
    return OdeSpec(
        name,
        rng.var,
        rng.first,
        rng.last,
        rng.text,
        tuple(out),
        method,
        rtol,
        atol,
        max_time,
        max_steps,
        str(raw.get("note", "")),
        line,
    )


def _expression(v, what: str) -> ex.Node:
    """A setting given as a number or as an expression text."""
    if isinstance(v, bool) or not isinstance(v, (int, float, str)):
        raise TemplateError(f"{what}: a number or an expression, got {v!r}")
    return ex.parse(v if isinstance(v, str) else repr(v), what=what)


def _setting(raw: dict, key: str, default: float, where: str) -> Setting:
    """A positive number, or an expression of the sheet (checked when it is evaluated)."""
    if isinstance(raw.get(key), str):
        return ex.parse(raw[key], what=f"{where}: {key}")
    return _positive(raw, key, default, where)


def check_budget(where: str, key: str, value: float, line: int | None = None) -> None:
    """Refuse a worksheet's ``max_time`` or ``max_steps`` above the engine's
    (:data:`MAX_TIME`, :data:`MAX_STEPS`)."""
    limit = {"max_time": MAX_TIME, "max_steps": MAX_STEPS}[key]
    if value > limit:
        shown = f"{value:g} s (limit {limit:g} s)" if key == "max_time" else f"{value:,.0f}"
        if key == "max_steps":
            shown += f" (limit {limit:,})"
        raise LimitError(
            f"{where}: {key} = {shown}: a worksheet may lower the budget of a run, not raise it",
            line=line,
        )


def _positive(raw: dict, key: str, default: float, where: str) -> float:
    v = raw.get(key, default)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not (v > 0 and math.isfinite(v)):
        raise TemplateError(f"{where}: {key} must be a positive number, got {v!r}")
    return float(v)


@dataclass(frozen=True)
class TypedOde:
    """The typed expressions of one section: derivatives in state unit per time unit,
    initial values and tolerances in the state's unit, the time bounds in the time variable's
    unit; settings given as expressions typed (None: the section's number)."""

    spec: OdeSpec
    time_unit: object  # pint.Unit
    units: tuple  # pint.Unit of each state
    derivatives: tuple  # typed nodes
    initials: tuple
    first: object
    last: object
    atols: tuple = ()  # typed node or None, per state
    settings: dict = field(default_factory=dict)  # "method", "rtol", "atol", "max_time"
    shapes: tuple = ()  # per state: None (a number) or (n, 1) (a vector)

    @property
    def sizes(self) -> tuple:
        """Per state: None (a number) or its number of elements."""
        shapes = self.shapes or (None,) * len(self.units)
        return tuple(None if s is None else s[0] for s in shapes)


def type_ode(typer, spec: OdeSpec) -> TypedOde:
    """Type a section's expressions (units are checked here, at load)."""
    from ..errors import WorkbookError
    from . import units as un

    time_unit = typer.spec.arguments[spec.var].unit
    dimensionless = un.registry().dimensionless
    units = []
    for s in spec.states:
        try:
            units.append(un.unit(s.unit, what=f"ode '{spec.name}', state '{s.name}'"))
        except WorkbookError as err:
            raise err.located(line=spec.line, definition=s.name) from None
    scope = {spec.var: time_unit}

    def in_unit(node, unit, what: str, plain_ok: bool):
        t = typer.expression(node, scope if not plain_ok else {}, what)
        if plain_ok and t.unit == dimensionless and not t.boolean and not t.text:
            return t  # a plain number is taken in the declared unit (as range bounds)
        try:
            return typer.convert(t, unit, what)
        except WorkbookError as err:
            raise err.located(line=spec.line, definition=what) from None

    inits = [
        in_unit(s.initial, u, f"initial {s.name} (ode '{spec.name}')", True)
        for s, u in zip(spec.states, units)
    ]
    shapes = tuple(_state_shape(spec, s, t) for s, t in zip(spec.states, inits))
    for s, u, shape in zip(spec.states, units, shapes):
        scope[s.name] = u if shape is None else (u, shape)
    ders, atols = [], []
    for s, u, shape in zip(spec.states, units, shapes):
        # a state in degC changes by differences: T' is in delta_degC per time unit
        step = un.difference_unit(u)
        der = in_unit(s.derivative, step / time_unit, f"{s.name}' (ode '{spec.name}')", False)
        if der.shape != shape:
            raise TemplateError(
                f"ode '{spec.name}': the derivative of '{s.name}' is {_shape_word(der.shape)}, "
                f"its initial value {_shape_word(shape)}",
                line=spec.line,
                definition=s.name,
            )
        ders.append(der)
        atols.append(
            in_unit(s.atol, step, f"atol of {s.name} (ode '{spec.name}')", True) if s.atol else None
        )
    first = in_unit(spec.first, time_unit, f"time range of ode '{spec.name}'", True)
    last = in_unit(spec.last, time_unit, f"time range of ode '{spec.name}'", True)
    settings = {}
    for key, unit in (("rtol", dimensionless), ("atol", dimensionless), ("max_time", "s")):
        node = getattr(spec, key)
        if isinstance(node, ex.Node):
            unit = un.unit(unit) if isinstance(unit, str) else unit
            settings[key] = in_unit(node, unit, f"{key} of ode '{spec.name}'", True)
    if isinstance(spec.method, ex.Node):
        settings["method"] = _typed_method(typer, spec)
    return TypedOde(
        spec,
        time_unit,
        tuple(units),
        tuple(ders),
        tuple(inits),
        first,
        last,
        tuple(atols),
        settings,
        shapes,
    )


def _state_shape(spec: OdeSpec, s: StateSpec, initial) -> tuple | None:
    """A state is a number or a vector (a column), as its initial value."""
    if initial.shape is not None and initial.shape[1] != 1:
        raise TemplateError(
            f"ode '{spec.name}': the initial value of '{s.name}' is a "
            f"{initial.shape[0]}x{initial.shape[1]} matrix; a state is a number or a vector",
            line=spec.line,
            definition=s.name,
        )
    return initial.shape


def _shape_word(shape) -> str:
    return "a number" if shape is None else f"a vector of {shape[0]}"


def _typed_method(typer, spec: OdeSpec):
    """The method as an expression: a text definition or a choice input."""
    from .typed import TRef

    node = spec.method
    known = set(typer.spec.inputs) | set(typer.spec.definitions)
    if isinstance(node, ex.Name) and node.id not in known:
        raise TemplateError(
            f"ode '{spec.name}': method {node.id!r} is not one of {', '.join(METHODS)}, nor a "
            "text definition or choice input of the sheet",
            line=spec.line,
        )
    t = typer.expression(node, {}, f"method of ode '{spec.name}'")
    if not (t.text or (isinstance(t, TRef) and t.kind == "choice")):
        raise TemplateError(
            f"ode '{spec.name}': method must give text, one of {', '.join(METHODS)}",
            line=spec.line,
        )
    return t
