"""Hard cases of every numerical built-in against mpmath at 50 digits: the table in
docs/numerics.md ("A sweep of hard cases").

``python scripts/numerics_sweep.py`` computes each case in a sheet of its own at tolerance
1e-10 and prints, per case, the relative error against the exact value, the built-in's
largest error estimate (relative, as the warnings measure it), whether ``run`` warns of it,
and a verdict:

- ok: the error is within 10 times the estimate (or within 1e-15, the rounding of the
  double it is returned as);
- warned: the estimate is above the tolerance and ``run`` says so (the value is kept);
- OVERCONFIDENT: the error is more than 10 times the estimate (warned or not);
- SILENT WRONG: overconfident, above the tolerance, and no warning; or a value where the
  integral does not exist;
- refused: the engine refuses it (with the refusal's first words); "refused (right)"
  where there is no value to give (a divergent integral).

The last line counts them. ``--quick`` leaves out the cases that take seconds each.
"""

from __future__ import annotations

import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import mpmath
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import workbook  # noqa: E402
from workbook.errors import WorkbookError  # noqa: E402
from workbook.numerics.estimates import estimate_findings  # noqa: E402

mpmath.mp.dps = 50
TOL = 1e-10
F = mpmath.mpf  # a double constant, read as the engine reads it


@dataclass
class Case:
    kind: str
    expr: str  # the definition's formula (y = ...), or a whole [definitions] body
    exact: object  # a callable giving the exact value(s), None where none exists
    defs: str = ""  # more definitions and sections
    slow: bool = False


def _hilbert(n: int) -> str:
    rows = ", ".join("[" + ", ".join(f"1/{i + j + 1}" for j in range(n)) + "]" for i in range(n))
    return f"[{rows}]"


def _hilbert_mp(n: int):
    return mpmath.matrix([[F(1.0 / (i + j + 1)) for j in range(n)] for i in range(n)])


def _eig(rows):
    e = mpmath.eig(mpmath.matrix(rows))[0]
    return sorted(mpmath.re(x) for x in e)


def _expm1mx(x):
    return mpmath.exp(x) - 1 - x


def _flat_peak(x):
    return mpmath.cos(F(1e-4) * x) - 1 + F(1e-9) * mpmath.sin(x)


def _quartic(x):
    return x**4 - 3 * x**2 + x


def _moment(t):
    return F(0.7) * t if t < F(0.3) else F(0.3) * (1 - t)


def _first_peak():
    x = mpmath.atan(100) / 100  # 100 cos(100 x) = sin(100 x): the first (largest) peak
    return mpmath.sin(100 * x) * mpmath.exp(-x)


def _damped():
    t = 2 * mpmath.pi - mpmath.atan(F(0.1))  # -sin t - cos t/10 = 0 past 1
    return max(mpmath.cos(t) * mpmath.exp(-t / 10), mpmath.cos(1) * mpmath.exp(F(-0.1)))


def _harmonic_shift(n, c):
    # sum 1/(i + c), i = 1..n, is psi(n + 1 + c) - psi(1 + c)
    return (mpmath.psi(0, n + 1) - mpmath.psi(0, 1)) - (
        mpmath.psi(0, n + 1 + c) - mpmath.psi(0, 1 + c)
    )


LOGISTIC = """[arguments]
t = { unit = "s" }
[[ode]]
name = "logistic"
time = "t := 0 .. 10 s"
states = [{ name = "u", unit = "", initial = "0.01", derivative = "u*(1 - u)/(1 s)" }]
"""
OSCILLATOR = """[arguments]
t = { unit = "s" }
[[ode]]
name = "osc"
time = "t := 0 .. 10 s"
rtol = 1e-9
atol = 1e-12
states = [
  { name = "p", unit = "", initial = "1", derivative = "q/(1 s)" },
  { name = "q", unit = "", initial = "0", derivative = "-p/(1 s)" },
]
"""
STIFF = """[arguments]
t = { unit = "s" }
[[ode]]
name = "stiff"
time = "t := 0 .. 2 s"
rtol = 1e-8
atol = 1e-10
states = [{ name = "v", unit = "", initial = "0", derivative = "-50*(v - cos(t/(1 s)))/(1 s)" }]
"""


