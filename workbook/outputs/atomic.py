"""Write output files so that an error or Ctrl-C never leaves a half-written file."""

from __future__ import annotations

import contextlib
import errno
import os
import re
import shutil
import signal
import sys
import tempfile
import threading
import zipfile
from pathlib import Path

from ..errors import InputError
from ..language.csvcells import csv_text
from ..limits import writable_target


class Terminated(KeyboardInterrupt):
    """SIGTERM (what ``timeout``, ``kill`` and service managers send), handled as Ctrl-C: the
    temporary files are removed and no output file is changed."""


@contextlib.contextmanager
def sigterm_as_interrupt():
    """Within the block, SIGTERM raises :class:`Terminated` in the main thread (by default it
    ends the process at once, leaving ``.NAME.partial`` folders beside the targets), and
    Ctrl-C raises KeyboardInterrupt as usual. A process forked meanwhile (a sweep's worker)
    still ends at once on SIGTERM.

    Python prints and drops an exception raised where nothing can catch it (a weakref
    callback, ``__del__``, the garbage collector): an interrupt raised there would be lost,
    and the command would go on or leave ``.partial`` folders. Within the block such an
    interrupt is not printed: the same signal is sent again, and handled at the next point
    where it can raise (held, like any signal, while outputs are moved into place)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    pid = os.getpid()
    in_hook = False

    def send_again(signum: int) -> None:
        # from another thread, so that the handler runs after the code that dropped it
        threading.Timer(0.001, os.kill, (pid, signum)).start()

    def on_signal(signum, frame):
        if os.getpid() != pid:  # a forked worker ends at once, as by default
            signal.signal(signum, signal.SIG_DFL)
            os.kill(os.getpid(), signum)
            return
        if in_hook:  # raised here it would be dropped again
            send_again(signum)
            return
        raise Terminated if signum == signal.SIGTERM else KeyboardInterrupt

    previous_hook = sys.unraisablehook

    def hook(unraisable):
        nonlocal in_hook
        exc = unraisable.exc_value
        if not isinstance(exc, KeyboardInterrupt) or os.getpid() != pid:
            previous_hook(unraisable)
            return
        in_hook = True
        try:
            send_again(signal.SIGTERM if isinstance(exc, Terminated) else signal.SIGINT)
        finally:
            in_hook = False

    previous_term = signal.signal(signal.SIGTERM, on_signal)
    # Ctrl-C only where Python's own handler is in force (not where it is ignored)
    previous_int = signal.getsignal(signal.SIGINT)
    if previous_int is signal.default_int_handler:
        signal.signal(signal.SIGINT, on_signal)
    sys.unraisablehook = hook
    try:
        yield
    finally:
        sys.unraisablehook = previous_hook
        signal.signal(signal.SIGTERM, previous_term)
        if previous_int is signal.default_int_handler:
            signal.signal(signal.SIGINT, previous_int)


#: Signals held while outputs are moved into place and temporary files removed: a signal
#: then is handled just after, so that every output is old or new and nothing is left over.
_HELD = (signal.SIGINT, signal.SIGTERM, signal.SIGALRM)


@contextlib.contextmanager
def signals_held():
    """Hold Ctrl-C, SIGTERM and the time budget's alarm until the block is done (only in
    the main thread, where Python runs signal handlers)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, _HELD)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def check_target(path: Path, *, kind: str = "xlsx", force: bool = False) -> None:
    """Refuse a directory, a missing parent folder, a FIFO or device, an existing file of
    another kind; an existing CSV is overwritten only with ``force``."""
    writable_target(path)
    if path.is_dir():
        raise InputError(
            f"output path {path} is a directory; give a file name like {path}/report.{kind}"
        )
    if not path.parent.exists():
        raise InputError(f"output folder {path.parent} does not exist")
    if path.exists() and not force and kind == "xlsx" and not _is_xlsx(path):
        raise InputError(f"{path} exists and is not an xlsx workbook; use --force to overwrite it")
    if path.exists() and not force and kind == "csv":  # a CSV cannot be recognised as ours
        raise InputError(f"{path} exists; use --force to overwrite it")


def _is_xlsx(path: Path) -> bool:
    try:
        with zipfile.ZipFile(path) as z:
            return "[Content_Types].xml" in z.namelist()
    except (zipfile.BadZipFile, OSError):
        return False


def _mode_for(path: Path) -> int:
    """Keep an existing file's permissions; a new file gets the usual 0666 less the umask."""
    try:
        return path.stat().st_mode & 0o7777
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


