"""Complex numbers: literals, arithmetic and built-ins against Python's complex and mpmath at
50 digits, units on complex values, matrices against numpy, the refusals at load, the Excel
forms against the formulas package, the report and the run output."""

import cmath
import math

import mpmath
import numpy as np
import pytest
from helpers.sheets import AC

import workbook
from workbook.compute.livecheck import agrees, complex_error
from workbook.errors import DomainError, TemplateError, UnitError, WorkbookError
from workbook.functions.complexes import excel_text, parse_text, readable
from workbook.language import expr as ex

mpmath.mp.dps = 50


def _text(definitions: str, head: str = "") -> str:
    return head + "[definitions]\n" + definitions


def _value(sheet, name, unit=None):
    q = sheet.evaluate(name)
    return (q.to(unit) if unit else q.to("")).magnitude


# -- literals ---------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "text,tree",
    [
        ("3 + 4i", ex.Binary("+", ex.Number(3.0), ex.Imaginary(4.0))),
        ("2.5j", ex.Imaginary(2.5)),
        ("1e3i", ex.Imaginary(1000.0)),
        ("X*1i", ex.Binary("*", ex.Name("X"), ex.Imaginary(1.0))),
        ("i + j", ex.Binary("+", ex.Name("i"), ex.Name("j"))),  # names, as range variables
        ("2*i", ex.Binary("*", ex.Number(2.0), ex.Name("i"))),
        ("v[i]", ex.Index(ex.Name("v"), (ex.Name("i"),))),
    ],
)
def test_literals_and_names(text, tree):
    assert ex.parse(text) == tree
    assert ex.parse(ex.to_text(tree)) == tree  # printed back, read the same


def test_a_unit_after_an_imaginary_number_says_what_to_write():
    with pytest.raises(TemplateError, match=r"write the unit as a factor, 4i\*1 ohm"):
        ex.parse("3 + 4i ohm")


def test_i_and_j_stay_range_variables(sheet_from):
    text = """[arguments]
i = { unit = "" }

[definitions]
v = "[10, 20, 30]"
z = "v[1] + 2i"

[[tables]]
name = "t"
range = "i := 0 .. 2"
columns = { "v[i]*2" = "", "i + 1" = "" }
"""
    sheet = sheet_from(text, name="r")
    table = sheet.table("t")
    assert list(table.iloc[:, 1]) == [20, 40, 60]
    assert list(table.iloc[:, 2]) == [1, 2, 3]
    assert _value(sheet, "z") == 20 + 2j


# -- arithmetic and built-ins against Python's complex and mpmath -------------------------------
CASES = [
    ("(3 + 4i)*(1 - 2i)/(2 + 1i)", (3 + 4j) * (1 - 2j) / (2 + 1j)),
    ("(3 + 4i)^2 - 1i", (3 + 4j) ** 2 - 1j),
    ("-(2 - 5j) + 0.5", -(2 - 5j) + 0.5),
    ("1/(1i)", 1 / 1j),
    ("abs(3 + 4i)", 5.0),
    ("arg(-1 - 1i)", cmath.phase(-1 - 1j)),
    ("Re(3 - 4i)*Im(2 + 7i)", 21.0),
    ("conj(3 + 4i)", 3 - 4j),
    ("sum(k*1i + 1, k, 1, 4)", 4 + 10j),
    ("sum([1i, 2, 3 + 1i])", 5 + 2j),
]
MPMATH = [
    ("exp(1i*pi/3)", lambda: mpmath.exp(1j * mpmath.pi / 3)),
    ("sqrt(-4 + 0i)", lambda: mpmath.sqrt(mpmath.mpc(-4, 0))),
    ("sqrt(3 - 4i)", lambda: mpmath.sqrt(mpmath.mpc(3, -4))),
    ("ln(-1 + 0i)", lambda: mpmath.log(mpmath.mpc(-1, 0))),
    ("ln(2 + 3i)", lambda: mpmath.log(mpmath.mpc(2, 3))),
    ("log10(2 + 3i)", lambda: mpmath.log(mpmath.mpc(2, 3), 10)),
    ("(1 + 1i)^0.5", lambda: mpmath.power(mpmath.mpc(1, 1), 0.5)),
    ("(1 + 1i)^(2 - 1i)", lambda: mpmath.power(mpmath.mpc(1, 1), mpmath.mpc(2, -1))),
    ("(-8 + 0i)^(1/3)", lambda: mpmath.cbrt(mpmath.mpc(-8, 0))),
    ("2^(1i)", lambda: mpmath.power(2, 1j)),
    ("sin(1 + 2i)", lambda: mpmath.sin(mpmath.mpc(1, 2))),
    ("cos(1 + 2i)", lambda: mpmath.cos(mpmath.mpc(1, 2))),
    ("tan(1 + 2i)", lambda: mpmath.tan(mpmath.mpc(1, 2))),
    ("sinh(1 - 2i)", lambda: mpmath.sinh(mpmath.mpc(1, -2))),
    ("cosh(1 - 2i)", lambda: mpmath.cosh(mpmath.mpc(1, -2))),
    ("tanh(1 - 2i)", lambda: mpmath.tanh(mpmath.mpc(1, -2))),
    ("polar(2, pi/3)", lambda: 2 * mpmath.expjpi(mpmath.mpf(1) / 3)),
    ("polar(2, 150 deg)", lambda: mpmath.mpc(2 * mpmath.cos(mpmath.pi * 5 / 6), 1)),
]


