"""The registry entries of the vector and matrix built-ins: for each, its unit and shape rule,
numpy hook, Excel form, SymPy form and documentation. What they compute is
:mod:`workbook.functions.matrix` (and :mod:`workbook.functions.factorizations`,
:mod:`workbook.functions.norms`,
:mod:`workbook.functions.samples`); :mod:`workbook.numerics.registry` imports this module, which
registers them."""

from __future__ import annotations

import numpy as np

from ..errors import NotLive, NotSymbolic, ShapeError, TemplateError, UnitError
from ..language import typed as ty
from ..language.expr import PREC
from ..language.typed import shape_text
from ..language.units import pretty
from . import factorizations, norms
from .entry import Builtin, register
from .excel_functions import stored
from .matrix import (
    MAX_EXCEL_IDENTITY,
    MAX_IDENTITY,
    SINGULAR_COND,
    augment,
    cross,
    csort,
    det,
    dot,
    eigenparts,
    eigenvals,
    eigenvec,
    eigenvecs,
    histogram,
    inverse,
    lsolve,
    norm,
    numpy_reverse,
    numpy_sort,
    numpy_statistic,
    numpy_submatrix,
    polyrootparts,
    polyroots,
    rank,
    reduce,
    rsort,
    size,
    stack,
    transpose,
)


def _numbers_as_1x1(values, shapes):
    """stack and augment take a number as a 1x1 matrix (as Mathcad's)."""
    return [np.reshape(v, (1, 1)) if s is None else v for v, s in zip(values, shapes)]


def _excel_list(function: str):
    from ..language.expr import PREC

    def printed(args, shapes=None):
        return f"{function}({', '.join(args)})", PREC["atom"]

    return printed


atom = PREC["atom"]


def need(args, k: int, name: str, what: str = "a vector or matrix"):
    a = args[k]
    if a.shape is None:
        raise ShapeError(f"{name}(): argument {k + 1} must be {what}, got a number")
    return a.shape


def vector(args, k: int, name: str) -> int:
    s = need(args, k, name, "a vector")
    if s[1] != 1:
        raise TemplateError(f"{name}(): argument {k + 1} must be a vector, got a {shape_text(s)}")
    return s[0]


def square(args, name: str) -> int:
    s = need(args, 0, name, "a square matrix")
    if s[0] != s[1]:
        raise TemplateError(f"{name}() needs a square matrix, got a {shape_text(s)}")
    return s[0]


def not_symbolic(name):
    def hook(sp, *a):
        raise NotSymbolic(f"{name}() of a matrix is not differentiated symbolically")

    return hook


def call(function: str, template: str = "{}"):
    def printed(args, shapes=None):
        return f"{function}({template.format(*args)})", atom

    return printed


def not_live(why: str):
    def printed(args, shapes=None):
        raise NotLive(why)

    return printed


def entry(name, arity, rule, numpy, excel, doc, runtime=None, sizes=False, complex="", **fields):
    """A built-in of vectors and matrices (``fields``: the entry's other fields, by name)."""
    register(
        Builtin(
            name,
            arity,
            rule,
            numpy,
            excel,
            not_symbolic(name),
            doc=doc,
            arrays=True,
            runtime=runtime,
            sizes=sizes,
            complex=complex,
            **fields,
        )
    )


# the unit rules when an argument is a run-time array (workbook.engine.runtime): units are
# checked here, shapes when the program runs
def origin_arg(ctx):
    return ty.TConst(ctx.dimensionless, value=float(ctx.spec.origin))


def rt_same_unit(ctx, name, args):
    unit = args[0].unit
    conv = [ctx.convert(a, unit, f"{name}(): argument {k + 1}") for k, a in enumerate(args)]
    return func(unit, name, conv, ty.RUNTIME)


def rt_with_origin(result_unit):
    def rule(ctx, name, args):
        rest = [ctx.plain(a, f"{name}(): argument {k}") for k, a in enumerate(args[1:], 2)]
        shape = None if result_unit == "plain" else ty.RUNTIME
        unit = ctx.dimensionless if result_unit == "plain" else args[0].unit
        return func(unit, name, [args[0], *rest, origin_arg(ctx)], shape)

    return rule


def func(unit, name, args, shape):
    return ty.TFunc(unit, func=name, args=tuple(args), shape=shape)


