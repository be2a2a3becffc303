"""The live-cell check covers every formula cell: scalar arithmetic too, table columns, text
results, checks. Its fast reader of Excel formulas (workbook.compute.xleval) is compared
with the `formulas` package formula by formula, and a ratio scaled twice (the printer's
mistake put back on purpose) is caught and written as the engine's value."""

from __future__ import annotations

import contextlib
import io
import math

import numpy as np
import openpyxl
import pytest
from helpers.recalc import formula_values
from helpers.sheets import FROZEN, RATIOS

from workbook.compute import livecheck, xleval
from workbook.language import cellunit


def _formulas_package(text: str):
    import formulas

    out = formulas.Parser().ast(text)[1].compile()()
    a = np.asarray(out, dtype=object)
    return a if a.ndim == 2 and a.size > 1 else a.ravel()[0]


def _same(mine, theirs) -> bool:
    if isinstance(mine, np.ndarray):
        theirs = np.asarray(theirs, dtype=object)
        return mine.shape == theirs.shape and all(
            _same(float(a), b) for a, b in zip(mine.flat, theirs.flat)
        )
    if isinstance(mine, xleval.XlError):
        return str(theirs).startswith("#")
    if isinstance(mine, (bool, str)):
        return str(mine).upper() == str(theirs).upper()
    if isinstance(mine, float) and math.isnan(mine):
        return str(theirs).startswith("#")
    return not isinstance(theirs, str) and math.isclose(mine, float(theirs), rel_tol=1e-13)


# Excel's rules where a second reader of formulas is most likely to slip
CASES = [
    "=-2^2",
    "=2^3^2",
    "=1-2-3",
    "=8/4/2",
    "=MOD(-3, 2)",
    "=MOD(3, -2)",
    "=ATAN2(1, 2)",
    "=ATAN2(-1, 0)",
    "=ROUND(2.5, 0)",
    "=ROUND(-2.5, 0)",
    "=TRUNC(-2.7)",
    "=INT(-2.5)",
    "=1/0",
    "=SQRT(-1)",
    "=IF(1>0, 2, 1/0)",
    "=IF(1<0, 2, 3)",
    '="a"&1.5&TRUE',
    '=IF(2>1, "Euler", "Johnson")',
    '="a"<"B"',
    '=1<"a"',
    "=AND(1>0, 2>1, NOT(0))",
    "=OR(1<0, 0)",
    "=SUMPRODUCT({1,2,3}*{4,5,6})",
    "=SUMPRODUCT({1,2,3},{4,5,6})",
    "=SUM({1,2,3})+MAX({4,5})-MIN({7,8})",
    "=SUMSQ({1,2,3})",
    "=INDEX({10;20;30}, 2)",
    "=INDEX({1,2;3,4}, 2, 1)",
    "=MATCH(2.5, {1,2,3})",
    "=MATCH(2, {1,2,3}, 0)",
    "=CHOOSE(2, 10, 20, 30)",
    "=MMULT({1,2;3,4}, {5;6})",
    "=MINVERSE({2,0;0,4})",
    "=MDETERM({1,2;3,4})",
    "=TRANSPOSE({1,2,3})",
    "=SIN({0.1,0.2})*COS({0.3,0.4})",
    "=ABS(-3)*SIGN(-2)+EXP(1)+LN(2)+LOG10(1000)+TAN(0.5)+ACOS(0.5)",
    "=IF({1,0,1}, {1,2,3}, {4,5,6})",
    "=PI()*POWER(2, 0.5)",
    "=(1+1E-3)*2.5E+2",
    "=50%",
    "=NA()",
]


@pytest.mark.parametrize("text", CASES)
def test_the_fast_reader_computes_as_the_formulas_package(text):
    mine = xleval.compile_formula(text)(lambda key: pytest.fail(f"reads {key}"))
    theirs = _formulas_package(text)
    assert _same(mine, theirs), (text, mine, theirs)


