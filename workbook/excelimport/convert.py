"""Excel's ``CONVERT(x, from, to)`` where both units are texts written in the formula: a factor
(an offset too for temperatures), from Excel's table of units.

Only units whose factor is fixed by definition are here (the inch is 0.0254 m, the pound
0.45359237 kg, the standard gravity 9.80665 m/s^2, the atmosphere 101325 Pa, the IT calorie
and BTU), so that the factor is Excel's to the last digits; a unit not listed (``mmHg``,
``Torr``, ``bar``, astronomical ones, bits) or written otherwise is refused, and the cell is
listed. Units are matched with case, as Excel does; the metric prefixes (``k``, ``m``, ``u``,
``da``...) apply to the metric units only (``km``, ``kPa``, ``mL``), squared and cubed in
``cm2`` and ``mm3``. Units of two different quantities are Excel's ``#N/A``: refused too.
"""

from __future__ import annotations

from .formula_terms import FormulaProblem

_LBF = 0.45359237 * 9.80665  # N
_FT = 0.3048

#: unit: (quantity, factor to the quantity's base unit, may take a metric prefix)
_UNITS: dict[str, tuple[str, float, bool]] = {
    # length (m)
    "m": ("length", 1.0, True),
    "mi": ("length", 1609.344, False),
    "Nmi": ("length", 1852.0, False),
    "in": ("length", 0.0254, False),
    "ft": ("length", _FT, False),
    "yd": ("length", 0.9144, False),
    "ang": ("length", 1e-10, False),
    # mass (g, as Excel's base)
    "g": ("mass", 1.0, True),
    "lbm": ("mass", 453.59237, False),
    "ozm": ("mass", 453.59237 / 16, False),
    "stone": ("mass", 453.59237 * 14, False),
    "ton": ("mass", 453.59237 * 2000, False),
    "grain": ("mass", 0.06479891, False),
    # time (s)
    "sec": ("time", 1.0, True),
    "s": ("time", 1.0, True),
    "mn": ("time", 60.0, False),
    "min": ("time", 60.0, False),
    "hr": ("time", 3600.0, False),
    "day": ("time", 86400.0, False),
    "d": ("time", 86400.0, False),
    "yr": ("time", 86400.0 * 365.25, False),
    # pressure (Pa)
    "Pa": ("pressure", 1.0, True),
    "p": ("pressure", 1.0, False),
    "atm": ("pressure", 101325.0, False),
    "at": ("pressure", 101325.0, False),
    "psi": ("pressure", _LBF / 0.0254**2, False),
    # force (N)
    "N": ("force", 1.0, True),
    "dyn": ("force", 1e-5, False),
    "dy": ("force", 1e-5, False),
    "lbf": ("force", _LBF, False),
    "pond": ("force", 9.80665e-3, False),
    # energy (J)
    "J": ("energy", 1.0, True),
    "e": ("energy", 1e-7, False),
    "c": ("energy", 4.184, False),
    "cal": ("energy", 4.1868, True),
    "Wh": ("energy", 3600.0, True),
    "wh": ("energy", 3600.0, False),
    "flb": ("energy", _LBF * _FT, False),
    "BTU": ("energy", 1055.05585262, False),
    "btu": ("energy", 1055.05585262, False),
    "HPh": ("energy", 550 * _LBF * _FT * 3600, False),
    "hh": ("energy", 550 * _LBF * _FT * 3600, False),
    # power (W)
    "W": ("power", 1.0, True),
    "w": ("power", 1.0, False),
    "HP": ("power", 550 * _LBF * _FT, False),
    "h": ("power", 550 * _LBF * _FT, False),
    "PS": ("power", 75 * 9.80665, False),
    # volume (m3)
    "l": ("volume", 1e-3, True),
    "L": ("volume", 1e-3, True),
    "lt": ("volume", 1e-3, True),
    "gal": ("volume", 231 * 0.0254**3, False),
    "qt": ("volume", 231 * 0.0254**3 / 4, False),
    "pt": ("volume", 231 * 0.0254**3 / 8, False),
    "us_pt": ("volume", 231 * 0.0254**3 / 8, False),
    "uk_gal": ("volume", 4.54609e-3, False),
    "ft3": ("volume", _FT**3, False),
    "ft^3": ("volume", _FT**3, False),
    "in3": ("volume", 0.0254**3, False),
    "in^3": ("volume", 0.0254**3, False),
    "yd3": ("volume", 0.9144**3, False),
    # area (m2)
    "ft2": ("area", _FT**2, False),
    "ft^2": ("area", _FT**2, False),
    "in2": ("area", 0.0254**2, False),
    "in^2": ("area", 0.0254**2, False),
    "yd2": ("area", 0.9144**2, False),
    "ha": ("area", 1e4, False),
    # speed (m/s)
    "m/s": ("speed", 1.0, False),
    "m/sec": ("speed", 1.0, False),
    "m/h": ("speed", 1 / 3600, False),
    "m/hr": ("speed", 1 / 3600, False),
    "mph": ("speed", 1609.344 / 3600, False),
}

