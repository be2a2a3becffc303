"""A typed program without loops as one live spreadsheet formula (a nested IF)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from .statements import Assign, If, Return, SetItem, Stmt, Try, Value, walk
from .typer import TypedProgram


# -- a live spreadsheet formula ---------------------------------------------------------------
def excel_value(typed: TypedProgram, printed: Callable[[Any, dict], str], subst: dict) -> str:
    """A program without loops as one nested IF: locals are replaced by their formulas and
    each branch carries the statements after it. A loop has no formula (NotLive)."""
    from ..errors import NotLive

    if typed.loops:
        raise NotLive("a program with a loop is written as values")
    if any(isinstance(st, Try) for st in walk(typed.body)):
        raise NotLive("a program with try / on error is written as values")

    def run(stmts: list[Stmt], s: dict, last: str | None) -> str:
        for k, st in enumerate(stmts):
            if isinstance(st, SetItem):  # pragma: no cover - typed as a loop (values)
                raise NotLive("a program that sets elements is written as values")
            if isinstance(st, Assign):
                s = {**s, st.name: f"({printed(st.value, s)})"}
            elif isinstance(st, Value):
                last = printed(st.value, s)
            elif isinstance(st, Return):
                return printed(st.value, s)
            elif isinstance(st, If):
                rest = list(stmts[k + 1 :])
                tail = run(list(st.otherwise or ()) + rest, s, last)
                for cond, block in reversed(st.branches):
                    tail = f"IF({printed(cond, s)}, {run(list(block) + rest, s, last)}, {tail})"
                return tail
            else:  # pragma: no cover - loops were refused above
                raise NotLive("a loop is written as values")
        return last if last is not None else "NA()"

    # a local read where its assignment did not run (under a false `if`) has no value: #N/A,
    # as the engine's error there
    unset = {st.name: "NA()" for st in walk(typed.body) if isinstance(st, Assign)}
    return run(list(typed.body), {**unset, **subst}, None)
