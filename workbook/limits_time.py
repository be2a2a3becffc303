"""The time budget of one command, and time limits of the blocks inside it.

A command (``workbook run``, ``check``, ``sweep``, ...) has one budget of CPU time (with a
wall-clock cap of :data:`WALL_FACTOR` times it), set when
it starts (:func:`command_budget`): the default :data:`DEFAULT_SECONDS`, lowered by a
worksheet's ``[sheet] time_limit`` or set by ``--time-limit`` up to :data:`MAX_SECONDS`.
The work that can run long checks it along the way (:func:`check_time`: a program's
statements, a table's rows, an ODE's steps and right-hand sides, a sweep's cases, the
writer); where no check is reached, an alarm stops the command :data:`GRACE_SECONDS` after
the budget. Either way the command stops with :class:`OutOfBudget`, which is not a value that
fails (no handler of :class:`workbook.errors.WorkbookError` keeps it): the command line
prints one paragraph naming the work and exits 2.

:func:`within_seconds` bounds one block inside the command (SymPy's derivative) by the same
alarm: it stops at its own limit or at the budget, whichever comes first.
"""

from __future__ import annotations

import contextlib
import signal
import threading
import time
from dataclasses import dataclass, field

from .errors import LimitError, OutOfBudget

#: The budget of one command, in seconds of its CPU time, when neither the worksheet nor the
#: command line sets one. CPU time, not wall-clock time: on a machine shared with other work
#: a command is given its time, not cut short by the others (the shipped templates with every
#: part take 2 to 9 s of CPU, and took up to 65 s of wall-clock time at a load average near 13
#: on 2 cores).
DEFAULT_SECONDS = 20.0
#: The most ``--time-limit`` may give; a worksheet's ``[sheet] time_limit`` may only lower
#: the default (a file cannot give itself more time).
MAX_SECONDS = 3600.0
#: Wall-clock time is bounded too, at this many times the budget: a command that waits (on
#: a process pool, a starved machine) stops as well.
WALL_FACTOR = 5.0
#: The alarm that stops work no check reaches comes this long after the budget.
GRACE_SECONDS = 0.5
#: Seconds between repeated alarms once the time is up: an alarm that lands in a weakref
#: callback or a ``__del__`` is printed and ignored by Python, so one alarm is not enough.
ALARM_REPEAT_SECONDS = 0.05


@dataclass
class Budget:
    """The time budget of one command: ``seconds`` of its CPU time (its threads' included),
    and :data:`WALL_FACTOR` times that of wall-clock time."""

    seconds: float
    source: str  # how it was set: "the default", "--time-limit", "[sheet] time_limit"
    start: float = field(default_factory=time.monotonic)
    cpu_start: float = field(default_factory=time.process_time)
    doing: str = "the command"  # the last work that checked the budget

    def left(self) -> float:
        """Seconds left: of CPU time, or of wall-clock time when that is nearer its cap."""
        cpu = self.seconds - (time.process_time() - self.cpu_start)
        wall = WALL_FACTOR * self.seconds - (time.monotonic() - self.start)
        return min(cpu, wall)

    def spent(self, what: str, definition: str | None = None) -> OutOfBudget:
        """The error of running past the budget while doing ``what``."""
        cpu = time.process_time() - self.cpu_start
        wall = time.monotonic() - self.start
        kind = (
            f"{self.seconds:g} s of CPU time"
            if cpu >= self.seconds
            else f"{WALL_FACTOR * self.seconds:g} s of wall-clock time, {WALL_FACTOR:g} times its "
            f"{self.seconds:g} s of CPU time"
        )
        return OutOfBudget(
            LimitError(
                f"{what} ran past the time budget of this command ({kind}, {self.source}; "
                f"{cpu:.1f} s of CPU in {wall:.1f} s); make it do less work (fewer rows, "
                f"points, cases or steps, a looser tolerance), or give it more time with "
                f"--time-limit SECONDS (at most {MAX_SECONDS:g})",
                definition=definition,
            )
        )


_budget: Budget | None = None
_blocks: list[list] = []  # [deadline, armed, expired exception class] of within_seconds


def current() -> Budget | None:
    """The budget of the running command (None outside one: the Python API is unbounded)."""
    return _budget


def remaining() -> float | None:
    """Seconds left of the command's budget (None outside a command)."""
    return None if _budget is None else _budget.left()


def check_time(what: str, definition: str | None = None) -> None:
    """Stop with :class:`OutOfBudget` when the command's budget is spent; ``what`` names the
    work (a table, a program line, an ODE), ``definition`` the definition it computes."""
    b = _budget
    if b is None:
        return
    b.doing = what
    if b.left() < 0:
        raise b.spent(what, definition)


def budgeted(fun, what: str, definition: str | None = None):
    """``fun`` checking the command's budget before each call (an ODE's right-hand side:
    every step of every solver calls it, an implicit one also for its Jacobian)."""
    if _budget is None:
        return fun

    def checked(*args):
        check_time(what, definition)
        return fun(*args)

    return checked


def within_budget(seconds: float) -> float:
    """``seconds``, or less when the command's budget ends sooner (an optional run, as an
    error estimate's reference, stops at its own limit before the command's)."""
    left = remaining()
    return seconds if left is None else max(min(seconds, left - GRACE_SECONDS), 1e-3)


