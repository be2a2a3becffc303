"""histogram(n, data) and histogram(intervals, data) against counts made one value at a time."""

from __future__ import annotations

import re

import numpy as np
import pytest

from workbook import WorkbookError

DATA = np.random.default_rng(7).normal(0.87, 0.5, 500).round(3)
EDGES = [-1.0, -0.25, 0.0, 0.5, 0.87, 1.0, 2.0, 2.1]

SHEET = f"""
[inputs]
m = "1 kg"

[definitions]
d = "[{", ".join(repr(float(v)) for v in DATA)}]"
w = "[1, 2, 3]*m"
H = "histogram(15, d)"
G = "histogram([{", ".join(repr(v) for v in EDGES)}], d)"
E = "histogram([1, 2, 3], [1, 2, 2, 3, 3, 3])"
"""


def _counts(edges, values):
    """Each value in the interval whose lower end it reaches; the last holds its upper end."""
    counts = [0] * (len(edges) - 1)
    for v in values:
        for i in range(len(edges) - 1):
            last = i == len(edges) - 2
            if edges[i] <= v < edges[i + 1] or (last and v == edges[i + 1]):
                counts[i] += 1
                break
    return counts


def test_equal_intervals_between_the_smallest_and_largest(sheet):
    got = np.asarray(sheet.evaluate("H").magnitude, dtype=float)
    lo, hi = float(DATA.min()), float(DATA.max())
    edges = [lo + (hi - lo) * k / 15 for k in range(16)]
    assert got.shape == (15, 2)
    assert got[:, 0] == pytest.approx([(a + b) / 2 for a, b in zip(edges, edges[1:])], rel=1e-15)
    assert list(got[:, 1]) == _counts(edges, DATA)
    assert got[:, 1].sum() == len(DATA)


def test_given_intervals(sheet):
    got = np.asarray(sheet.evaluate("G").magnitude, dtype=float)
    assert got.shape == (len(EDGES) - 1, 2)
    assert list(got[:, 1]) == _counts(EDGES, DATA)
    exact = np.asarray(sheet.evaluate("E").magnitude, dtype=float)
    assert exact.tolist() == [[1.5, 1.0], [2.5, 5.0]]  # 2 in the upper interval, 3 in the last


@pytest.mark.parametrize(
    "line, message",
    [
        ('bad = "histogram(3, w)"', "divide the data by their unit (data/kg)"),
        ('bad = "histogram(w[0]/m, d)"', "n must be a positive integer known at load"),
        ('bad = "histogram(2.5, d)"', "n must be a positive integer known at load"),
        ('bad = "histogram([1], d)"', "at least 2 interval points"),
        ('bad = "histogram(3, 4)"', "argument 2 must be a vector"),
    ],
)
def test_checked_at_load(sheet_from, line, message):
    with pytest.raises(WorkbookError, match=re.escape(message)):
        sheet_from(SHEET + line + "\n")


def test_intervals_that_do_not_increase(sheet_from):
    sheet = sheet_from(SHEET + 'bad = "histogram([0, 2, 1], d)"\n')
    with pytest.raises(WorkbookError, match="the interval points must increase"):
        sheet.evaluate("bad")


def test_written_as_values_with_a_comment(sheet, tmp_path):
    import openpyxl

    book = openpyxl.load_workbook(sheet.write_xlsx(tmp_path / "hist.xlsx"))
    comments = [
        c.comment.text for ws in book.worksheets for r in ws.iter_rows() for c in r if c.comment
    ]
    assert any("a histogram has no spreadsheet formula" in t for t in comments)
