"""round, trunc (numbers) against mpmath, at the halves where numpy's half-to-even round
differs, and their refusal of values with units; the Excel formulas recalculated by
LibreOffice (slow)."""

from __future__ import annotations

import re

import mpmath
import numpy as np
import pytest

from workbook.errors import WorkbookError
from workbook.functions.builtins import round_numpy

SHEET = """
[inputs]
L = "17 mm"
step = "5 mm"
phi = "30 deg"

[arguments]
u = { unit = "" }
n = { unit = "" }

[definitions]
"r0(u)" = "round(u)"
"rn(u, n)" = "round(u, n)"
"t(u)" = "trunc(u)"
Lr = { expr = "round(L/step)*step", unit = "mm" }
"""


def _away(u: float, n: int = 0) -> float:
    """Half away from zero, of the exact value of the double u."""
    with mpmath.workdps(60):
        x, scale = mpmath.mpf(u), mpmath.mpf(10) ** n
        return float(mpmath.sign(x) * mpmath.floor(abs(x) * scale + mpmath.mpf(0.5)) / scale)


def test_round_goes_half_away_from_zero(sheet):
    halves = np.arange(-20, 21) + 0.5
    rng = np.random.default_rng(1)
    u = np.concatenate([halves, rng.uniform(-1e6, 1e6, 500), rng.uniform(-3, 3, 500)])
    got = sheet.evaluate("r0", u).magnitude
    assert got.tolist() == [_away(x) for x in u]
    assert np.any(got[:41] != np.round(halves))  # numpy's round would differ here


@pytest.mark.parametrize("n", [-3, -1, 1, 2, 5])
def test_round_to_decimals(sheet, n):
    rng = np.random.default_rng(n + 10)
    u = np.concatenate([rng.uniform(-1e4, 1e4, 400), np.array([0.125, -0.125, 2.5, 1250.0])])
    got = sheet.evaluate("rn", u, n).magnitude
    assert got.tolist() == [_away(x, n) for x in u]


def test_round_keeps_a_decimal_half_as_written():
    # the doubles of 2.675 and 1.005 are just below the half; Excel and LibreOffice round up
    assert round_numpy(2.675, 2) == 2.68
    assert round_numpy(1.005, 2) == 1.01
    assert round_numpy(-2.675, 2) == -2.68
    assert round_numpy(0.49999999999999, 0) == 0.0  # far from the half (many ulps): down
    assert round_numpy(2.0**50 + 0.25, 0) == 2.0**50  # no tolerance for large values


def test_round_edges():
    assert round_numpy(1e300, 2) == 1e300
    assert round_numpy(123.0, -400) == 0.0
    assert np.isnan(round_numpy(1.5, 0.5))
    assert str(round_numpy(-0.3)) == "0.0"  # not -0.0


def test_trunc_goes_toward_zero(sheet):
    u = np.array([-2.7, -2.0, -0.5, 0.0, 0.5, 2.7, 1e17 + 2])
    assert sheet.evaluate("t", u).magnitude.tolist() == [-2.0, -2.0, 0.0, 0.0, 0.0, 2.0, 1e17 + 2]


def test_round_of_a_ratio_times_a_step(sheet):
    assert sheet.evaluate("Lr").to("mm").magnitude == pytest.approx(15.0, rel=1e-15)


def test_a_ratio_of_units_of_one_kind_is_its_plain_number(sheet_from):
    """round(b/(1 mm)) with b in metres counts millimetres, as Mathcad does (the ratio m/mm is
    the plain number 1000 times its magnitude); floor and trunc likewise."""
    text = SHEET + 'B = "0.3047 m"\nm = "round(B/(1 mm))"\nk = "trunc(B/(1 cm))"\n'
    sheet = sheet_from(text)
    assert sheet.evaluate("m").magnitude == 305.0
    assert sheet.evaluate("k").magnitude == 30.0


@pytest.mark.parametrize(
    "expr,message",
    [
        ("round(L)", "round() needs a plain number, got a value in mm"),
        ("trunc(phi)", "trunc() needs a plain number, got a value in deg"),
        ("round(phi/(1 s)*(1 s))", "round() needs a plain number"),
        ("floor(L/(1 mm)*(1 percent))", "floor() needs a plain number"),
        ("round(2.5, L)", "the number of decimals needs a dimensionless argument"),
    ],
)
def test_a_value_with_a_unit_is_refused(sheet_from, expr, message):
    with pytest.raises(WorkbookError, match=message.replace("(", r"\(").replace(")", r"\)")):
        sheet_from(SHEET + f'bad = "{expr}"\n')


