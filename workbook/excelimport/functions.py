"""Excel's worksheet functions and VBA's own functions, as data: what each becomes in the
language. An entry is a text with ``{0}``, ``{1}``, ... for the arguments (already
translated) and the number of arguments it takes; a function not listed is not translated
(the cell or the VBA function that calls it is listed, never dropped)."""

from __future__ import annotations

#: Excel worksheet functions (also called from VBA as WorksheetFunction.NAME / Application.NAME)
EXCEL: dict[str, tuple[str, tuple[int, ...]]] = {
    "ABS": ("abs({0})", (1,)),
    "SQRT": ("sqrt({0})", (1,)),
    "EXP": ("exp({0})", (1,)),
    "LN": ("ln({0})", (1,)),
    "LOG10": ("log10({0})", (1,)),
    "LOG": ("log10({0})", (1,)),
    "SIN": ("sin({0})", (1,)),
    "COS": ("cos({0})", (1,)),
    "TAN": ("tan({0})", (1,)),
    "ASIN": ("asin({0})", (1,)),
    "ACOS": ("acos({0})", (1,)),
    "ATAN": ("atan({0})", (1,)),
    "ATAN2": ("atan2({0}, {1})", (2,)),  # x first in both
    "SINH": ("sinh({0})", (1,)),
    "COSH": ("cosh({0})", (1,)),
    "TANH": ("tanh({0})", (1,)),
    "SIGN": ("sign({0})", (1,)),
    "PI": ("pi", (0,)),
    "NA": ("1/0", (0,)),  # #N/A: an error value, no number
    "TRUE": ("1", (0,)),  # TRUE() and FALSE(), as LibreOffice writes the constants
    "FALSE": ("0", (0,)),
    "POWER": ("({0})^({1})", (2,)),
    "RADIANS": ("({0})*pi/180", (1,)),
    "DEGREES": ("({0})*180/pi", (1,)),
    "INT": ("floor({0})", (1,)),
    "TRUNC": ("trunc({0})", (1,)),
    "ROUND": ("round({0}, {1})", (2,)),
    # the sign of the divisor, as Excel; a remainder that rounds to the divisor itself
    # (MOD(-2.5E-16, 2*PI())) Excel gives as 0, a rule not known here for certain: no value
    "MOD": (
        "(1/0 if ({0}) - ({1})*floor(({0})/({1})) == ({1}) "
        "otherwise ({0}) - ({1})*floor(({0})/({1})))",
        (2,),
    ),
}

#: Excel functions that take any number of arguments, each a number or a range: joined
EXCEL_VARIADIC: dict[str, str] = {"MAX": "max", "MIN": "min", "SUM": "+", "AVERAGE": "mean"}

#: Excel functions whose value changes at every recalculation: listed, never translated
VOLATILE = {"RAND", "RANDBETWEEN", "NOW", "TODAY", "OFFSET", "INDIRECT", "CELL", "INFO"}

#: VBA's own functions of numbers
VBA: dict[str, tuple[str, tuple[int, ...]]] = {
    "sqr": ("sqrt({0})", (1,)),
    "abs": ("abs({0})", (1,)),
    "exp": ("exp({0})", (1,)),
    "log": ("ln({0})", (1,)),  # VBA's Log is the natural logarithm
    "sin": ("sin({0})", (1,)),
    "cos": ("cos({0})", (1,)),
    "tan": ("tan({0})", (1,)),
    "atn": ("atan({0})", (1,)),
    "sgn": ("sign({0})", (1,)),
    "int": ("floor({0})", (1,)),
    "fix": ("trunc({0})", (1,)),
    "cbool": ("(-1 if {0} != 0 otherwise 0)", (1,)),  # True is -1
    "cdbl": ("{0}", (1,)),
    "csng": ("{0}", (1,)),
    "cdec": ("{0}", (1,)),
}
