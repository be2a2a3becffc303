"""Complex numbers in a written workbook, recalculated by LibreOffice Calc: every formula cell
(complex texts compared as numbers), and an edited input followed."""

import os
import shutil

import openpyxl
import pytest
from helpers.recalc import cell_values, formula_values, recalculate, soffice
from helpers.sheets import AC

from workbook.functions.complexes import parse_text

if soffice() is None and os.environ.get("CI"):
    raise RuntimeError("CI must run the LibreOffice recalculation tests: install libreoffice-calc")
pytestmark = [
    pytest.mark.skipif(soffice() is None, reason="LibreOffice is not installed"),
    pytest.mark.slow,  # each test starts LibreOffice (10 s or more)
]

#: every kind of complex formula the printer writes: constants, the four operators, powers
#: (real and complex exponents), the built-ins over the complex plane, a user function inlined,
#: a table column, matrix elements
EXTRA = """
k1 = "(3 + 4i)^2 - 1i"
k2 = "(1 + 1i)^(2 - 1i)*R/R"
k3 = "exp(1i*omega/omega) + sqrt(-R/R + 0i) + ln(-R/R + 0i) + log10(R/R + 1i)"
k4 = "sin(1 + 2i*R/R) + cos(1 - 1i) + tan(0.5 + 0.5i) + sinh(1i) + cosh(2 - 1i) + tanh(1 + 1i)"
k5 = { expr = "Re(Z) + Im(Z) + abs(Z) - conj(Z)", unit = "ohm" }
k6 = "arg(1i*R/R) + arg(-R/R + 0i)"
k7 = "-Z/(2 ohm)"
k8 = "sum(k*1i*R/R + 1, k, 1, 4)"
"""


def _agree(got, cached) -> bool:
    if isinstance(cached, str):
        a, b = parse_text(cached), parse_text(str(got))
        return a is not None and b is not None and abs(a - b) <= 1e-9 * max(1.0, abs(a))
    return isinstance(got, (int, float)) and abs(got - cached) <= 1e-9 * max(1.0, abs(cached))


@pytest.fixture(scope="module")
def ac(load_text):
    return load_text(AC.replace("\n[[tables]]", EXTRA + "\n[[tables]]"), name="ac")


def test_every_complex_cell_recalculates_to_the_engine_value(tmp_path, ac):
    path = ac.write_xlsx(tmp_path / "ac.xlsx")
    cached = formula_values(path)
    new = cell_values(recalculate(path, tmp_path / "lo"))
    bad, complex_cells = [], 0
    for key, (formula, value) in cached.items():
        if "IM" in formula or "COMPLEX(" in formula:
            complex_cells += 1
        if not _agree(new.get(key), value):
            bad.append((key, formula[:80], value, new.get(key)))
    assert not bad, f"{len(bad)} of {len(cached)} formula cells differ, e.g. {bad[:5]}"
    assert complex_cells >= 45
    # the cells LibreOffice writes are Excel's complex texts, as the cached ones
    texts = [k for k, (_, v) in cached.items() if isinstance(v, str)]
    assert len(texts) >= 24 and all(new[k].endswith("i") for k in texts)


def test_an_edited_input_is_followed(tmp_path, ac):
    path = ac.write_xlsx(tmp_path / "ac.xlsx")
    edited = tmp_path / "edited.xlsx"
    shutil.copy(path, edited)
    wb = openpyxl.load_workbook(edited)
    row = next(r for r in wb["Inputs"].iter_rows() if r[0].value == "L")
    row[1].value = 80  # mH
    wb.save(edited)
    values = cell_values(recalculate(edited, tmp_path / "lo"))
    expected = formula_values(ac.with_inputs(L="80 mH").write_xlsx(tmp_path / "expected.xlsx"))
    before = formula_values(path)
    changed = 0
    for key, (formula, value) in expected.items():
        assert _agree(values.get(key), value), (key, formula[:80], value, values.get(key))
        changed += isinstance(value, str) and not _agree(before[key][1], value)
    assert changed >= 15  # complex cells that L changes: Z and what reads it, a column of 10
