"""Mathcad's unit names, as data: the names written in formulas, and the names in results.

In a formula a unit is a predefined variable (``m``, ``kN``, ``MPa``); a worksheet may
redefine the name (``l := 12 m`` hides the litre). A stored result names its units in full
(``<unitReference unit="kilonewton" power-numerator="-2"/>``). Both map to pint unit text.
"""

from __future__ import annotations

#: Unit names in Mathcad 11-15 formulas -> pint.
FORMULA_UNITS: dict[str, str] = {
    # length
    "m": "meter", "cm": "centimeter", "mm": "millimeter", "km": "kilometer",
    "μm": "micrometer", "nm": "nanometer", "in": "inch", "ft": "foot", "yd": "yard",
    "mi": "mile",
    # mass
    # Mathcad's gram is gm; its g is the acceleration of gravity (Prime's constant g too)
    "kg": "kilogram", "gm": "gram", "mg": "milligram", "tonne": "tonne", "ton": "ton",
    "lb": "pound", "oz": "ounce",
    # time
    "s": "second", "ms": "millisecond", "min": "minute", "hr": "hour", "day": "day",
    "yr": "year", "wk": "week",
    # force
    "N": "newton", "kN": "kilonewton", "MN": "meganewton", "dyne": "dyne", "kgf": "kilogram_force",
    "N·m": "newton * meter", "kN·m": "kilonewton * meter",  # moments, one name in Mathcad
    "lbf": "pound_force", "kip": "kip", "tonf": "ton_force",
    # pressure, stress
    "Pa": "pascal", "kPa": "kilopascal", "MPa": "megapascal", "GPa": "gigapascal",
    "bar": "bar", "atm": "atmosphere", "psi": "psi", "ksi": "ksi", "mmHg": "mmHg",
    "torr": "torr",
    # energy, power
    "J": "joule", "kJ": "kilojoule", "MJ": "megajoule", "W": "watt", "kW": "kilowatt",
    "MW": "megawatt", "cal": "calorie", "kcal": "kilocalorie", "hp": "horsepower",
    "BTU": "BTU", "kWh": "kilowatt_hour",
    # angle
    "deg": "degree", "rad": "radian", "rev": "revolution",
    # volume
    "L": "liter", "l": "liter", "mL": "milliliter", "ml": "milliliter", "gal": "gallon",
    # electric
    "A": "ampere", "mA": "milliampere", "kA": "kiloampere", "V": "volt", "mV": "millivolt",
    "kV": "kilovolt", "Ω": "ohm", "ohm": "ohm", "kΩ": "kiloohm", "C": "coulomb",
    "F": "farad", "μF": "microfarad", "pC": "picocoulomb", "nC": "nanocoulomb",
    "μC": "microcoulomb", "H": "henry", "Wb": "weber", "T": "tesla",
    "S": "siemens",
    # frequency, speed
    "Hz": "hertz", "kHz": "kilohertz", "MHz": "megahertz", "rpm": "revolutions_per_minute",
    "mph": "mile_per_hour", "kph": "kilometer_per_hour", "knot": "knot",
    "g": "standard_gravity",
    # temperature (differences) and amount
    "K": "kelvin", "R": "degree_Rankine", "mol": "mole", "mole": "mole", "cd": "candela",
    # area
    "ha": "hectare", "acre": "acre",
    # ratios and signs
    "%": "percent", "°": "degree", "′": "arcminute", "″": "arcsecond",
}  # fmt: skip

#: Unit names in stored results (``unitReference unit="..."``) that pint reads otherwise.
RESULT_UNITS: dict[str, str] = {
    "liter": "liter",
    "degree": "degree",
    "revolution": "revolution",
    "hour": "hour",
    "minute": "minute",
    "tonne": "tonne",
    "ohm": "ohm",
    "kelvin": "kelvin",
}


def result_unit(name: str) -> str:
    """pint text of a unit named in a stored result (full names pint mostly knows; a
    compound name such as ``kiloNewton_meter`` is read as the product of its parts)."""
    if name in RESULT_UNITS:
        return RESULT_UNITS[name]
    if "_" in name or name != name.lower():
        parts = [p.lower() for p in name.split("_") if p]
        # full names only: lowering a symbol would change it (Ms, megasecond, is not ms)
        if parts and all(p.isalpha() and len(p) >= 4 for p in parts):
            return " * ".join(parts)
    return name


#: Units whose size in Mathcad Prime is not pint's, as measured from a stored result: a value
#: Prime stored in one of them is listed as not computable with the reason, never compared
#: (kitchen-materials.mcdx stores pi/4 (9.5 in)^2 (3.25 in) as 0.9972601194974439 gal, a
#: gallon of 3.785411968 L, where the US gallon of 231 in^3 is 3.785411784 L)
PRIME_UNITS_OFF: dict[str, str] = {
    "gallon": "Prime's gallon (3.785411968 L, measured from a stored volume) is not pint's "
    "US gallon of 231 in^3 (3.785411784 L)",
}
