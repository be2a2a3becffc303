"""One worksheet as the language server sees it: its text loaded and unit-checked by the
engine, and the errors of the load (and, later, of the values) as located diagnostics: the
line the engine names, narrowed to the text it is about (a name it quotes, a call, the TOML
column, else the formula's string)."""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import re
import signal
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import LimitError, WorkbookError

#: Seconds the values of a document's scalar definitions may take, all together, before the
#: rest is left unchecked (their errors are diagnostics too: a domain error, a limit).
VALUES_BUDGET = 2.0

_WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_QUOTED = re.compile(r"'([A-Za-z_][A-Za-z0-9_]*)'")
_CALL = re.compile(r"\b([A-Za-z_][A-Za-z0-9_]*)\(\)")
_COLUMN = re.compile(r"\(at line (\d+), column (\d+)\)")
_STRING = re.compile(r"\"(?:[^\"\\]|\\.)*\"|'[^']*'")


@dataclass(frozen=True)
class Span:
    """A range of the text: 0-based line and characters, the end exclusive."""

    line: int
    start: int
    end_line: int
    end: int


@dataclass(frozen=True)
class Problem:
    """One diagnostic: where, the engine's kind (``unit error``) and its message."""

    span: Span
    kind: str
    message: str
    definition: str | None = None


@dataclass
class Document:
    """The text of one worksheet, loaded: ``sheet`` (None when the load failed) and the
    problems found."""

    text: str
    path: Path
    sheet: object = None
    problems: list[Problem] = field(default_factory=list)
    values: dict[str, object] = field(default_factory=dict)  # name -> quantity or error
    raw: dict | None = None  # the TOML the text reads as
    seconds: float = 0.0
    lock: threading.Lock = field(default_factory=threading.Lock)  # one evaluation at a time
    stale: bool = False  # a newer text has come: its values are no longer wanted

    @property
    def lines(self) -> list[str]:
        return self.text.splitlines()


def load(text: str, path: Path, previous: Document | None = None) -> Document:
    """Load ``text`` as the worksheet at ``path`` (the files it names are read beside it),
    typed (not computed). With ``previous`` (the last good load of the same document), only
    what the edit reaches is typed again: the definitions whose text, and whose inputs' and
    definitions' texts, did not change keep their typing and the values already computed
    (:func:`workbook.serve.incremental.successor`)."""
    from ..language.template import MAX_TEMPLATE_BYTES, parse_spec, read_toml
    from ..serve.incremental import successor

    t0 = time.perf_counter()
    doc = Document(text, path)
    try:
        if len(text.encode("utf-8")) > MAX_TEMPLATE_BYTES:
            raise LimitError(f"template text is larger than {MAX_TEMPLATE_BYTES:,} bytes")
        doc.raw = read_toml(text, str(path))  # read once: the spec is built from it
        spec = parse_spec(text, path, path.stem, doc.raw)
        old = previous.sheet if previous is not None else None
        old_raw = previous.raw if previous is not None else {}
        values = {n: i.value for n, i in spec.inputs.items()}
        doc.sheet = successor(old, old_raw or {}, spec, doc.raw, values)[0]
    except WorkbookError as err:
        doc.problems.append(problem(doc.lines, err))
    except RecursionError:
        doc.problems.append(
            Problem(Span(0, 0, 0, 0), "limit exceeded", "nested too deeply for the engine")
        )
    doc.seconds = time.perf_counter() - t0
    return doc


def compute_values(doc: Document, budget: float = VALUES_BUDGET) -> list[Problem]:
    """The values of the scalar definitions and the range tables, until ``budget`` seconds
    are spent; the problems of those that fail (domain errors, limits, a value outside its
    bounds, a range without points)."""
    sheet = doc.sheet
    if sheet is None:
        return []
    found = []
    start = time.perf_counter()
    for name, d in sheet.spec.definitions.items():
        if doc.stale or time.perf_counter() - start > budget:
            break
        if d.is_function:
            continue
        try:
            with doc.lock:
                doc.values[name] = sheet.scalar_quantity(name)
        except WorkbookError as err:
            doc.values[name] = err
            p = problem(doc.lines, err)
            if p not in found:
                found.append(p)
        except (ArithmeticError, ValueError, RecursionError) as exc:  # kept as a diagnostic
            doc.values[name] = exc
    for t in sheet.spec.tables:  # range tables: their ranges and columns
        if doc.stale or time.perf_counter() - start > budget:
            break
        if t.computed or t.range is None:
            continue
        try:
            with doc.lock:
                sheet.table_data(t)
        except WorkbookError as err:
            p = problem(doc.lines, err)
            if p not in found:
                found.append(p)
    return found