# transpose, det, inverse, lsolve
def r_transpose(ctx, name, args):
    r, c = need(args, 0, name)
    return func(args[0].unit, name, args, (c, r))


def rt_transpose(ctx, name, args):
    return func(args[0].unit, name, args, ty.RUNTIME)


def r_det(ctx, name, args):
    n = square(args, name)
    return func(args[0].unit ** n, name, args, None)


def r_inverse(ctx, name, args):
    n = square(args, name)
    return func(1 / args[0].unit, name, args, (n, n))


def r_lsolve(ctx, name, args):
    n = square(args, name)
    m = vector(args, 1, name)
    if m != n:
        raise TemplateError(f"lsolve(M, v): M is {n}x{n} but v has {m} elements")
    return func(args[1].unit / args[0].unit, name, args, (n, 1))


entry(
    "transpose",
    1,
    r_transpose,
    lambda m, shapes: transpose(m),
    call("TRANSPOSE"),
    "rows and columns swapped",
    runtime=rt_transpose,
    complex="complex",
    mathcad=("transpose",),
    mathcad_operator="transpose",
)
entry(
    "det",
    1,
    r_det,
    lambda m, shapes: det(m),
    call("MDETERM"),
    "determinant of a square matrix",
    estimate="condition",
    complex="complex",
    mathcad=("det",),
    mathcad_operator="determinant",
)
entry(
    "inverse",
    1,
    r_inverse,
    lambda m, shapes: inverse(m),
    call("MINVERSE"),
    "inverse of a square matrix (a singular one is an error)",
    estimate="condition",
    complex="complex",
)
entry(
    "lsolve",
    2,
    r_lsolve,
    lambda m, v, shapes: lsolve(m, v),
    call("MMULT", "MINVERSE({}), {}"),
    "solution x of M x = v",
    estimate="condition",
    complex="complex",
    mathcad=("lsolve",),
)


# eigenvalues and eigenvectors
def r_eigenvals(ctx, name, args):
    n = square(args, name)
    return func(args[0].unit, name, args, (n, 1))


def r_eigenvecs(ctx, name, args):
    n = square(args, name)
    return func(ctx.dimensionless, name, args, (n, n))


entry(
    "eigenvals",
    1,
    r_eigenvals,
    lambda m, shapes: eigenvals(m),
    not_live("eigenvalues have no spreadsheet formula"),
    "eigenvalues of a square matrix, ascending (real ones only)",
    estimate="condition",
    complex="complex",
)


def r_eigenparts(ctx, name, args):
    n = square(args, name)
    return func(args[0].unit, name, args, (n, 2))


entry(
    "eigenparts",
    1,
    r_eigenparts,
    lambda m, shapes: eigenparts(m),
    not_live("eigenvalues have no spreadsheet formula"),
    "eigenvalues, complex ones included, as rows (Re, Im) by modulus",
)
entry(
    "eigenvecs",
    1,
    r_eigenvecs,
    lambda m, shapes: eigenvecs(m),
    not_live("eigenvectors have no spreadsheet formula"),
    "unit eigenvectors as columns, in the order of eigenvals",
    estimate="condition",
    complex="complex",
)


def r_eigenvec(ctx, name, args):
    n = square(args, name)
    z = ctx.convert(args[1], args[0].unit, "eigenvec(M, z): z and the elements of M")
    return func(ctx.dimensionless, name, [args[0], z], (n, 1))


entry(
    "eigenvec",
    2,
    r_eigenvec,
    lambda m, z, shapes: eigenvec(m, z),
    not_live("eigenvectors have no spreadsheet formula"),
    "eigenvec(M, z): the unit eigenvector of the eigenvalue z (Mathcad's eigenvec)",
)


def r_rank(ctx, name, args):
    need(args, 0, name, "a matrix")
    return func(ctx.dimensionless, name, args, None)


entry(
    "rank",
    1,
    r_rank,
    lambda m, shapes: rank(m),
    not_live("the rank of a matrix has no spreadsheet formula"),
    "rank of a matrix (the number of independent rows)",
    mathcad=("rank",),
)


