"""Live formulas against the engine: the nested integral's live form, and the independent
check (workbook.compute.livecheck, the `formulas` package) that writes a disagreeing cell as a
value."""

import math

import openpyxl
import pytest

import workbook
from workbook.compute import livecheck
from workbook.numerics import gauss

# A beam's double integration and relatives: each value known in closed form.
BEAM = """
[sheet]
title = "Beam by double integration"

[inputs]
w = { value = "10 N/m" }
L = { value = "6 m" }

[arguments]
x = { unit = "m" }
s = { unit = "m" }

[definitions]
"q(x)" = { expr = "integral(w*s/L, s, 0, x)", unit = "N" }
M1 = { expr = "integral(integral(w*s/L, s, 0, x), x, 0, L)", unit = "N*m" }
M2 = { expr = "integral(q(x), x, 0, L)", unit = "N*m" }
M3 = { expr = "integral(integral(w*s^2/L^2, s, 0, x), x, 0, L)", unit = "N*m" }
M4 = { expr = "integral(integral(w*x*s/L^2, s, 0, L/2), x, 0, L)", unit = "N*m" }
M5 = { expr = "integral(integral(w*s^3/L^3, s, 0, x), x, 0, L)", unit = "N*m" }
M6 = { expr = "integral(integral(w/L, s, 0, L), x, 0, L)", unit = "N" }
"""
W, L = 10.0, 6.0
EXACT = {
    "M1": W * L**2 / 6,
    "M2": W * L**2 / 6,
    "M3": W * L**2 / 12,
    "M4": W * L**2 / 16,
    "M5": W * L**2 / 20,
    "M6": W * L,
}


def _results(path) -> dict:
    """{name: (formula or value, cached value, comment)} of the Results sheet."""
    ws = openpyxl.load_workbook(path)["Results"]
    values = openpyxl.load_workbook(path, data_only=True)["Results"]
    return {
        ws.cell(r, 1).value: (
            ws.cell(r, 2).value,
            values.cell(r, 2).value,
            ws.cell(r, 2).comment.text if ws.cell(r, 2).comment else "",
        )
        for r in range(2, ws.max_row + 1)
        if ws.cell(r, 1).value
    }


def _formulas_package(path) -> dict:
    """{cell: value} of the Results sheet recalculated by the formulas package."""
    import formulas

    solution = formulas.ExcelModel().loads(str(path)).finish().calculate()
    out = {}
    for key, value in solution.items():
        if "]RESULTS'!B" in key.upper():
            v = value.value[0][0]
            out[key.upper().split("!")[1]] = v
    return out


@pytest.mark.slow
def test_nested_integrals_are_live_and_recalculate_to_the_engine(tmp_path, sheet_from):
    sheet = sheet_from(BEAM)
    out = tmp_path / "beam.xlsx"
    refusals = []
    sheet.write_xlsx(out, refusals=refusals)
    assert refusals == []
    cells = _results(out)
    recalculated = _formulas_package(out)
    for row, (name, exact) in enumerate(EXACT.items(), start=2):
        formula, cached, _ = cells[name]
        assert formula.startswith("="), (name, formula)
        assert math.isclose(cached, exact, rel_tol=1e-12), (name, cached, exact)
        got = recalculated[f"B{row}"]
        assert math.isclose(got, exact, rel_tol=1e-12), (name, got, exact)


def _elementwise(body, a, b, n, scope):
    """The live form before nested integrals had their own axis: node rows multiplied
    element by element (the silent wrong number the check must catch)."""
    row, weights, _, _ = gauss.literals(n)
    width = f"(({b})-({a}))"
    return f"{width}*SUMPRODUCT({weights}*({body(f'(({a})+{width}*{row})')}))"


def test_a_live_formula_that_disagrees_is_written_as_the_engines_value(
    tmp_path, monkeypatch, sheet_from
):
    monkeypatch.setattr(gauss, "excel_form", _elementwise)
    sheet = sheet_from(BEAM)
    out = tmp_path / "beam.xlsx"
    refusals = []
    sheet.write_xlsx(out, refusals=refusals)
    refused = {r.where for r in refusals}
    cells = _results(out)
    # M1 agrees by chance with the element-by-element form (sum of w_i t_i^2 is 1/3)
    for name in ("M3", "M4", "M5"):
        value, cached, comment = cells[name]
        assert isinstance(value, (int, float)) and math.isclose(value, EXACT[name], rel_tol=1e-12)
        assert "independent evaluation" in comment
        assert "formulas package" in comment or "workbook.compute.xleval" in comment
    assert {"'Results'!B4", "'Results'!B5", "'Results'!B6"} <= refused
    about = openpyxl.load_workbook(out)["About"]
    texts = [r[1] for r in about.iter_rows(values_only=True) if r[0] == "Formulas checked"]
    assert "that did not are values" in texts[0]