@pytest.mark.parametrize("text,want", CASES, ids=[c[0] for c in CASES])
def test_arithmetic_against_python_complex(sheet_from, text, want):
    sheet = sheet_from(_text(f'x = "{text}"\ny = "{text} + 0*p"\n', '[inputs]\np = "1"\n'))
    for name in ("x", "y"):  # folded at load, and computed by numpy
        got = complex(_value(sheet, name))
        assert abs(got - want) <= 1e-15 * max(1.0, abs(want)), (name, got, want)


@pytest.mark.parametrize("text,want", MPMATH, ids=[c[0] for c in MPMATH])
def test_functions_against_mpmath(sheet_from, text, want):
    sheet = sheet_from(_text(f'x = "{text}*p"\n', '[inputs]\np = "1"\n'))
    got = complex(_value(sheet, "x"))
    ref = complex(want())
    assert abs(got - ref) <= 4e-15 * abs(ref), (got, ref)


def test_the_flag_says_which_values_are_complex(sheet_from):
    sheet = sheet_from(
        _text(
            'z = "p + 2i"\nm = "abs(z)"\na = "arg(z)"\nr = "Re(z)*2"\nc = "conj(z)"\n',
            '[inputs]\np = "1"\n',
        )
    )
    flags = {n: sheet.typer.scalar(n).complex for n in ("z", "m", "a", "r", "c")}
    assert flags == {"z": True, "m": False, "a": False, "r": False, "c": True}


def _ac_reference():
    w = 2 * math.pi * 50
    z = 10 + 1j * w * 0.05 + 1 / (1j * w * 100e-6)
    zl = 1j * w * 0.05
    return z, 230 / z, z * zl / (z + zl)


@pytest.fixture(scope="module")
def ac(tmp_path_factory):
    path = tmp_path_factory.mktemp("ac") / "ac.toml"
    path.write_text(AC, encoding="utf-8")
    return workbook.load(path)


def test_units_on_complex_values(ac):
    z, i, zp = _ac_reference()
    assert complex(_value(ac, "Z", "ohm")) == pytest.approx(z, rel=1e-14)
    assert complex(_value(ac, "Zk", "kohm")) == pytest.approx(z / 1000, rel=1e-14)
    assert complex(_value(ac, "I", "A")) == pytest.approx(i, rel=1e-14)
    assert _value(ac, "I_mag", "mA") == pytest.approx(abs(i) * 1000, rel=1e-14)
    assert _value(ac, "phi", "deg") == pytest.approx(math.degrees(cmath.phase(z)), rel=1e-14)
    assert complex(_value(ac, "Zp", "ohm")) == pytest.approx(zp, rel=1e-14)
    assert ac.typer.scalar("Zr").complex is False  # par() of real values stays real
    assert _value(ac, "Zr", "ohm") == pytest.approx(5.0)
    assert complex(_value(ac, "P", "V")) == pytest.approx(cmath.rect(230, math.pi / 6), rel=1e-14)
    assert complex(_value(ac, "S", "W")) == pytest.approx(230 * i.conjugate(), rel=1e-14)
    table = ac.table("sweep")
    fr = np.arange(10, 101, 10)
    want = 10 + 1j * 2 * np.pi * fr * 0.05
    assert np.allclose(table.iloc[:, 1].to_numpy(dtype=complex), want, rtol=1e-14)
    assert np.allclose(table.iloc[:, 2].to_numpy(dtype=float), np.abs(want), rtol=1e-14)
    assert np.allclose(table.iloc[:, 3].to_numpy(dtype=float), np.degrees(np.angle(want)))


