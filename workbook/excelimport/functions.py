"""Excel's worksheet functions and VBA's own functions: what each becomes in the language. A
built-in's registry entry names the Excel and VBA functions it is (``excel_import``, ``vba``);
here are the forms that are no one built-in (``PI``, ``POWER``, ``MOD``, VBA's ``CBool``). An
entry is a text with ``{0}``, ``{1}``, ... for the arguments (already translated) and the
numbers of arguments it takes; a function not listed is not translated (the cell or the VBA
function that calls it is listed, never dropped)."""

from __future__ import annotations

from ..numerics.registry import REGISTRY


def _call(name: str, arity: int | tuple[int, int]) -> tuple[str, tuple[int, ...]]:
    """``name({0}, {1}, ...)`` of the most arguments the built-in takes, the only number taken
    (Excel's ROUND has both of round's; a call with other numbers is listed)."""
    n = arity if isinstance(arity, int) else arity[1]
    return f"{name}({', '.join(f'{{{i}}}' for i in range(n))})", (n,)


_FIXED = [e for e in REGISTRY.values() if e.arity is not None]

#: Excel worksheet functions (also called from VBA as WorksheetFunction.NAME / Application.NAME)
EXCEL: dict[str, tuple[str, tuple[int, ...]]] = {
    excel: _call(e.name, e.arity) for e in _FIXED for excel in e.excel_import
} | {
    "PI": ("pi", (0,)),
    "NA": ("1/0", (0,)),  # #N/A: an error value, no number
    "TRUE": ("1", (0,)),  # TRUE() and FALSE(), as LibreOffice writes the constants
    "FALSE": ("0", (0,)),
    "POWER": ("({0})^({1})", (2,)),
    "RADIANS": ("({0})*pi/180", (1,)),
    "DEGREES": ("({0})*180/pi", (1,)),
    # the sign of the divisor, as Excel; a remainder that rounds to the divisor itself
    # (MOD(-2.5E-16, 2*PI())) Excel gives as 0, a rule not known here for certain: no value
    "MOD": (
        "(1/0 if ({0}) - ({1})*floor(({0})/({1})) == ({1}) "
        "otherwise ({0}) - ({1})*floor(({0})/({1})))",
        (2,),
    ),
}

#: Excel functions that take any number of arguments, each a number or a range: joined
EXCEL_VARIADIC: dict[str, str] = {
    excel: e.name for e in REGISTRY.values() if e.arity is None for excel in e.excel_import
} | {"SUM": "+"}

#: Excel functions whose value changes at every recalculation: listed, never translated
VOLATILE = {"RAND", "RANDBETWEEN", "NOW", "TODAY", "OFFSET", "INDIRECT", "CELL", "INFO"}

#: VBA's own functions of numbers
VBA: dict[str, tuple[str, tuple[int, ...]]] = {
    vba: _call(e.name, e.arity) for e in _FIXED for vba in e.vba
} | {
    "cbool": ("(-1 if {0} != 0 otherwise 0)", (1,)),  # True is -1
    "cdbl": ("{0}", (1,)),
    "csng": ("{0}", (1,)),
    "cdec": ("{0}", (1,)),
}
