"""Findings: what a check found, one line of a check report."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass
class Finding:
    """One line of a check report: a number the engine found, and what it means."""

    topic: str
    what: str
    value: float | None = None
    unit: str = ""
    verdict: str = "info"  # one of verdicts.FINDING_VERDICTS
    note: str = ""
