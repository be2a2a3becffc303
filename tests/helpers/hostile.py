"""Hostile worksheets run by the real command line in a fresh guarded process (forked from
one interpreter that imported the engine, tests/helpers/guard_server.py), with its memory, CPU and
wall-clock limits; and a sheet with a one-argument program."""

from __future__ import annotations

import json
import time

from helpers.guard_server import SERVER_INSTANCE

MEMORY = 1536 * 2**20  # bytes of address space for one run
CPU_SECONDS = 60
WALL_SECONDS = 120  # generous: CI machines are shared; a refused case takes about 1 s of CPU


def guarded(tmp_path, text: str | bytes, *args: str):
    """Run the command line on ``text`` (or ``args``) in a fresh guarded process."""
    path = tmp_path / "hostile.toml"
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text, encoding="utf-8")
    start = time.monotonic()
    out = SERVER_INSTANCE.run(
        tmp_path,
        list(args or ("run", path.name)),
        memory=MEMORY,
        cpu=CPU_SECONDS,
        wall=WALL_SECONDS,
    )
    out.elapsed = time.monotonic() - start
    return out


def program(body: str, value: str) -> str:
    """A sheet with a one-argument program ``p(n)`` and the definition ``s = value``."""
    return (
        '[arguments]\nn = { unit = "" }\n\n[definitions]\n"p(n)" = { program = """\n'
        + body.strip("\n")
        + '\n""" }\ns = '
        + json.dumps(value)
        + "\n"
    )
