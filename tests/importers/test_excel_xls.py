"""Excel 97-2003 workbooks (.xls): formulas through LibreOffice's conversion, Excel's cached
values from the file's own records, the VBA from the file (../shared corpora, not in the
repository: skipped when absent, or when LibreOffice is not installed)."""

from __future__ import annotations

import json
import shutil

import pytest
from helpers.paths import ROOT, SHARED

from workbook.cli import main

VINCENTY = SHARED / "corpus-more" / "excel-vba-a" / "vincenty.xls"
REFPROP = SHARED / "excel-vba" / "refprop.xls"
needs_soffice = pytest.mark.skipif(shutil.which("soffice") is None, reason="no LibreOffice")


def test_without_libreoffice_an_xls_is_exit_2(tmp_path, monkeypatch, capsys):
    from workbook.excelimport import xls

    monkeypatch.setattr(xls.shutil, "which", lambda name: None)
    path = tmp_path / "old.xls"
    path.write_bytes(b"\xd0\xcf\x11\xe0" + b"\0" * 508)
    assert main(["import", str(path), "--out", str(tmp_path / "o")]) == 2
    assert "needs LibreOffice (soffice)" in capsys.readouterr().err


def test_the_cached_values_of_an_xls_are_read_from_its_records():
    if not VINCENTY.is_file():
        pytest.skip("the corpus ../shared is absent")
    from workbook.excelimport.xls import cached_values

    (sheet, values), *_ = cached_values(VINCENTY)
    assert sheet == "Vincenty formulae" and len(values) == 14
    assert values[(24, 10)] == "37°39'10.1561\"S"  # a text, from its STRING record
    assert values[(32, 8)] == pytest.approx(54972.2711384156, rel=1e-15)


@pytest.mark.slow
@needs_soffice
@pytest.mark.parametrize("path", [VINCENTY, REFPROP], ids=["vincenty", "refprop"])
def test_an_xls_imports_and_every_cached_value_is_counted(path, tmp_path, capsys):
    if not path.is_file():
        pytest.skip("the corpus ../shared is absent")
    out = tmp_path / "o"
    assert main(["import", str(path), "--out", str(out)]) == 0
    capsys.readouterr()
    code = main(["check", str(next(out.glob("*.toml"))), "--json"])
    report = json.loads(capsys.readouterr().out)
    assert code in (0, 1) and report["failed"] == 0
    import sys

    sys.path.insert(0, str(ROOT / "scripts"))
    from excel_import_table import cached_formula_cells

    assert report["printed"] == cached_formula_cells(path)
