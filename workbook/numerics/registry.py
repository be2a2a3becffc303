"""The complete registry of built-in functions: the plain ones of
:mod:`workbook.functions.builtins`, the distributions of :mod:`workbook.functions.distributions`,
the numerical ones of :mod:`workbook.numerics.entries`, the complex ones of
:mod:`workbook.functions.complexes`, the texts of :mod:`workbook.functions.texts`, the vector and
matrix ones of :mod:`workbook.functions.matrix_entries`, the special functions of
:mod:`workbook.functions.special` and the decompositions of
:mod:`workbook.functions.decompositions`. Every back end reads built-ins from here; the built-in
constants (pi, e, g) are :data:`workbook.functions.constants.CONSTANTS`, and :data:`BUILTINS`
holds both."""

from __future__ import annotations

from ..functions import builtins as _plain  # noqa: F401 - registers the plain built-ins on import
from ..functions import complexes as _complexes  # noqa: F401 - Re, Im, arg, conj, polar
from ..functions import decompositions as _decompositions  # noqa: F401 - cholesky, qr, svd
from ..functions import distributions as _distributions  # noqa: F401 - pnorm, qt, pchisq, ...
from ..functions import matrix_entries as _matrix  # noqa: F401 - min, max, mean, the vector and matrix built-ins
from ..functions import sample_entries as _samples  # noqa: F401 - corr, Var, Stdev, Rank, ...
from ..functions import special as _special  # noqa: F401 - gamma, erf, Bessel functions, factorial
from ..functions import texts as _texts  # noqa: F401 - concat, num2str
from ..functions.constants import CONSTANTS
from ..functions.entry import ENTRIES, Builtins
from . import entries as _numerical  # noqa: F401 - root, integral, ..., diff register

#: Every built-in function by name.
REGISTRY = ENTRIES

#: Both, as the typer is given them (the typer, in workbook.language, imports no registry).
BUILTINS = Builtins(REGISTRY, CONSTANTS, home=f"{__name__}:BUILTINS")
