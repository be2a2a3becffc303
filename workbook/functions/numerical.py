"""What every primitive shares: tolerances, the result with its error, the error type."""

from __future__ import annotations

import contextlib
import contextvars
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import DomainError, TemplateError

Fn = Callable[..., object]


@dataclass(frozen=True)
class Tolerance:
    """Tolerances of the numerical built-ins (``[sheet] tolerance`` sets ``rtol``).

    ``rtol`` is relative to the result, ``atol`` absolute (in the unit of the result, 0: none);
    ``samples`` is the number of intervals a bracket is sampled at (sign changes, extrema).
    """

    rtol: float = 1e-10
    atol: float = 0.0
    samples: int = 8

    def tighter(self, rtol: float = 1e-14) -> Tolerance:
        """The same sampling at a tighter tolerance (the reference of ``workbook bench``)."""
        return replace(self, rtol=rtol, atol=0.0)


class NumericsError(DomainError):
    """A numerical built-in cannot give a trustworthy value (no root, divergent integral...)."""

    kind = "numerical error"


@dataclass
class Result:
    """Values (one per row), their estimated absolute errors, and where an extremum is."""

    value: np.ndarray
    error: np.ndarray
    where: np.ndarray | None = None  # argmax/argmin for extrema
    where_error: np.ndarray | None = None
    evaluations: int = 0  # largest number of function evaluations of a row
    notes: dict = field(default_factory=dict)


_current: contextvars.ContextVar[Tolerance | None] = contextvars.ContextVar(
    "workbook_numerics_tolerance", default=None
)


def current(default: Tolerance) -> Tolerance:
    """The tolerance in force: an override set by :func:`tolerance`, else ``default``."""
    return _current.get() or default


_defining: contextvars.ContextVar[str | None] = contextvars.ContextVar(
    "workbook_numerics_defining", default=None
)


_records: contextvars.ContextVar[list | None] = contextvars.ContextVar(
    "workbook_numerics_records", default=None
)


@contextlib.contextmanager
def defining(what: str, records: list | None = None) -> Iterator[None]:
    """Name the definition or table column being computed: the built-ins' results keep it
    (``Result.notes["in"]``), so that a finding about an estimate can say where it is.
    ``records`` (the evaluator's list of (built-in, Result)) receives the results of the
    built-ins that are given no EXPR (``lsolve``, ``eigenvals``: :func:`record`)."""
    token = _defining.set(what)
    sink = _records.set(records) if records is not None else None
    try:
        yield
    finally:
        if sink is not None:
            _records.reset(sink)
        _defining.reset(token)


def recording() -> bool:
    """True where :func:`record` keeps what it is given (inside a sheet's definition)."""
    return _records.get() is not None


def record(name: str, value, error, **notes) -> None:
    """Keep the error estimate of a built-in computed on values (no EXPR), with the
    definition being computed, where :func:`defining` was given the list to keep it in."""
    sink = _records.get()
    if sink is None:
        return
    res = Result(np.asarray(value, dtype=float), np.asarray(error, dtype=float), notes=notes)
    res.notes.setdefault("in", defined())
    sink.append((name, res))


def defined() -> str | None:
    """The name given by the innermost :func:`defining`, if any."""
    return _defining.get()


_live: contextvars.ContextVar[bool] = contextvars.ContextVar(
    "workbook_numerics_live", default=False
)


def live() -> bool:
    """True inside :func:`live_forms`: built-ins compute what their Excel form computes."""
    return _live.get()


@contextlib.contextmanager
def live_forms() -> Iterator[None]:
    """Evaluate the built-ins' live Excel forms (a fixed Gauss-Legendre sum for an integral)
    instead of the engine's methods, to say how far the workbook's formula is from the value."""
    token = _live.set(True)
    try:
        yield
    finally:
        _live.reset(token)


@dataclass
class ReferenceLog:
    """What :func:`reference_methods` saw: (method, rows, of) per call, and (EXPR's tree,
    values) per call, in the order of the calls."""

    methods: list = field(default_factory=list)
    values: list = field(default_factory=list)


_reference: contextvars.ContextVar[ReferenceLog | None] = contextvars.ContextVar(
    "workbook_numerics_reference", default=None
)


def reference() -> bool:
    """True inside :func:`reference_methods`: built-ins compute by other algorithms."""
    return _reference.get() is not None