LIVE = """
[inputs]
x = "2.675"

[definitions]
a = "round(x, 2)"
b = "round(-2.5) + 10*round(0.125, 2)"
c = "trunc(-x) + round(1234.5, -2)"
d = "round(1.005, 2)"
v = "[1, 2, 3, 4, 10]"
e = "stdev(v) + 10*var(v) + 100*median(v, 7)"
f = "det(identity(3)*2) + sum(identity(2))"
B = "0.3047 m"
g = "round(B/(1 mm)) + trunc(B/(1 cm))"
"""


@pytest.mark.slow
def test_libreoffice_agrees(sheet_from, tmp_path):
    import openpyxl
    from helpers.recalc import recalculate, soffice

    if soffice() is None:
        pytest.skip("LibreOffice is not installed")
    sheet = sheet_from(LIVE)
    path = sheet.write_xlsx(tmp_path / "live.xlsx")
    written = openpyxl.load_workbook(path)
    cached = openpyxl.load_workbook(path, data_only=True)
    lo = openpyxl.load_workbook(recalculate(path, tmp_path / "lo"), data_only=True)
    checked = []
    for ws in written.worksheets:
        for row in ws.iter_rows():
            for c in row:
                formula = getattr(c.value, "text", c.value)  # array formulas: their text
                if not (isinstance(formula, str) and formula.startswith("=")):
                    continue
                want = cached[ws.title][c.coordinate].value
                got = lo[ws.title][c.coordinate].value
                assert got == pytest.approx(want, rel=1e-15, abs=1e-15), (formula, got, want)
                checked.append(formula)
    called = " ".join(checked)
    for function in ("ROUND(", "TRUNC(", "_xlfn.STDEV.P(", "_xlfn.VAR.P(", "MEDIAN(", "({1,0"):
        assert function in called, function


# -- sort, reverse, rsort ------------------------------------------------------------------------
ARRAYS = '''
[sheet]
origin = 1

[inputs]
a = "2 m"

[arguments]
u = { unit = "" }
n = { unit = "" }

[definitions]
v = { expr = "[3, 1, 2, 1]*a", unit = "mm" }
s = { expr = "sort(v)", unit = "m" }
r = "reverse([[1, 2], [3, 4], [5, 6]])"
rv = "reverse(v)"
rs = "rsort([[3, 1, 2, 1], [30, 10, 20, 11]], 1)"
rs2 = "rsort([[3, 1, 2], [30, 10, 20]], 2)"
"f(u)" = "sort([u, 1 - u, 0.5])"
"g(u)" = "reverse([u, 2*u])"
"grown(n)" = { program = """
for i in 1 .. n
    w[i] := mod(7*i, 5)
sort(w)
""" }
"backwards(n)" = { program = """
for i in 1 .. n
    w[i] := [i, 2*i]
reverse(w)
""" }
"by_row(n)" = { program = """
M[1, 1] := n
M[1, 2] := 1
M[2, 1] := 10*n
M[2, 2] := 10
rsort(M, 1)
""" }
"maybe(n)" = { program = """
for i in 1 .. n
    w[i] := i if i > 3
sort(w)
""" }
"rowsort(n)" = { program = """
for i in 1 .. n
    w[i] := i
rsort(w, n + 1)
""" }
back = "backwards(3)"
'''


@pytest.fixture(scope="module")
def arrays(load_text):
    return load_text(ARRAYS, name="t")


def test_sort_reverse_rsort_of_fixed_arrays(arrays):
    assert arrays.evaluate("s").to("m").magnitude.ravel().tolist() == [2.0, 2.0, 4.0, 6.0]
    assert arrays.evaluate("r").magnitude.tolist() == [[5, 6], [3, 4], [1, 2]]
    assert arrays.evaluate("rv").to("m").magnitude.ravel().tolist() == [2.0, 4.0, 2.0, 6.0]
    # stable: the two columns with 1 in row 1 keep their order
    assert arrays.evaluate("rs").magnitude.tolist() == [[1, 1, 2, 3], [10, 11, 20, 30]]
    assert arrays.evaluate("rs2").magnitude.tolist() == [[1, 2, 3], [10, 20, 30]]


def test_sort_over_a_range_sorts_each_point(arrays):
    u = np.linspace(-1, 2, 31)
    got = arrays.evaluate("f", u).magnitude
    want = np.sort(np.stack([u, 1 - u, np.full_like(u, 0.5)]), axis=0)
    assert got.shape == (3, 1, 31) and np.array_equal(got[:, 0, :], want)
    assert np.array_equal(arrays.evaluate("g", u).magnitude[:, 0, :], np.stack([2 * u, u]))


