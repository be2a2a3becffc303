"""Bad input by class, through the API and the command line: each is an error (exit 2) or a
visible result, never a silent wrong number, a hang, or a lost file."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import openpyxl
import pytest

import workbook
from workbook import WorkbookError
from workbook import excel_names as xn
from workbook import units as un
from workbook.errors import InputError, LimitError

CODE = "import sys; from workbook.cli import main; sys.exit(main())"


def cli(cwd: Path, *args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-c", CODE, *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=timeout,
    )


def write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


# -- quantity text -------------------------------------------------------------------------


@pytest.mark.parametrize(
    "text, message",
    [
        ("45,5 mm", "decimal comma; write a decimal point: '45.5 mm'"),
        ("45 5 mm", "has a number where a unit should be"),
        ("[1,2] m/s", "is not one value"),
        ("700 MPa MPa", "unit 'MPa' is written twice"),
        ("9**9**9 mm", "write the number itself"),
        ("2**2000 mm", "write the number itself"),
        ("1 mm^13", "power 13"),
        ("1 m + 2 mm", "allowed only in an exponent"),
        ("mm", "it starts with no number"),
        ("4 furlongz", "'furlongz' is not a unit (did you mean furlong"),
        ("x" * 100_000, "characters long"),
    ],
)
def test_quantity_text_is_refused(text, message):
    start = time.monotonic()
    with pytest.raises((InputError, LimitError)) as err:
        un.quantity(text, what="R3")
    assert message in str(err.value)
    assert time.monotonic() - start < 1.0


@pytest.mark.parametrize(
    "text, value, unit",
    [
        ("45.5 mm", 45.5, "mm"),
        ("45.5mm", 45.5, "mm"),
        ("104.6 1/s", 104.6, "1/s"),
        ("1.5e-4 kg*m^2", 1.5e-4, "kg*m^2"),
        ("3 s^-2", 3, "1/s^2"),
        ("2 N m", 2, "N*m"),
        ("-1 mm", -1, "mm"),
    ],
)
def test_quantity_text_is_read(text, value, unit):
    q = un.quantity(text)
    assert q.magnitude == value
    assert q.units == un.unit(unit)


# -- Excel names ---------------------------------------------------------------------------


def test_excel_names_are_unique_ignoring_case():
    names = xn.ExcelNames(["d", "D", "k", "K", "g", "g_", "Rp", "rp", "R1", "a" * 300, "pi"])
    assigned = list(names.mapping.values())
    assert len({n.lower() for n in assigned}) == len(assigned)
    assert all(len(n) <= xn.MAX_NAME and not xn.needs_change(n) for n in assigned)
    assert names["Rp"] == "Rp" and names["g_"] == "g_"
    assert names["g"] not in ("g", "g_") and names["R1"] == "R1_"
    assert set(names.renamed) == {"d", "D", "k", "K", "g", "rp", "R1", "a" * 300, "pi"}


CASE_SHEET = """
[inputs]
d = "10 mm"
D = "30 mm"
k = "2"
K = "5"
g = "3"
g_ = "7"
Rp = "4 mm"
rp = "2 mm"

[definitions]
C = "D/d"
q = "K/k"
r = "g_/g"
ratio = "Rp/rp"
"""


def test_names_equal_but_for_case_recalculate_to_the_engine_values(tmp_path):
    from recalc import cell_values, recalculate, soffice

    sheet = workbook.load(write(tmp_path / "case.toml", CASE_SHEET))
    path = sheet.write_xlsx(tmp_path / "case.xlsx")
    wb = openpyxl.load_workbook(path)
    defined = list(wb.defined_names)
    assert len({n.lower() for n in defined}) == len(defined)
    if soffice() is None:
        pytest.skip("LibreOffice is not installed")
    values = cell_values(recalculate(path, tmp_path / "lo"))
    got = {values[("Definitions", f"A{r}")]: values[("Definitions", f"B{r}")] for r in range(2, 6)}
    assert got == pytest.approx({"C": 3.0, "q": 2.5, "r": 7 / 3, "ratio": 2.0})