# factorizations (workbook.functions.factorizations): Mathcad's choices of pivot
def r_lu(ctx, name, args):
    n = square(args, name)
    if args[0].unit.dimensionality:
        raise UnitError(
            f"lu(): the matrix is in {pretty(args[0].unit)}; P and L are plain and U in the "
            "matrix's unit, and augment(P, L, U) is one matrix of one unit: divide the "
            "matrix by its unit"
        )
    plain = ctx.convert(args[0], ctx.dimensionless, "lu(M)")
    return func(ctx.dimensionless, name, [plain], (n, 3 * n))


def r_rref(ctx, name, args):
    # rref(c M) = rref(M): the result is plain whatever the unit of M
    return func(ctx.dimensionless, name, args, need(args, 0, name, "a matrix"))


def r_geninv(ctx, name, args):
    r, c = need(args, 0, name, "a matrix")
    if r < c:
        raise TemplateError(
            f"geninv() needs at least as many rows as columns, got a {shape_text((r, c))}"
        )
    return func(1 / args[0].unit, name, args, (c, r))


entry(
    "lu",
    1,
    r_lu,
    lambda m, shapes: factorizations.lu(m),
    not_live("an LU factorization has no spreadsheet formula"),
    "lu(M): augment(P, L, U) with P M = L U (Mathcad's lu: Crout's method, its pivots)",
    mathcad=("lu",),
)
entry(
    "rref",
    1,
    r_rref,
    lambda m, shapes: factorizations.rref(m),
    not_live("the reduced row echelon form has no spreadsheet formula"),
    "rref(M): the reduced row echelon form of M",
    mathcad=("rref",),
)
entry(
    "geninv",
    1,
    r_geninv,
    lambda m, shapes: factorizations.geninv(m, SINGULAR_COND),
    not_live("the generalized inverse has no spreadsheet formula"),
    "geninv(M): the left inverse of a matrix of independent columns (Mathcad's geninv)",
    mathcad=("geninv",),
)


# norms, condition numbers, trace, diagonal, singular values (workbook.functions.norms)
def r_matrix_norm(ctx, name, args):
    need(args, 0, name, "a matrix")
    return func(args[0].unit, name, args, None)


def r_cond(ctx, name, args):
    square(args, name)
    return func(ctx.dimensionless, name, args, None)


def r_trace(ctx, name, args):
    square(args, name)
    return func(args[0].unit, name, args, None)


def r_diag(ctx, name, args):
    r, c = need(args, 0, name)
    if c == 1:
        return func(args[0].unit, name, args, (r, r))
    return func(args[0].unit, name, args, (square(args, name), 1))


def r_svds(ctx, name, args):
    r, c = need(args, 0, name, "a matrix")
    return func(args[0].unit, name, args, (min(r, c), 1))


def norm_hook(kind: str):
    return lambda m, shapes: norms.matrix_norm(m, kind)


def cond_hook(kind: str):
    return lambda m, shapes: norms.condition(m, kind, SINGULAR_COND)


values = "has no spreadsheet formula here"
for kind, what in (
    ("1", "largest column sum of |elements|"),
    ("2", "largest singular value"),
    ("i", "largest row sum of |elements|"),
):
    entry(
        f"norm{kind}",
        1,
        r_matrix_norm,
        norm_hook(kind),
        not_live(f"norm{kind}() {values}"),
        f"norm{kind}(M): the {what} of M",
        mathcad=(f"norm{kind}",),
    )
for kind, what in (("1", "norm1"), ("2", "norm2"), ("e", "Frobenius norm"), ("i", "normi")):
    entry(
        f"cond{kind}",
        1,
        r_cond,
        cond_hook(kind),
        not_live(f"cond{kind}() {values}"),
        f"cond{kind}(M): the condition number of M in the {what} (singular: an error)",
        mathcad=(f"cond{kind}",),
    )
entry(
    "tr",
    1,
    r_trace,
    lambda m, shapes: norms.trace(m),
    not_live(f"tr() {values}"),
    "tr(M): the trace of a square matrix (the sum of its diagonal)",
    mathcad=("tr",),
)
entry(
    "diag",
    1,
    r_diag,
    lambda m, shapes: norms.diag(m),
    not_live(f"diag() {values}"),
    "diag(v): the diagonal matrix of a vector; diag(M): the diagonal of a square matrix",
    mathcad=("diag",),
)
entry("svds", 1, r_svds, lambda m, shapes: norms.singular_values(m),
      not_live(f"svds() {values}"),
      "svds(M): the singular values of M, largest first", mathcad=("svds",))  # fmt: skip