def test_a_formula_it_does_not_know_goes_to_the_formulas_package():
    with pytest.raises(xleval.Unsupported):
        xleval.compile_formula("=IFERROR(1/0, 2)")
    log = livecheck.CellLog()
    log.values[("S", 0, 0)] = 2.0
    log.values[("S", 0, 1)] = 2.0
    log.formulas[("S", 0, 1)] = livecheck.Formula("S", 0, 1, "=IFERROR(1/0, A1)", 0, 1)
    outcome = livecheck.check(log)
    assert outcome.checked == 1 and outcome.refusals == []


@pytest.fixture
def scaled_twice(monkeypatch):
    """The printer's old mistake: a reference printed in the unit the formula is typed in,
    whatever unit its cell holds the number in."""
    monkeypatch.setattr(cellunit, "reading", lambda convert, t: t)


def test_a_ratio_scaled_twice_is_caught_and_written_as_the_engines_value(
    tmp_path, sheet_from, scaled_twice
):
    sheet = sheet_from(RATIOS)
    refusals: list = []
    out = sheet.write_xlsx(tmp_path / "ratios.xlsx", refusals=refusals)
    where = {r.where for r in refusals}
    assert any(w.startswith("'Results'!B") for w in where), where  # y = 2*r: plain arithmetic
    assert any(w.startswith("'Listing'!C") for w in where), where  # "f(x)" = "x*r"
    ws = openpyxl.load_workbook(out)["Results"]
    values = openpyxl.load_workbook(out, data_only=True)["Results"]
    rows = {ws.cell(r, 1).value: r for r in range(2, ws.max_row + 1)}
    y = ws.cell(rows["y"], 2)
    assert not str(y.value).startswith("=") and math.isclose(y.value, 1.5, rel_tol=1e-12)
    assert "independent evaluation" in y.comment.text
    assert values.cell(rows["r"], 2).value == pytest.approx(0.75, rel=1e-12)


@pytest.mark.slow
def test_run_prints_each_cell_written_as_a_value(tmp_path, scaled_twice):
    from workbook.cli import main

    path = tmp_path / "ratios.toml"
    path.write_text(RATIOS, encoding="utf-8")
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        assert main(["run", str(path), "--out", str(tmp_path / "r.xlsx")]) == 0
    lines = [x for x in buf.getvalue().splitlines() if x.startswith("written as a value")]
    assert lines and all("the engine" in x for x in lines)


def test_every_formula_cell_is_computed(tmp_path, sheet_from):
    sheet = sheet_from(RATIOS)
    out = sheet.write_xlsx(tmp_path / "ratios.xlsx")
    about = openpyxl.load_workbook(out)["About"]
    text = next(r[1] for r in about.iter_rows(values_only=True) if r[0] == "Formulas checked")
    assert "every formula cell" in text and "not computed" not in text


# |v| of a crank over a turn: four equal peaks (48, 138, 228 and 318 deg), 8 samples apart
CRANK = """
[inputs]
r = "50 mm"
omega = "100 rad/s"

[arguments]
th = { unit = "deg" }

[definitions]
"v(th)" = { expr = "r*omega*sin(2*(th - 3 deg))", unit = "m/s" }
vmax = { expr = "maximum(abs(v(th)), th, 0 deg, 360 deg)", unit = "m/s" }
thmax = { expr = "argmax(abs(v(th)), th, 0 deg, 360 deg)", unit = "deg" }
"""


