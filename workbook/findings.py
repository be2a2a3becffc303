"""Findings: what a check found, one line of a check report."""

from __future__ import annotations

from dataclasses import dataclass

from .verdicts import FINDING_VERDICTS


@dataclass
class Finding:
    """One line of a check report: a number the engine found, and what it means."""

    topic: str
    what: str
    value: float | None = None
    unit: str = ""
    verdict: str = "info"  # one of verdicts.FINDING_VERDICTS
    note: str = ""

    def __post_init__(self):
        # the two vocabularies are easy to mix up ("pass" is a printed value's, "ok" a finding's)
        if self.verdict not in FINDING_VERDICTS:
            raise ValueError(
                f"finding {self.what!r}: verdict {self.verdict!r} is not one of "
                f"{', '.join(FINDING_VERDICTS)}"
            )
