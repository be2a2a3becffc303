"""The one shared pint registry, with the project's definition files loaded."""

from __future__ import annotations

import functools
import math
import re

import pint
from pint.util import to_units_container

from ..errors import InputError, LimitError, UnitError
from .fields import nearest
from .quantity import MAX_UNIT_POWER, check_unit_text, split_quantity


@functools.cache
def registry() -> pint.UnitRegistry:
    """Return the shared registry (created on first use).

    Parsing pint's definition files costs ~0.15 s per process; pint's disk cache (a pickle of
    the parsed definitions, keyed by the files) cuts that to ~0.03 s. The cache lives in the
    user cache folder (``WORKBOOK_CACHE`` overrides it; set it empty to turn it off); any
    problem with it (unwritable, damaged, written by another process at the same time) falls
    back to parsing.
    """
    folder = _cache_folder()
    ureg = None
    if folder is not None:
        try:
            ureg = _new_registry(folder)
        except Exception:  # noqa: BLE001 - a cache problem must never stop a worksheet
            ureg = None
    if ureg is None:
        ureg = _new_registry(None)
    pint.set_application_registry(ureg)
    return ureg


def _new_registry(cache_folder) -> pint.UnitRegistry:
    from ..data import data_dir

    ureg = pint.UnitRegistry(autoconvert_offset_to_baseunit=True, cache_folder=cache_folder)
    for path in sorted(data_dir("units").glob("*.txt")):
        ureg.load_definitions(str(path))
    return ureg


def _cache_folder():
    import os

    env = os.environ.get("WORKBOOK_CACHE")
    if env is not None:
        return os.path.join(env, "pint-" + pint.__version__) if env.strip() else None
    try:
        import platformdirs

        base = platformdirs.user_cache_path("workbook", appauthor=False)
        return base / f"pint-{pint.__version__}"
    except Exception:  # noqa: BLE001 - no cache folder (no platformdirs, no home): no cache
        return None


def quantity(value, unit: str | None = None, *, what: str = "value") -> pint.Quantity:
    """Parse ``"20 mm"``, a number, or a pint quantity into a Quantity of the shared registry.

    ``unit`` is the unit a plain number is taken in. Text goes through the one quantity
    reader (:func:`workbook.language.quantity.split_quantity`): one number, then a unit.
    """
    ureg = registry()
    if isinstance(value, pint.Quantity):
        return ureg.Quantity(value.magnitude, str(value.units))
    if isinstance(value, bool):
        raise InputError(f"{what}: expected a number with a unit, got {value!r}")
    if isinstance(value, (int, float)):
        return ureg.Quantity(_finite_float(value, what), unit or "")
    if isinstance(value, str):
        number, text = split_quantity(value, what=what)
        if not text:
            return ureg.Quantity(number, unit or "")
        return ureg.Quantity(number, _parsed_unit(text, what, value))
    if not isinstance(value, (list, tuple)) and type(value).__name__ != "ndarray":
        raise InputError(f"{what}: cannot read {value!r} as a quantity")
    try:
        import numpy as np

        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{what}: cannot read {value!r} as a quantity") from None
    return ureg.Quantity(arr, unit or "")


def _finite_float(value, what: str) -> float:
    try:
        return float(value)
    except OverflowError:  # a TOML integer beyond a double
        raise InputError(f"{what}: {value} is too large for a number") from None


def unit(text: str, *, what: str = "unit") -> pint.Unit:
    """Parse a unit string ('' or '1' for dimensionless)."""
    if text is not None and not isinstance(text, str):
        raise InputError(f'{what}: a unit is text like "mm", got {text!r}')
    text = (text or "").strip()
    if text in ("", "1", "-"):
        return registry().dimensionless
    return _parsed_unit(check_unit_text(text, what=what), what, text)


@functools.lru_cache(maxsize=512)
def _unit_of(text: str) -> pint.Unit:
    return registry().Quantity(1, text).units


@functools.cache
def _unit_names() -> tuple[str, ...]:
    return tuple(n for n in dir(registry()) if not n.startswith("_"))


def is_unit_name(name: str) -> bool:
    """True when pint knows ``name`` as a unit (``mm``, ``kN``, ``degC``)."""
    try:
        _unit_of(name)
    except Exception:  # noqa: BLE001 - pint raises many kinds for names it does not know
        return False
    return True