def values_apart(doc: Document, budget: float = VALUES_BUDGET) -> list[Problem] | None:
    """:func:`compute_values` in a child process (forked: it has the document as it is), so
    that the typing of the next change does not share the interpreter with a long value (an
    ODE, a block); None when a newer text came first (the child is stopped) or the child
    failed. Where a process cannot be forked, computed here."""
    if not hasattr(os, "fork"):
        return compute_values(doc, budget)
    receive, send = multiprocessing.Pipe(duplex=False)
    pid = os.fork()
    if pid == 0:  # the child: answers through the pipe, writes nothing else, never returns
        status = 0
        try:
            receive.close()
            doc.lock = threading.Lock()  # another thread of the parent may have held it
            send.send(compute_values(doc, budget))
        except BaseException:  # noqa: BLE001 - the parent is told by the closed pipe
            status = 1
        finally:
            os._exit(status)  # no buffer of the parent's (its stdout) is flushed twice
    send.close()
    try:
        while not doc.stale:
            if receive.poll(0.02):
                try:
                    return receive.recv()
                except (EOFError, OSError):
                    return None
        return None
    finally:
        receive.close()
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)


def problem(lines: list[str], err: WorkbookError) -> Problem:
    """The error as a diagnostic at the text it names."""
    return Problem(span_of(lines, err), err.kind, err.message, err.definition)


def span_of(lines: list[str], err: WorkbookError) -> Span:
    """Where ``err`` is in the text: its line (else its definition's line, else the first),
    narrowed to what the message is about."""
    number = err.line
    if number is None and err.definition:
        number = _line_of_key(lines, err.definition)
    m = _COLUMN.search(err.message)
    if m:  # TOML syntax: the column the reader stopped at
        number = number or int(m.group(1))
        row = int(m.group(1)) - 1
        col = max(int(m.group(2)) - 1, 0)
        if row < len(lines):
            return Span(row, col, row, max(col + 1, len(lines[row])))
    row = (number or 1) - 1
    if row >= len(lines) or row < 0:
        return Span(0, 0, 0, 0)
    text = lines[row]
    after = text.index("=") + 1 if "=" in text else 0
    for name in _QUOTED.findall(err.message):
        if name == err.definition and "unknown" not in err.message:
            continue
        found = _word_at(text, name, after)
        if found is not None:
            return Span(row, found, row, found + len(name))
    for name in _CALL.findall(err.message):
        found = _word_at(text, name, after)
        if found is not None:
            return Span(row, found, row, found + len(name))
    strings = [m for m in _STRING.finditer(text) if m.start() >= after]
    if strings:  # the formula (or value): the first string after the key
        chosen = next((m for m in strings if "expr" in text[: m.start()]), strings[0])
        return Span(row, chosen.start() + 1, row, max(chosen.end() - 1, chosen.start() + 1))
    start = len(text) - len(text.lstrip())
    return Span(row, start, row, len(text))


def _word_at(text: str, word: str, after: int) -> int | None:
    for m in _WORD.finditer(text, after):
        if m.group(0) == word:
            return m.start()
    for m in _WORD.finditer(text):
        if m.group(0) == word:
            return m.start()
    return None


def _line_of_key(lines: list[str], name: str) -> int | None:
    pattern = re.compile(r'^\s*["\']?' + re.escape(name) + r"(\(|[\"']?\s*=)")
    for i, text in enumerate(lines, start=1):
        if pattern.match(text):
            return i
    return None


def word_at(line: str, character: int) -> tuple[str, int, int] | None:
    """The name under the cursor (and its start and end), or None."""
    for m in _WORD.finditer(line):
        if m.start() <= character <= m.end():
            return m.group(0), m.start(), m.end()
    return None


def section_at(lines: list[str], row: int) -> str | None:
    """The TOML section the line ``row`` is in (``inputs``, ``tables`` for ``[[tables]]``)."""
    for text in reversed(lines[: row + 1]):
        s = text.strip()
        if s.startswith("["):
            return s.strip("[]").strip().split(".")[0]
    return None