def check_seconds(seconds, source: str) -> float:
    """A budget given by ``source`` as a number of seconds, within (0, MAX_SECONDS]."""
    try:
        value = float(seconds)
    except (TypeError, ValueError):
        value = float("nan")
    if isinstance(seconds, bool) or not 0 < value <= MAX_SECONDS:
        raise LimitError(
            f"{source} {seconds!r}: give a number of seconds above 0 and at most {MAX_SECONDS:g}"
        )
    return value


#: What the default budget grows by for each item a command was given: a definition, an
#: input or a printed value of a worksheet, a kilobyte of a file to import. Work in proportion
#: to what a file states is its own (an imported workbook of 7,597 definitions and 10,261
#: printed values took 41 s of CPU to check, its import from a 330 kB file 61 s); work that
#: grows faster than that (a row summing up to its own index) still meets the default.
SECONDS_PER_ITEM = 0.005
SECONDS_PER_KILOBYTE = 0.5
#: The most the default grows to by the size of what it is given.
MAX_SIZED_SECONDS = 600.0


def grow_default(extra: float, what: str) -> None:
    """Let the default budget of the running command be :data:`DEFAULT_SECONDS` plus
    ``extra`` (at most :data:`MAX_SIZED_SECONDS`) for the size of ``what`` it was given; a
    budget set by ``--time-limit`` or a worksheet's ``time_limit`` is left as it is."""
    b = _budget
    if b is None or not b.source.startswith("the default"):
        return
    seconds = min(DEFAULT_SECONDS + extra, MAX_SIZED_SECONDS)
    if seconds > b.seconds:
        b.seconds, b.source = seconds, f"the default for the size of {what}"
        _arm()


def set_seconds(seconds: float, source: str) -> None:
    """Give the running command's budget ``seconds`` from its start (a worksheet's
    ``time_limit``, read once it is loaded)."""
    if _budget is not None:
        _budget.seconds, _budget.source = seconds, source
        _arm()


def _main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


@contextlib.contextmanager
def command_budget(seconds: float = DEFAULT_SECONDS, source: str = "the default"):
    """The block is one command with a budget of ``seconds``; in the main thread, an alarm
    stops work that no :func:`check_time` reaches. Outside the main thread, or inside another
    budget, the block runs under the budget already there (or none)."""
    global _budget
    if _budget is not None or not _main_thread():
        yield
        return
    _budget = Budget(seconds, source)
    previous = signal.signal(signal.SIGALRM, _on_alarm)
    _arm()
    try:
        yield
    finally:
        _budget = None
        if not _blocks:
            signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def disarm() -> None:
    """No further alarm for the budget (its error is being reported)."""
    global _budget
    _budget = None
    if not _blocks:
        signal.setitimer(signal.ITIMER_REAL, 0)


def _deadlines() -> list[float]:
    """When the alarm is next due (monotonic): a block's limit, or the budget's grace past the
    time it has left (CPU time runs at most as fast as wall-clock time in one thread: a
    command whose threads run in parallel is caught at the next check or alarm)."""
    out = [b[0] for b in _blocks if b[1]]
    if _budget is not None:
        out.append(time.monotonic() + max(_budget.left(), 0.0) + GRACE_SECONDS)
    return out


def _arm() -> None:
    times = _deadlines()
    if not times or not _main_thread():
        return
    wait = max(min(times) - time.monotonic(), 1e-3)
    signal.setitimer(signal.ITIMER_REAL, wait, ALARM_REPEAT_SECONDS)


def _importing(frame) -> bool:
    """The interrupted code is inside an import: an exception raised there would leave a
    module half initialised in ``sys.modules`` (a later import of it fails)."""
    while frame is not None:
        if frame.f_code.co_filename.startswith("<frozen importlib"):
            return True
        frame = frame.f_back
    return False


def _on_alarm(signum, frame) -> None:
    if _importing(frame):
        return  # the alarm repeats: it is raised once the import is done
    now = time.monotonic()
    for block in reversed(_blocks):
        if block[1] and now >= block[0]:
            raise block[2]
    b = _budget
    if b is not None and b.left() < -GRACE_SECONDS * 0.9:
        raise b.spent(f"the work on {b.doing}" if b.doing != "the command" else b.doing)
    _arm()  # not yet due (CPU time runs behind wall-clock time on a busy machine): later


@contextlib.contextmanager
def within_seconds(seconds: float, what: str):
    """Stop the block with a LimitError after ``seconds`` of wall-clock time (SIGALRM: pure
    Python work such as SymPy's is interrupted between bytecodes; the alarm repeats until the
    block has stopped), or with :class:`OutOfBudget` when the command's budget is spent first.
    Only in the main thread of a process where no other timer is set; elsewhere the block
    runs unbounded."""
    if not _main_thread() or (
        _budget is None and not _blocks and signal.getitimer(signal.ITIMER_REAL)[0] > 0
    ):
        yield
        return

    class _Expired(Exception):
        pass

    block = [time.monotonic() + seconds, True, _Expired]
    outermost = _budget is None and not _blocks
    previous = signal.signal(signal.SIGALRM, _on_alarm) if outermost else None
    _blocks.append(block)
    _arm()
    expired = False
    try:
        try:
            yield
        finally:
            block[1] = False  # an alarm raised before this line is caught just below
    except _Expired:
        expired = True
    finally:
        block[1] = False
        _blocks.remove(block)
        if outermost:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, previous)
        else:
            _arm()
    if expired:
        raise LimitError(f"{what} took more than {seconds:g} s")