def _stiff_integral():
    # v = (2500 cos t + 50 sin t - 2500 e^(-50 t))/2501, integrated over [0, 2]
    return (2500 * mpmath.sin(2) + 50 * (1 - mpmath.cos(2)) - 50 * (1 - mpmath.exp(-100))) / 2501


FN = '[arguments]\nx = { unit = "" }\n'


def _logistic(t):
    return 1 / (1 + 99 * mpmath.exp(-t))


CASES = [
    # roots
    Case(
        "root",
        "root((exp(x) - 1 - x) - 1e-9, x, 1e-6, 1)",
        lambda: mpmath.findroot(lambda x: _expm1mx(x) - F(1e-9), 4.5e-5),
    ),
    Case(
        "root",
        "root(cos(x) - 1 + 1e-12, x, 1e-9, 1)",
        lambda: mpmath.findroot(lambda x: mpmath.cos(x) - 1 + F(1e-12), 1.4e-6),
    ),
    Case("root", "root(x^3 - 3*x^2 + 3*x - 1, x, 0, 1.7)", lambda: 1),
    Case("root", "root(1/(x - 0.5) - 1e8, x, 0.4, 0.6)", lambda: F(0.5) + 1 / F(1e8)),
    Case("root", "root(exp(x) - 1e300, x, 600, 800)", lambda: mpmath.log(F(1e300))),
    Case(
        "root",
        "root(tan(x) - x, x, 4, 4.6)",
        lambda: mpmath.findroot(lambda x: mpmath.tan(x) - x, 4.49),
    ),
    Case("root", "root(x*exp(x) - 1e-20, x, -1e-10, 1)", lambda: mpmath.lambertw(F(1e-20)).real),
    Case("root", "root(sin(1/x), x, 0.3, 0.4)", lambda: 1 / mpmath.pi),
    Case("root", "root(x^2 - 2, x, 1)", lambda: mpmath.sqrt(2)),
    Case("root", "root(log10(x) - 1e-12, x, 0.5, 2)", lambda: mpmath.power(10, F(1e-12))),
    Case("root", "root(u(t) - 0.5, t, 0 s, 10 s)", lambda: mpmath.log(99), LOGISTIC),
    Case("root", "root(x^2 - 1e-20, x, 0, 1)", lambda: F(1e-10)),
    Case("root", "root(exp(-x) - x, x, 0, 1)", lambda: mpmath.lambertw(1).real),
    # integrals
    Case("integral", "integral(sin(x)/x, x, 0, 100)", lambda: mpmath.si(100)),
    Case(
        "integral",
        "integral(1/(x^2 + 1e-10), x, -1, 1)",
        lambda: 2 * mpmath.atan(1 / mpmath.sqrt(F(1e-10))) / mpmath.sqrt(F(1e-10)),
    ),
    Case("integral", "integral(floor(x), x, 0, 10.5)", lambda: F(45) + 5),
    Case("integral", "integral(exp(x), x, 0, 700)", lambda: mpmath.exp(700) - 1),
    Case("integral", "integral(v(t), t, 0 s, 2 s)", lambda: _stiff_integral(), STIFF),
    Case(
        "integral", "integral(cos(1e-4*x) - 1, x, 0, 1)", lambda: mpmath.sin(F(1e-4)) / F(1e-4) - 1
    ),
    Case(
        "integral",
        "integral(exp(-((x - 3.7)/0.01)^2), x, 0, 10)",
        lambda: mpmath.quad(
            lambda x: mpmath.exp(-(((x - F(3.7)) / F(0.01)) ** 2)), [0, 3.6, 3.7, 3.8, 10]
        ),
    ),
    Case("integral", "integral(x^-0.99, x, 0, 1)", lambda: 1 / (1 - F(0.99))),
    Case(
        "integral",
        "integral(ln(abs(x - 0.3)), x, 0, 1)",
        lambda: mpmath.quad(lambda x: mpmath.log(abs(x - F(0.3))), [0, F(0.3), 1]),
    ),
    Case(
        "integral",
        "integral(1/sqrt(abs(x - 0.3)), x, 0, 1)",
        lambda: 2 * mpmath.sqrt(F(0.3)) + 2 * mpmath.sqrt(1 - F(0.3)),
    ),
    Case(
        "integral",
        "integral(sin(100*x)^2, x, 0, 3)",
        lambda: mpmath.quad(lambda x: mpmath.sin(100 * x) ** 2, mpmath.linspace(0, 3, 60)),
    ),
    Case(
        "integral",
        "integral(1/(1 + 1e6*(x - 0.5)^2), x, 0, 1)",
        lambda: 2 * mpmath.atan(F(0.5) * 1000) / 1000,
    ),
    Case(
        "integral",
        "integral(abs(sin(x)), x, 0, 10)",
        lambda: mpmath.quad(
            lambda x: abs(mpmath.sin(x)), [0, mpmath.pi, 2 * mpmath.pi, 3 * mpmath.pi, 10]
        ),
    ),
    Case("integral", "integral(sqrt(x)*ln(x), x, 0, 1)", lambda: F(-4) / 9),
    Case("integral", "integral(x^10*exp(-x), x, 0, 50)", lambda: mpmath.gammainc(11, 0, 50)),
    Case("integral", "integral(1/(x - 0.5), x, 0, 1)", None),
    Case("integral", "integral(x/(x^2 - 0.25), x, -1, 1)", None),
    Case("integral", "integral(tan(x), x, -2, 2)", None),
    Case("integral", "integral(1/sqrt(1 - x^2), x, -1, 1)", lambda: mpmath.pi),
    Case(
        "integral",
        "integral(u(t), t, 0 s, 10 s)",
        lambda: 10 + mpmath.log((1 + 99 * mpmath.exp(-10)) / 100),
        LOGISTIC,
    ),
    Case(
        "integral",
        "integral(integral(0.7*t if t < 0.3 otherwise 0.3*(1 - t), t, 0, s), s, 0, 1)",
        lambda: mpmath.quad(
            lambda s: mpmath.quad(_moment, [0, F(0.3), s] if s > F(0.3) else [0, s]), [0, F(0.3), 1]
        ),
    ),
    Case(
        "integral",
        "integral(integral(1/sqrt(x - y), y, 0, x), x, 0, 1)",
        lambda: F(4) / 3,
        slow=True,
    ),
    # extrema
    Case("maximum", "maximum(sin(100*x)*exp(-x), x, 0, 10)", lambda: _first_peak()),
    Case("maximum", "maximum(exp(-((x - 0.3)/1e-4)^2), x, 0, 1)", lambda: 1),
    Case(
        "argmax",
        "argmax(cos(1e-4*x) - 1 + 1e-9*sin(x), x, 0, 3)",
        lambda: mpmath.findroot(lambda x: mpmath.diff(_flat_peak, x), 0.0995),
    ),
    Case(
        "maximum",
        "maximum(cos(1e-4*x) - 1 + 1e-9*sin(x), x, 0, 3)",
        lambda: _flat_peak(mpmath.findroot(lambda x: mpmath.diff(_flat_peak, x), 0.0995)),
    ),
    Case(
        "minimum",
        "minimum(x^4 - 3*x^2 + x, x, -2, 2)",
        lambda: _quartic(mpmath.findroot(lambda x: 4 * x**3 - 6 * x + 1, -1.3)),
    ),
    Case(
        "argmin",
        "argmin(x^4 - 3*x^2 + x, x, -2, 2)",
        lambda: mpmath.findroot(lambda x: 4 * x**3 - 6 * x + 1, -1.3),
    ),
    Case(
        "maximum",
        "maximum((1 - cos(x))/x^2, x, 1e-5, 1e-3)",
        lambda: (1 - mpmath.cos(F(1e-5))) / F(1e-5) ** 2,
    ),
    Case("maximum", "maximum(p(t)*exp(-0.1*t/(1 s)), t, 1 s, 10 s)", lambda: _damped(), OSCILLATOR),
    Case("minimum", "minimum(abs(x - 1/3), x, 0, 1)", lambda: 0),
    Case("argmin", "argmin(abs(x - 1/3), x, 0, 1)", lambda: F(1) / 3),
    Case(
        "maximum",
        "maximum(x*sin(1/x), x, 0.01, 1)",
        lambda: max(
            x * mpmath.sin(1 / x)
            for x in [
                mpmath.findroot(lambda x: mpmath.sin(1 / x) - mpmath.cos(1 / x) / x, 0.2225),
                F(1),
            ]
        ),
    ),
    # sums and products
    Case("sum", "sum(1/i, i, 1, 1000000)", lambda: mpmath.harmonic(1000000)),
    Case(
        "product",
        "product(1 - 1/(4*i^2), i, 1, 10000)",
        lambda: mpmath.fprod(1 - F(1) / (4 * F(i) ** 2) for i in range(1, 10001)),
    ),
    Case("sum", "sum(1/i^2, i, 1, 10000)", lambda: mpmath.zeta(2) - mpmath.zeta(2, 10001)),
    Case(
        "sum",
        "sum((-20)^i/product(k, k, 1, i), i, 0, 100)",
        lambda: mpmath.fsum(F(-20) ** i / mpmath.factorial(i) for i in range(101)),
    ),
    Case("sum", "sum(1/i - 1/(i + 1e-9), i, 1, 100000)", lambda: _harmonic_shift(100000, F(1e-9))),
    Case(
        "product",
        "product(1 + 1/i^2, i, 1, 1000)",
        lambda: mpmath.fprod(1 + F(1) / i**2 for i in range(1, 1001)),
    ),
    Case(
        "sum",
        "sum((-1)^(i + 1)/i, i, 1, 10000)",
        lambda: mpmath.fsum(F((-1) ** (i + 1)) / i for i in range(1, 10001)),
    ),
    # derivatives
    Case(
        "diff",
        "g(0.001)",
        lambda: mpmath.diff(lambda x: _expm1mx(x) / x**2, F(0.001)),
        FN + '[definitions]\n"g(x)" = "diff((exp(x) - 1 - x)/x^2, x)"\n',
    ),
    Case(
        "diff",
        "g(0.7)",
        lambda: mpmath.exp(F(0.7)) * (mpmath.sin(F(0.7)) + mpmath.cos(F(0.7))),
        FN + '[definitions]\n"g(x)" = "diff(sin(x)*exp(x), x)"\n',
    ),
    Case(
        "diff",
        "g(1.1)",
        lambda: 90 * F(1.1) ** 8,
        FN + '[definitions]\n"g(x)" = "diff(x^10, x, 2)"\n',
    ),
    Case(
        "diff",
        "g(1e-10)",
        lambda: 1 / (1 + F(1e-10)),
        FN + '[definitions]\n"g(x)" = "diff(ln(1 + x), x)"\n',
    ),
    Case(
        "diff",
        "g(1)",
        None,
        FN + '[definitions]\n"g(x)" = "diff(x if x < 1 otherwise 2*x - 1, x)"\n',
    ),
    Case(
        "diff",
        "g(1e-20)",
        lambda: F(1e-20) ** (F(-2) / 3) / 3,
        FN + '[definitions]\n"g(x)" = "diff(x^(1/3), x)"\n',
    ),
    Case(
        "diff",
        "g(1e-8)",
        lambda: mpmath.diff(lambda x: (1 - mpmath.cos(x)) / x**2, F(1e-8)),
        FN + '[definitions]\n"g(x)" = "diff((1 - cos(x))/x^2, x)"\n',
    ),
    # linear algebra
    Case(
        "lsolve",
        "lsolve([[1, 1, 1, 1], [1, 2, 4, 8], [1, 3, 9, 27], [1, 4, 16, 64]], [1, 0, 0, 1])",
        lambda: list(
            mpmath.lu_solve(
                mpmath.matrix([[1, 1, 1, 1], [1, 2, 4, 8], [1, 3, 9, 27], [1, 4, 16, 64]]),
                mpmath.matrix([1, 0, 0, 1]),
            )
        ),
    ),
    Case(
        "lsolve",
        f"lsolve({_hilbert(10)}, [1, 1, 1, 1, 1, 1, 1, 1, 1, 1])",
        lambda: list(mpmath.lu_solve(_hilbert_mp(10), mpmath.matrix([1] * 10))),
    ),
    Case(
        "lsolve",
        "lsolve([[1, 1], [1, 1 + 1e-10]], [2, 2 + 1e-10])",
        lambda: list(
            mpmath.lu_solve(
                mpmath.matrix([[1, 1], [1, 1 + F(1e-10)]]), mpmath.matrix([2, 2 + F(1e-10)])
            )
        ),
    ),
    Case("det", f"det({_hilbert(6)})", lambda: mpmath.det(_hilbert_mp(6))),
    Case(
        "eigenvals",
        "eigenvals([[2, 1, 0], [1, 3, 1], [0, 1, 4]])",
        lambda: _eig([[2, 1, 0], [1, 3, 1], [0, 1, 4]]),
    ),
    Case("eigenvals", "eigenvals([[0.1, 0.1], [-0.1, 0.3]])", lambda: [F(0.2), F(0.2)]),
    Case(
        "eigenvals", "eigenvals([[1, 1e-8], [1e-8, 1]])", lambda: _eig([[1, F(1e-8)], [F(1e-8), 1]])
    ),
    Case("eigenvals", "eigenvals([[1, 1000], [0, 1.001]])", lambda: [1, F(1.001)]),
]