# -- refused at load, failing when computed ----------------------------------------------------
@pytest.mark.parametrize(
    "definitions,error,message",
    [
        ('x = "1 if (1 + 2i) < 3 otherwise 0"', TemplateError, "complex numbers have no order"),
        ('x = "floor(2 + 1i)"', TemplateError, r"floor\(\) takes real numbers"),
        ('x = "root(t^2 + 1i, t, 0, 1)"', TemplateError, r"root\(\) takes real numbers"),
        ('x = "(2 m)^(1i)"', UnitError, "raised to a complex power"),
        ('v = "[1, 2]"\nx = "v[1i]"', TemplateError, "index is complex"),
        (
            'x = { program = """\nz := 1 + 2i\nreturn z\n""" }',
            TemplateError,
            "complex values in a program are not supported",
        ),
    ],
)
def test_refused_at_load(sheet_from, definitions, error, message):
    with pytest.raises(error, match=message):
        sheet_from(_text(definitions + "\n")).check_units()


def test_a_real_square_root_of_a_negative_number_stays_a_failure(sheet_from):
    sheet = sheet_from(_text('x = "sqrt(-p)"\ny = "sqrt(-p + 0i)"\n', '[inputs]\np = "4"\n'))
    with pytest.raises(DomainError, match="not a finite number"):
        sheet.evaluate("x")
    assert complex(_value(sheet, "y")) == 2j


# -- vectors and matrices against numpy and mpmath ---------------------------------------------
def test_lsolve_of_a_complex_nodal_system(sheet_from):
    sheet = sheet_from(
        _text(
            'Y = "[[1/R + 1/(1i*X), -1/(1i*X), 0 S], [-1/(1i*X), 1/(1i*X) + 1i/X + 1/R, -1/R],'
            ' [0 S, -1/R, 2/R - 1i/X]]"\n'
            'n = { expr = "lsolve(Y, [V/R, 0 A, 1i*V/X])", unit = "V" }\n'
            'm = "abs(n[2])"\nd = "det(Y)"\nYi = "inverse(Y)"\nYt = "transpose(Y)"\n',
            '[inputs]\nR = "10 ohm"\nX = "20 ohm"\nV = "10 V"\n',
        )
    )
    y = np.array(
        [
            [1 / 10 + 1 / 20j, -1 / 20j, 0],
            [-1 / 20j, 1 / 20j + 1j / 20 + 1 / 10, -1 / 10],
            [0, -1 / 10, 2 / 10 - 1j / 20],
        ]
    )
    want = np.linalg.solve(y, [1.0, 0.0, 0.5j])
    got = _value(sheet, "n", "V")
    assert got.shape == (3, 1)
    assert np.allclose(got[:, 0], want, rtol=1e-13)
    assert sheet.typer.scalar("m").complex is False
    assert _value(sheet, "m", "V") == pytest.approx(abs(want[2]), rel=1e-13)
    assert complex(_value(sheet, "d", "S^3")) == pytest.approx(np.linalg.det(y), rel=1e-13)
    assert np.allclose(_value(sheet, "Yi", "ohm"), np.linalg.inv(y), rtol=1e-13)
    assert np.allclose(_value(sheet, "Yt", "S"), y.T)


def test_eigenvalues_and_eigenvectors_of_complex_matrices(sheet_from):
    sheet = sheet_from(
        _text(
            'A = "[[1, -2, 0], [3, 1, 1], [0, 1, 4]]*(1 + 0i)"\n'
            'lam = "eigenvals(A)"\nV = "eigenvecs(A)"\nreal = "eigenvals([[0, -1], [1, 0]])"\n',
        )
    )
    a = np.array([[1, -2, 0], [3, 1, 1], [0, 1, 4]], dtype=float)
    lam = _value(sheet, "lam")[:, 0]
    ref = [complex(z) for z in mpmath.eig(mpmath.matrix(a.tolist()), right=False)]
    assert sorted(ref, key=lambda z: (round(z.real, 9), z.imag)) == pytest.approx(lam, rel=1e-12)
    assert np.iscomplexobj(lam) and abs(lam[0].imag) > 1  # a real matrix's complex pair
    vecs = _value(sheet, "V")
    for k in range(3):
        v = vecs[:, k]
        assert np.allclose(a @ v, lam[k] * v, atol=1e-12)
        assert np.linalg.norm(v) == pytest.approx(1.0)
        big = v[np.argmax(np.abs(v))]
        assert abs(big.imag) < 1e-12 and big.real > 0  # the largest component real, positive
    with pytest.raises(DomainError, match="complex eigenvalues.*M\\*\\(1 \\+ 0i\\)"):
        sheet.evaluate("real")


