"""Inputs edited on the live page written back into the worksheet's text: the value string
of each input's entry replaced on its line, the result read back and checked before the file
is replaced (atomically)."""

from __future__ import annotations

import json
import re
from pathlib import Path

from ..engine.sheet import coerce_input
from ..errors import InputError
from ..language.template import parse_spec
from ..outputs.atomic import replacing

_STRING = r"(\"(?:[^\"\\]|\\.)*\"|'[^']*')"


def with_inputs(text: str, spec, changes: dict[str, str]) -> str:
    """``text`` with the value of each input in ``changes`` replaced (its line is the input's
    line in ``spec``)."""
    lines = text.splitlines(keepends=True)
    for name, value in changes.items():
        i = spec.inputs.get(name)
        if i is None or not i.line:
            raise InputError(f"'{name}' is not an input of {spec.name}")
        line = lines[i.line - 1]
        quoted = json.dumps(value, ensure_ascii=False)
        inline = re.compile(r"(\bvalue\s*=\s*)" + _STRING)
        plain = re.compile(r"^(\s*[\"']?" + re.escape(name) + r"[\"']?\s*=\s*)" + _STRING)
        for pattern in (inline, plain):
            new, n = pattern.subn(lambda m, q=quoted: m.group(1) + q, line, count=1)
            if n:
                lines[i.line - 1] = new
                break
        else:
            raise InputError(
                f"the value of input {name} is not written as a string on line {i.line}; "
                "edit it in the file",
                file=str(spec.path),
                line=i.line,
                definition=name,
            )
    return "".join(lines)


def save_inputs(path: Path, changes: dict[str, str]) -> None:
    """Write ``changes`` (input name -> value text) into the worksheet at ``path``: read back,
    each input must have the value given, and nothing else may change."""
    text = path.read_text(encoding="utf-8")
    spec = parse_spec(text, path, path.stem)
    new_text = with_inputs(text, spec, changes)
    new_spec = parse_spec(new_text, path, path.stem)
    for name, value in changes.items():
        wanted = coerce_input(spec.inputs[name], value, file=str(path))
        if str(new_spec.inputs[name].value) != str(wanted):
            raise InputError(f"input {name} did not read back as {value}", file=str(path))
    with replacing(path) as tmp:
        tmp.write_text(new_text, encoding="utf-8")
