"""Mathcad's built-in functions, as data: each maps one to one onto a language built-in.

``name: (language name, argument order)``; the order lists Mathcad's argument positions in
the order the language takes them (None: Mathcad's order, as ``atan2(x, y)``, x first in
both). A Mathcad function whose language name is not (yet) a built-in of the language is
reported as not translated, never dropped.
"""

from __future__ import annotations

MATHCAD_FUNCTIONS: dict[str, tuple[str, tuple[int, ...] | None]] = {
    "sin": ("sin", None), "cos": ("cos", None), "tan": ("tan", None),
    "asin": ("asin", None), "acos": ("acos", None), "atan": ("atan", None),
    "atan2": ("atan2", None), "angle": ("atan2", None),
    "sinh": ("sinh", None), "cosh": ("cosh", None), "tanh": ("tanh", None),
    "exp": ("exp", None), "ln": ("ln", None), "log": ("log10", None),
    "sqrt": ("sqrt", None), "abs": ("abs", None), "sign": ("sign", None),
    "floor": ("floor", None), "ceil": ("ceil", None), "min": ("min", None),
    "max": ("max", None), "mod": ("mod", None), "round": ("round", None),
    "trunc": ("trunc", None),
    "sec": ("sec", None), "csc": ("csc", None), "cot": ("cot", None),
    # numerical methods and arrays (built-ins of the language once they exist)
    "root": ("root", None), "linterp": ("linterp", None), "interp": ("interp", None),
    "lspline": ("lspline", None), "pspline": ("pspline", None), "cspline": ("cspline", None),
    "Find": ("find", None), "Maximize": ("maximize", None), "Minimize": ("minimize", None),
    "length": ("length", None), "rows": ("rows", None), "cols": ("cols", None),
    "last": ("last", None), "transpose": ("transpose", None), "det": ("det", None),
    "stack": ("stack", None), "augment": ("augment", None), "submatrix": ("submatrix", None),
    "identity": ("identity", None), "mean": ("mean", None), "stdev": ("stdev", None),
    "var": ("var", None), "median": ("median", None),
    "norme": ("norm", None), "cross": ("cross", None), "lsolve": ("lsolve", None),
    "csort": ("csort", None), "rsort": ("rsort", None), "sort": ("sort", None),
    "reverse": ("reverse", None),
    "rank": ("rank", None), "polyroots": ("polyroots", None),
    "lu": ("lu", None), "rref": ("rref", None), "geninv": ("geninv", None),
    "Var": ("Var", None), "Stdev": ("Stdev", None), "corr": ("corr", None),
    "cvar": ("cvar", None), "slope": ("fit_slope", None), "intercept": ("fit_intercept", None),
    "skew": ("skew", None), "kurt": ("kurt", None), "gmean": ("gmean", None),
    "hmean": ("hmean", None), "Rank": ("Rank", None),
    "norm1": ("norm1", None), "norm2": ("norm2", None), "normi": ("normi", None),
    "cond1": ("cond1", None), "cond2": ("cond2", None), "conde": ("conde", None),
    "condi": ("condi", None), "tr": ("tr", None), "diag": ("diag", None),
    "svds": ("svds", None),
    "histogram": ("histogram", None), "concat": ("concat", None), "num2str": ("num2str", None),
    # probability distributions (workbook.functions.distributions)
    "dnorm": ("dnorm", None), "pnorm": ("pnorm", None), "qnorm": ("qnorm", None),
    "dt": ("dt", None), "pt": ("pt", None), "qt": ("qt", None),
    "dchisq": ("dchisq", None), "pchisq": ("pchisq", None), "qchisq": ("qchisq", None),
    "pF": ("pF", None), "qF": ("qF", None),
    "dexp": ("dexp", None), "pexp": ("pexp", None), "qexp": ("qexp", None),
    "dunif": ("dunif", None), "punif": ("punif", None), "qunif": ("qunif", None),
    # special functions (workbook.functions.special) and decompositions; Γ(a, x), the
    # incomplete gamma function, is not translated (one argument only)
    "Γ": ("gamma", (0,)), "erf": ("erf", None), "erfc": ("erfc", None),
    "Jn": ("bessel_j", None), "Yn": ("bessel_y", None), "In": ("bessel_i", None),
    "Kn": ("bessel_k", None), "combin": ("combin", None), "permut": ("permut", None),
    "cholesky": ("cholesky", None),
    # complex numbers (docs/language.md, Complex numbers)
    "Re": ("Re", None), "Im": ("Im", None), "arg": ("arg", None),
}  # fmt: skip

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

#: Mathcad operators written as elements (``<ml:sqrt/>``) and their built-in.
OPERATOR_FUNCTIONS: dict[str, str] = {
    "sqrt": "sqrt", "absval": "abs", "transpose": "transpose",
    "determinant": "det",  # |M| written as the determinant operator
    "polyroots": "polyroots",  # the keyword form (its method: the roots are the same)
    "factorial": "factorial",  # n!
}  # fmt: skip

#: Mathcad operators of two operands written as elements, and their built-in
OPERATOR_FUNCTIONS_2: dict[str, str] = {"crossProduct": "cross"}


def language_functions() -> set[str]:
    """The built-in function names of the language (its registry)."""
    from ..functions.registry import REGISTRY

    return set(REGISTRY)