def test_run_time_arrays(arrays):
    from workbook.engine import runtime as rt

    grown = rt.value(arrays.evaluate("grown", 6.0).magnitude)
    assert grown.ravel().tolist() == sorted(float(7 * i % 5) for i in range(1, 7))
    back = rt.value(arrays.scalar_value("back", "definition"))  # a nested array reversed
    assert [rt.value(e).ravel().tolist() for e in back.ravel()] == [[3, 6], [2, 4], [1, 2]]
    assert rt.value(arrays.evaluate("by_row", 5.0).magnitude).tolist() == [[1, 5], [10, 50]]


@pytest.mark.parametrize(
    "call,message",
    [
        ("maybe(2)", r"sort\(\) takes a vector, got a number"),
        ("rowsort(2)", r"rsort\(\): row 3 is outside the 2x1 matrix"),
    ],
)
def test_run_time_mistakes_are_errors(arrays, call, message):
    name, _, n = call.partition("(")
    with pytest.raises(WorkbookError, match=message):
        arrays.evaluate(name, float(n.rstrip(")")))


@pytest.mark.parametrize(
    "expr,message",
    [
        ("sort([[1, 2], [3, 4]])", r"sort\(\): argument 1 must be a vector, got a 2x2"),
        ("sort(a)", r"sort\(\): argument 1 must be a vector, got a number"),
        ("reverse(a)", r"reverse\(\): argument 1 must be a vector or matrix, got a number"),
        ("rsort([[1, 2], [3, 4]], 3)", r"rsort\(\): row 3 is outside the 2x2"),
        ("rsort([[1, 2], [3, 4]], a)", r"rsort\(\): the row needs a dimensionless"),
    ],
)
def test_load_mistakes_are_errors(sheet_from, expr, message):
    with pytest.raises(WorkbookError, match=message):
        sheet_from(ARRAYS + f'bad = "{expr}"\n')


def test_sorted_arrays_are_written_as_values(arrays, tmp_path):
    import openpyxl

    wb = openpyxl.load_workbook(arrays.write_xlsx(tmp_path / "sorts.xlsx"))
    comments = [c.comment.text for ws in wb for row in ws.iter_rows() for c in row if c.comment]
    for name in ("sort", "reverse", "rsort"):
        assert any(f"{name}() is written as values" in t for t in comments), name


# -- identity, stdev, var, median ----------------------------------------------------------------
STATS = '''
[inputs]
a = "2 kN/m"
N = "3"

[arguments]
u = { unit = "" }
n = { unit = "" }

[definitions]
K = "[[4, 1], [2, 3]]*a"
I3 = "identity(3)"
A = "K - a*identity(rows(K))"
x = { expr = "[1, 2, 3, 4, 10]*a", unit = "N/mm" }
sd = { expr = "stdev(x)", unit = "N/mm" }
vr = { expr = "var(x)", unit = "N^2/mm^2" }
md = { expr = "median(x)", unit = "N/mm" }
md_even = "median([4, 1, 3, 2])"
mixed = { expr = "stdev(x, a, [[1, 2], [3, 4]]*a)", unit = "N/mm" }
"sdu(u)" = "stdev([u, 2*u^2, 3], 1)"
"vru(u)" = "var([u, 2*u^2, 3], 1)"
"mdu(u)" = "median([u, 2*u^2, 3], 1)"
"grown(n)" = { program = """
for i in 1 .. n
    w[i] := i^2
stdev(w) + 1000*median(w)
""" }
'''


@pytest.fixture(scope="module")
def stats(load_text):
    return load_text(STATS, name="t")


def _population(values):
    """mpmath at 50 digits: (stdev, var, median), divided by N."""
    with mpmath.workdps(50):
        xs = [mpmath.mpf(float(v)) for v in values]
        mean = mpmath.fsum(xs) / len(xs)
        var = mpmath.fsum((x - mean) ** 2 for x in xs) / len(xs)
        s = sorted(xs)
        k = len(s) // 2
        median = s[k] if len(s) % 2 else (s[k - 1] + s[k]) / 2
        return float(mpmath.sqrt(var)), float(var), float(median)


def test_identity(stats):
    assert stats.evaluate("I3").magnitude.tolist() == np.eye(3).tolist()
    assert stats.evaluate("A").to("kN/m").magnitude.tolist() == [[6, 2], [4, 4]]


@pytest.mark.parametrize(
    "expr,message",
    [
        ("identity(N)", "n must be a positive integer known at load"),
        ("identity(0)", "n must be a positive integer known at load"),
        ("identity(2.5)", "n must be a positive integer known at load"),
        ("identity(a)", "needs a dimensionless argument"),
        ("identity(5000)", "more than 2000 rows"),
    ],
)
def test_identity_needs_a_size_known_at_load(sheet_from, expr, message):
    with pytest.raises(WorkbookError, match=re.escape(message)):
        sheet_from(STATS + f'bad = "{expr}"\n')