def test_polyroots_with_complex_roots_against_mpmath(sheet_from):
    sheet = sheet_from(
        _text(
            'x = "polyroots([5, -2, 1]*(1 + 0i))"\ny = "polyroots([2, 1i, -3, 1 + 1i])"\n',
        )
    )
    assert np.allclose(_value(sheet, "x")[:, 0], [1 - 2j, 1 + 2j], rtol=1e-14)
    got = _value(sheet, "y")[:, 0]
    ref = [complex(r) for r in mpmath.polyroots([1 + 1j, -3, 1j, 2], maxsteps=200, extraprec=200)]
    ref = sorted(ref, key=lambda z: (round(z.real, 9), z.imag))
    assert np.allclose(got, ref, rtol=1e-12)
    assert list(got.real) == sorted(got.real)


# -- Excel: texts, live formulas, the live check ----------------------------------------------
@pytest.mark.parametrize(
    "z,text",
    [
        (3 + 4j, "3+4i"),
        (3 - 4j, "3-4i"),
        (1j, "i"),
        (-1j, "-i"),
        (-2.5j, "-2.5i"),
        (7 + 0j, "7"),
        (0j, "0"),
        (1 / 3 + 2j, "0.333333333333333+2i"),
        (1e-20 + 1e20j, "1E-20+1E+20i"),
    ],
)
def test_excel_text(z, text):
    assert excel_text(z) == text
    assert parse_text(text) == pytest.approx(z, rel=1e-14)


def test_readable():
    assert readable(10 - 16.1230253504j) == "10 - 16.123i"
    assert readable(2j) == "2i" and readable(-2j) == "-2i" and readable(-7 + 0j) == "-7"


def test_the_live_check_compares_complex_texts_as_numbers():
    assert agrees("6.389741804926116+10.302196910352675i", "6.38974180492611+10.3021969103527i", 0)
    assert agrees("2j", "2i", 0)
    assert not agrees("2.1i", "2i", 0)
    import formulas

    # the formulas package has no value for IMARGUMENT of a pure imaginary number: not checked
    from formulas.tokens.operand import XlError

    got = formulas.Parser().ast("=IMARGUMENT(COMPLEX(0, 2))")[1].compile()()
    assert isinstance(got, XlError)
    assert complex_error("=IMARGUMENT(COMPLEX(0, 2))", got)
    assert not complex_error("=SQRT(-1)", got)


@pytest.fixture(scope="module")
def ac_book(ac, tmp_path_factory):
    import openpyxl

    path = ac.write_xlsx(tmp_path_factory.mktemp("book") / "ac.xlsx")
    return path, openpyxl.load_workbook(path), openpyxl.load_workbook(path, data_only=True)


def test_complex_cells_are_live_im_formulas_with_excel_text(ac, ac_book):
    _, book, cached = ac_book
    ws, values = book["Results"], cached["Results"]
    rows = {ws.cell(r, 1).value: r for r in range(2, ws.max_row + 1)}
    formulas = {n: ws.cell(rows[n], 2).value for n in ("Z", "I", "I_mag", "phi", "Zp", "S", "P")}
    assert all(f.startswith("=") for f in formulas.values()), formulas
    assert formulas["I"].startswith("=IMDIV(") and formulas["I_mag"].startswith("=IMABS(")
    assert "IMARGUMENT(" in formulas["phi"] and "IMCONJUGATE(" in formulas["S"]
    z, i, _ = _ac_reference()
    assert parse_text(values.cell(rows["Z"], 2).value) == pytest.approx(z, rel=1e-14)
    assert values.cell(rows["Z"], 2).value == excel_text(complex(_value(ac, "Z", "ohm")))
    assert values.cell(rows["I_mag"], 2).value == pytest.approx(abs(i) * 1000, rel=1e-14)
    table = book["Listing"]
    assert table["B3"].value.startswith("=IMSUM(") and table["C3"].value.startswith("=IMABS(")
    assert parse_text(cached["Listing"]["B3"].value) == pytest.approx(10 + 1j * math.pi, rel=1e-14)


