"""`workbook bench`'s reference of an extremum resolves an EXPR that oscillates far more often
than its first 4,001 samples: sin(x) + 1e-5 x on [0, 150000] (2.4e4 periods; its maximum is
1 + 1e-5 x at the last crest, x = 2 pi k + pi/2 + 1e-5 to first order, from the closed form)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from workbook.numerics import bench, mpref

SHEET = """
[sheet]
tolerance = 1e-10
[arguments]
x = { unit = "" }
[definitions]
osc = "maximum(sin(x) + 1e-5*x, x, 0, 150000)"
"""


def _true_maximum() -> float:
    """The last crest below 150000: cos(x) = -1e-5 there, so x = 2 pi k + acos(-1e-5)...
    taken as the maximum of 1 + 1e-5 x over crests (sin at acos(-1e-5) is sqrt(1 - 1e-10))."""
    k = math.floor((150000 - math.pi / 2) / (2 * math.pi))
    x = 2 * math.pi * k + math.acos(-1e-5)
    return math.sqrt(1 - 1e-10) + 1e-5 * x


def test_the_samples_of_a_fast_oscillation_are_made_dense_enough():
    xs, fs = mpref.samples(lambda x: np.sin(24000 * x), 0.0, 6.3, [])
    periods = 24000 * 6.3 / (2 * math.pi)
    assert xs.size >= 20 * periods  # at least 20 samples a period
    flat_xs, _ = mpref.samples(lambda x: 1 + 1e-14 * np.sin(1e5 * x), 0.0, 1.0, [])
    assert flat_xs.size == 3 * mpref.DENSE + 1  # rounding-sized wiggles are not resolved


@pytest.mark.slow
def test_bench_of_a_maximum_over_24000_periods_is_not_a_false_wrong(sheet_from, monkeypatch):
    sheet = sheet_from(SHEET, name="osc")
    assert sheet.evaluate("osc").magnitude == pytest.approx(_true_maximum(), rel=1e-10)
    (line,) = bench.run(sheet, repeats=1)
    assert line.verdict == "ok" and line.difference <= 1e-10, line.text()
    monkeypatch.setattr(mpref, "DENSE_MAX", mpref.DENSE)  # 4,001 samples only, as it was
    monkeypatch.setattr(mpref, "OFFSETS", ())
    (line,) = bench.run(sheet, repeats=1)
    assert line.verdict == "WRONG", line.text()
