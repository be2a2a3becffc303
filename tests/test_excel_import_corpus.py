"""The public corpus of Excel workbooks with VBA (../shared/excel-vba, not in the repository):
every workbook imports with exit 0, no cached number that the translation computes is wrong,
and the counts of docs/excel-import.md hold (scripts/excel_import_table.py prints them)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
CORPUS = ROOT.parent / "shared" / "excel-vba"

#: workbook -> (cells calling VBA with a cached number, reproduced), as measured
COUNTS = {
    "aero-toolkit-test.xlsm": (423, 423),
    "beam-user-functions.xlsm": (1492, 1492),
    "circular-section.xlsm": (0, 0),
    "dynamic-balancing.xlsm": (0, 0),
    "engineering-box-sandbox.xlsm": (65, 63),
    "feed-section-scenario1.xlsm": (0, 0),
    "general-beam-analysis.xlsm": (1315, 1315),
    "pressure-loss.xlsm": (39, 9),
    "pumps-piping-calculator.xlsm": (0, 0),
    "refprop.xls": (0, 0),
    "rigid-base-plate.xlsm": (0, 0),
    "strip-foundation.xlsm": (3076, 3076),
    "structural-calc.xlsm": (1, 1),
    "tlr-beam-capacity.xlsm": (0, 0),
    "traverse-computation.xlsm": (0, 0),
    "wood-shear-wall-foundation.xlsm": (11028, 11028),
}

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(not CORPUS.is_dir(), reason="the corpus ../shared/excel-vba is absent"),
]


def books():
    if not CORPUS.is_dir():
        return []
    return sorted(p.name for p in CORPUS.iterdir() if p.suffix.lower() in (".xlsm", ".xls"))


@pytest.mark.parametrize("name", books())
def test_corpus_workbook(name):
    sys.path.insert(0, str(ROOT / "scripts"))
    from excel_import_table import measure

    row = measure(CORPUS / name)
    assert row["exit"] == 0, row.get("error")
    assert row["wrong"] == 0
    cells, reproduced = COUNTS[name]
    assert (row["cells"], row["reproduced"]) == (cells, reproduced)