def reference_note(method: str, rows: int, of: int) -> None:
    """Inside :func:`reference_methods`: the reference of one call was ``method``, on
    ``rows`` of its ``of`` rows (the rest take the engine's values)."""
    log = _reference.get()
    if log is not None:
        log.methods.append((method, rows, of))


def reference_values(body, values) -> None:
    """Inside :func:`reference_methods`: the reference's values of one call of the built-in
    whose EXPR is the typed tree ``body`` (NaN in the rows it did not compute)."""
    log = _reference.get()
    if log is not None:
        log.values.append((body, np.array(values, dtype=float)))


@contextlib.contextmanager
def reference_methods(on: bool = True) -> Iterator[ReferenceLog]:
    """Compute root, integral and the extrema by the methods of
    :mod:`workbook.numerics.mpref` (mpmath on EXPR's tree) or, where EXPR has no mpmath
    form, of :mod:`workbook.numerics.reference` (other algorithms in doubles), never the
    engine's: ``workbook bench``'s reference (``on=False``: the engine's methods again, for
    the rows the reference leaves out). Yields the log of the calls."""
    log = ReferenceLog() if on else None
    token = _reference.set(log)
    try:
        yield log if log is not None else ReferenceLog()
    finally:
        _reference.reset(token)


_chains: contextvars.ContextVar[dict | None] = contextvars.ContextVar(
    "workbook_numerics_chains", default=None
)


def chains() -> dict | None:
    """Inside :func:`recording_chains`: id of a root's EXPR -> the bisection chains found."""
    return _chains.get()


@contextlib.contextmanager
def recording_chains() -> Iterator[dict]:
    """Keep every bisection chain a live root computes (the cached values of the workbook's
    step cells): ``{id(EXPR's typed tree): [chain, ...]}``, one chain per evaluation."""
    found: dict = {}
    token = _chains.set(found)
    try:
        yield found
    finally:
        _chains.reset(token)


@contextlib.contextmanager
def tolerance(tol: Tolerance) -> Iterator[None]:
    """Evaluate with ``tol`` instead of the sheet's tolerance (``workbook bench``'s reference)."""
    token = _current.set(tol)
    try:
        yield
    finally:
        _current.reset(token)


def rows(*arrays) -> tuple[tuple[int, ...], list[np.ndarray]]:
    """Broadcast bounds and arguments to one shape; return it and the arrays flattened."""
    arrs = np.broadcast_arrays(*[np.asarray(a, dtype=float) for a in arrays])
    shape = arrs[0].shape
    return shape, [np.ascontiguousarray(a).reshape(-1) for a in arrs]


def call(f: Fn, x: np.ndarray, args: list[np.ndarray]) -> np.ndarray:
    """``f(x, *args)`` as a float array of x's shape (a constant f is broadcast)."""
    out = np.asarray(f(x, *args), dtype=float)
    return np.broadcast_to(out, np.shape(x)) if out.shape != np.shape(x) else out


def num(v: float) -> str:
    """A number as messages print it."""
    return f"{float(v):.6g}"


def row_text(label: Callable[[int], str] | None, i: int, n: int) -> str:
    """' (for ROW)' naming row ``i`` of ``n`` in messages."""
    if label is not None:
        text = label(i)
        return f" ({text})" if text else ""
    return f" (row {i + 1} of {n})" if n > 1 else ""


def unit_suffix(unit: str) -> str:
    """' mm' after a number in messages, or nothing for a plain number."""
    return f" {unit}" if unit else ""


#: the tolerance of a sheet that sets none
DEFAULT = Tolerance()


def sheet_tolerance(meta: dict) -> Tolerance:
    """``[sheet] tolerance = 1e-8`` (relative) and ``samples = 16``: the sheet's tolerance."""
    rtol = meta.get("tolerance", DEFAULT.rtol)
    samples = meta.get("samples", DEFAULT.samples)
    if isinstance(rtol, bool) or not isinstance(rtol, (int, float)) or not 1e-15 <= rtol <= 1e-2:
        raise TemplateError(
            f"[sheet] tolerance = {rtol!r}: give a relative tolerance between 1e-15 and 0.01"
        )
    if isinstance(samples, bool) or not isinstance(samples, int) or not 2 <= samples <= 10_000:
        raise TemplateError(f"[sheet] samples = {samples!r}: give a whole number from 2 to 10000")
    return Tolerance(rtol=float(rtol), samples=samples)
