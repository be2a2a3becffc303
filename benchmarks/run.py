"""Run every benchmark, print each ratio with its target; exit 1 if one misses.

python benchmarks/run.py            # full sizes (a few minutes on 2 cores)
python benchmarks/run.py --quick    # tiny sizes: only shows that the scripts work
python benchmarks/run.py --only write
"""

from __future__ import annotations

import argparse
import datetime
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_builtins  # noqa: E402
import bench_coldstart  # noqa: E402
import bench_evaluate  # noqa: E402
import bench_import  # noqa: E402
import bench_livecheck  # noqa: E402
import bench_load  # noqa: E402
import bench_ode  # noqa: E402
import bench_write  # noqa: E402
from _timing import machine  # noqa: E402

FULL = {
    "evaluate": lambda: bench_evaluate.run(n=1_000_000, reps=7),
    "coldstart": lambda: bench_coldstart.run(reps=9),
    "write": lambda: bench_write.run(n=100_000, reps=5),
    "load": lambda: bench_load.run(reps=5),
    "builtins": lambda: bench_builtins.run(n=10_000, reps=5),
    "ode": lambda: bench_ode.run(reps=7),
    "livecheck": lambda: bench_livecheck.run(n=1_000, rows=10_000, reps=5),
    "import": lambda: bench_import.run(reps=3),
}
QUICK = {
    "evaluate": lambda: bench_evaluate.run(n=1_000, reps=1),
    "coldstart": lambda: bench_coldstart.run(reps=1),
    "write": lambda: bench_write.run(n=50, reps=1),
    "load": lambda: bench_load.run(reps=1),
    "builtins": lambda: bench_builtins.run(n=200, reps=1),
    "ode": lambda: bench_ode.run(reps=1),
    "livecheck": lambda: bench_livecheck.run(n=20, rows=20, reps=1, templates=["concave-cam"]),
    "import": lambda: bench_import.run(reps=1, only={"wind-load"}),
}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="tiny sizes (smoke test)")
    ap.add_argument("--only", action="append", choices=list(FULL), help="run only these")
    args = ap.parse_args(argv)
    table = QUICK if args.quick else FULL
    now = datetime.datetime.now(datetime.timezone.utc)
    print(f"{now:%Y-%m-%d %H:%M} UTC, {machine()}")
    results = []
    for name in args.only or list(table):
        for r in table[name]():
            print(r.line(), flush=True)
            results.append(r)
    missed = [r for r in results if not r.ok]
    if args.quick:
        print(f"quick run: {len(results)} results (sizes too small for the targets to mean much)")
        return 0
    print(f"{len(results) - len(missed)} of {len(results)} targets met")
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