@pytest.mark.slow
def test_run_says_which_cells_are_values(tmp_path, monkeypatch):
    from workbook.cli import main

    monkeypatch.setattr(gauss, "excel_form", _elementwise)
    path = tmp_path / "beam.toml"
    path.write_text(BEAM, encoding="utf-8")
    out = tmp_path / "beam.xlsx"
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        assert main(["run", str(path), "--out", str(out)]) == 0
    lines = [line for line in buf.getvalue().splitlines() if line.startswith("written as a value")]
    assert len(lines) == 3 and all("the engine" in line for line in lines)


@pytest.mark.slow
def test_an_integral_inside_two_integrals_is_a_value(tmp_path, sheet_from):
    triple = "integral(integral(integral(w/L^2, u, 0, s), s, 0, x), x, 0, L)"
    text = BEAM.replace('s = { unit = "m" }', 's = { unit = "m" }\nu = { unit = "m" }')
    text += f'T = {{ expr = "{triple}", unit = "N" }}\n'
    sheet = sheet_from(text)
    out = tmp_path / "t.xlsx"
    sheet.write_xlsx(out)
    value, cached, comment = _results(out)["T"]
    assert isinstance(value, (int, float)) and math.isclose(value, W * L / 6, rel_tol=1e-9)
    assert "two enclosing integrals" in comment


def test_a_root_inside_an_integral_is_a_value(tmp_path, sheet_from):
    text = BEAM + 'R = { expr = "integral(root(s - x/2, s, 0, L), x, 0, L)", unit = "m^2" }\n'
    sheet = sheet_from(text)
    out = tmp_path / "r.xlsx"
    sheet.write_xlsx(out)
    value, _, comment = _results(out)["R"]
    assert isinstance(value, (int, float)) and math.isclose(value, L**2 / 4, rel_tol=1e-9)
    assert comment.startswith("A value, not a formula")


@pytest.mark.parametrize(
    "text, expected",
    [
        ("=R_*COS(omega*$A$3)", True),
        ("=SUMPRODUCT({1,2}*x_)", False),
        ("=MAX('Design'!$E$3:$E$103)", False),
        ("=MMULT(a_, b_)", False),
        ("=INDEX(v_, 2)", False),
        ("=MAX(v_)*2", False),  # v_ names a vector's cells
        ("=MAX(a_, 2)", True),
        ('=IF(x>0,"MMULT(",1)', True),  # a text is not a call
    ],
)
def test_plain_formulas_are_those_of_scalar_arithmetic(text, expected):
    assert livecheck.plain(text, "Definitions", frozenset({"V_"})) is expected


def test_references_and_numbers_become_inputs_of_one_compiled_formula():
    generic, refs = livecheck.generic("=R1_*$A$3^2+'Solver steps'!$B$4+SUM({1,2})")
    assert generic == "=R1_*_REF_0_^_REF_1_+_REF_2_+SUM({1,2})"  # in the order they stand
    assert refs == ("A3", "2", "'Solver steps'!B4")


def test_loads_reads_template_text_and_names_it_in_messages(sheet_from, tmp_path):
    sheet = sheet_from(
        '[inputs]\nR = "2 mm"\n[definitions]\nA = { expr = "pi*R^2", unit = "mm^2" }'
    )
    assert math.isclose(sheet.scalar_quantity("A").magnitude, 4 * math.pi, rel_tol=1e-15)
    with pytest.raises(workbook.WorkbookError) as err:
        sheet_from('[definitions]\nA = { expr = "2", unit = "kg" }', name="bad")
    assert str(tmp_path / "bad.toml") + ":2, in 'A'" in str(err.value)


class _NoChanges(list):
    """A list of tables that fails on any change (the writer must not change the Sheet)."""

    def _refuse(self, *args, **kwargs):
        raise AssertionError("the writer changed the Sheet's tables")

    append = remove = extend = insert = pop = __setitem__ = __delitem__ = _refuse


def test_writing_a_chart_leaves_the_sheets_tables_as_they_are(tmp_path, sheet_from):
    from helpers.sheets import SINE

    chart = """
[[charts]]
name = "wave"
range = "phi := 0, 30 .. 360"
series = [{ y = "y", unit = "mm", name = "y" }]
"""
    sheet = sheet_from(SINE + chart)
    before = list(sheet.spec.tables)
    sheet.spec.tables = _NoChanges(before)
    out = sheet.write_xlsx(tmp_path / "wave.xlsx")
    assert list(sheet.spec.tables) == before == []
    assert "Chart data" in openpyxl.load_workbook(out).sheetnames