def _recalculated(path) -> dict:
    """{(SHEET, CELL): value} of the whole workbook computed by the formulas package."""
    import formulas

    solution = formulas.ExcelModel().loads(str(path)).finish().calculate()
    out = {}
    for key, ranges in solution.items():
        book_sheet, _, cell = key.rpartition("!")
        if ":" in cell or "]" not in book_sheet:
            continue
        out[(book_sheet.split("]", 1)[1].strip("'").upper(), cell.upper())] = ranges.value[0, 0]
    return out


def test_every_complex_formula_agrees_with_the_formulas_package(ac_book):
    """The whole workbook recalculated by the formulas package (an evaluator independent of
    the engine, from the inputs): each complex formula cell against the engine's cached
    value, to 1e-12 (the formulas package writes a complex text with 17 digits a part)."""
    from formulas.tokens.operand import XlError
    from helpers.recalc import formula_values

    path, _, _ = ac_book
    recalculated = _recalculated(path)
    cells = formula_values(path)
    checked = 0
    for (sheet, cell), (formula, cached) in cells.items():
        if "IM" not in formula and "COMPLEX(" not in formula:
            continue
        got = recalculated[(sheet.upper(), cell)]
        if "IMARGUMENT" in formula and isinstance(got, XlError):
            continue  # the formulas package has no value for the angle of a pure imaginary
        if isinstance(cached, str):
            want, got = parse_text(cached), parse_text(str(got))
        else:
            want, got = cached, float(got)
        assert abs(got - want) <= 1e-12 * max(1.0, abs(want)), (sheet, cell, formula, got, cached)
        checked += 1
    assert checked >= 38  # 8 results and 3 columns of 10 rows


def test_run_prints_a_plus_bi(ac, tmp_path, capsys):
    from workbook.cli import main

    main(["run", str(ac.spec.path), "--out", str(tmp_path / "o.xlsx")])
    out = capsys.readouterr().out
    assert "Z = 10 - 16.123i Ω" in out
    assert "Y = [ 0.1 - 0.063662i              -0.1 ] 1/Ω" in out  # aligned rows
    assert "    [            -0.1  0.1 + 0.0314159i ]" in out
    assert "I_mag = 12122.9 mA" in out


def test_the_report_shows_a_plus_bi(ac):
    from workbook.outputs.report import mathml as mm
    from workbook.outputs.report import render

    box = mm.quantity_box(10 - 16.123j, "ohm")
    assert box.xml.count("<mo stretchy='false'>(</mo>") == 1  # (10 − 16.123i) Ω
    assert "<mn>10</mn>" in box.xml and "<mo>\u2212</mo>" in box.xml and "<mi>i</mi>" in box.xml
    assert mm.complex_box(2j).xml == "<mrow><mn>2</mn></mrow><mi>i</mi>"
    assert mm.complex_box(-1j).xml == "<mrow><mo>\u2212</mo><mi>i</mi></mrow>"
    written = mm.MathML().box(ex.parse("R + 1i*omega")).xml
    assert "<mrow><mn>1</mn><mi>i</mi></mrow><mo>\u22c5</mo><mi>ω</mi>" in written  # 1i⋅ω
    html = render(workbook.compute.computed.compute(ac))
    assert "16.123" in html and "<mi>i</mi>" in html


PIECES = """[arguments]
x = { unit = "" }

[definitions]
"f(x)" = ["x + 1i if x > 0", "x otherwise"]

[[tables]]
name = "t"
range = "x := -2 .. 2"
columns = { "f(x)" = "" }
"""


def test_a_piecewise_function_with_a_complex_piece(sheet_from, tmp_path):
    import openpyxl

    sheet = sheet_from(PIECES, name="p")
    got = sheet.table("t").iloc[:, 1].to_numpy(dtype=complex)
    assert list(got) == [-2, -1, 0, 1 + 1j, 2 + 1j]
    limited = sheet_from(_text('z = { expr = "3 + 4i", positive = true }\n'))
    with pytest.raises(WorkbookError, match="'z' is complex: its limits"):
        limited.evaluate("z")
    book = sheet.write_xlsx(tmp_path / "p.xlsx")
    ws = openpyxl.load_workbook(book)["Listing"]
    cached = openpyxl.load_workbook(book, data_only=True)["Listing"]
    assert all(ws.cell(r, 2).value.startswith("=IF(") for r in range(3, 8))  # live, not refused
    assert [cached.cell(r, 2).value for r in range(3, 8)] == ["-2", "-1", "0", "1+i", "2+i"]