def run_case(case: Case, folder: Path) -> tuple[str, float, float, bool]:
    """(refusal or "", relative error, relative estimate, warned)."""
    defs = case.defs
    line = f'out = "{case.expr}"\n'
    body = defs + line if "[definitions]" in defs else defs + "[definitions]\n" + line
    path = folder / "case.toml"
    path.write_text(f"[sheet]\ntolerance = {TOL}\n{body}", encoding="utf-8")
    s = workbook.load(path)
    try:
        v = np.ravel(np.asarray(s.evaluate("out").magnitude, dtype=float))
    except WorkbookError as err:
        return getattr(err, "message", str(err)).split(": ", 2)[-1][:60], 0.0, 0.0, False
    if case.exact is None:
        return "", np.inf, 0.0, False
    exact = case.exact()
    exact = np.array([float(e) for e in (exact if isinstance(exact, list) else [exact])])
    size = float(np.max(np.abs(exact))) or 1.0  # (an exact 0: absolute)
    err = float(np.max(np.abs(np.sort(v) - np.sort(exact)) if v.size > 1 else np.abs(v - exact)))
    # the outermost built-in's (computed last: an inner product's comes before its sum's)
    mine = [r for _, r in s.evaluator.records if r.error.size and r.notes.get("in") == "out"]
    est = float(np.max(np.abs(mine[-1].error))) if mine else 0.0
    warned = any(f.topic.endswith(" out") or ", out" in f.topic for f in estimate_findings(s))
    return "", err / size, est / size, warned