def _parsed_unit(text: str, what: str, shown: str) -> pint.Unit:
    """pint's unit for a text the quantity reader accepted (a clear error for unknown names)."""
    try:
        u = _unit_of(text)
    except pint.UndefinedUnitError as exc:
        names = [str(n) for n in (getattr(exc, "unit_names", ()) or ())]
        bad = ", ".join(repr(n) for n in names) or "a name"
        near = nearest(names[0], _unit_names()) if names else ""
        raise InputError(f"{what}: cannot read {shown!r}: {bad} is not a unit{near}") from None
    except Exception as exc:  # noqa: BLE001 - pint raises many kinds for malformed text
        raise InputError(f"{what}: cannot read {shown!r} as a unit ({exc})") from None
    big = [(n, p) for n, p in u.dimensionality.items() if abs(p) > MAX_UNIT_POWER]
    if big:  # ((kg^12)^12)^12: each power is allowed, the product of them is not
        name, power = big[0]
        raise LimitError(
            f"{what}: {shown!r} is {name} to the power {power:g} (a unit's power is at most "
            f"{MAX_UNIT_POWER} in magnitude)"
        )
    return u


def factor(src: pint.Unit, dst: pint.Unit) -> float:
    """Multiplier that converts a magnitude in ``src`` into ``dst`` (raises on mismatch).

    A conversion from or to an absolute temperature with an offset (degC, degF) is not a
    multiplier: it raises a UnitError (:func:`affine` gives its factor and offset)."""
    if src == dst:
        return 1.0
    if temperature_kind(src) == "absolute" or temperature_kind(dst) == "absolute":
        raise UnitError(
            f"{pretty(src)} to {pretty(dst)} is not a scale factor (an absolute temperature "
            "with an offset)"
        )
    try:
        return float(registry().Quantity(1.0, src).to(dst).magnitude)
    except pint.errors.PintError as err:  # degC inside a compound unit: pint refuses it
        raise UnitError(
            f"{pretty(src)} cannot be converted to {pretty(dst)}: {err}; inside a compound "
            "unit a temperature is a difference (write delta_degC or K)"
        ) from None


def affine(src: pint.Unit, dst: pint.Unit) -> tuple[float, float]:
    """``(factor, offset)`` with ``value in dst = value in src * factor + offset``, pint's
    conversion (offset 0 for a multiplicative one). Between temperature units the two are
    exact where the scales are (degC to degF is 1.8 and 32, not 31.999999999999936)."""
    if temperature_kind(src) and temperature_kind(dst):
        s1, o1 = _kelvin_scale(src)
        s2, o2 = _kelvin_scale(dst)
        return float(s1 / s2), float((o1 - o2) / s2)
    q = registry().Quantity
    zero = float(q(0.0, src).to(dst).magnitude)
    return float(q(1.0, src).to(dst).magnitude) - zero, zero


@functools.lru_cache(maxsize=64)
def _kelvin_scale(u: pint.Unit):
    """``(scale, offset)`` of a temperature unit as fractions: kelvin = value*scale + offset."""
    from fractions import Fraction

    q = registry().Quantity
    zero = float(q(0.0, u).to("kelvin").magnitude)
    scale = float(q(1.0, u).to("kelvin").magnitude) - zero
    out = []
    for x in (scale, zero):
        f = Fraction(x).limit_denominator(10**6)
        out.append(f if abs(float(f) - x) <= 1e-12 * max(abs(x), 1.0) else Fraction(x))
    return tuple(out)


def temperature_kind(u: pint.Unit) -> str | None:
    """What a temperature unit can mean, as pint and Mathcad Prime read it: ``"absolute"``
    (degC, degF: a temperature on a scale with an offset), ``"difference"`` (delta_degC,
    delta_degF), ``"kelvin"`` (K, degR: either); None for any other unit, compound ones
    included (W/(m*degC) is per degree of difference)."""
    items = list(to_units_container(u).items())
    if len(items) != 1 or items[0][1] != 1:
        return None
    name = items[0][0]
    if u.dimensionality != registry().kelvin.dimensionality:
        return None
    if registry().Quantity(0.0, name).to_base_units().magnitude != 0:  # a scale with an offset
        return "absolute"
    return "difference" if name.startswith("delta_") else "kelvin"


