"""Statistics of samples (Mathcad's Var, Stdev, corr, cvar, slope, intercept, skew, kurt,
gmean, hmean, Rank): the numerical side of their registry entries in
:mod:`workbook.functions.matrix`.

A sample is every element of a vector or matrix (column by column, as Mathcad reads one); the
formulas are Excel's (VAR.S, STDEV.S, CORREL, COVARIANCE.P, SLOPE, INTERCEPT, SKEW, KURT,
GEOMEAN, HARMEAN, RANK.AVG), which are Mathcad's. A sample too small for the formula, or values
outside its domain, is an error, never a number.
"""

from __future__ import annotations

import numpy as np

from ..errors import DomainError, InputError


def _sample(v, what: str, least: int = 1) -> np.ndarray:
    x = np.asarray(v, dtype=float)
    if x.ndim > 2:
        raise InputError(f"{what}: the sample varies over a range; give one vector or matrix")
    x = x.reshape(-1, order="F")
    if x.size < least:
        raise DomainError(f"{what} needs at least {least} values, got {x.size}")
    return x


def _pair(a, b, what: str, least: int = 2) -> tuple[np.ndarray, np.ndarray]:
    x, y = _sample(a, what, least), _sample(b, what, least)
    if x.size != y.size:
        raise InputError(f"{what}: the samples have {x.size} and {y.size} values")
    return x, y


def _spread(x: np.ndarray, what: str) -> None:
    if np.all(x == x[0]):
        raise DomainError(f"{what}: every value of the sample is the same (no spread)")


def sample_var(v) -> float:
    """The sample variance (divided by N - 1)."""
    return float(np.var(_sample(v, "Var()", 2), ddof=1))


def sample_stdev(v) -> float:
    """The sample standard deviation (divided by N - 1)."""
    return float(np.std(_sample(v, "Stdev()", 2), ddof=1))


def corr(a, b) -> float:
    """Pearson's correlation coefficient."""
    x, y = _pair(a, b, "corr()")
    _spread(x, "corr()")
    _spread(y, "corr()")
    return float(np.corrcoef(x, y)[0, 1])


def cvar(a, b) -> float:
    """The covariance, divided by N (Mathcad's cvar, Excel's COVARIANCE.P)."""
    x, y = _pair(a, b, "cvar()", 1)
    return float(np.mean((x - x.mean()) * (y - y.mean())))


def slope(vx, vy) -> float:
    """The slope of the least-squares line through the points (vx, vy)."""
    x, y = _pair(vx, vy, "slope()")
    _spread(x, "slope()")
    return float(np.sum((x - x.mean()) * (y - y.mean())) / np.sum((x - x.mean()) ** 2))


def intercept(vx, vy) -> float:
    """The intercept of the least-squares line through the points (vx, vy)."""
    x, y = _pair(vx, vy, "intercept()")
    return float(y.mean() - slope(vx, vy) * x.mean())


def skew(v) -> float:
    """The sample skewness, n / ((n - 1)(n - 2)) sum(((x - mean)/s)^3) (Excel's SKEW)."""
    x = _sample(v, "skew()", 3)
    _spread(x, "skew()")
    import scipy.stats  # imported when used: loading a sheet imports no SciPy solver

    return float(scipy.stats.skew(x, bias=False))


def kurt(v) -> float:
    """The sample excess kurtosis (Excel's KURT)."""
    x = _sample(v, "kurt()", 4)
    _spread(x, "kurt()")
    import scipy.stats

    return float(scipy.stats.kurtosis(x, fisher=True, bias=False))


def gmean(v) -> float:
    """The geometric mean of positive values."""
    x = _sample(v, "gmean()")
    if np.any(x <= 0):
        raise DomainError("gmean(): the values must be positive")
    import scipy.stats

    return float(scipy.stats.gmean(x))


def hmean(v) -> float:
    """The harmonic mean of positive values."""
    x = _sample(v, "hmean()")
    if np.any(x <= 0):
        raise DomainError("hmean(): the values must be positive")
    import scipy.stats

    return float(scipy.stats.hmean(x))


def rank(v) -> np.ndarray:
    """The rank of each element of a vector, 1 for the smallest; equal values share the
    mean of their ranks (Excel's RANK.AVG, ascending)."""
    x = _sample(v, "Rank()")
    import scipy.stats

    return scipy.stats.rankdata(x, method="average").reshape(-1, 1)
