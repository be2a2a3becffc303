"""Solver blocks: numerical procedures that a template may call by name.

A template names a block in ``[blocks]`` as ``local_name = "module.function"``;
the engine imports ``workbook.blocks.<module>`` only when a requested output
needs it (so scipy is imported only by scenes that solve something). Only
functions registered with one of the decorators below can be reached, so a
template cannot call arbitrary Python.

Five kinds:

* ``@block(args={...}, returns="mm")``: called inside expressions like a
  function. It receives magnitudes (floats or numpy arrays) in the declared
  units, in the declared order, and returns a magnitude in ``returns``.
  With ``vectorized=False`` the engine calls it once per element.
* ``@table_block``: ``func(sheet) -> pandas.DataFrame``; headers carry units as
  ``"name [unit]"``. Used for tables that are values, not formulas (benchmarks,
  ODE histories).
* ``@findings_block``: ``func(sheet) -> list[Finding]``; shown by
  ``workbook check`` and in the Checks sheet.
* ``@bench_block``: ``func(sheet, quick=False) -> pandas.DataFrame``; what
  ``workbook bench NAME`` prints (``[sheet] bench = "module.func"``).
* ``@export_block``: ``func(sheet, path) -> path``; writes a file for other programs
  (``workbook run NAME --export PATH``, ``[sheet] export = "module.func"``).
"""

from __future__ import annotations

import hashlib
import importlib
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import TemplateError

__all__ = [
    "Block",
    "input_magnitude",
    "block",
    "table_block",
    "findings_block",
    "bench_block",
    "export_block",
    "get",
    "kept",
]

_REGISTRY: dict[str, Block] = {}


@dataclass
class Block:
    ref: str
    func: Callable[..., Any]
    kind: str  # "function" | "table" | "findings" | "bench"
    args: dict[str, str] = field(default_factory=dict)
    returns: str = ""
    vectorized: bool = True

    @property
    def doc(self) -> str:
        return (self.func.__doc__ or "").strip().splitlines()[0] if self.func.__doc__ else ""


_CACHE: dict = {}


def content_key(spec) -> str:
    """A digest of what a template's results depend on besides its input values: its text
    and the measured data read beside it. Two loads of the same file before and after an
    edit differ; copies of the same text at two paths share their results."""
    digest = hashlib.sha256(spec.text.encode())
    for name in sorted(spec.data):
        column = spec.data[name]
        digest.update(f"\0{name}\0{column.unit}\0".encode())
        digest.update(np.ascontiguousarray(column.values, dtype=float).tobytes())
    return digest.hexdigest()


def cached(sheet, key, make):
    """``make()`` computed once per template content (:func:`content_key`), input values and
    ``key``, and kept (many input variations, as in a sweep, start the store afresh). A result
    is stored only when complete: a Ctrl-C leaves no half-filled entry."""
    values = tuple(sorted((k, str(v)) for k, v in sheet.values.items()))
    full = (content_key(sheet.spec), values, key)
    if full not in _CACHE:
        value = make()
        if len(_CACHE) > 512:
            _CACHE.clear()
        _CACHE[full] = value
    return _CACHE[full]


def kept() -> set:
    """The keys of the results :func:`cached` keeps: (content, input values, key)."""
    return set(_CACHE)


def input_magnitude(sheet, name: str, unit: str) -> float:
    """The sheet's input ``name`` as a plain number in ``unit``."""
    return float(sheet.evaluate(name).to(unit).magnitude)


def _ref(func: Callable) -> str:
    module = func.__module__.rsplit(".", 1)[-1]
    return f"{module}.{func.__name__}"


def block(args: dict[str, str], returns: str, vectorized: bool = True):
    """Register a function block (see module docstring)."""

    def wrap(func):
        _REGISTRY[_ref(func)] = Block(_ref(func), func, "function", dict(args), returns, vectorized)
        return func

    return wrap


def _simple(kind: str):
    def deco(func):
        _REGISTRY[_ref(func)] = Block(_ref(func), func, kind)
        return func

    return deco


table_block = _simple("table")
findings_block = _simple("findings")
bench_block = _simple("bench")
export_block = _simple("export")  # func(sheet, path) writes a file for other programs (CAD)


def get(ref: str, kind: str | None = None) -> Block:
    """Import ``workbook.blocks.<module>`` and return the registered block ``module.function``."""
    module, _, name = ref.partition(".")
    if not module.isidentifier() or not name.isidentifier():
        raise TemplateError(f"block {ref!r} must be named 'module.function'")
    try:
        importlib.import_module(f"{__name__}.{module}")
    except ModuleNotFoundError as exc:
        if exc.name == f"{__name__}.{module}":
            raise TemplateError(
                f"no block module '{module}' (looked for workbook/blocks/{module}.py)"
            ) from None
        raise
    blk = _REGISTRY.get(ref)
    if blk is None:
        raise TemplateError(f"block module '{module}' has no registered block '{name}'")
    if kind is not None and blk.kind != kind:
        raise TemplateError(f"block {ref!r} is a {blk.kind} block, not a {kind} block")
    return blk
