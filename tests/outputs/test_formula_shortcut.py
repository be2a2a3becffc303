"""The writer skips xlsxwriter's formula rewriting for classic functions
(``xlsx.classic_formulas_as_they_are`` replaces the private ``Worksheet._prepare_formula``).
Guard: every template's worksheets are byte for byte the same with and without it, on the
xlsxwriter versions pyproject.toml allows."""

from __future__ import annotations

import zipfile

import pytest

import workbook
from workbook.outputs import xlsx

FAST = ["concave-cam"]  # the others write for seconds each: run with the slow tests
TEMPLATES = [
    name if name in FAST else pytest.param(name, marks=pytest.mark.slow)
    for name in workbook.list_templates()
]


def _worksheets(path) -> dict[str, bytes]:
    with zipfile.ZipFile(path) as z:
        return {n: z.read(n) for n in z.namelist() if n.startswith("xl/worksheets/")}


@pytest.mark.parametrize("name", TEMPLATES)
def test_the_shortcut_changes_no_worksheet(tmp_path, monkeypatch, name):
    sheet = workbook.load(name)
    patched = []
    shortcut = xlsx.classic_formulas_as_they_are

    def spy(ws):
        shortcut(ws)
        patched.append(ws.__dict__.get("_prepare_formula") is not None)

    monkeypatch.setattr(xlsx, "classic_formulas_as_they_are", spy)
    fast = _worksheets(sheet.write_xlsx(tmp_path / "fast.xlsx"))
    assert patched and all(patched), "the shortcut was not installed: xlsxwriter changed"
    monkeypatch.setattr(xlsx, "classic_formulas_as_they_are", lambda ws: None)
    plain = _worksheets(sheet.write_xlsx(tmp_path / "plain.xlsx"))
    assert b"<f>" in b"".join(plain.values())
    assert fast.keys() == plain.keys()
    for part in plain:
        assert fast[part] == plain[part], f"{name}: {part} differs with the shortcut"
