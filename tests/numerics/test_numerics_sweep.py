"""scripts/numerics_sweep.py's hard cases (every numerical built-in against mpmath at 50
digits): none silently wrong, none overconfident (the table in docs/numerics.md is its
output)."""

from __future__ import annotations

import sys

import pytest
from helpers.paths import ROOT

sys.path.insert(0, str(ROOT / "scripts"))


@pytest.mark.slow
def test_no_hard_case_is_silently_wrong_or_overconfident(tmp_path):
    import numerics_sweep as sweep

    verdicts = {}
    for case in sweep.CASES:
        if case.slow:
            continue
        refused, err, est, warned = sweep.run_case(case, tmp_path)
        verdicts[case.expr] = sweep.verdict(refused, err, est, warned, case.exact is not None)
    bad = {k: v for k, v in verdicts.items() if v.startswith(("SILENT", "OVERCONFIDENT"))}
    assert not bad, bad
    refused = {k: v for k, v in verdicts.items() if v.startswith("refused:")}
    assert not refused, refused
    assert len(verdicts) >= 60
