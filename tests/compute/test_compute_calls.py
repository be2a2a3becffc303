"""The typed stage: after ``load``, computing and writing a sheet calls no typer code and
parses nothing (the typed trees are made at load and read), and through the Python API a Sheet is
checked and computed once however often it is checked, written and reported
(scripts/compute_calls.py counts the calls)."""

from __future__ import annotations

import sys
import warnings

import pytest
from helpers.paths import ROOT
from helpers.sheets import write_template

import workbook
from workbook.language import expr as ex

sys.path.insert(0, str(ROOT / "scripts"))
try:
    import compute_calls
finally:
    sys.path.pop(0)

#: what the typed stage keeps, small: a table over a range with bounds that are expressions,
#: a log range, a chart over a range no table has, printed values (one of a function at an
#: argument) and a declared check with placeholders
SMALL = """
[inputs]
a = { value = "2 mm" }
n = { value = "3" }

[arguments]
t = { unit = "" }
f = { unit = "Hz" }

[definitions]
c = "a*n"
"g(t)" = "a*sin(t) + c"
"h(f)" = "a*f/(1 Hz)"

[[tables]]
name = "curve"
range = "t := 0, n/4 .. n"
columns = { g = "mm" }

[[tables]]
name = "spectrum"
range = "f := logspace(1 Hz, 1 kHz, n + 1)"
columns = { h = "mm" }

[[charts]]
name = "lines"
title = "g"
range = "t := 0, 0.5 .. 2*n"
y_title = "mm"
series = [{ y = "g", unit = "mm", name = "g" }]

[[printed]]
file = "printed.csv"
argument = "t"
tolerance = 0.001

[[checks]]
topic = "size"
what = "c = {c:mm} is {c/a} times a, g(1) = {g(1):mm}"
value = "c"
unit = "mm"
ok = "c > a"
"""

PRINTED = "name,argument,value,unit\nc,,6,mm\ng,0,6,mm\n"


def small(tmp_path):
    (tmp_path / "printed.csv").write_text(PRINTED)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return workbook.load(write_template(tmp_path, SMALL))


def test_the_count_sees_typing_and_parsing(tmp_path):
    sheet = small(tmp_path)
    found = compute_calls.counted(
        lambda: sheet.typer.expression(ex.parse("a*n + c", what="x"), {}, "x")
    )
    assert found["typecheck.expression"] == 1 and found["parse"] == 1
    assert found["typing"] >= 4  # the expression, three names and two operators visited
    assert found["typer"] >= found["typing"]


@pytest.mark.slow
def test_computing_and_writing_a_small_sheet_types_and_parses_nothing(tmp_path):
    sheet = small(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    found = compute_calls.counted(lambda: compute_calls.compute_and_write(sheet, out))
    assert found["typing"] == 0, found
    assert found["parse"] == 0, found
    assert found["printed"] <= 1  # the check reads the rows the load read
    report = sheet.check()
    assert [r.verdict for r in report.rows] == ["pass", "pass"]
    assert any("6 mm is 3 times a" in f.what for f in report.findings)


def test_the_sheets_of_other_inputs_and_parts_share_the_typed_trees(tmp_path):
    sheet = small(tmp_path)
    other = sheet.with_inputs(a="3 mm").with_parts()
    assert other.typed is sheet.typed and len(sheet.typed) > 0
    found = compute_calls.counted(lambda: other.computed(excel=True))
    assert found["typing"] == 0 and found["parse"] == 0, found
    assert other.computed().table("curve").columns[1].values[0] == pytest.approx(9.0)


@pytest.mark.slow
def test_a_sheet_is_checked_and_computed_once_through_the_api(tmp_path, monkeypatch):
    from workbook import facade
    from workbook.compute import checks, computed

    calls = {"compute": 0, "check": 0}

    def counting(name, module, attr):
        real = getattr(module, attr)

        def wrapper(*args, **kwargs):
            calls[name] += 1
            return real(*args, **kwargs)

        monkeypatch.setattr(module, attr, wrapper)

    counting("compute", facade, "compute")
    counting("check", checks, "run_checks")
    sheet = small(tmp_path)
    report = sheet.check()
    sheet.write_xlsx(tmp_path / "a.xlsx")
    assert calls == {"compute": 1, "check": 1}
    sheet.write_xlsx(tmp_path / "a.xlsx", force=True)
    assert sheet.check() is report and calls == {"compute": 1, "check": 1}
    sheet.report(tmp_path / "a.html")
    sheet.report(tmp_path / "b.html")
    sheet._repr_html_()
    assert calls == {"compute": 2, "check": 1}  # the report's kind, once
    assert isinstance(sheet.computed(), computed.ComputedSheet)
    sheet.with_inputs(n="4").write_xlsx(tmp_path / "b.xlsx")  # another Sheet: its own
    assert calls == {"compute": 3, "check": 2}


@pytest.mark.slow
@pytest.mark.parametrize("name", compute_calls.sheets())
def test_computing_and_writing_types_and_parses_nothing(name):
    found = compute_calls.calls(name)
    assert found["typer"] == 0, found  # the typed trees are read, not asked of the typer
    assert found["typing"] == 0, found
    assert found["parse"] == 0, found