def test_statistics_against_mpmath(stats):
    sd, var, med = _population([2, 4, 6, 8, 20])  # x in N/mm
    assert stats.evaluate("sd").to("N/mm").magnitude == pytest.approx(sd, rel=1e-15)
    assert stats.evaluate("vr").to("N^2/mm^2").magnitude == pytest.approx(var, rel=1e-15)
    assert stats.evaluate("md").to("N/mm").magnitude == med == 6.0
    assert stats.evaluate("md_even").magnitude == 2.5
    sd, _, _ = _population([2, 4, 6, 8, 20, 2, 2, 4, 6, 8])
    assert stats.evaluate("mixed").to("N/mm").magnitude == pytest.approx(sd, rel=1e-15)


@pytest.mark.parametrize("name,which", [("sdu", 0), ("vru", 1), ("mdu", 2)])
def test_statistics_over_a_range_against_mpmath(stats, name, which):
    u = np.concatenate([np.linspace(-3, 3, 61), np.random.default_rng(7).uniform(-1e3, 1e3, 100)])
    got = stats.evaluate(name, u).magnitude
    want = np.array([_population([x, 2 * x * x, 3.0, 1.0])[which] for x in u])
    assert np.allclose(got, want, rtol=4e-16 * 8, atol=0)


def test_statistics_of_a_run_time_array(stats):
    sd, _, med = _population([0, 1, 4, 9, 16])  # origin 0: w[0] is 0
    assert stats.evaluate("grown", 4.0).magnitude == pytest.approx(sd + 1000 * med, rel=1e-15)


def test_statistics_are_live_and_formulas_agrees(stats, tmp_path):
    import formulas
    import openpyxl

    path = stats.write_xlsx(tmp_path / "stats.xlsx")
    ws = openpyxl.load_workbook(path)["Results"]
    rows = {
        r[0].value: getattr(r[1].value, "text", r[1].value)  # array formulas: their text
        for r in ws.iter_rows(min_row=2)
        if r[0].value
    }
    assert rows["sd"] == "=_xlfn.STDEV.P(x_)"
    assert rows["vr"] == "=_xlfn.VAR.P(x_)"
    assert rows["md"] == "=MEDIAN(x_)"
    solution = formulas.ExcelModel().loads(str(path)).finish().calculate()
    got = {}
    for key, value in solution.items():
        book_sheet, _, cell = key.rpartition("!")
        if book_sheet.upper().endswith("RESULTS'") and ":" not in cell:
            got[cell.upper()] = value.value[0, 0]
    checked = 0
    for r in ws.iter_rows(min_row=2):
        if r[0].value in ("sd", "vr", "md", "md_even", "mixed"):
            checked += 1
            unit = r[2].value or ""
            want = stats.evaluate(r[0].value).to(unit).magnitude
            assert float(got[r[1].coordinate]) == pytest.approx(want, rel=1e-13), r[0].value
    assert checked == 5


# -- sec, csc, cot ------------------------------------------------------------------------------
RECIPROCAL = """
[inputs]
a = "35 deg"
x = "0.7"

[definitions]
s = "sec(a)"
c = "csc(x)"
k = "cot(a) + cot(x)"
"""


def test_reciprocal_trigonometry_against_mpmath_and_formulas(sheet_from, tmp_path):
    """sec, csc and cot (Mathcad's) against mpmath at 30 digits; their Excel form 1/COS(...)
    recalculated by the `formulas` package."""
    import formulas
    import openpyxl

    sheet = sheet_from(RECIPROCAL)
    mpmath.mp.dps = 30
    a = mpmath.radians(35)
    want = {
        "s": mpmath.sec(a),
        "c": mpmath.csc(mpmath.mpf("0.7")),
        "k": mpmath.cot(a) + mpmath.cot(mpmath.mpf("0.7")),
    }
    for name, value in want.items():
        assert sheet.evaluate(name).magnitude == pytest.approx(float(value), rel=4e-16), name
    path = sheet.write_xlsx(tmp_path / "trig.xlsx")
    ws = openpyxl.load_workbook(path)["Results"]
    cells = {r[0].value: r[1] for r in ws.iter_rows(min_row=2) if r[0].value in want}
    assert cells["s"].value.startswith("=1/COS(")
    solution = formulas.ExcelModel().loads(str(path)).finish().calculate()
    got = {
        key.rpartition("!")[2].upper(): v.value[0, 0]
        for key, v in solution.items()
        if key.rpartition("!")[0].upper().endswith("RESULTS'")
    }
    for name, cell in cells.items():
        assert float(got[cell.coordinate]) == pytest.approx(float(want[name]), rel=1e-14), name