_POWERS = {"m2": ("area", 2), "m^2": ("area", 2), "m3": ("volume", 3), "m^3": ("volume", 3)}

_PREFIXES = {
    "Y": 1e24, "Z": 1e21, "E": 1e18, "P": 1e15, "T": 1e12, "G": 1e9, "M": 1e6, "k": 1e3,
    "h": 1e2, "da": 1e1, "d": 1e-1, "c": 1e-2, "m": 1e-3, "u": 1e-6, "n": 1e-9,
    "p": 1e-12, "f": 1e-15, "a": 1e-18, "z": 1e-21, "y": 1e-24,
}  # fmt: skip

#: temperatures: unit -> its scale: C, F, K or Rank
_TEMPERATURES = {"C": "C", "cel": "C", "F": "F", "fah": "F", "K": "K", "kel": "K", "Rank": "R"}

#: (from, to) -> the expression of x in the other scale (C and F directly, as written by hand)
_TEMPERATURE_FORMS = {
    ("C", "F"): "({x})*9/5 + 32",
    ("F", "C"): "(({x}) - 32)*5/9",
    ("C", "K"): "({x}) + 273.15",
    ("K", "C"): "({x}) - 273.15",
    ("F", "K"): "(({x}) - 32)*5/9 + 273.15",
    ("K", "F"): "(({x}) - 273.15)*9/5 + 32",
    ("R", "K"): "({x})*5/9",
    ("K", "R"): "({x})*9/5",
    ("F", "R"): "({x}) + 459.67",
    ("R", "F"): "({x}) - 459.67",
}


def unit(text: str) -> tuple[str, float]:
    """(quantity, factor to its base unit) of an Excel unit text."""
    if text in _UNITS:
        kind, factor, _ = _UNITS[text]
        return kind, factor
    if text in _POWERS:
        return _POWERS[text][0], 1.0
    for p in sorted(_PREFIXES, key=len, reverse=True):
        if not text.startswith(p) or len(text) == len(p):
            continue
        rest = text[len(p) :]
        if rest in _POWERS:
            kind, n = _POWERS[rest]
            return kind, _PREFIXES[p] ** n
        if rest in _UNITS and _UNITS[rest][2]:
            kind, factor, _ = _UNITS[rest]
            return kind, _PREFIXES[p] * factor
    raise FormulaProblem(f"CONVERT of the unit {text!r} (not in this translation's table)")


def convert(x: str, source: str, target: str) -> str:
    """The expression of ``CONVERT(x, source, target)``, x already translated."""
    if source in _TEMPERATURES or target in _TEMPERATURES:
        if source not in _TEMPERATURES or target not in _TEMPERATURES:
            raise FormulaProblem(f"CONVERT from {source!r} to {target!r} (#N/A in Excel)")
        a, b = _TEMPERATURES[source], _TEMPERATURES[target]
        if a == b:
            return f"({x})"
        if (a, b) not in _TEMPERATURE_FORMS:
            raise FormulaProblem(f"CONVERT from {source!r} to {target!r} (not translated)")
        return "(" + _TEMPERATURE_FORMS[(a, b)].format(x=x) + ")"
    kind, f1 = unit(source)
    kind2, f2 = unit(target)
    if kind != kind2:
        raise FormulaProblem(f"CONVERT from {source!r} to {target!r} (#N/A in Excel)")
    factor = f1 / f2
    return f"({x})" if factor == 1 else f"(({x})*{factor!r})"
