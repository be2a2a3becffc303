"""Running a typed program: one closure per program for the numeric back end."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..engine import runtime as rt
from ..errors import InputError, LimitError, TemplateError, WorkbookError
from ..language.typed import is_runtime
from ..limits_time import check_time
from .statements import (
    Assign,
    Break,
    Continue,
    For,
    If,
    Return,
    SetItem,
    Stmt,
    Try,
    Value,
    While,
    walk,
)
from .typer import TypedProgram

#: Statements one call of a program may execute (a `while` that never ends stops here).
MAX_STEPS = 1_000_000
#: The command's time budget is checked every 1,024 statements (a statement is at least
#: a microsecond; one that builds a large array is bounded by the element limit).
TIME_CHECK_MASK = 1023


# -- running ----------------------------------------------------------------------------------
class _Break(Exception):
    pass


class _Continue(Exception):
    pass


class _Return(Exception):
    def __init__(self, value):
        self.value = value


class NoValue(Exception):
    """The program ended without a value (the numeric back end names the function)."""


_NONE = object()


class _Compiler:
    """A typed program's statements to closures ``(env, last) -> last``, one method per kind
    of statement; every statement run counts against the program's step limit."""

    def __init__(self, compile_expr: Callable[[Any], Callable], name: str):
        self.compile_expr, self.name = compile_expr, name
        self.steps = steps = [0]

        def tick(s: Stmt):
            steps[0] += 1
            if not steps[0] & TIME_CHECK_MASK:
                check_time(f"the program of '{name}' (line {s.line})")
            if steps[0] > MAX_STEPS:
                raise LimitError(
                    f"the program of '{name}' ran {MAX_STEPS:,} statements without ending "
                    f"(line {s.line}: a loop that never ends?)",
                    definition=name,
                )

        self.tick = tick
        self.kinds = (
            (Assign, self.assign),
            (SetItem, self.set_item),
            (Value, self.value),
            (Return, self.ret),
            (Break, self.brk),
            (Continue, self.cont),
            (If, self.if_),
            (For, self.for_),
            (While, self.while_),
            (Try, self.try_),
        )

    def block(self, stmts) -> Callable:
        """A block of statements, run in order."""
        compiled = [self.stmt(s) for s in stmts]

        def run(env, last):
            for c in compiled:
                last = c(env, last)
            return last

        return run

    def stmt(self, s: Stmt) -> Callable:
        """One statement, by its kind."""
        for kind, make in self.kinds:
            if isinstance(s, kind):
                return make(s)
        raise TypeError(s)  # pragma: no cover

    def assign(self, s) -> Callable:
        """``n := expr``: the local set (a matrix copied: its elements may be set later)."""
        tick = self.tick
        f, n = self.compile_expr(s.value), s.name

        def assign(env, last):
            tick(s)
            value = f(env)  # a matrix is copied: its elements may be set later
            if isinstance(value, np.ndarray) and value.dtype == object:
                env[n] = value.copy()
            else:
                env[n] = np.array(value, dtype=float) if np.ndim(value) else value
            env.setdefault(_OWNED, set()).add(n)
            return last

        return assign

    def set_item(self, s) -> Callable:
        """``n[i] := expr``: an element set, the local made or grown to its length."""
        from ..functions.matrix import element_index

        tick = self.tick
        f, n, origin, grow = self.compile_expr(s.value), s.name, s.origin, s.grow
        idx = [self.compile_expr(i) for i in s.indices]
        if is_runtime(grow):
            what = f"program of '{self.name}', line {s.line}: {n}[...]"

            def set_runtime(env, last):
                tick(s)
                _own(env, n)
                at = [i(env) for i in idx]
                env[n] = rt.set_item(env.get(n), at, f(env), origin=origin, what=what)
                return last

            return set_runtime

        def set_item(env, last):
            tick(s)
            _own(env, n)
            if grow is not None:  # made, or grown with zeros, to its length at load
                old = env.get(n)
                if old is None or np.shape(old)[:2] != tuple(grow):
                    target = np.zeros(grow)
                    if old is not None and np.ndim(old):  # a number becomes a vector
                        old = np.asarray(old, dtype=float).reshape(np.shape(old)[0], -1)
                        target[: old.shape[0], : old.shape[1]] = old
                    env[n] = target
            target = env[n]
            at = element_index(target.shape, [i(env) for i in idx], origin, f"{n}[...]")
            target[at] = f(env)
            return last

        return set_item

    def value(self, s) -> Callable:
        """A line that is the program's value so far."""
        tick = self.tick
        f = self.compile_expr(s.value)

        def value(env, last):
            tick(s)
            return _result(f(env))  # a local set after this line does not change it

        return value

    def ret(self, s) -> Callable:
        """``return expr``."""
        tick = self.tick
        f = self.compile_expr(s.value)

        def ret(env, last):
            tick(s)
            raise _Return(f(env))

        return ret

    def brk(self, s) -> Callable:
        """``break``."""

        def brk(env, last):
            raise _Break

        return brk

    def cont(self, s) -> Callable:
        """``continue``."""

        def cont(env, last):
            raise _Continue

        return cont

    def if_(self, s) -> Callable:
        """``if`` / ``else if`` / ``else``."""
        tick = self.tick
        branches = [(self.compile_expr(c), self.block(b)) for c, b in s.branches]
        other = self.block(s.otherwise) if s.otherwise is not None else None

        def if_(env, last):
            tick(s)
            for c, b in branches:
                if bool(c(env)):
                    return b(env, last)
            return other(env, last) if other is not None else last

        return if_

    def for_(self, s) -> Callable:
        """``for var in first[, second] .. last``."""
        from ..language.ranges import loop_values

        tick, name = self.tick, self.name
        first, last_ = self.compile_expr(s.first), self.compile_expr(s.last)
        second = self.compile_expr(s.second) if s.second is not None else None
        body, var = self.block(s.body), s.var

        def for_(env, last):
            where = f"program of '{name}', line {s.line}"
            values = loop_values(
                rt.number(first(env), where),
                rt.number(second(env), where) if second is not None else None,
                rt.number(last_(env), where),
                what=where,
            )
            for v in values:
                tick(s)
                env[var] = float(v)
                try:
                    last = body(env, last)
                except _Break:
                    break
                except _Continue:
                    continue
            return last

        return for_

    def while_(self, s) -> Callable:
        """``while cond``."""
        tick = self.tick
        cond, body = self.compile_expr(s.condition), self.block(s.body)

        def while_(env, last):
            while True:
                tick(s)
                if not bool(cond(env)):
                    return last
                try:
                    last = body(env, last)
                except _Break:
                    return last
                except _Continue:
                    continue

        return while_

    def try_(self, s) -> Callable:
        """``try`` / ``on error``: an error of the engine raised in the first block (a value
        out of its domain, an index out of range, a solver that fails, a division by zero, an
        overflow or 0/0) runs the second from there, with what the first had set; a limit
        (the statements, the time, the elements) is no such error and stops the program."""
        tick = self.tick
        body, handler = self.block(s.body), self.block(s.handler)

        def try_(env, last):
            tick(s)
            try:
                with np.errstate(divide="raise", over="raise", invalid="raise"):
                    return body(env, last)
            except LimitError:
                raise
            except (WorkbookError, FloatingPointError):
                return handler(env, last)

        return try_