def test_a_chart_of_complex_values_is_refused(sheet_from, tmp_path):
    text = """[arguments]
fr = { unit = "Hz" }

[definitions]
"Zf(fr)" = "1 ohm + 1i*fr*1 ohm*s"

[[charts]]
name = "c"
range = "fr := 1 Hz .. 5 Hz"
x = { expr = "fr", title = "f" }
series = [ { y = "Zf(fr)", unit = "ohm", name = "Z" }, { y = "abs(Zf(fr))", unit = "ohm" } ]
"""
    with pytest.raises(WorkbookError, match="a series of complex values has no points"):
        sheet_from(text, name="ch").write_xlsx(tmp_path / "ch.xlsx")


def test_polar_form_on_request(tmp_path, capsys):
    from workbook.cli import main
    from workbook.outputs.report import render

    path = tmp_path / "p.toml"
    path.write_text(AC.replace("[inputs]", '[sheet]\ncomplex = "polar"\n\n[inputs]'), "utf-8")
    main(["run", str(path), "--out", str(tmp_path / "o.xlsx")])
    z = _ac_reference()[0]
    r, phi = abs(z), math.degrees(cmath.phase(z))
    assert f"Z = {r:.6g}\u2220{phi:.6g}\u00b0 Ω" in capsys.readouterr().out
    html = render(workbook.compute.computed.compute(workbook.load(path)))
    assert f"<mn>{r:.6g}</mn></mrow><mo>\u2220</mo>" in html
    path.write_text(AC.replace("[inputs]", '[sheet]\ncomplex = "round"\n\n[inputs]'), "utf-8")
    with pytest.raises(TemplateError, match='complex is "rectangular"'):
        workbook.load(path)


def test_the_largest_value_of_a_complex_column_is_refused(sheet_from):
    text = AC.replace("[[tables]]", 'top = "max_over(sweep, Zf)"\n\n[[tables]]')
    text = text.replace('columns = { "Zf(fr)" = "ohm"', 'columns = { Zf = "ohm"')
    with pytest.raises(TemplateError, match="the column is complex"):
        sheet_from(text, name="m").check_units()


def test_a_sweep_of_a_complex_output_is_refused(ac):
    from workbook.sweep import sweep

    with pytest.raises(TemplateError, match="the output is complex"):
        sweep(ac, {"R": "5 ohm..10 ohm:3"}, {"Zo": "Z"})
    result = sweep(ac, {"R": "5 ohm..10 ohm:3"}, {"m": "abs(Z)"})
    assert result.table.iloc[2, 1] == pytest.approx(abs(_ac_reference()[0]), rel=1e-12)


def test_a_printed_value_of_a_complex_definition_says_to_check_its_parts(sheet_from, tmp_path):
    csv = "name,argument,value,unit\nZ,,10,ohm\nI_mag,,12122.87,mA\n"
    (tmp_path / "printed.csv").write_text(csv, encoding="utf-8")
    sheet = sheet_from(AC + '\n[[printed]]\nfile = "printed.csv"\ntolerance = 0.01\n', name="p")
    rows = {r.name: r for r in sheet.check().rows}
    assert rows["Z"].verdict == "error" and 'Z_re = "Re(Z)"' in rows["Z"].note
    assert rows["I_mag"].verdict == "pass"


def test_a_complex_argument_of_sin_is_no_angle_slip(sheet_from):
    head = '[arguments]\nphi = { unit = "deg" }\n\n'
    sheet = sheet_from(_text('"f(phi)" = "sin(phi)"\nx = "sin(10 + 2i)"\ny = "sin(10)"\n', head))
    warned = [f.what for f in sheet.check().findings if f.topic == "angles"]
    assert any("'y'" in w for w in warned) and not any("'x'" in w for w in warned)


@pytest.mark.parametrize("text", ["3 + 4i ohm", "4i", "2.5j V"])
def test_a_complex_input_value_says_what_to_write(sheet_from, text):
    with pytest.raises(WorkbookError, match="is a complex number.*R \\+ X\\*1i"):
        sheet_from(f'[inputs]\nZ = "{text}"\n[definitions]\nx = "Z"\n', name="i")
