"""The blocks' result cache is keyed by the template's content, not its path: a template
edited in place (as in a notebook that loads it again) gives fresh results."""

from __future__ import annotations

import shutil

import numpy as np
import pytest
from helpers.paths import ROOT

import workbook
from workbook import blocks

TEMPLATES = ROOT / "templates"


@pytest.fixture
def valve(tmp_path):
    for f in TEMPLATES.glob("cam-wear-valve*"):
        shutil.copy(f, tmp_path / f.name)
    return tmp_path / "cam-wear-valve.toml"


def _formula_column(path) -> np.ndarray:
    return workbook.load(path).table("measured")["h formula [mm]"].to_numpy()


def test_an_edited_template_gives_fresh_block_results(valve):
    before = _formula_column(valve)
    text = valve.read_text()
    old = '"h_w2(phi)" = { expr = "h_w(phi, w_b2, w_n2)"'
    assert old in text
    valve.write_text(text.replace(old, '"h_w2(phi)" = { expr = "2*h_w(phi, w_b2, w_n2)"'))
    after = _formula_column(valve)  # same path, same input values, another formula
    assert np.abs(before).max() > 0
    np.testing.assert_allclose(after, 2 * before, rtol=1e-12)


def test_edited_measured_data_gives_fresh_block_results(valve):
    before = workbook.load(valve).table("measured")["h measured [mm]"].to_numpy()
    data = valve.with_name("cam-wear-valve.measured-lift.csv")
    lines = data.read_text().splitlines()
    head = [i for i, ln in enumerate(lines) if ln and ln[0].isdigit()][0]
    cells = lines[head].split(",")
    cells[1] = repr(float(cells[1]) + 0.5)
    lines[head] = ",".join(cells)
    data.write_text("\n".join(lines) + "\n")
    after = workbook.load(valve).table("measured")["h measured [mm]"].to_numpy()
    assert after[0] == pytest.approx(before[0] + 0.5) and np.array_equal(after[1:], before[1:])


def test_same_content_at_two_paths_shares_results(valve, tmp_path):
    other = tmp_path / "copy"
    other.mkdir()
    for f in valve.parent.glob("cam-wear-valve*"):
        shutil.copy(f, other / f.name)
    a, b = workbook.load(valve), workbook.load(other / valve.name)
    assert blocks.content_key(a.spec) == blocks.content_key(b.spec)
    calls = []
    blocks.cached(a, "shared-test", lambda: calls.append(1) or "x")
    assert blocks.cached(b, "shared-test", lambda: calls.append(2) or "y") == "x"
    assert calls == [1]
