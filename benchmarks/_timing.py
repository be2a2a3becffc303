"""Shared helpers: alternate two timed callables, take medians, print one result line."""

from __future__ import annotations

import os
import platform
import statistics
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


@dataclass
class Result:
    name: str  # what is compared
    value: float  # the measured ratio (or seconds, for a limit)
    target: float
    unit: str = "x"  # "x" for a ratio
    detail: str = ""  # the medians behind the ratio
    info: bool = False  # shown for information: not one of the targets

    @property
    def ok(self) -> bool:
        return self.info or self.value <= self.target

    def line(self) -> str:
        verdict = "information" if self.info else "ok" if self.ok else "MISSED"
        return (
            f"{self.name}: {self.value:.2f}{self.unit} (target <= {self.target:g}{self.unit}) "
            f"{verdict}   [{self.detail}]"
        )


def report(results: list[Result]) -> int:
    """Print each result line; the exit status: 1 if a target is missed, else 0."""
    for r in results:
        print(r.line())
    return 0 if all(r.ok for r in results) else 1


def alternate(
    engine, plain, reps: int = 5, warmup: int = 1, clock=time.perf_counter
) -> tuple[list[float], list[float]]:
    """Time ``engine()`` and ``plain()`` alternately (engine first, then plain first, ...).

    ``clock``: wall time by default; ``time.process_time`` counts only this process's CPU
    time, which a loaded machine disturbs less.
    """
    for _ in range(warmup):
        engine()
        plain()
    te, tp = [], []
    for i in range(reps):
        pair = [(engine, te), (plain, tp)]
        if i % 2:
            pair.reverse()
        for fn, out in pair:
            t0 = clock()
            fn()
            out.append(clock() - t0)
    return te, tp


# A fresh process as an installed package runs: with bytecode (pip compiles it at install),
# also where the calling environment sets PYTHONDONTWRITEBYTECODE (then every module of the
# engine would be compiled from source in every run, and numpy's and pint's would not be).
INSTALLED_ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


def run_seconds(cmd: list[str], **kw) -> float:
    """Wall time of one subprocess (checked), with bytecode as installed."""
    kw.setdefault("env", INSTALLED_ENV)
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, **kw)
    return time.perf_counter() - t0


def median(xs: list[float]) -> float:
    return statistics.median(xs)


def ms(x: float) -> str:
    return f"{1000 * x:.0f} ms" if x < 10 else f"{x:.1f} s"


def machine() -> str:
    mem = ""
    try:
        kb = int(
            next(line for line in open("/proc/meminfo") if line.startswith("MemTotal")).split()[1]
        )
        mem = f", {kb / 2**20:.0f} GiB"
    except (OSError, StopIteration, ValueError):
        pass
    load = ""
    if hasattr(os, "getloadavg"):
        load = f", load average {os.getloadavg()[0]:.1f} at start"
    return (
        f"{os.cpu_count()} cores{mem}, {platform.machine()}, Python {platform.python_version()}, "
        f"{sys.platform}{load}"
    )


def workbook_command() -> list[str]:
    """The installed ``workbook`` console script of this interpreter (or ``-m workbook.cli``)."""
    script = Path(sys.executable).parent / "workbook"
    if script.is_file():
        return [str(script)]
    return [sys.executable, "-m", "workbook.cli"]
