"""Watching files for edits by polling their modification time and size (no extra
dependency, and it sees an editor's write-and-rename as well as a write in place). A change
is reported when the file has stayed as it is for one more poll, so that a file read while
an editor is still writing it (truncated, half written) is not taken for the edit."""

from __future__ import annotations

import os
import threading
from collections.abc import Callable
from pathlib import Path

#: Seconds between two looks at the files (five watched files: about 1 % of a core,
#: measured), so that an edit is seen 10 to 20 ms after it is written.
POLL_SECONDS = 0.01


def stamp(path: Path) -> tuple[int, int, int] | None:
    """What changes when a file is written: modification time, size and inode (None: gone)."""
    try:
        st = os.stat(path)
    except OSError:
        return None
    return (st.st_mtime_ns, st.st_size, st.st_ino)


class Watcher:
    """Calls ``on_change(path)`` from its own thread when a watched file's :func:`stamp`
    changed and then held for one poll; :meth:`stop` ends the thread."""

    def __init__(self, on_change: Callable[[Path], None], interval: float = POLL_SECONDS):
        self.on_change = on_change
        self.interval = interval
        self.stamps: dict[Path, tuple | None] = {}
        self.lock = threading.Lock()
        self.stopping = threading.Event()
        self.thread = threading.Thread(target=self._run, name="workbook-watch", daemon=True)

    def watch(self, path: Path) -> None:
        """Watch ``path`` from now on (its present state is the one compared with)."""
        with self.lock:
            self.stamps.setdefault(Path(path), stamp(path))

    def start(self) -> Watcher:
        self.thread.start()
        return self

    def stop(self) -> None:
        self.stopping.set()
        if self.thread.is_alive():
            self.thread.join(timeout=5)

    def _run(self) -> None:
        seen: dict[Path, tuple | None] = {}  # a change seen once, reported when it holds
        while not self.stopping.wait(self.interval):
            with self.lock:
                paths = list(self.stamps.items())
            for path, old in paths:
                new = stamp(path)
                if new == old:
                    seen.pop(path, None)
                elif seen.get(path, "unseen") != new:
                    seen[path] = new  # an editor may be halfway through writing it
                else:
                    del seen[path]
                    with self.lock:
                        self.stamps[path] = new
                    if new is not None:
                        self.on_change(path)
