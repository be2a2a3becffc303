"""The two verdict vocabularies (workbook/verdicts.py) cannot be mixed up."""

import pytest

from workbook import verdicts
from workbook.compute.checks import CheckRow
from workbook.findings import Finding


def _row(verdict: str) -> CheckRow:
    return CheckRow("set", "check", "h1", "phi", 5.0, "mm", 1.0, 1.0, 1e-3, None, verdict)


@pytest.mark.parametrize("verdict", verdicts.FINDING_VERDICTS)
def test_a_finding_takes_the_finding_verdicts(verdict):
    assert Finding("topic", "what", verdict=verdict).verdict == verdict


@pytest.mark.parametrize("verdict", ["pass", "FAIL", "misprint", "error", "OK"])
def test_a_finding_refuses_other_words(verdict):
    with pytest.raises(ValueError, match="is not one of ok, info, warning, fail"):
        Finding("topic", "what", verdict=verdict)


@pytest.mark.parametrize("verdict", verdicts.ROW_VERDICTS)
def test_a_printed_value_takes_the_row_verdicts(verdict):
    assert _row(verdict).verdict == verdict


@pytest.mark.parametrize("verdict", ["ok", "fail", "warning", "Pass"])
def test_a_printed_value_refuses_other_words(verdict):
    with pytest.raises(ValueError, match="is not one of pass, FAIL, misprint, info, error"):
        _row(verdict)


def test_the_sets_use_only_their_own_words():
    rows, findings = set(verdicts.ROW_VERDICTS), set(verdicts.FINDING_VERDICTS)
    assert verdicts.REPRODUCED | verdicts.NOT_FAILED | verdicts.ROW_FAILED <= rows
    assert verdicts.FINDING_FAILED | verdicts.FINDING_FLAGGED <= findings
