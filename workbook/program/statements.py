"""A program's statements and the walks over them (after parsing their expressions are expr
nodes, after typing typed nodes)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ..language import expr as ex


# -- statements (E is ex.Node after parsing, a typed node after typing) -----------------------
@dataclass(frozen=True)
class Stmt:
    line: int  # line within the program text, from 1


@dataclass(frozen=True)
class Assign(Stmt):
    name: str
    value: Any


@dataclass(frozen=True)
class SetItem(Stmt):
    """``v[i] := EXPR`` or ``M[i, j] := EXPR``: an element of a local vector or matrix."""

    name: str
    indices: tuple
    value: Any
    origin: int = 0
    grow: Any = None  # (rows, columns) the local is made or grown to (zeros), if it is


@dataclass(frozen=True)
class Value(Stmt):
    value: Any


@dataclass(frozen=True)
class Return(Stmt):
    value: Any


@dataclass(frozen=True)
class Break(Stmt):
    pass


@dataclass(frozen=True)
class Continue(Stmt):
    pass


@dataclass(frozen=True)
class If(Stmt):
    branches: tuple[tuple[Any, tuple[Stmt, ...]], ...]  # (condition, block)
    otherwise: tuple[Stmt, ...] | None


@dataclass(frozen=True)
class For(Stmt):
    var: str
    first: Any
    second: Any  # None: step 1 (or -1)
    last: Any
    body: tuple[Stmt, ...]


@dataclass(frozen=True)
class While(Stmt):
    condition: Any
    body: tuple[Stmt, ...]


@dataclass(frozen=True)
class Try(Stmt):
    """``try`` over a block, then ``on error`` over a block: the first block runs; if an error
    is raised in it, the second runs from there (Mathcad Prime's try / on error)."""

    body: tuple[Stmt, ...]
    handler: tuple[Stmt, ...]


@dataclass(frozen=True)
class Program:
    body: tuple[Stmt, ...]
    text: str


# -- helpers for the back ends ----------------------------------------------------------------
def walk(block: tuple[Stmt, ...]):
    """Every statement of a block, nested ones included, parents first."""
    for s in block:
        yield s
        if isinstance(s, If):
            for _, b in s.branches:
                yield from walk(b)
            if s.otherwise:
                yield from walk(s.otherwise)
        elif isinstance(s, (For, While)):
            yield from walk(s.body)
        elif isinstance(s, Try):
            yield from walk(s.body)
            yield from walk(s.handler)


def expressions(block: tuple[Stmt, ...]):
    """Every expression of a block (conditions, values, loop bounds)."""
    for s in walk(block):
        if isinstance(s, (Assign, Value, Return)):
            yield s.value
        elif isinstance(s, SetItem):
            yield from s.indices
            yield s.value
        elif isinstance(s, If):
            for c, _ in s.branches:
                yield c
        elif isinstance(s, For):
            yield from (e for e in (s.first, s.second, s.last) if e is not None)
        elif isinstance(s, While):
            yield s.condition


def names(program: Program) -> set[str]:
    """Names the program refers to that it does not define itself (locals, loop variables)."""
    local = set()
    for s in walk(program.body):
        if isinstance(s, Assign):
            local.add(s.name)
        elif isinstance(s, For):
            local.add(s.var)
    found = set()
    for e in expressions(program.body):
        found |= ex.names(e)
    return found - local


def has_loops(program: Program) -> bool:
    return any(isinstance(s, (For, While)) for s in walk(program.body))
