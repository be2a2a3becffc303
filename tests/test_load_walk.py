"""Loading runs down the stages: the walk of each template's load climbs back up at most 6
times, and the unit rules of the registry's entries and the array rules never climb back into
the typer (scripts/load_walk.py traces the calls)."""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import pytest

import workbook

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
try:
    import load_walk
finally:
    sys.path.pop(0)

MOST_CLIMBS = 6
#: modules that hold only rules on typed trees: a call from them into the typer is a callback
RULES = ("workbook.builtins", "workbook.matrix", "workbook.numerics.entries", "workbook.typearrays")
TEMPLATES = sorted(workbook.list_templates())


def _walk(name: str) -> load_walk.Walk:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        workbook.load(name)
        return load_walk.walk(lambda: workbook.load(name))


@pytest.mark.parametrize("name", TEMPLATES)
def test_loading_a_template_climbs_back_up_at_most_six_times(name):
    found = _walk(name)
    assert len(found.climbs) <= MOST_CLIMBS, sorted(found.climbs)
    back_into_typer = [c for c in found.climbs if c[0] in RULES and c[1] == "workbook.typecheck"]
    assert not back_into_typer


def test_the_walk_sees_a_callback_as_a_climb():
    # an [[ode]] section's expressions are typed by the typer, asked from ode.py: one climb
    found = _walk("advance-coupling")
    assert ("workbook.ode", "workbook.typecheck") in found.climbs_by_pair()