@pytest.mark.slow
def test_equal_peaks_are_chosen_alike_whatever_the_rounding(tmp_path, sheet_from):
    """Another program's sin rounds the samples of the later peaks up by an ulp or so: the
    live formulas still take the first peak, as the engine does (a MATCH of the exact MAX
    would jump to the later one)."""
    from helpers.recalculated import formulas_recalculated

    sheet = sheet_from(CRANK)
    out = sheet.write_xlsx(tmp_path / "crank.xlsx")
    book = openpyxl.load_workbook(out)
    cached = openpyxl.load_workbook(out, data_only=True)["Solver steps"]
    ws = book["Solver steps"]
    header = [c.value for c in ws[2]]
    best = header.index("best") + 1
    k = int(cached.cell(3, best).value)
    samples = [cached.cell(3, 2 + j).value for j in range(best - 2)]
    m = len(samples) - 1
    later = [j for j in range(m + 1) if j > k and abs(samples[j] - samples[k]) < 1e-12]
    assert later, samples  # the curve has equal peaks where the engine samples it
    for j in later:  # each later peak a little higher, as a last-bit difference makes it
        ws.cell(3, 2 + j).value = samples[j] * (1 + 4e-16)
    edited = tmp_path / "edited.xlsx"
    book.save(edited)
    got = formulas_recalculated(edited)
    assert got[("SOLVER STEPS", f"{openpyxl.utils.get_column_letter(best)}3")] == k
    thmax, vmax = sheet.evaluate("thmax").magnitude, sheet.evaluate("vmax").magnitude
    rows = {book["Results"].cell(r, 1).value: r for r in range(2, book["Results"].max_row + 1)}
    assert math.isclose(got[("RESULTS", f"B{rows['thmax']}")], thmax, rel_tol=1e-9)
    assert math.isclose(got[("RESULTS", f"B{rows['vmax']}")], vmax, rel_tol=1e-9)
    # the exact maximum's first match is a later peak: the tie rule is what kept the first
    values = np.array(
        [[samples[j] * (1 + 4e-16) if j in later else samples[j]] for j in range(m + 1)],
        dtype=object,
    ).T
    match = xleval.compile_formula("=MATCH(MAX(S),S,0)-1")(lambda key: values)
    assert match != k


def test_frozen_values_and_the_live_cells_that_read_them_are_marked(tmp_path, sheet_from):
    out = sheet_from(FROZEN).write_xlsx(tmp_path / "frozen.xlsx")
    book = openpyxl.load_workbook(out)
    ws = book["Results"]
    cells = {ws.cell(r, 1).value: ws.cell(r, 2) for r in range(2, ws.max_row + 1)}

    def fill(c) -> str:
        return c.fill.fgColor.rgb if c.fill.fill_type else ""

    for name in ("S", "y"):  # found by a solver block; y reads it, so has no formula either
        assert not str(cells[name].value).startswith("=") and fill(cells[name]) == "FFD9D9D9"
        assert "not a formula" in cells[name].comment.text
    z = cells["z"]  # live, but reads y
    assert str(z.value).startswith("=") and fill(z) == "FFFCE4D6"
    assert "reads y" in z.comment.text and "workbook run" in z.comment.text
    assert fill(cells["w"]) == "" and cells["w"].comment is None
    # a sum whose bounds follow an input is live, as guarded terms up to a maximum
    assert str(cells["total"].value).startswith("=IF(OR(") and fill(cells["total"]) == ""
    notes = [str(r[0]) for r in book["Inputs"].iter_rows(values_only=True) if r[0]]
    assert any(t.startswith("Frozen (grey): S, y:") and "--inputs" in t for t in notes)
    assert any(t.startswith("Live but reading a frozen value") and ": z" in t for t in notes)
    # the edited workbook's inputs still read back: the lists stand below the input table
    from workbook.roundtrip import read_inputs

    assert set(read_inputs(sheet_from(FROZEN), out)) <= {"a", "n"}


# two tables read g(x), a root, at their own rows: a single-row table over an input
TWO_TABLES = """
[inputs]
k = "2"
xa = "3"
xb = "5"

[arguments]
x = { unit = "" }
u = { unit = "" }

[definitions]
"g(x)" = "root(u^3 + k*u - x, u, 0, 10)"

[[tables]]
name = "many"
range = "x := 1, 2 .. xb"
columns = ["g"]

[[tables]]
name = "one"
range = "x := xa .. xa"
columns = ["g(x)", "2*g(x)"]
sheet = "One"

[[tables]]
name = "log"
range = "x := logspace(xa, xb*10, 5)"
columns = ["x^2"]
sheet = "Log"
"""