def os_error(path: Path, exc: OSError) -> InputError:
    """An error of the file system (disk full, read-only, name too long) as an input error
    naming the output (not the temporary file beside it that was being written)."""
    hint = {
        errno.ENOSPC: "; the disk is full: free some space, or write elsewhere",
        errno.EDQUOT: "; the disk quota is used up: free some space, or write elsewhere",
        errno.EROFS: "; write elsewhere",
        errno.EACCES: "; write elsewhere, or change the folder's permissions",
        errno.EPERM: "; write elsewhere, or change the folder's permissions",
    }.get(exc.errno, "")
    return InputError(f"cannot write {target_of(Path(path))}: {exc.strerror or exc}{hint}")


_PARTIAL = re.compile(r"^\.(.+)\.[^.]+\.partial$")


def target_of(path: Path) -> Path:
    """The output a temporary path stands for: ``DIR/.NAME.XXXX.partial/...`` is
    ``DIR/NAME`` (the first such part of the path); any other path is itself."""
    parts = path.parts
    for k, part in enumerate(parts):
        m = _PARTIAL.match(part)
        if m:
            return Path(*parts[:k], m.group(1)) if k else Path(m.group(1))
    return path


@contextlib.contextmanager
def replacing(path: Path):
    """Yield a temporary path beside ``path``; move it into place only if the block succeeds.

    ``path`` must be new or a regular file: moving a file over a device or FIFO would replace
    the node itself."""
    writable_target(path)
    try:
        fd, tmp = tempfile.mkstemp(
            prefix=f".{path.name[:100]}.", suffix=".partial", dir=path.parent
        )
    except OSError as exc:
        raise os_error(path, exc) from None
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        yield tmp_path
        with signals_held():
            os.chmod(tmp_path, _mode_for(path))
            os.replace(tmp_path, path)
    except BaseException as exc:  # includes KeyboardInterrupt: the old file stays as it was
        with signals_held(), contextlib.suppress(OSError):
            tmp_path.unlink()
        if isinstance(exc, OSError):
            raise os_error(path, exc) from None
        raise


#: The outputs moved into place by :class:`Outputs` in this process: a Ctrl-C held until
#: they were complete is said to have come after them.
MOVED: list[Path] = []


class Outputs:
    """Several output files written as one: each is written to a temporary folder beside its
    target, and all are moved into place only when every one is complete (an error in the
    last leaves every earlier target as it was).

        with Outputs(force=False) as outs:
            tmp = outs.add(Path("a.xlsx"), "xlsx")   # checked now, before anything is written
            ...write tmp...
    """

    def __init__(self, *, force: bool = False):
        self.force = force
        self.items: list[tuple[Path, Path]] = []  # (target, temporary path)

    def add(self, path: Path, kind: str) -> Path:
        """Check ``path`` as a target of ``kind`` and return the temporary path to write."""
        path = Path(path)
        check_target(path, kind=kind, force=self.force)
        if any(os.path.abspath(t) == os.path.abspath(path) for t, _ in self.items):
            raise InputError(f"{path} is named twice as an output")
        try:
            folder = tempfile.mkdtemp(
                prefix=f".{path.name[:100]}.", suffix=".partial", dir=path.parent
            )
        except OSError as exc:
            raise os_error(path, exc) from None
        self.items.append((path, Path(folder) / path.name))
        return self.items[-1][1]

    def __enter__(self) -> Outputs:
        return self

    def __exit__(self, kind, exc, tb) -> None:
        with signals_held():
            self._finish(kind is None)

    def _finish(self, complete: bool) -> None:
        """Move every output into place (``complete``) and remove the temporary folders."""
        try:
            if complete:
                for target, tmp in self.items:
                    if not tmp.exists():
                        raise RuntimeError(f"{target} was not written")
                for target, tmp in self.items:
                    try:
                        os.chmod(tmp, _mode_for(target))
                        os.replace(tmp, target)
                    except OSError as err:
                        raise os_error(target, err) from None
                    MOVED.append(target)
        finally:
            for _, tmp in self.items:
                shutil.rmtree(tmp.parent, ignore_errors=True)


def write_csv(frame, path: Path) -> None:
    """A table (pandas DataFrame) as CSV; every text cell and header that a spreadsheet would
    run as a formula gets a leading apostrophe (:func:`csv_text`). Cells are escaped by their
    value, whatever the column's dtype (pandas gives text columns ``object``, ``str`` or
    ``category``); only columns of numbers are left as they are."""
    frame = frame.rename(columns=lambda c: csv_text(str(c)))
    for name in frame.columns:
        if frame[name].dtype.kind not in "biufcmM":  # not numbers, booleans or times
            frame[name] = frame[name].map(_csv_cell).astype(object)
    try:
        frame.to_csv(path, index=False, lineterminator="\r\n")
    except OSError as exc:
        raise os_error(path, exc) from None


def _csv_cell(value):
    return csv_text(value) if isinstance(value, str) else value
