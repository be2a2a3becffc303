"""Mathcad's built-in functions and operators, read from the language's registry: an entry
names the Mathcad functions it is (``mathcad``), the operator element Mathcad writes it as
(``mathcad_operator``) and Mathcad's argument order (``mathcad_order``). Here is only what is
Mathcad's own: its solve-block functions, fixed-order Bessel functions, the functions refused
and why, the writers, the functions that count from ORIGIN.

A Mathcad function that is no built-in of the language is reported as not translated, never
dropped.
"""

from __future__ import annotations

from ..numerics.registry import REGISTRY

#: ``name: (language name, argument order)``; the order lists Mathcad's argument positions in
#: the order the language takes them (None: Mathcad's order, as ``atan2(x, y)``, x first in
#: both). Find, Maximize and Minimize end a solve block (workbook.mathcad.solving): no
#: built-ins of the language.
MATHCAD_FUNCTIONS: dict[str, tuple[str, tuple[int, ...] | None]] = {
    name: (entry.name, entry.mathcad_order) for entry in REGISTRY.values() for name in entry.mathcad
} | {"Find": ("find", None), "Maximize": ("maximize", None), "Minimize": ("minimize", None)}

#: Mathcad's operators written as elements (``<ml:sqrt/>``, ``<ml:absval/>``) and their
#: built-in: of one operand, of two, and those that bind a variable (summation, integral)
_OPERATORS = [e for e in REGISTRY.values() if e.mathcad_operator]
BINDERS: dict[str, str] = {e.mathcad_operator: e.name for e in _OPERATORS if e.binds}
OPERATOR_FUNCTIONS: dict[str, str] = {
    e.mathcad_operator: e.name for e in _OPERATORS if not e.binds and e.arity == 1
}
OPERATOR_FUNCTIONS_2: dict[str, str] = {
    e.mathcad_operator: e.name for e in _OPERATORS if not e.binds and e.arity == 2
}

#: Mathcad's Bessel functions of a fixed order: ``J0(x)`` is ``bessel_j(0, x)``.
FIXED_ORDER: dict[str, tuple[str, int]] = {
    f"{letter}{order}": (f"bessel_{letter.lower()}", order)
    for letter in "JYIK" for order in (0, 1)
}  # fmt: skip

#: Mathcad functions that are never translated, and why (a worksheet reads and writes no
#: files but the data tables it declares)
REFUSED: dict[str, str] = {
    name: "writes a file (a worksheet of the language writes no files)"
    for name in ("WRITEPRN", "APPENDPRN", "WRITE", "APPEND", "WRITEBMP", "WRITERGB",
                 "WRITEWAV", "WRITECSV", "WRITEEXCEL", "WRITEFILE", "WRITEBIN")
} | {
    name: "reads a file (a worksheet reads measured data from a [data] table: see the language)"
    for name in ("READPRN", "READ", "READFILE", "READEXCEL", "READCSV", "READBMP", "READRGB",
                 "READWAV", "READBIN")
} | {
    # an eigenvector's sign is its solver's: Prime stores [-0.805; 0.575; -0.143] (the
    # largest component negative) and [-0.272; -0.145; 0.951] in one worksheet, no rule
    name: "gives eigenvectors whose sign is that of Mathcad's solver, which the language "
    "cannot reproduce (the language's eigenvec has the largest component positive)"
    for name in ("eigenvec", "eigenvecs")
} | {
    # Mathcad's generator is its own, seeded by the worksheet's seed setting: no generator
    # of the language gives its numbers, so a stored random value is never compared
    name: "gives random numbers of Mathcad's own generator (seeded by the worksheet's seed "
    "setting); a stored random value is not reproducible"
    for name in ("rnd", "runif", "rnorm", "rbeta", "rbinom", "rcauchy", "rchisq", "rexp",
                 "rF", "rgamma", "rgeom", "rhypergeom", "rlnorm", "rlogis", "rnbinom",
                 "rpois", "rt", "rweibull", "rsample")
} | {
    # the language's qr and svd fix the signs their own way (R's diagonal >= 0, U's columns
    # largest component positive); Mathcad's are its solver's, and no stored result shows them
    name: "gives a decomposition whose signs are those of Mathcad's solver, which no stored "
    f"result shows (the language's {name} fixes them its own way)"
    for name in ("qr", "svd")
} | {
    "regress": "gives a vector whose first elements are Mathcad's own bookkeeping for interp "
    "(the language fits a line with fit_slope and fit_intercept)",
    "loess": "gives a vector of Mathcad's own local fits for interp, not a formula",
    "genfit": "fits by Mathcad's own nonlinear solver from a guess, with a vector of functions "
    "the language has no value for",
}  # fmt: skip

#: Mathcad functions that write a value to a file (``WRITEPRN("f", M)``, or
#: ``WRITEPRN("f") := M`` in older worksheets): the value written is translated, as Mathcad
#: shows it, but no file is written.
WRITERS: frozenset[str] = frozenset({"WRITEPRN", "APPENDPRN", "WRITECSV", "WRITE", "APPEND"})

#: Mathcad functions whose indices count from ORIGIN (the language's count from the sheet's
#: origin): where the worksheet sets another ORIGIN than the one at its first index, a call
#: is refused rather than read off by one
ORIGIN_FUNCTIONS: frozenset[str] = frozenset(
    {"submatrix", "last", "csort", "rsort", "lookup", "hlookup", "vlookup", "match"}
)


def language_functions() -> set[str]:
    """The built-in function names of the language (its registry)."""
    return set(REGISTRY)
