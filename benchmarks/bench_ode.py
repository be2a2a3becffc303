"""ODE method "auto" on Robertson's kinetics to t = 40 s: engine against SciPy's Radau.

The system is not stiff at t = 0 (the Jacobian there has eigenvalues near -0.04 1/s) and
becomes stiff within 0.01 s (an eigenvalue near -2000 1/s and falling). The engine side
solves tests/data/robertson.toml's [[ode]] from a fresh Sheet each time with ``method =
"auto"`` (the sheet's default), rtol 1e-6, atol 1e-10: it starts explicit (RK45), sees the
stiffness along the way and solves again with Radau from the start. The baseline is
``solve_ivp(method="Radau")`` called directly on the same right-hand side in plain numpy with
the same tolerances and dense output, as one would write it knowing the system is stiff. Times
are medians of alternated runs in process CPU time (the machine is shared). Each side's error
at t = 40 s against a Radau run at rtol 1e-12 is printed beside the ratio.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _timing import ROOT, Result, alternate, median, ms, report  # noqa: E402

TEMPLATE = ROOT / "tests" / "data" / "robertson.toml"
TARGET = 2.0  # engine "auto" / Radau called directly
RTOL, ATOL, T_END = 1e-6, 1e-10, 40.0


def robertson(t, y):
    y1, y2, y3 = y
    return np.array(
        [-0.04 * y1 + 1e4 * y2 * y3, 0.04 * y1 - 1e4 * y2 * y3 - 3e7 * y2**2, 3e7 * y2**2]
    )


def run(reps: int = 5) -> list[Result]:
    """The ratio of the engine's auto solve to a direct Radau solve."""
    from scipy.integrate import solve_ivp

    import workbook

    sheet = workbook.load(TEMPLATE)
    y0 = [1.0, 0.0, 0.0]

    def engine():
        return sheet.with_inputs().evaluator.ode_solution("rob")

    def direct():
        return solve_ivp(
            robertson, (0, T_END), y0, method="Radau", rtol=RTOL, atol=ATOL, dense_output=True
        )

    ref = solve_ivp(robertson, (0, T_END), y0, method="Radau", rtol=1e-12, atol=1e-16).y[:, -1]
    sol = engine()
    err_engine = np.max(np.abs([sol(k, T_END) for k in range(3)] - ref) / np.maximum(ref, 1e-10))
    err_direct = np.max(np.abs(direct().y[:, -1] - ref) / np.maximum(ref, 1e-10))
    te, td = alternate(engine, direct, reps=reps, clock=time.process_time)
    return [
        Result(
            "Robertson to t = 40 s: engine auto / SciPy Radau called directly",
            median(te) / median(td),
            TARGET,
            detail=f"engine {ms(median(te))} ({sol.method}), Radau {ms(median(td))}; "
            f"rel error at t = 40: engine {err_engine:.1e}, Radau {err_direct:.1e}",
        )
    ]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=5)
    args = ap.parse_args(argv)
    return report(run(args.reps))


if __name__ == "__main__":
    sys.exit(main())