def r_polyroots(columns: int):
    def rule(ctx, name, args):
        n = vector(args, 0, name)
        if n < 2:
            raise TemplateError(f"{name}(v): v needs at least 2 coefficients, got {n}")
        return func(ctx.dimensionless, name, args, (n - 1, columns))

    return rule


entry(
    "polyroots",
    1,
    r_polyroots(1),
    lambda v, shapes: polyroots(v),
    not_live("the roots of a polynomial have no spreadsheet formula"),
    "polyroots(v): the roots of v[0] + v[1]*x + ... + v[n]*x^n, ascending (real ones only)",
    complex="complex",
    mathcad=("polyroots",),
    mathcad_operator="polyroots",
)
entry(
    "polyrootparts",
    1,
    r_polyroots(2),
    lambda v, shapes: polyrootparts(v),
    not_live("the roots of a polynomial have no spreadsheet formula"),
    "polyrootparts(v): the roots, complex ones included, as rows (Re, Im) by modulus",
)


def r_histogram(ctx, name, args):
    intervals, data = args
    vector(args, 1, name)
    factor = None if data.unit.dimensionality else (1 * data.unit).to("").magnitude
    if factor != 1:
        raise UnitError(
            f"histogram(): the data are in {pretty(data.unit)}; its midpoints and counts "
            "are one matrix, of one unit: divide the data by their unit (data/kg)"
        )
    if intervals.shape is None:
        n = ctx.plain(intervals, "histogram(n, data): the number of intervals")
        if not isinstance(n, ty.TConst) or n.value != int(n.value) or n.value < 1:
            raise TemplateError(
                "histogram(n, data): n must be a positive integer known at load, as the "
                "shape of every matrix is (or give the interval points as a vector)"
            )
        if n.value > MAX_IDENTITY:
            raise TemplateError(f"histogram({n.value:g}, data): more than {MAX_IDENTITY} rows")
        return func(ctx.dimensionless, name, [n, data], (int(n.value), 2))
    points = vector(args, 0, name)
    if points < 2:
        raise TemplateError("histogram(intervals, data): give at least 2 interval points")
    intervals = ctx.plain(intervals, "histogram(intervals, data): the interval points")
    return func(ctx.dimensionless, name, [intervals, data], (points - 1, 2))


entry(
    "histogram",
    2,
    r_histogram,
    lambda i, d, shapes: histogram(i, d, counted=shapes[0] is None),
    not_live("a histogram has no spreadsheet formula here"),
    "histogram(n, data) or histogram(intervals, data): rows (midpoint, count) of each "
    "interval (Mathcad's histogram)",
    mathcad=("histogram",),
)


# vectors
def r_cross(ctx, name, args):
    for k in (0, 1):
        if vector(args, k, name) != 3:
            raise TemplateError("cross() takes two vectors of 3 elements")
    return func(args[0].unit * args[1].unit, name, args, (3, 1))


def r_dot(ctx, name, args):
    n, m = vector(args, 0, name), vector(args, 1, name)
    if n != m:
        raise TemplateError(f"dot(): the vectors have {n} and {m} elements")
    return func(args[0].unit * args[1].unit, name, args, None)


def r_norm(ctx, name, args):
    need(args, 0, name)  # a vector's length, a matrix's Frobenius norm
    return func(args[0].unit, name, args, None)


def x_cross(args, shapes=None):
    a, b = args
    e = [
        f"INDEX({a},{i})*INDEX({b},{j})-INDEX({a},{j})*INDEX({b},{i})"
        for i, j in ((2, 3), (3, 1), (1, 2))
    ]
    return f"CHOOSE({{1;2;3}},{','.join(e)})", atom


entry(
    "cross",
    2,
    r_cross,
    lambda a, b, shapes: cross(a, b),
    x_cross,
    "cross product of two vectors of 3",
    mathcad=("cross",),
    mathcad_operator="crossProduct",
)
entry(
    "dot",
    2,
    r_dot,
    lambda a, b, shapes: dot(a, b),
    call("SUMPRODUCT", "{}, {}"),
    "dot product of two vectors",
)
entry(
    "norm",
    1,
    r_norm,
    lambda v, shapes: norm(v),
    call("SQRT", "SUMSQ({})"),
    "length (Euclidean norm) of a vector; of a matrix, the square root of the sum of the "
    "squares of its elements (Frobenius)",
    mathcad=("norme",),
)


