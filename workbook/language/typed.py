"""The typed tree: expression nodes with their units resolved (built by
workbook.language.typecheck).

Every node carries the pint unit its value is in; every unit conversion is an explicit
:class:`TScale`. The nodes are frozen: back ends (:mod:`workbook.engine.numeric`,
:mod:`workbook.compute.excel`, :mod:`workbook.numerics.symbolic`, :mod:`workbook.engine.analysis`)
read them and never change them; each back end is a :class:`workbook.language.visitor.Visitor` with
one ``visit_<Node>`` method per class below."""

from __future__ import annotations

from dataclasses import dataclass, field

import pint

from . import units as un
from .visitor import Visitor


@dataclass(frozen=True, eq=False)
class T:
    """Base of typed nodes: the unit the value is in; ``boolean`` for conditions; ``shape``
    (rows, columns) for a vector or matrix (None for a scalar); ``text`` for a string value;
    ``complex`` for a complex value (or one whose elements are complex). ``complex`` left
    None is derived from the children: an operator, scaling, index, matrix or built-in call
    of a complex value is complex (a rule whose value is real, as abs(z), says False)."""

    unit: pint.Unit
    boolean: bool = field(default=False, kw_only=True)
    shape: tuple[int, int] | None = field(default=None, kw_only=True)
    text: bool = field(default=False, kw_only=True)
    complex: bool | None = field(default=None, kw_only=True)

    def __post_init__(self) -> None:
        if self.complex is None:
            object.__setattr__(self, "complex", not self.boolean and _derived_complex(self))


@dataclass(frozen=True, eq=False)
class TConst(T):
    value: float | complex = 0.0
    #: folded from quantities (``20 mm/10 mm``, ``15 %`` as a plain number): a plain number,
    #: but not one written bare, so never read as degrees next to an angle
    derived: bool = False


@dataclass(frozen=True, eq=False)
class TText(T):
    value: str = ""


@dataclass(frozen=True, eq=False)
class TParam(T):
    name: str = ""


@dataclass(frozen=True, eq=False)
class TRef(T):
    """A scalar: an input, a scalar definition, or the built-in pi."""

    name: str = ""
    kind: str = "input"  # input | definition | builtin


@dataclass(frozen=True, eq=False)
class TScale(T):
    child: T = None
    factor: float = 1.0


@dataclass(frozen=True, eq=False)
class TUnary(T):
    op: str = "-"
    child: T = None


@dataclass(frozen=True, eq=False)
class TBinary(T):
    op: str = "+"
    left: T = None
    right: T = None


@dataclass(frozen=True, eq=False)
class TCompare(T):
    ops: tuple = ()
    operands: tuple = ()


@dataclass(frozen=True, eq=False)
class TLogic(T):
    op: str = "and"
    values: tuple = ()


@dataclass(frozen=True, eq=False)
class TFunc(T):
    """Call of a built-in function (an entry of :data:`workbook.numerics.registry.REGISTRY`).

    For a built-in that binds a variable, ``args`` keeps the source order: the typed
    expression, a :class:`TParam` naming the bound variable, then the other arguments.
    """

    func: str = ""
    args: tuple = ()


@dataclass(frozen=True, eq=False)
class TCall(T):
    """Call of a user function; args are already in the parameters' binding units."""

    name: str = ""
    args: tuple = ()


@dataclass(frozen=True, eq=False)
class TBlock(T):
    name: str = ""
    ref: str = ""
    args: tuple = ()


@dataclass(frozen=True, eq=False)
class TAggregate(T):
    """max_over(table, column) / min_over(...): one number from a range table's column."""

    func: str = "max"
    table: str = ""
    column: str = ""


@dataclass(frozen=True, eq=False)
class TPiecewise(T):
    conditions: tuple = ()  # None for 'otherwise'
    values: tuple = ()
    texts: tuple = ()


@dataclass(frozen=True, eq=False)
class TMatrix(T):
    """A vector or matrix written out: ``rows`` of typed elements, all in ``unit``."""

    rows: tuple = ()


@dataclass(frozen=True, eq=False)
class TIndex(T):
    """``v[i]`` or ``M[i, j]``: indices are plain numbers counted from ``origin``."""

    target: T = None
    indices: tuple = ()
    origin: int = 0


@dataclass(frozen=True, eq=False)
class TProgram(T):
    """A function body written as statements (:mod:`workbook.program`); ``program`` is the
    typed program, ``params`` the names of the arguments it reads."""

    name: str = ""
    program: object = None  # workbook.program.typer.TypedProgram
    params: tuple = ()
    matrices: tuple = ()  # the parameters that are vectors or matrices


@dataclass(frozen=True, eq=False)
class TOde(T):
    """State ``state`` of the ODE ``ode`` at the time ``args[0]`` (in the time unit)."""

    ode: str = ""
    state: int = 0
    name: str = ""
    args: tuple = ()


