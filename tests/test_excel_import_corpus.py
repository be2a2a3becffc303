"""The public corpora of Excel workbooks with VBA (../shared/excel-vba and
../shared/corpus-more/excel-vba-a, not in the repository): every workbook imports with exit 0
and checks with exit 0 or 1, every formula cell with a cached value is counted by the check,
none is computed wrong, and at least as many are reproduced as docs/excel-import.md reports
(scripts/excel_import_table.py prints that table)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared"
FOLDERS = [SHARED / "excel-vba", SHARED / "corpus-more" / "excel-vba-a"]

#: workbook -> cached values reproduced, as measured (docs/excel-import.md, The corpus)
REPRODUCED: dict[str, int] = {}

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(not FOLDERS[0].is_dir(), reason="the corpus ../shared is absent"),
]


def books():
    return [
        pytest.param(p, id=p.name)
        for folder in FOLDERS
        if folder.is_dir()
        for p in sorted(folder.iterdir())
        if p.suffix.lower() in (".xlsm", ".xls")
    ]


@pytest.mark.parametrize("book", books())
def test_corpus_workbook(book):
    sys.path.insert(0, str(ROOT / "scripts"))
    from excel_import_table import measure

    row = measure(book)
    assert row["import_exit"] == 0, row.get("error")
    assert row["check_exit"] in (0, 1), row.get("error")
    assert row["wrong"] == 0
    assert row["printed"] == row["cached"]  # every formula cell with a cached value counted
    assert row["reproduced"] >= REPRODUCED.get(book.name, 0)
