"""One interpreter that imports the engine once and forks a guarded child per hostile case.

Each case still runs the real command line in a process of its own, with its own address-space
and CPU-time limits, a wall-clock timeout and an audit hook installed before the command runs;
only the imports, which are most of a refused case's time, are shared.
"""

from __future__ import annotations

import atexit
import json
import os
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

SERVER = r"""
import json, os, resource, sys, time, traceback
import numpy, pint, workbook
import workbook.cli, workbook.engine.sheet, workbook.language.template, workbook.language.units
import workbook.language.typecheck, workbook.engine.numeric
import workbook.compute.checks, workbook.blocks
workbook.language.units.registry()
from workbook.cli import main
SYSTEM = {"subprocess", "socket", "ctypes", "pickle", "shutil", "multiprocessing", "pty",
          "webbrowser", "http", "urllib", "ftplib", "smtplib", "telnetlib", "code", "pdb"}
SPAWN = ("os.system", "os.exec", "os.posix_spawn", "os.spawn", "os.fork", "subprocess.Popen",
         "os.remove", "os.rename", "os.rmdir", "os.unlink", "shutil.", "socket.")


def case(request):
    os.chdir(request["cwd"])
    for fd, name in ((1, "stdout"), (2, "stderr")):
        out = os.open(request[name], os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        os.dup2(out, fd)
        os.close(out)
    memory, cpu = request["memory"], request["cpu"]
    resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
    resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu))
    roots = tuple(os.path.realpath(p) for p in {sys.prefix, sys.base_prefix, sys.exec_prefix,
                  os.path.dirname(os.path.dirname(workbook.__file__)), os.getcwd()})
    events = []

    def hook(event, args):
        if event == "open":
            path, mode, flags = args
            if isinstance(path, int) or path is None:
                return
            path = os.fsdecode(path)
            writing = (isinstance(mode, str) and any(c in mode for c in "wax+")) or (
                isinstance(flags, int) and flags & (os.O_WRONLY | os.O_RDWR | os.O_CREAT))
            real = os.path.realpath(path)
            if writing or not real.startswith(roots):
                events.append(f"open {path} {mode!r}")
        elif event == "import" and args[0].split(".")[0] in SYSTEM:
            events.append(f"import {args[0]}")
        elif event.startswith(SPAWN):
            events.append(event)

    sys.argv = ["workbook", *request["args"]]
    sys.addaudithook(hook)
    try:
        code = main(request["args"])
    except SystemExit as stop:
        code = stop.code if isinstance(stop.code, int) else 1
    except BaseException:
        traceback.print_exc()
        code = 1
    print("AUDIT " + json.dumps(events))
    return code


for line in sys.stdin:
    request = json.loads(line)
    sys.stdout.flush()
    sys.stderr.flush()
    pid = os.fork()
    if pid == 0:
        code = 1
        try:
            code = case(request)
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            os._exit(code if isinstance(code, int) else 1)
    deadline = time.monotonic() + request["wall"]
    while True:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            break
        if time.monotonic() > deadline:
            os.kill(pid, 9)
            os.waitpid(pid, 0)
            status = None
            break
        time.sleep(0.01)
    code = None if status is None else os.waitstatus_to_exitcode(status)
    print(json.dumps({"returncode": code}), flush=True)
"""


@dataclass
class Outcome:
    """What a guarded case printed and its exit status (negative: ended by that signal)."""

    returncode: int
    stdout: str
    stderr: str
    events: list[str] | None = field(default=None)
    elapsed: float = 0.0


class GuardServer:
    """The forking interpreter, started at first use and shared by every test."""

    def __init__(self) -> None:
        self._process: subprocess.Popen | None = None
        self._folder = Path(tempfile.mkdtemp(prefix="workbook-guard-"))
        atexit.register(self.close)

    def close(self) -> None:
        """End the server (its input closed, its loop ends) and remove its folder."""
        if self._process is not None and self._process.poll() is None:
            self._process.stdin.close()
            self._process.wait(timeout=30)
        shutil.rmtree(self._folder, ignore_errors=True)

    def _start(self) -> subprocess.Popen:
        if self._process is None or self._process.poll() is not None:
            env = dict(
                os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1"
            )
            self._process = subprocess.Popen(
                [sys.executable, "-c", SERVER],
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                text=True,
                env=env,
            )
        return self._process

    def run(self, cwd: Path, args: list[str], *, memory: int, cpu: int, wall: float) -> Outcome:
        """Run ``workbook *args`` in ``cwd`` in a fresh guarded child; a case that outlasts
        ``wall`` seconds raises subprocess.TimeoutExpired."""
        server = self._start()
        out, err = self._folder / "stdout", self._folder / "stderr"
        request = dict(
            cwd=str(cwd), args=args, memory=memory, cpu=cpu, wall=wall, stdout=str(out),
            stderr=str(err),
        )  # fmt: skip
        server.stdin.write(json.dumps(request) + "\n")
        server.stdin.flush()
        reply = server.stdout.readline()
        if not reply:
            raise RuntimeError(f"the guard server ended (status {server.wait()})")
        code = json.loads(reply)["returncode"]
        if code is None:
            raise subprocess.TimeoutExpired(args, wall)
        stdout = out.read_text(encoding="utf-8", errors="replace")
        stderr = err.read_text(encoding="utf-8", errors="replace")
        audit = [line for line in stdout.splitlines() if line.startswith("AUDIT ")]
        events = json.loads(audit[-1][6:]) if audit else None
        return Outcome(code, stdout, stderr, events)


SERVER_INSTANCE = GuardServer()