def verdict(refused: str, err: float, est: float, warned: bool, exists: bool) -> str:
    if refused:
        return "refused (right)" if not exists else f"refused: {refused}"
    if not exists:
        return "SILENT WRONG (no value exists)"
    if err <= max(10 * est, 1e-15):
        return "warned" if warned else "ok"
    if warned:
        return "OVERCONFIDENT (warned)"
    return "SILENT WRONG" if err > TOL else "OVERCONFIDENT (within tolerance)"


def main(argv: list[str]) -> int:
    quick = "--quick" in argv
    counts: dict[str, int] = {}
    print(f"{'built-in':<10} {'case':<64} {'error':>9} {'estimate':>9}  verdict")
    with tempfile.TemporaryDirectory() as tmp:
        for case in CASES:
            if quick and case.slow:
                continue
            refused, err, est, warned = run_case(case, Path(tmp))
            v = verdict(refused, err, est, warned, case.exact is not None)
            key = v.split(":")[0].split(" (")[0] if not v.startswith("refused (right)") else v
            counts[key] = counts.get(key, 0) + 1
            shown = "" if refused or case.exact is None else f"{err:>9.1e} {est:>9.1e}"
            print(f"{case.kind:<10} {case.expr[:64]:<64} {shown:>19}  {v}")
    total = sum(counts.values())
    print(f"{total} cases: " + ", ".join(f"{n} {k}" for k, n in sorted(counts.items())))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
