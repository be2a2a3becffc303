"""Units are shown as the worksheet declared them (order and spelling), not as pint sorts them."""

from __future__ import annotations

import subprocess
import sys

import openpyxl
import pytest
from helpers.sheets import write_template

import workbook
from workbook.language import units as un

SHEET = """
[sheet]
title = "units as declared"

[inputs]
F = { value = "2 kN" }
arm = { value = "0.5 m" }
Q = { value = "3 L/s" }
k = { value = "40 W/(m*K)" }

[definitions]
torque = { expr = "F*arm", unit = "N*m" }
flow = { expr = "2*Q", unit = "L/min" }
energy = { expr = "F*arm*3600", unit = "kW*h" }
conduct = { expr = "2*k", unit = "W/(m*K)" }
"""


@pytest.mark.parametrize(
    "text,shown",
    [
        ("N*m", "N*m"),
        ("m*N", "m*N"),
        ("W/(m*K)", "W/(m*K)"),
        ("kW*h", "kW*h"),
        ("mm^2*deg", "mm^2*deg"),
        ("m/s^2", "m/s^2"),
        ("1/s", "1/s"),
        ("percent", "%"),
        ("delta_degC", "delta_degC"),
    ],
)
def test_pretty_keeps_the_declared_order(text, shown):
    assert un.pretty(un.unit(text)) == shown
    assert un.unit(shown) == un.unit(text)  # what is shown reads back as the same unit


@pytest.mark.slow
def test_run_and_the_workbook_show_the_declared_units(tmp_path):
    path = write_template(tmp_path, SHEET, "shown.toml")
    code = "import sys; from workbook.cli import main; sys.exit(main())"
    done = subprocess.run(
        [sys.executable, "-c", code, "run", "shown.toml", "--out", "shown.xlsx"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    for line in (
        "torque = 1000 N*m",
        "flow = 360 L/min",
        "energy = 1 kW*h",
        "conduct = 80 W/(m*K)",
    ):
        assert line in done.stdout, done.stdout
    results = openpyxl.load_workbook(tmp_path / "shown.xlsx")["Results"]
    units = {r[0]: r[2] for r in results.iter_rows(min_row=2, values_only=True) if r[0]}
    # the Results sheet is for people: the units typeset, in the declared order
    assert units["torque"] == "N·m" and units["flow"] == "L/min" and units["energy"] == "kW·h"
    assert units["conduct"] == "W/(m·K)"
    inputs = openpyxl.load_workbook(tmp_path / "shown.xlsx")["Inputs"]
    shown = [c for r in inputs.iter_rows(values_only=True) for c in r if isinstance(c, str)]
    assert "L/s" in shown and "W/(m*K)" in shown
    sheet = workbook.load(path)
    assert sheet.evaluate("energy").to("J").magnitude == pytest.approx(3.6e6)


@pytest.mark.parametrize(
    "text,shown",
    [
        ("N*m", "N·m"),
        ("m*N", "m·N"),
        ("W/(m^2*K)", "W/(m²·K)"),
        ("degC", "°C"),
        ("delta_degC", "Δ°C"),
        ("delta_degF", "Δ°F"),
        ("ohm", "Ω"),
        ("kohm", "kΩ"),
        ("um", "µm"),
        ("L/s", "L/s"),
        ("mL", "mL"),
        ("deg", "°"),
        ("percent", "%"),
        ("m/s^2", "m/s²"),
        ("1/s", "1/s"),
        ("kg^12", "kg¹²"),
        ("m^0.5/s", "m^0.5/s"),
        ("J/(kg*K)", "J/(kg·K)"),
        ("", ""),
    ],
)
def test_typeset_is_what_a_person_writes_and_reads_back(text, shown):
    assert un.typeset(un.unit(text)) == shown
    if shown:
        assert un.unit(shown) == un.unit(text)  # the workbook's text reads back as the unit


def test_typeset_does_not_change_how_units_are_spelt():
    """typeset and the report's reading of unit text are pure: the spelling pretty() keeps
    (the worksheet's L for pint's l) is not changed by them."""
    before = un.pretty(un.unit("L/s"))
    for text in ("l/s", "liter/s", "W/(m*K)"):
        un.typeset(un.unit("m"))
        assert un.shown_factors(text) is not None
    assert un.pretty(un.unit("L/s")) == before
    assert un.shown_factors("pieces") is None  # a label is not a unit


def test_pretty_is_a_function_of_the_unit_alone():
    """What a sheet loaded before spelt does not change how a unit is shown: the same unit
    text before and after sheets that write kohm, um and l/min."""
    units = [un.unit(t) for t in ("kohm", "um", "l/min", "mL", "W/(m*K)")]
    before = [un.pretty(u) for u in units]
    workbook.loads('[inputs]\nR = "2 kohm"\nd = "3 um"\nQ = "4 l/min"\nV = "5 mL"\n')
    assert [un.pretty(u) for u in units] == before == ["kΩ", "µm", "L/min", "mL", "W/(m*K)"]