# Mathcad's |x|: one operator whose meaning follows the shape (known at load)
def r_mag(ctx, name, args):
    (a,) = args
    if a.shape is None or a.shape[1] == 1:
        return func(a.unit, name, args, None)
    return func(a.unit ** square(args, name), name, args, None)


def numpy_mag(v, shapes):
    if shapes[0] is None:
        return np.abs(v)
    return norm(v) if shapes[0][1] == 1 else det(v)


def excel_mag(args, shapes=None):
    shape = shapes[0] if shapes else None
    if shape is None:
        return f"ABS({args[0]})", atom
    return (f"SQRT(SUMSQ({args[0]}))" if shape[1] == 1 else f"MDETERM({args[0]})"), atom


register(
    Builtin(
        "mag",
        1,
        r_mag,
        numpy_mag,
        excel_mag,
        lambda sp, a: sp.Abs(a),
        doc="Mathcad's |x|: abs of a number, length of a vector, determinant of a square matrix",
        arrays=True,
    )
)


# joining and cutting
def r_join(axis: int):
    def rule(ctx, name, args):
        shapes = [need(args, k, name) for k in range(len(args))]
        keep = 1 - axis
        if len({s[keep] for s in shapes}) != 1:
            word = "rows" if axis == 1 else "columns"
            raise TemplateError(
                f"{name}(): the matrices must have the same number of {word} "
                f"({', '.join(shape_text(s) for s in shapes)})"
            )
        unit = args[0].unit
        conv = [ctx.convert(a, unit, f"{name}(): argument {k + 1}") for k, a in enumerate(args)]
        total = sum(s[axis] for s in shapes)
        shape = (shapes[0][0], total) if axis == 1 else (total, shapes[0][1])
        return func(unit, name, conv, shape)

    return rule


entry(
    "augment",
    (2, None),
    r_join(1),
    lambda *m, shapes: augment(*_numbers_as_1x1(m, shapes)),
    not_live("augment() is written as values"),
    "matrices side by side (same rows)",
    runtime=rt_same_unit,
    mathcad=("augment",),
)
entry(
    "stack",
    (2, None),
    r_join(0),
    lambda *m, shapes: stack(*_numbers_as_1x1(m, shapes)),
    not_live("stack() is written as values"),
    "matrices one above the other (same columns)",
    runtime=rt_same_unit,
    mathcad=("stack",),
)


def r_submatrix(ctx, name, args):
    r, c = need(args, 0, name)
    origin = ctx.spec.origin
    if not isinstance(args[3], ty.TConst) and same_tree(args[3], args[4]):
        return r_column(ctx, name, args, r)
    bounds = []
    for k, a in enumerate(args[1:], start=2):
        a = ctx.plain(a, f"submatrix(): argument {k}")
        if not isinstance(a, ty.TConst) or a.value != int(a.value):
            raise TemplateError(f"submatrix(): argument {k} must be a constant integer")
        bounds.append(int(a.value) - origin)
    ir, jr, ic, jc = bounds
    if not (0 <= ir <= jr < r and 0 <= ic <= jc < c):
        raise TemplateError(
            f"submatrix(M, {ir + origin}, {jr + origin}, {ic + origin}, {jc + origin}) is "
            f"outside the {shape_text((r, c))} (origin {origin})"
        )
    consts = [ty.TConst(ctx.dimensionless, value=float(b)) for b in bounds]
    return func(args[0].unit, name, [args[0], *consts], (jr - ir + 1, jc - ic + 1))


def same_tree(a, b) -> bool:
    from ..language.subtrees import Keys

    keys = Keys()
    return keys.key(a) == keys.key(b)