def test_a_table_computed_at_other_inputs_is_marked_frozen(tmp_path, sheet_from):
    """A `vary` table's values were computed at other values of an input: they are numbers,
    grey, and listed as frozen on the Inputs sheet."""
    text = (
        '[inputs]\nk = "2000 N/m"\nm = "0.5 kg"\nx0 = "10 mm"\n[arguments]\nt = { unit = "s" }\n'
        '[definitions]\n"x(t)" = { expr = "x0*cos(sqrt(k/m)*t)", unit = "mm" }\n'
        '[[tables]]\nname = "family"\nrange = "t := 0, 0.05 .. 0.1"\n'
        'vary = { k = ["1000 N/m", "4000 N/m"] }\ncolumns = { x = "mm" }\n'
    )
    book = openpyxl.load_workbook(sheet_from(text).write_xlsx(tmp_path / "family.xlsx"))
    grey = [
        c.value
        for row in book["Listing"].iter_rows()
        for c in row
        if c.fill.fill_type and c.fill.fgColor.rgb == "FFD9D9D9"
    ]
    assert len(grey) == 3 * 3 and all(isinstance(v, (int, float)) for v in grey)
    notes = [str(r[0]) for r in book["Inputs"].iter_rows(values_only=True) if r[0]]
    assert any(t.startswith("Frozen (grey): family.t [s], family.x k=1000 N/m") for t in notes)


def test_each_table_reads_its_own_rows_steps_and_ranges_over_inputs_are_live(tmp_path, sheet_from):
    """The printed text of a call is reused only with the same helper cells: the second
    table's root reads its own bisection steps, not the first table's; a single-row range
    and a log-spaced range whose bounds are inputs are formulas, so they follow an edit."""
    sheet = sheet_from(TWO_TABLES)
    form = sheet.computed(excel=True).excel
    assert not form.refusals, [r.why for r in form.refusals]
    out = sheet.write_xlsx(tmp_path / "two.xlsx")
    book = openpyxl.load_workbook(out)
    one, log = book["One"], book["Log"]
    assert one["A3"].value == "=(xa)+$D$1"  # its row-count guard: right of the title
    assert one["D1"].value.startswith("=IF(AND(")
    assert log["C1"].value == "=IF((5)=5,0,NA())"
    assert log["A3"].value == "=(xa)+$C$1" and log["A7"].value == "=(xb*10)+$C$1"
    assert log["A5"].value.startswith("=(xa)*((xb*10)/(xa))^(")
    first = book["Listing"]["B3"].value
    assert "Solver rows" in first and "Solver rows" in one["B3"].value
    steps = {c.value for c in book["Solver rows"][3] if isinstance(c.value, str)}
    assert any("'One'!$A$3" in s for s in steps) and any("'Listing'!$A$3" in s for s in steps)


def test_the_workbook_does_not_depend_on_what_was_evaluated_before(tmp_path, sheet_from):
    """A definition evaluated through the API before writing is not thereby 'used' by a
    table: the workbook written after evaluating every definition is the one written
    without (no Definitions sheet appears)."""
    text = RATIOS + '[[tables]]\nname = "t"\nrange = "n_row := 0 .. 2"\ncolumns = ["2*n_row"]\n'
    first = formula_values(sheet_from(text).write_xlsx(tmp_path / "a.xlsx"))
    asked = sheet_from(text)
    for name, d in asked.spec.definitions.items():
        if not d.is_function:
            asked.evaluate(name)
    assert formula_values(asked.write_xlsx(tmp_path / "b.xlsx")) == first