def difference_unit(u: pint.Unit) -> pint.Unit:
    """The unit of a difference of two temperatures in ``u``: delta_degC for degC, else ``u``."""
    if temperature_kind(u) != "absolute":
        return u
    (name,) = to_units_container(u)
    return registry().Unit("delta_" + name)


def dims(u: pint.Unit) -> str:
    """Human-readable dimensionality, e.g. '[length]' or 'dimensionless'."""
    d = u.dimensionality
    return "dimensionless" if not d else str(d)


def is_angle(u: pint.Unit) -> bool:
    """True for units that pint treats as angles (radian, degree, turn...)."""
    ureg = registry()
    return u.dimensionless and (
        u == ureg.radian
        or "radian" in str(u)
        or "degree" in str(u)
        or "revolution" in str(u)
        or "turn" in str(u)
    )


def is_compound_ratio(u: pint.Unit) -> bool:
    """True for a dimensionless unit that is a leftover product of units (``kg*mm/m^2/Pa/s^2``),
    which reads better as a plain number; angles and named ratios (percent) are kept."""
    text = str(u)
    return not u.dimensionality and ("/" in text or "*" in text) and not is_angle(u)


@functools.lru_cache(maxsize=512)
def reduced(u: pint.Unit) -> pint.Unit:
    """``u`` with its factors of one dimension combined (``kg*L/m^3`` is ``kg``, ``N*m/mm``
    is ``N``), as pint's ``to_reduced_units``; ``u`` itself when that leaves as many factors,
    when it is dimensionless, or when a factor is an angle (``N*m/rad`` is a torsional
    stiffness) or a temperature with an offset. A percentage (or per mille, ppm) beside other
    factors is a number, as in Mathcad: ``kW/%`` is ``kW`` and ``%^2`` a plain number."""
    ureg = registry()
    names = to_units_container(u)
    scales = [n for n in names if _is_scale(n)]
    if scales and (len(names) > 1 or any(names[n] != 1 for n in scales)):
        for name in scales:
            u = u / ureg.Unit(name) ** names[name]
        names = to_units_container(u)
    if not u.dimensionality or len(names) < 2:
        return u
    for name in names:
        if not ureg.Unit(name).dimensionality or ureg.Quantity(0.0, name).to_base_units().magnitude:
            return u
    out = ureg.Quantity(1.0, u).to_reduced_units().units
    return out if len(to_units_container(out)) < len(names) else u


@functools.lru_cache(maxsize=256)
def _is_scale(name: str) -> bool:
    """A unit that is a pure number times a scale (percent, permille, ppm), not an angle."""
    factor, root = registry().get_root_units(name)
    return root == registry().dimensionless and factor != 1


#: How a worksheet spells a unit where pint's symbol is not what it types: pint's liter is l.
_SPELT = {"liter": "L"}


def pretty(u: pint.Unit) -> str:
    """Compact unit text for headers, in the order the worksheet declared it: 'mm', 'm/s^2',
    'N*m' (not pint's sorted 'm*N'), 'L/s' (pint's symbol is 'l'), 'W/(m*K)'. Each unit by
    pint's symbol ('%' for percent, 'degC'), the liter as a worksheet writes it; a function of
    the unit alone (what was read before does not change it)."""
    if u == registry().dimensionless:
        return ""
    top, bottom = [], []
    for name, power in to_units_container(u).items():
        symbol = _symbol(name)
        p = abs(power)
        text = symbol if p == 1 else f"{symbol}^{p:g}"
        (top if power > 0 else bottom).append(text)
    out = "*".join(top) or "1"
    if bottom:
        out += "/" + (bottom[0] if len(bottom) == 1 else "(" + "*".join(bottom) + ")")
    return out


@functools.lru_cache(maxsize=512)
def _symbol(name: str) -> str:
    return _named(name, _SPELT).replace("°", "deg").replace("Δ", "delta_")


def _named(name: str, symbols: dict[str, str]) -> str:
    """pint's symbol of unit ``name``, or its own in ``symbols`` (prefixed too: mL)."""
    if name in symbols:
        return symbols[name]
    symbol = registry().get_symbol(name)
    for full, shown in symbols.items():
        if name.endswith(full) and symbol.endswith(registry().get_symbol(full)):
            return symbol[: len(symbol) - len(registry().get_symbol(full))] + shown
    return symbol


