"""Values that fail: named by `run` and `check` (exit 1), a failed table row an Excel error
cell with its cause, the rest of the workbook written."""

from __future__ import annotations

import contextlib
import io
import math
import os
import re
import zipfile

import numpy as np
import openpyxl
import pytest
from helpers.sheets import write_template

import workbook
from workbook.cli import main
from workbook.errors import DomainError

FAILING = """
[inputs]
a = "-2"
b = "0"
Q_far = "80 m^3/h"

[arguments]
x = { unit = "" }

[[solve]]
unknowns = { z = "1" }
equations = ["z^2 == -1"]

[data.pump]
file = "pump.csv"
columns = { Q = "m^3/h", H = "m" }

[definitions]
l = { expr = "ln(a)" }
good = { expr = "a*2" }
zz = { expr = "z + 1" }
H_far = { expr = "linterp(Q, H, Q_far)", unit = "m" }
"q(x)" = "1/(x - b)"
"r(x)" = "sqrt(x)"

[[tables]]
name = "t"
range = "x := -1, 0 .. 2"
columns = ["q", "r"]
"""

PUMP = "Q,H\n0,32\n10,31.2\n20,29.5\n"


def _cli(tmp_path, *args) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(list(args))
    finally:
        os.chdir(cwd)
    return code, out.getvalue(), err.getvalue()


@pytest.fixture
def failing(tmp_path):
    (tmp_path / "pump.csv").write_text(PUMP, encoding="utf-8")
    return write_template(tmp_path, FAILING)


def test_run_writes_the_workbook_names_each_failure_and_exits_1(tmp_path, failing):
    code, out, err = _cli(tmp_path, "run", str(failing), "--out", "f.xlsx")
    assert code == 1, err
    assert "good = -4" in out
    for name in ("l has no value", "z, zz have no value", "H_far has no value"):
        assert f"fail: [failed values] {name}" in err, err
    assert "table t: q has no value in 1 of 4 rows" in err
    assert "table t: r has no value in 1 of 4 rows" in err  # sqrt(-1): its own row
    assert "is outside the data" in err  # linterp names why
    wb = openpyxl.load_workbook(tmp_path / "f.xlsx")
    ws = wb["Listing"] if "Listing" in wb.sheetnames else wb[wb.sheetnames[1]]
    cells = {c.coordinate: c for row in ws.iter_rows() for c in row if c.value is not None}
    assert cells["B4"].value.startswith("=1/(")  # still the live formula
    assert "division by zero" in cells["B4"].comment.text
    assert "sqrt of a negative number" in cells["C3"].comment.text
    assert cells["B5"].comment is None and cells["C5"].comment is None
    with zipfile.ZipFile(tmp_path / "f.xlsx") as z:
        xml = next(
            z.read(n).decode()
            for n in z.namelist()
            if n.startswith("xl/worksheets/") and "<v>#DIV/0!</v>" in z.read(n).decode()
        )
    assert re.search(r'<c r="B4" [^>]*t="e"><f>[^<]*</f><v>#DIV/0!</v>', xml)
    assert re.search(r'<c r="C3" [^>]*t="e"><f>[^<]*</f><v>#NUM!</v>', xml)  # sqrt(-1)


def test_check_lists_the_failed_rows_and_exits_1(tmp_path, failing):
    code, out, _ = _cli(tmp_path, "check", str(failing))
    assert code == 1
    assert "table t: q has no value in 1 of 4 rows" in out and "x = 0: " in out
    assert "result: no printed values to check; 5 finding(s) FAIL" in out


def test_the_other_rows_are_the_engines_values(tmp_path, failing):
    (tmp_path / "pump.csv").write_text(PUMP, encoding="utf-8")
    sheet = workbook.load(failing)
    data = sheet.table_data("t")
    q, r = data.columns[1], data.columns[2]
    assert sorted(q.failed) == [1] and sorted(r.failed) == [0]
    assert np.isnan(q.values[1]) and q.values.tolist()[::2] == [-1.0, 1.0]
    assert q.values[3] == 0.5 and r.values[3] == pytest.approx(math.sqrt(2), rel=1e-15)
    assert q.excel_error(1) == "#DIV/0!" and r.excel_error(0) == "#NUM!"