@dataclass(frozen=True, eq=False)
class TypedFunction:
    name: str
    params: tuple[str, ...]
    param_units: tuple[pint.Unit, ...]
    body: T
    # the parameters' shapes, (rows, columns) or None for a number (() for numbers only):
    # a function called with vectors or matrices is typed once per tuple of shapes
    shapes: tuple = ()

    @property
    def unit(self) -> pint.Unit:
        return self.body.unit


class _Children(Visitor):
    """The direct sub-trees of a typed node, in source order."""

    def _none(self, t: T) -> tuple[T, ...]:
        return ()

    visit_TConst = visit_TText = visit_TParam = visit_TRef = visit_TAggregate = _none

    def visit_TScale(self, t: TScale) -> tuple[T, ...]:
        return (t.child,)

    visit_TUnary = visit_TScale

    def visit_TBinary(self, t: TBinary) -> tuple[T, ...]:
        return (t.left, t.right)

    def visit_TCompare(self, t: TCompare) -> tuple[T, ...]:
        return tuple(t.operands)

    def visit_TLogic(self, t: TLogic) -> tuple[T, ...]:
        return tuple(t.values)

    def visit_TFunc(self, t: TFunc) -> tuple[T, ...]:
        return tuple(t.args)

    visit_TCall = visit_TBlock = visit_TFunc

    def visit_TPiecewise(self, t: TPiecewise) -> tuple[T, ...]:
        return tuple(t.values) + tuple(c for c in t.conditions if c is not None)

    def visit_TMatrix(self, t: TMatrix) -> tuple[T, ...]:
        return tuple(e for row in t.rows for e in row)

    def visit_TIndex(self, t: TIndex) -> tuple[T, ...]:
        return (t.target, *t.indices)

    def visit_TProgram(self, t: TProgram) -> tuple[T, ...]:
        return tuple(t.program.expressions())

    def visit_TOde(self, t: TOde) -> tuple[T, ...]:
        return tuple(t.args)


_CHILDREN = _Children()


def _derived_complex(t: T) -> bool:
    """Whether ``t`` is complex, from its children (every typed node asks once, when made)."""
    if isinstance(t, TConst):
        return isinstance(t.value, complex)
    if isinstance(t, TBinary):
        return t.left.complex or t.right.complex
    if isinstance(t, (TScale, TUnary)):
        return t.child is not None and t.child.complex
    if isinstance(t, TFunc):
        return any(a.complex for a in t.args)
    if isinstance(t, TMatrix):
        return any(e.complex for row in t.rows for e in row)
    if isinstance(t, TIndex):
        return t.target.complex
    if isinstance(t, TPiecewise):
        return any(v.complex for v in t.values)
    return False


def is_bare(t: T) -> bool:
    """A plain number written in the expression (a literal, or plain literals folded; not
    a ratio of quantities)."""
    return isinstance(t, TConst) and t.unit == un.registry().dimensionless and not t.derived


def is_zero(t: T) -> bool:
    """A dimensionless literal zero, which agrees with any unit."""
    return (
        isinstance(t, TConst)
        and t.value == 0.0
        and not t.unit.dimensionality
        and (t.unit == un.registry().dimensionless)
    )


class RuntimeShape:
    """The shape of a value known only when a program runs (a vector grown element by
    element, a nested array): one object, :data:`RUNTIME`. It cannot be unpacked or indexed,
    so code that needs rows and columns at load fails loudly instead of guessing."""

    _instance = None

    def __new__(cls):
        if cls._instance is None:
            cls._instance = super().__new__(cls)
        return cls._instance

    def __iter__(self):
        raise TypeError("the shape of a run-time array is not known at load")

    __getitem__ = __len__ = __iter__

    def __bool__(self) -> bool:  # a shape: "an array", as a (rows, columns) tuple is
        return True

    def __repr__(self) -> str:
        return "RUNTIME"

    def __reduce__(self):
        return (RuntimeShape, ())


RUNTIME = RuntimeShape()


def is_runtime(shape) -> bool:
    """True for the shape of a value known only when its program runs."""
    return shape is RUNTIME


def shape_text(shape) -> str:
    """``3x2 matrix`` or ``vector of 3``, for messages."""
    if shape is RUNTIME:
        return "run-time array"
    r, c = shape
    return f"{r}x{c} matrix" if c != 1 else f"vector of {r}"


def children(t: T) -> tuple[T, ...]:
    """The direct sub-trees of ``t`` (values, then conditions, for a piecewise node)."""
    return _CHILDREN.visit(t)


def with_calls(defs, t: T):
    """Every node of ``t`` and of the bodies of the sheet functions it calls, each body once
    (``defs.function(name)`` gives a call's typed function)."""
    stack, seen = [t], set()
    while stack:
        n = stack.pop()
        yield n
        if isinstance(n, TCall) and n.name not in seen:
            seen.add(n.name)
            stack.append(defs.function(n.name).body)
        stack.extend(children(n))


def parameters(t: T) -> set[str]:
    """Names of the parameters (function arguments, bound variables) that ``t`` refers to."""
    out, stack = set(), [t]
    while stack:
        n = stack.pop()
        if isinstance(n, TParam):
            out.add(n.name)
        stack.extend(children(n))
    return out
