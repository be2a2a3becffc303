"""Registry entries of the statistics of samples (:mod:`workbook.functions.samples`): corr,
cvar, the least-squares line, skew, kurt, the means, the sample variance and standard
deviation, ranks; every element of a vector or matrix is a sample."""

from __future__ import annotations

import inspect

from ..errors import TemplateError
from . import samples
from .excel_functions import stored
from .matrix_entries import call, entry, func, need, not_live, vector


def statistic_hook(fn):
    """A numpy hook of a statistic of samples: the values, then the shapes (not used)."""

    def hook(*values, shapes):
        return fn(*values)

    return hook


def r_var_sample(ctx, name, args):
    need(args, 0, name)
    return func(args[0].unit ** 2, name, args, None)


# statistics of samples (workbook.functions.samples): every element of a vector or matrix
def r_sample(result: str):
    def rule(ctx, name, args):
        need(args, 0, name)
        unit = {"same": args[0].unit, "plain": ctx.dimensionless}[result]
        return func(unit, name, args, None)

    return rule


def r_pair(result: str):
    def rule(ctx, name, args):
        n, m = vector(args, 0, name), vector(args, 1, name)
        if n != m:
            raise TemplateError(f"{name}(): the vectors have {n} and {m} elements")
        a, b = args[0].unit, args[1].unit
        unit = {
            "plain": ctx.dimensionless,
            "product": a * b,
            "ratio": b / a,
            "second": b,
        }[result]
        return func(unit, name, args, None)

    return rule


def r_ranks(ctx, name, args):
    return func(ctx.dimensionless, name, args, (vector(args, 0, name), 1))


for name, rule, hook, excel, doc in (
    ("corr", r_pair("plain"), samples.corr, call("CORREL", "{}, {}"),
     "corr(a, b): Pearson's correlation coefficient of two vectors"),
    ("cvar", r_pair("product"), samples.cvar, call(stored("COVARIANCE.P"), "{}, {}"),
     "cvar(a, b): the covariance of two vectors, divided by N (Mathcad's cvar)"),
    ("fit_slope", r_pair("ratio"), samples.slope, call("SLOPE", "{1}, {0}"),
     "fit_slope(vx, vy): the slope of the least-squares line (Mathcad's slope)"),
    ("fit_intercept", r_pair("second"), samples.intercept, call("INTERCEPT", "{1}, {0}"),
     "fit_intercept(vx, vy): the intercept of the least-squares line (Mathcad's intercept)"),
    ("skew", r_sample("plain"), samples.skew, call("SKEW"),
     "skew(v): the sample skewness (Excel's SKEW)"),
    ("kurt", r_sample("plain"), samples.kurt, call("KURT"),
     "kurt(v): the sample excess kurtosis (Excel's KURT)"),
    ("gmean", r_sample("same"), samples.gmean, call("GEOMEAN"),
     "gmean(v): the geometric mean of positive values"),
    ("hmean", r_sample("same"), samples.hmean, call("HARMEAN"),
     "hmean(v): the harmonic mean of positive values"),
    ("Var", r_var_sample, samples.sample_var, call(stored("VAR.S")),
     "Var(v): the sample variance (divided by N - 1; var divides by N)"),
    ("Stdev", r_sample("same"), samples.sample_stdev, call(stored("STDEV.S")),
     "Stdev(v): the sample standard deviation (divided by N - 1; stdev divides by N)"),
    ("Rank", r_ranks, samples.rank, not_live("ranks are written as values"),
     "Rank(v): the rank of each element, 1 for the smallest, ties sharing their mean rank"),
):  # fmt: skip
    # each is Mathcad's function of its name (fit_slope and fit_intercept: slope, intercept)
    mathcad = (name.removeprefix("fit_"),)
    entry(name, len(inspect.signature(hook).parameters), rule, statistic_hook(hook), excel, doc,
          mathcad=mathcad)  # fmt: skip
