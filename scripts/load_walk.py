"""The walk through the engine's modules while a worksheet loads, counted from the calls made.

    python scripts/load_walk.py concave-cam advance-coupling

A *move* is a call from one module of the package into another, counted once per (caller
module, callee module, callee function). A *climb back up* is a move into a module that is
already on the call stack below the caller: a callback into a stage that called this one (a
unit rule of a registry entry calling the typer's conversions, declared checks calling the
Sheet). The module that dispatches visitor methods is not counted as a module of its own.
Each worksheet is loaded once before it is traced, so that importing modules is not counted.
"""

from __future__ import annotations

import collections
import sys
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field

import workbook

#: modules that only pass a call on (visitor dispatch): not rooms of the walk
TRANSPARENT = frozenset({"workbook.language.visitor"})


@dataclass
class Walk:
    moves: set[tuple[str, str, str]] = field(default_factory=set)
    climbs: set[tuple[str, str, str]] = field(default_factory=set)

    @property
    def rooms(self) -> set[str]:
        return {m for _, m, _ in self.moves} | {c for c, _, _ in self.moves}

    def climbs_by_pair(self) -> dict[tuple[str, str], int]:
        return dict(collections.Counter((c, m) for c, m, _ in self.climbs))


def walk(action: Callable[[], object]) -> Walk:
    """Trace ``action`` with a profile hook and count its moves and climbs back up."""
    stack: list[str | None] = []
    out = Walk()

    def profile(frame, event, arg):
        if event == "call":
            name = frame.f_globals.get("__name__", "")
            module = name if name.startswith("workbook") and name not in TRANSPARENT else None
            below = [m for m in stack if m is not None]
            caller = below[-1] if below else None
            if module is not None and caller is not None and module != caller:
                key = (caller, module, frame.f_code.co_qualname)
                if key not in out.moves:
                    out.moves.add(key)
                    if module in below:
                        out.climbs.add(key)
            stack.append(module)
        elif event == "return" and stack:
            stack.pop()

    sys.setprofile(profile)
    try:
        action()
    finally:
        sys.setprofile(None)
    return out


def main(names: list[str]) -> None:
    warnings.simplefilter("ignore")
    for name in names:
        workbook.load(name)
        found = walk(lambda n=name: workbook.load(n))
        by_pair = sorted(found.climbs_by_pair().items())
        pairs = ", ".join(f"{c} -> {m}: {k}" for (c, m), k in by_pair)
        print(
            f"{name}: {len(found.rooms)} modules, {len(found.moves)} moves, "
            f"{len(found.climbs)} climbs back up ({pairs})"
        )


if __name__ == "__main__":
    main(sys.argv[1:] or ["concave-cam"])
