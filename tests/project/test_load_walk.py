"""Loading runs down the stages: the walk of each template's load climbs back up at most 6
times, and the unit rules of the registry's entries and the array rules never climb back into
the typer (scripts/load_walk.py traces the calls)."""

from __future__ import annotations

import sys
import warnings

import pytest
from helpers.paths import ROOT

import workbook

sys.path.insert(0, str(ROOT / "scripts"))
try:
    import load_walk
finally:
    sys.path.pop(0)

MOST_CLIMBS = 6
#: modules that hold only rules on typed trees: a call from them into the typer is a callback
RULES = (
    "workbook.functions.builtins",
    "workbook.functions.matrix_entries",
    "workbook.numerics.entries",
    "workbook.language.typearrays",
)
#: the one question a rule asks the typer: whether diff's body has a symbolic form (the
#: functions it calls are looked up in the typer)
ASKED = {("workbook.numerics.entries", "workbook.language.typecheck", "Typer.symbolic_refusal")}
TEMPLATES = sorted(workbook.list_templates())


def _walk(name: str) -> load_walk.Walk:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        workbook.load(name)
        return load_walk.walk(lambda: workbook.load(name))


@pytest.mark.slow
@pytest.mark.parametrize("name", TEMPLATES)
def test_loading_a_template_climbs_back_up_at_most_six_times(name):
    found = _walk(name)
    assert len(found.climbs) <= MOST_CLIMBS, sorted(found.climbs)
    back_into_typer = [
        c for c in found.climbs - ASKED if c[0] in RULES and c[1] == "workbook.language.typecheck"
    ]
    assert not back_into_typer


def test_the_walk_sees_a_callback_as_a_climb():
    # an [[ode]] section's expressions are typed by the typer, asked from odes.py: one climb
    found = _walk("advance-coupling")
    assert ("workbook.language.odes", "workbook.language.typecheck") in found.climbs_by_pair()


def test_the_readers_of_measured_data_and_solve_blocks_return_what_they_read(tmp_path):
    # they used to claim names and find lines through callbacks of the template reader
    (tmp_path / "pump.csv").write_text("Q,H\n0,10\n10,8\n20,5\n")
    text = """
[data.pump]
file = "pump.csv"
columns = { Q = "m^3/h", H = "m" }

[inputs]
q = "12 m^3/h"

[[solve]]
unknowns = { x = "1 m" }
equations = ["x^2 == 2 m^2"]

[definitions]
head = "linterp(Q, H, q)"
"""
    workbook.loads(text, folder=tmp_path)
    found = load_walk.walk(lambda: workbook.loads(text, folder=tmp_path))
    assert {"workbook.language.measured", "workbook.language.given_find"} <= found.rooms
    assert not found.climbs, sorted(found.climbs)
