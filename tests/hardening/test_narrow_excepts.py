"""Failures are not swallowed: the sheet analysis reports a worksheet's error as a warning
and lets a bug of the engine through (exit 3), and ruff's blind-except rule is on."""

from __future__ import annotations

import pytest
from helpers.paths import ROOT

from workbook.engine import analysis
from workbook.errors import DomainError


@pytest.fixture
def sheet(sheet_from):
    return sheet_from('[inputs]\nR = "2 mm"\n[definitions]\nA = "pi*R^2"\n')


def test_a_worksheet_error_in_the_analysis_is_a_warning(sheet, monkeypatch):
    def fails(_sheet):
        raise DomainError("sqrt of a negative number")

    monkeypatch.setattr(analysis, "join_findings", fails)
    found = [f for f in analysis.findings(sheet) if f.topic == "analysis"]
    assert [(f.what, f.verdict) for f in found] == [("analysis stopped", "warning")]
    assert "sqrt of a negative number" in found[0].note


def test_a_bug_in_the_analysis_is_not_swallowed(sheet, monkeypatch):
    def bug(_sheet):
        raise KeyError("a bug of the engine")

    monkeypatch.setattr(analysis, "domain_margins", bug)
    with pytest.raises(KeyError):
        analysis.findings(sheet)


def test_ruff_refuses_a_blind_except():
    text = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    select = next(line for line in text.splitlines() if line.startswith("select = "))
    assert '"BLE"' in select