#: How a unit is typeset for people where pint's symbol is not what a person writes (pint's
#: liter is l, its degree deg); every other unit by pint's symbol (°C, Δ°C, Ω, µm).
_TYPESET_SYMBOLS = {
    "liter": "L",
    "degree": "°",
    "percent": "%",
}
_SUPERSCRIPTS = str.maketrans("0123456789", "⁰¹²³⁴⁵⁶⁷⁸⁹")


def typeset_factors(u: pint.Unit) -> tuple[list[tuple[str, float]], list[tuple[str, float]]]:
    """The factors of ``u`` above and below the fraction bar, each ``(symbol, power)`` with a
    positive power, in the order written (a pure function of the unit)."""
    top: list[tuple[str, float]] = []
    bottom: list[tuple[str, float]] = []
    for name, power in to_units_container(u).items():
        (top if power > 0 else bottom).append((_typeset_symbol(name), abs(float(power))))
    return top, bottom


@functools.lru_cache(maxsize=512)
def _typeset_symbol(name: str) -> str:
    return _named(name, _TYPESET_SYMBOLS)


def shown_factors(text: str) -> tuple[list[tuple[str, float]], list[tuple[str, float]]] | None:
    """:func:`typeset_factors` of a unit text as shown (``W/(m*K)``, ``delta_degC``), or None
    when the text is not a unit (a label). Reading it here never changes how units are
    spelt (:func:`pretty`)."""
    try:
        u = _unit_of(check_unit_text(text.strip()))
    except Exception:  # noqa: BLE001 - a label, or text pint cannot read
        return None
    if u == registry().dimensionless:
        return None
    return typeset_factors(u)


def superscript(power: float) -> str:
    """``²`` for 2, ``""`` for 1; a power that is not an integer as ``^0.5``."""
    if power == 1:
        return ""
    if float(power).is_integer():
        return str(int(power)).translate(_SUPERSCRIPTS)
    return f"^{power:g}"


def typeset(u: pint.Unit) -> str:
    """A unit as a person writes it: ``W/(m²·K)``, ``Δ°C``, ``µm``, ``kN·m``, ``1/s`` ('' for
    dimensionless). The text is read back by the unit reader as the same unit."""
    if u == registry().dimensionless:
        return ""
    top, bottom = typeset_factors(u)

    def part(factors: list[tuple[str, float]]) -> str:
        return "·".join(symbol + superscript(p) for symbol, p in factors)

    out = part(top) or "1"
    if bottom:
        out += "/" + (part(bottom) if len(bottom) == 1 else f"({part(bottom)})")
    return out


def close(a: float, b: float, rel: float = 1e-12) -> bool:
    return math.isclose(a, b, rel_tol=rel, abs_tol=0.0)


def header(title: str, unit, *, typeset_unit: bool = False) -> str:
    """A column header with its unit: ``"h1 [mm]"`` (the title alone when dimensionless);
    ``typeset_unit``: the unit typeset for people (``"h [W/(m²·K)]"``, see :func:`typeset`)."""
    u = typeset(unit) if typeset_unit else pretty(unit)
    return f"{title} [{u}]" if u else title


def is_scaled_angle(unit: pint.Unit) -> bool:
    """An angle unit other than the radian (deg, grad, arcmin...)."""
    if unit.dimensionality:
        return False
    factor, root = registry().get_root_units(unit)
    return factor != 1 and root == registry().radian


@functools.lru_cache(maxsize=256)
def _angle_in(text: str) -> str:
    reg = registry()
    for name in re.findall(r"[A-Za-z_]+", text):
        if is_scaled_angle(reg.Unit(name)):
            return pretty(reg.Unit(name))
    return ""


def angle_in(unit: pint.Unit) -> str:
    """The angle unit other than the radian that ``unit`` has as a factor ('deg' for mm*deg),
    or '' (also when the angles cancel: deg*min/revolution is a time)."""
    reg = registry()
    if "radian" not in str(reg.get_root_units(unit)[1]):
        return ""
    return _angle_in(str(unit))
