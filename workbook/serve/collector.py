"""Python's garbage collector kept out of an edit's way: the live page and the language
server load a worksheet at every edit, and a full collection over every object of the
process (the engine, its unit registry, NumPy, SciPy) took 100 to 400 ms when it fell inside
one. What is loaded when the process starts is frozen (never traversed again), and no
collection starts while an edit is being answered; the collector resumes after it."""

from __future__ import annotations

import contextlib
import gc
import threading

_state = {"paused": 0}
_lock = threading.Lock()


def freeze_loaded() -> None:
    """Leave what the process holds now out of every later collection (call it once the
    modules are imported)."""
    gc.collect()
    gc.freeze()


@contextlib.contextmanager
def no_collection():
    """No automatic collection inside the block (blocks of several threads may overlap:
    collection resumes when the last ends)."""
    with _lock:
        _state["paused"] += 1
        gc.disable()
    try:
        yield
    finally:
        with _lock:
            _state["paused"] -= 1
            if _state["paused"] == 0:
                gc.enable()