def r_column(ctx, name, args, r):
    """submatrix(M, ir, jr, j, j): one column whose index j is computed (Mathcad's M<j>
    with j a parameter): rows constant, the column checked when it is computed."""
    origin = ctx.spec.origin
    rows = []
    for k in (1, 2):
        a = ctx.plain(args[k], f"submatrix(): argument {k + 1}")
        if not isinstance(a, ty.TConst) or a.value != int(a.value):
            raise TemplateError(f"submatrix(): argument {k + 1} must be a constant integer")
        rows.append(int(a.value) - origin)
    if not 0 <= rows[0] <= rows[1] < r:
        raise TemplateError(
            f"submatrix(M, {rows[0] + origin}, {rows[1] + origin}, j, j): rows outside the "
            f"{r} rows of M (origin {origin})"
        )
    j = ctx.plain(args[3], "submatrix(): the column")
    consts = [ty.TConst(ctx.dimensionless, value=float(b + origin)) for b in rows]
    return func(
        args[0].unit,
        name,
        [args[0], *consts, j, j, origin_arg(ctx)],
        (rows[1] - rows[0] + 1, 1),
    )


entry(
    "submatrix",
    5,
    r_submatrix,
    numpy_submatrix,
    not_live("submatrix() is written as values"),
    "submatrix(M, first row, last row, first column, last column)",
    runtime=rt_with_origin("same"),
    mathcad=("submatrix",),
)


def r_sort_by(word: str, axis: int, what: str = "a vector or matrix"):
    """csort(M, j) / rsort(M, i): the column (row) to sort by, checked if constant."""

    def rule(ctx, name, args):
        r, c = need(args, 0, name, what)
        k = ctx.plain(args[1], f"{name}(): the {word}")
        size, origin = (r, c)[axis], ctx.spec.origin
        if isinstance(k, ty.TConst) and not origin <= k.value < origin + size:
            raise TemplateError(
                f"{name}(): {word} {k.value:g} is outside the {shape_text((r, c))} "
                f"(origin {origin})"
            )
        return func(args[0].unit, name, [args[0], k, origin_arg(ctx)], (r, c))

    return rule


entry(
    "csort",
    2,
    r_sort_by("column", 1),
    lambda m, j, origin, shapes: csort(m, j, int(origin)),
    not_live("csort() is written as values"),
    "csort(M, j): the rows of M sorted by column j, smallest first (Mathcad's csort)",
    runtime=rt_with_origin("same"),
    mathcad=("csort",),
)


# sizes (constants at load)
def r_size(kind: str):
    def rule(ctx, name, args):
        r, c = need(args, 0, name)
        if kind in ("length", "last") and c != 1:
            raise TemplateError(f"{name}() takes a vector, got a {shape_text((r, c))}")
        value = {"rows": r, "cols": c, "length": r, "last": r - 1 + ctx.spec.origin}[kind]
        return ty.TConst(ctx.dimensionless, value=float(value))

    return rule


def numpy_size(kind: str):
    def hook(v, origin=0.0, *, shapes):  # a run-time array: its size when it runs
        return size(kind, v, int(origin))

    return hook


for kind, doc in (
    ("rows", "number of rows"),
    ("cols", "number of columns"),
    ("length", "number of elements of a vector"),
    ("last", "index of the last element of a vector (with the sheet's origin)"),
):
    entry(
        kind,
        1,
        r_size(kind),
        numpy_size(kind),
        not_live(kind),
        doc,
        runtime=rt_with_origin("plain"),
        sizes=True,
        complex="real",
        mathcad=(kind,),
    )


# reductions: max and min of numbers and of the elements of matrices; mean
def r_reduce(ctx, name, args):
    args = tuple(ctx.meeting(args))  # max(theta, 45): 45 degrees next to an angle
    first = next((a for a in args if a.shape is not None), args[0])
    conv = [ctx.convert(a, first.unit, f"{name}() arguments") for a in args]
    return func(first.unit, name, conv, None)


def numpy_reduce(kind: str):
    def hook(*values, shapes):
        if not any(s is not None for s in shapes):
            if kind in ("max", "min"):
                red = np.maximum if kind == "max" else np.minimum
                out = values[0]
                for v in values[1:]:
                    out = red(out, v)
                return out
        return reduce(kind, *values, matrix=tuple(s is not None for s in shapes))

    return hook


def sympy_reduce(kind: str):
    def hook(sp, *a):
        return (sp.Max if kind == "max" else sp.Min)(*a)

    return hook


