"""VBA's arguments passed by reference: a function that changes such a parameter changes the
caller's variable. ``x = G(a, b)`` with variables there calls ``G_refs``, G's program whose
value is ``[value, the changed parameters...]``, and the caller's variables take them back."""

from __future__ import annotations

import re
from typing import Protocol

from .vbaexpr import strip
from .vbamembers import NotTranslated
from .vbatypes import INTEGER_TYPES, bankers


class Translated(Protocol):
    """What the ``_refs`` program reads of a translated function (vbaprogram's FunctionInfo)."""

    final: str
    params: list[str]
    refs: list[int]
    program: str


class ByReference:
    """The calls that read back parameters changed by reference (mixed into the Translator
    of vbaprogram)."""

    def assign_by_reference(self, target, rhs, indent: int) -> bool:
        """``x = G(a, b, ...)`` where G changes parameters passed by reference (VBA's default)
        and the caller gives variables there: G's program is also written as ``G_refs``, whose
        value is ``[value, the changed parameters...]``, and the caller's variables take those
        values after the call, as VBA's do (False where the call is not of that form)."""
        own = target[1].lower() == self.proc.name.lower()  # FunctionName = G(...)
        if rhs[0] != "call" or strip(rhs[1])[0] != "id" or (own and self.text_function):
            return False
        key = strip(rhs[1])[1].lower()
        positions = sorted(self.changed_params.get(key, ()))
        if key not in self.functions or not positions or key in self.arrays:
            return False
        args = rhs[2]
        given = [(k, strip(args[k])) for k in positions if k < len(args) and args[k] is not None]
        special = {"true", "false", "empty", "vbnullstring", "pi", self.proc.name.lower()}
        if any(
            n[0] == "call" and strip(n[1])[0] == "id" and strip(n[1])[1].lower() in self.arrays
            for _, n in given
        ):
            return False  # an array element: the refusal of the call
        # an expression is passed as a temporary: only variables take the values back
        given = [
            (k, n)
            for k, n in given
            if n[0] == "id" and n[1].lower() not in special and n[1].lower() not in self.functions
        ]
        names = [n[1].lower() for _, n in given]
        if len(set(names)) != len(names):
            raise NotTranslated(f"passes one variable twice to {self.functions[key].proc.name}")
        for _, node in given:
            self.name(node[1])  # an undeclared variable is a local (Empty, 0, until set)
        text = self._call_function(key, args, refs=positions)
        values = self.temp("refs")
        self.emit(indent, f"{values} := {text}")
        for k, node in given:
            self.emit(indent, f"{self.local(node[1])} := {values}[{positions.index(k) + 1}]")
        if not own:
            self.emit(indent, f"{self.local(target[1])} := {values}[0]")
            return True
        value = f"{values}[0]"
        if self.proc.returns.lower() in INTEGER_TYPES:
            value = bankers(value)  # VBA rounds the value of an Integer function
        self.emit(indent, f"{self.ret} := {value}")
        if self.error_flag is not None:
            self.emit(indent, f"{self.error_flag} := 0")
        self.assigned = True
        return True


def refs_name(info: Translated) -> str:
    """The name of a function's program that also gives its parameters changed by reference."""
    return f"{info.final}_refs"


def refs_program(info: Translated) -> str:
    """The function's program whose value is ``[value, the parameters at info.refs...]``:
    its last line and each ``return`` give the vector."""
    outs = ", ".join(info.params[k] for k in info.refs)
    lines = info.program.split("\n")
    out = []
    for line in lines[:-1]:
        m = re.match(r"^(\s*)return (.*)$", line)
        if not m:
            out.append(line)
            continue
        value, guard = _statement_guard(m.group(2))
        out.append(f"{m.group(1)}return [{value}, {outs}]{guard}")
    out.append(f"[{lines[-1].strip()}, {outs}]")
    return "\n".join(out)


def _statement_guard(text: str) -> tuple[str, str]:
    """``1/0 if flag != 0`` -> (``1/0``, `` if flag != 0``): the condition of a statement,
    at the top level (an ``if`` inside brackets is part of the value)."""
    depth = 0
    for i, ch in enumerate(text):
        depth += {"(": 1, "[": 1, ")": -1, "]": -1}.get(ch, 0)
        if depth == 0 and text.startswith(" if ", i):
            return text[:i], text[i:]
    return text, ""