def test_a_long_column_finds_each_failed_row(sheet_from):
    """The rows found by halving are exactly those that fail one by one."""
    text = """
[arguments]
x = { unit = "" }

[definitions]
"f(x)" = "1/(x - 3) + 1/(x - 4567) + sqrt(x - 5)"

[[tables]]
name = "t"
range = "x := 5, 6 .. 20004"
columns = ["f"]
"""
    sheet = sheet_from(text)
    col = sheet.table_data("t").columns[1]
    assert sorted(col.failed) == [4567 - 5]
    assert col.values[0] == pytest.approx(1 / 2 + 1 / (5 - 4567), rel=1e-15)
    assert np.isfinite(np.delete(col.values, 4567 - 5)).all()


def test_max_over_a_column_with_a_failed_row_is_an_error(sheet_from):
    text = """
[arguments]
x = { unit = "" }

[definitions]
"q(x)" = "1/(x - 1)"
top = "max_over(t, q)"

[[tables]]
name = "t"
range = "x := 0 .. 3"
columns = ["q"]
"""
    sheet = sheet_from(text)
    with pytest.raises(DomainError, match="has no value in 1 row"):
        sheet.evaluate("top")


def test_a_column_that_fails_everywhere_stops_the_run(tmp_path):
    text = """
[arguments]
x = { unit = "" }

[definitions]
"q(x)" = "ln(x - 10)"

[[tables]]
name = "t"
range = "x := 0 .. 3"
columns = ["q"]
"""
    code, _, err = _cli(tmp_path, "run", str(write_template(tmp_path, text)), "--out", "f.xlsx")
    assert code == 2 and "domain error" in err
    assert not (tmp_path / "f.xlsx").exists()


@pytest.mark.slow
def test_libreoffice_recalculates_the_error_cells_as_written(sheet_from, tmp_path):
    """LibreOffice's own evaluation of the written formulas gives the same error values in the
    failed rows (#DIV/0! for 1/0; for sqrt(-1) an error value too) and the engine's numbers in
    the others."""
    from helpers.recalc import cell_values, recalculate, soffice

    if soffice() is None:
        pytest.skip("LibreOffice is not installed")
    text = """
[inputs]
b = "0"

[arguments]
x = { unit = "" }

[definitions]
"q(x)" = "1/(x - b)"
"r(x)" = "sqrt(x)"

[[tables]]
name = "t"
range = "x := -1, 0 .. 2"
columns = ["q", "r"]
"""
    sheet = sheet_from(text)
    written = sheet.write_xlsx(tmp_path / "t.xlsx")
    ours = cell_values(written)
    theirs = cell_values(recalculate(written, tmp_path / "lo"))
    table = next(s for s, _ in ours if s not in ("Inputs", "Results", "Checks", "About"))
    assert ours[(table, "B4")] == theirs[(table, "B4")] == "#DIV/0!"
    # Excel's SQRT(-1) is #NUM! (what the engine caches); LibreOffice's is its Err:502,
    # saved as #VALUE!: an error value either way, never a number
    assert ours[(table, "C3")] == "#NUM!" and theirs[(table, "C3")] in ("#NUM!", "#VALUE!")
    for cell in ("B3", "B5", "B6", "C4", "C5", "C6"):
        assert theirs[(table, cell)] == pytest.approx(ours[(table, cell)], rel=1e-12)


def test_a_failed_value_is_computed_once(sheet_from, monkeypatch):
    """A table whose every row needs a [[solve]] that fails asks for it at every halving of
    its rows; the failure is remembered, so the block is solved once."""
    from workbook.engine import solve_blocks

    calls = []
    solve_block = solve_blocks.solve_block

    def counted(*args, **kw):
        calls.append(1)
        return solve_block(*args, **kw)

    monkeypatch.setattr(solve_blocks, "solve_block", counted)
    text = """
[arguments]
x = { unit = "" }

[[solve]]
unknowns = { z = "1" }
equations = ["z^2 == -1"]

[definitions]
"q(x)" = "x + z"

[[tables]]
name = "t"
range = "x := 0 .. 1000"
columns = ["q"]
"""
    sheet = sheet_from(text)
    with pytest.raises(DomainError, match="did not converge"):
        sheet.table("t")
    assert len(calls) == 1