def _kink_where_equal(t: ty.TFunc) -> tuple:
    """max, min of two numbers: a kink where the two are equal."""
    return ((t.args[0], t.args[1]),) if len(t.args) == 2 else ()


for kind, excel_name, doc in (
    ("max", "MAX", "largest argument (or element of vectors and matrices)"),
    ("min", "MIN", "smallest argument (or element of vectors and matrices)"),
):
    register(
        Builtin(
            kind,
            None,
            r_reduce,
            numpy_reduce(kind),
            _excel_list(excel_name),
            sympy_reduce(kind),
            doc=doc,
            arrays=True,
            runtime=r_reduce,
            kinks=_kink_where_equal,
            mathcad=(kind,),
            excel_import=(excel_name,),
        )
    )
entry(
    "mean",
    None,
    r_reduce,
    numpy_reduce("mean"),
    _excel_list("AVERAGE"),
    "mean of the arguments (or of the elements of vectors and matrices)",
    runtime=r_reduce,
    mathcad=("mean",),
    excel_import=("AVERAGE",),
)


# sort, reverse, rsort: the shape of the argument, in its unit
def r_sort(ctx, name, args):
    return func(args[0].unit, name, args, (vector(args, 0, name), 1))


def r_reverse(ctx, name, args):
    return func(args[0].unit, name, args, need(args, 0, name))


entry(
    "sort",
    1,
    r_sort,
    numpy_sort,
    not_live("sort() is written as values"),
    "the elements of a vector, smallest first",
    runtime=rt_same_unit,
    mathcad=("sort",),
)
entry(
    "reverse",
    1,
    r_reverse,
    numpy_reverse,
    not_live("reverse() is written as values"),
    "the elements of a vector, or the rows of a matrix, in reverse order",
    runtime=rt_same_unit,
    mathcad=("reverse",),
)
entry(
    "rsort",
    2,
    r_sort_by("row", 0, "a matrix"),
    lambda m, i, origin, shapes: rsort(m, i, int(origin), shapes[0]),
    not_live("rsort() is written as values"),
    "rsort(M, i): the columns of M sorted by row i, smallest first (Mathcad's rsort)",
    runtime=rt_with_origin("same"),
    mathcad=("rsort",),
)


# identity(n): the size a constant
def r_identity(ctx, name, args):
    n = ctx.plain(args[0], "identity(): the size")
    if not isinstance(n, ty.TConst) or n.value != int(n.value) or n.value < 1:
        raise TemplateError(
            "identity(n): n must be a positive integer known at load (a number, or "
            "rows(M) of a matrix M), as the shape of every matrix is"
        )
    if n.value > MAX_IDENTITY:
        raise TemplateError(f"identity({n.value:g}): more than {MAX_IDENTITY} rows")
    return func(ctx.dimensionless, name, [n], (int(n.value), int(n.value)))


def x_identity(args, shapes=None):
    n = int(float(args[0]))
    if n > MAX_EXCEL_IDENTITY:
        raise NotLive(f"identity({n}) is written as values (a constant of {n}x{n})")
    rows = (",".join("1" if i == j else "0" for j in range(n)) for i in range(n))
    # bracketed: a formula that ends with "}" loses it (read as an array formula's brace)
    return "({" + ";".join(rows) + "})", atom


entry(
    "identity",
    1,
    r_identity,
    lambda n, shapes: np.eye(int(n)),
    x_identity,
    "identity(n): the n x n identity matrix (n known at load)",
    mathcad=("identity",),
)


# statistics of the elements (and numbers): Mathcad's stdev and var are the population
# ones (divided by N), as Excel's STDEV.P and VAR.P
def r_var(ctx, name, args):
    t = r_reduce(ctx, name, args)
    return func(t.unit**2, name, t.args, None)


for kind, rule, excel_name, doc in (
    ("stdev", r_reduce, stored("STDEV.P"), "population standard deviation (divided by N)"),
    ("var", r_var, stored("VAR.P"), "population variance (divided by N)"),
    ("median", r_reduce, "MEDIAN", "median"),
):
    entry(
        kind,
        None,
        rule,
        numpy_statistic(kind),
        _excel_list(excel_name),
        f"{doc} of the arguments (or of the elements of vectors and matrices)",
        runtime=rule,
        mathcad=(kind,),
    )
