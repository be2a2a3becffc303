"""The timing table of docs/mathcad.md: importing each Mathcad worksheet against checking it.

For every .xmcd or .mcdx file under the folders (default ../shared/mathcad and
../shared/mathcad-prime beside the repository), prints the median CPU time of
``workbook import`` and of ``workbook check`` of the imported worksheet (fresh processes,
alternating; CPU time, as the machine's cores are shared), their ratio, and how many
times the import built a ``Sheet`` (an engine load).

    python scripts/import_timing.py [FOLDER ...] [--reps N]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))
import bench_import  # noqa: E402
from _timing import machine  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folders", nargs="*", type=Path)
    ap.add_argument("--reps", type=int, default=3)
    args = ap.parse_args(argv)
    rows = []
    for folder in args.folders or bench_import.FOLDERS:
        for path in bench_import.files(folder):
            rows.append(bench_import.measure(path, args.reps, path.relative_to(folder).as_posix()))
            print(f"measured {path.name}", file=sys.stderr, flush=True)
    print(machine())
    print(bench_import.table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
