"""Reference values of the numerical built-ins by other algorithms (``workbook bench``).

Inside :func:`workbook.numerics.reference_methods`, root, integral and the extrema compute
each row with a method that is not the engine's, at a tolerance near double precision:

- root in a bracket: Brent's method (``scipy.optimize.brentq``), on [A, B] or, where f has
  the same sign at both ends, on the one sample interval with a sign change;
  root from a guess: Brent's method on a bracket grown around the guess;
- integral: QUADPACK's adaptive rule with extrapolation (``scipy.integrate.quad``, epsrel
  1e-13, the kinks as its ``points``);
- maximum, minimum, argmax, argmin: EXPR at 4,001 points, then the bounded Brent minimiser
  (``scipy.optimize.minimize_scalar``) between the neighbours of the best one.

Of a call with more than ``ROWS`` rows, ``ROWS`` rows spread over it are computed and the
others are NaN, which the hooks fill with the engine's values (a Python loop of scalar
routines takes about a millisecond a row). A row
the reference method cannot do raises :class:`ReferenceFailed` with the reason; the bench
prints it as the row's reference, never a crash.
"""

from __future__ import annotations

import warnings

import numpy as np

from ..errors import WorkbookError
from ..functions.numerical import NumericsError, Result

#: points of the dense sampling of an extremum's reference
DENSE = 4000
RTOL = 1e-13
_RTOL = 4 * float(np.finfo(float).eps)
#: rows of one call computed at most (spread over it)
ROWS = 64


class ReferenceFailed(NumericsError):
    """The reference method did not converge on a row."""


def _row(f, x, args, i):
    """f at x in row i; NaN where the expression has no value there."""
    try:
        with np.errstate(all="ignore"):
            v = f(np.asarray([x], dtype=float), *[a[i : i + 1] for a in args])
        return float(np.asarray(v, dtype=float).ravel()[0])
    except WorkbookError:
        return float("nan")


def _rows(n: int) -> np.ndarray:
    """The rows computed: all, or ROWS spread over them."""
    return np.arange(n) if n <= ROWS else np.unique(np.linspace(0, n - 1, ROWS).astype(np.intp))


def root_in(f, a, b, args) -> Result:
    from scipy.optimize import brentq

    a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    out = np.full(a.size, np.nan)
    for i in _rows(a.size):
        g = lambda x, i=i: _row(f, x, args, i)  # noqa: E731
        lo, hi = min(a.flat[i], b.flat[i]), max(a.flat[i], b.flat[i])
        if g(lo) * g(hi) > 0:
            xs = np.linspace(lo, hi, 65)
            fs = np.array([g(x) for x in xs])
            change = np.flatnonzero(np.sign(fs[:-1]) * np.sign(fs[1:]) <= 0)
            if change.size != 1:
                raise ReferenceFailed(f"brentq: {change.size} sign changes at 65 samples")
            lo, hi = xs[change[0]], xs[change[0] + 1]
        out[i] = brentq(g, lo, hi, xtol=1e-300, rtol=_RTOL, maxiter=500)
    return Result(out.reshape(a.shape), np.zeros(a.shape))


def root_near(f, guess, args) -> Result:
    from scipy.optimize import brentq

    x0 = np.asarray(guess, dtype=float)
    out = np.full(x0.size, np.nan)
    for i in _rows(x0.size):
        x = float(x0.flat[i])
        g = lambda t, i=i: _row(f, t, args, i)  # noqa: E731
        f0 = g(x)
        if f0 == 0:
            out[i] = x
            continue
        h, found = max(abs(x) * 1e-6, 1e-9), []
        for _ in range(400):  # each side on its own, the nearer sign change first
            for t in (x + h, x - h):
                ft = g(t)
                if np.isfinite(ft) and ft * f0 <= 0:
                    found.append(brentq(g, min(x, t), max(x, t), xtol=1e-300, rtol=_RTOL))
            if found:
                break
            h *= 1.25
        else:
            raise ReferenceFailed("brentq: no sign change around the guess")
        out[i] = min(found, key=lambda r: abs(r - x))
    return Result(out.reshape(x0.shape), np.zeros(x0.shape))


def integral(f, a, b, args, breaks) -> Result:
    from scipy.integrate import IntegrationWarning, quad

    a, b, *brk = np.broadcast_arrays(*[np.asarray(v, dtype=float) for v in (a, b, *breaks)])
    out = np.full(a.size, np.nan)
    for i in _rows(a.size):
        lo, hi = a.flat[i], b.flat[i]
        pts = sorted({float(p.flat[i]) for p in brk if min(lo, hi) < p.flat[i] < max(lo, hi)})
        with warnings.catch_warnings():
            warnings.simplefilter("error", IntegrationWarning)
            # roundoff detected: quad's best is at the rounding level, which is what is wanted
            warnings.filterwarnings("ignore", "The occurrence of roundoff", IntegrationWarning)
            try:
                out[i], _ = quad(
                    lambda x, i=i: _row(f, x, args, i),
                    lo,
                    hi,
                    epsabs=0.0,
                    epsrel=RTOL,
                    limit=2000,
                    points=pts or None,
                )
            except IntegrationWarning as w:
                raise ReferenceFailed(f"quad: {str(w).splitlines()[0]}") from None
    return Result(out.reshape(a.shape), np.zeros(a.shape))


def extremum(f, a, b, args, kind: str, need_where: bool) -> Result:
    from scipy.optimize import minimize_scalar

    a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    sgn = -1.0 if kind == "max" else 1.0
    value, where = np.full(a.size, np.nan), np.full(a.size, np.nan)
    for i in _rows(a.size):
        lo, hi = min(a.flat[i], b.flat[i]), max(a.flat[i], b.flat[i])
        xs = np.linspace(lo, hi, DENSE + 1)
        fs = sgn * np.broadcast_to(
            np.asarray(f(xs, *[np.repeat(g[i : i + 1], xs.size) for g in args]), dtype=float),
            xs.shape,
        )
        k = int(np.argmin(fs))
        left, right = xs[max(k - 1, 0)], xs[min(k + 1, DENSE)]
        best_v, best_x = fs[k], xs[k]
        if right > left:
            res = minimize_scalar(
                lambda x, i=i: sgn * _row(f, x, args, i),
                bounds=(left, right),
                method="bounded",
                options={"xatol": 1e-15 * max(abs(left), abs(right), 1e-300)},
            )
            if res.fun < best_v:
                best_v, best_x = float(res.fun), float(res.x)
        value[i], where[i] = sgn * best_v, best_x
    shape = a.shape
    return Result(value.reshape(shape), np.zeros(shape), where.reshape(shape), np.zeros(shape))
