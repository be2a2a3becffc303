"""Importing a Mathcad worksheet against checking the imported worksheet.

For each .xmcd/.mcdx file of a folder (default ../shared/mathcad and ../shared/mathcad-prime
beside the repository; a file only referenced by another is skipped): the CPU time (user +
system, of the child process) of ``workbook import FILE --out DIR`` and of
``workbook check DIR/NAME.toml`` in fresh processes (median of ``reps``, alternating), their
ratio (target <= 1.2), and how many times the import built a ``Sheet`` (one engine load and
unit check each), counted in a separate run. CPU time, not wall time: the project machine's
two cores are shared, and its wall times move by a factor of two with the load.
"""

from __future__ import annotations

import re
import resource
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _timing import INSTALLED_ENV, ROOT, Result, median, ms, workbook_command  # noqa: E402

TARGET = 1.2
FOLDERS = [ROOT.parent / "shared" / "mathcad", ROOT.parent / "shared" / "mathcad-prime"]

#: The import, run with Sheet construction counted (printed on the last line of stderr).
COUNT_LOADS = """
import sys
from workbook import cli
from workbook.engine import sheet
n = [0]
init = sheet.Sheet.__init__
def counted(self, *a, **k):
    n[0] += 1
    init(self, *a, **k)
sheet.Sheet.__init__ = counted
try:
    cli.main(sys.argv[1:])
finally:
    print("sheets built:", n[0], file=sys.stderr)
"""


@dataclass
class Row:
    name: str
    import_s: float
    check_s: float
    loads: int

    @property
    def ratio(self) -> float:
        return self.import_s / self.check_s


def files(folder: Path) -> list[Path]:
    """The worksheets of ``folder``, without those only referenced by another."""
    referenced = set()
    for path in folder.rglob("*.xmcd"):
        text = path.read_text(encoding="utf-8", errors="replace")
        for href in re.findall(r'<link href="([^"]+)"', text):
            referenced.add((path.parent / href).resolve())
    found = sorted([*folder.rglob("*.xmcd"), *folder.rglob("*.mcdx")])
    return [p for p in found if p.resolve() not in referenced]


def _seconds(cmd: list[str]) -> float:
    """CPU seconds (user + system) of one run of ``cmd`` in a fresh process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    # check exits 1 when a value is not reproduced: that is a result, not a failure
    done = subprocess.run(cmd, env=INSTALLED_ENV, capture_output=True, text=True, cwd=ROOT)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode not in (0, 1):
        raise RuntimeError(f"{' '.join(cmd)} exited {done.returncode}: {done.stderr[-400:]}")
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def loads_of(path: Path, out: Path) -> int:
    done = subprocess.run(
        [sys.executable, "-c", COUNT_LOADS, "import", str(path), "--out", str(out), "--force"],
        env=INSTALLED_ENV,
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    m = re.search(r"sheets built: (\d+)", done.stderr)
    if m is None:
        raise RuntimeError(f"import of {path} failed: {done.stderr[-400:]}")
    return int(m.group(1))


def measure(path: Path, reps: int = 3, name: str = "") -> Row:
    """Medians of ``reps`` imports and checks of one file, alternating, after one of each."""
    wb = workbook_command()
    with tempfile.TemporaryDirectory() as tmp:
        importing = [*wb, "import", str(path), "--out", tmp, "--force"]
        checking = [*wb, "check", str(Path(tmp) / (path.stem + ".toml"))]
        _seconds(importing)
        _seconds(checking)
        ti, tc = [], []
        for i in range(reps):
            pair = [(importing, ti), (checking, tc)]
            for cmd, out in reversed(pair) if i % 2 else pair:
                out.append(_seconds(cmd))
        loads = loads_of(path, Path(tmp))
    return Row(name or path.name, median(ti), median(tc), loads)


def table(rows: list[Row]) -> str:
    """The Markdown table of docs/mathcad.md."""
    lines = [
        "| file | import (CPU) | check (CPU) | import / check | Sheets built by the import |",
        "| --- | ---: | ---: | ---: | ---: |",
    ]
    for r in rows:
        mark = "" if r.ratio <= TARGET else " (missed)"
        lines.append(
            f"| {r.name} | {ms(r.import_s)} | {ms(r.check_s)} | {r.ratio:.2f}{mark} | {r.loads} |"
        )
    return "\n".join(lines)


def run(reps: int = 3, folders: list[Path] | None = None, only: set[str] | None = None):
    """One benchmark result per file: import time / check time (target <= 1.2)."""
    results = []
    for folder in folders or FOLDERS:
        if not folder.is_dir():
            continue
        for path in files(folder):
            if only is not None and path.stem not in only:
                continue
            name = path.relative_to(folder).as_posix()
            r = measure(path, reps, name)
            results.append(
                Result(
                    f"import {name} / check it",
                    r.ratio,
                    TARGET,
                    detail=f"import {ms(r.import_s)}, check {ms(r.check_s)} of CPU, "
                    f"{r.loads} sheet(s) built",
                )
            )
    return results