def compile_program(
    typed: TypedProgram, compile_expr: Callable[[Any], Callable], name: str
) -> Callable[[dict], Any]:
    """A closure env -> value for scalar arguments (the back end loops over arrays)."""
    compiler = _Compiler(compile_expr, name)
    steps = compiler.steps
    main = compiler.block(typed.body)
    # a local made by its elements when the program runs is the number 0 until its first
    # element is set (Mathcad's start of a local): rows(v) is 0, so v[rows(v) + 1] appends
    made = {s.name for s in walk(typed.body) if isinstance(s, SetItem) and is_runtime(s.grow)}
    assigned = frozenset(s.name for s in walk(typed.body) if isinstance(s, Assign))

    def run(env: dict):
        steps[0] = 0
        local = _Locals(env, assigned, name)
        for n in made:
            local.setdefault(n, 0.0)
        try:
            out = main(local, _NONE)
        except _Return as r:
            return _result(r.value)
        except (_Break, _Continue):
            raise TemplateError(f"'break'/'continue' outside a loop in '{name}'") from None
        if out is _NONE:
            raise NoValue(name)
        return _result(out)

    return run


class _Locals(dict):
    """A program run's names: a local read before any line gave it a value (its assignment
    under an ``if`` that was false) is an error of the program, not a missing key."""

    def __init__(self, env: dict, assigned: frozenset, program: str):
        super().__init__(env)
        self.assigned, self.program = assigned, program

    def __missing__(self, key):
        if key in self.assigned:
            raise InputError(
                f"the program of '{self.program}' reads the local '{key}' before any line "
                f"gave it a value (its assignment did not run: an 'if' that was false?)",
                definition=self.program,
            )
        raise KeyError(key)


def _result(value):
    """A program's value: an array is the program's own copy."""
    if isinstance(value, np.ndarray):
        return value.copy() if value.dtype == object else np.array(value)
    return value


#: Where a program run keeps the names of the locals it made (an argument's array is copied
#: before its first element is set); not a valid name, so no local can meet it.
_OWNED = "#owned"


def _own(env: dict, name: str) -> None:
    """Before the first element of ``name`` is set in this run: an array the run did not
    make (an argument's, the caller's) is replaced by a copy of it."""
    owned = env.setdefault(_OWNED, set())
    if name not in owned and isinstance(env.get(name), np.ndarray):
        env[name] = env[name].copy()
    owned.add(name)
