"""Recalculate a workbook in LibreOffice Calc (headless) and read the values back.

LibreOffice recalculates xlsx on load only when its OOXMLRecalcMode setting says so;
a private user profile sets it to 0 ("always").
"""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from pathlib import Path

_PROFILE_XCU = """<?xml version="1.0" encoding="UTF-8"?>
<oor:items xmlns:oor="http://openoffice.org/2001/registry"
           xmlns:xs="http://www.w3.org/2001/XMLSchema"
           xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance">
<item oor:path="/org.openoffice.Office.Calc/Formula/Load">
  <prop oor:name="OOXMLRecalcMode" oor:op="fuse"><value>0</value></prop>
</item>
<item oor:path="/org.openoffice.Office.Calc/Formula/Load">
  <prop oor:name="ODFRecalcMode" oor:op="fuse"><value>0</value></prop>
</item>
</oor:items>
"""


def soffice() -> str | None:
    return shutil.which("soffice") or shutil.which("libreoffice")


def recalculate(xlsx: Path, out_dir: Path | None = None, timeout: float = 180) -> Path:
    """Open ``xlsx`` in LibreOffice, recalculate everything, save as xlsx; return the new path."""
    exe = soffice()
    if exe is None:
        raise RuntimeError("LibreOffice (soffice) is not installed")
    out_dir = Path(out_dir or tempfile.mkdtemp(prefix="recalc-"))
    out_dir.mkdir(parents=True, exist_ok=True)
    profile = Path(tempfile.mkdtemp(prefix="lo-profile-"))
    user = profile / "user"
    user.mkdir(parents=True)
    (user / "registrymodifications.xcu").write_text(_PROFILE_XCU, encoding="utf-8")
    src_dir = Path(tempfile.mkdtemp(prefix="recalc-src-"))
    src = src_dir / Path(xlsx).name
    shutil.copy(xlsx, src)
    cmd = [
        exe,
        f"-env:UserInstallation={profile.as_uri()}",
        "--headless",
        "--norestore",
        "--convert-to",
        "xlsx:Calc MS Excel 2007 XML",
        "--outdir",
        str(out_dir),
        str(src),
    ]
    try:
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    finally:
        shutil.rmtree(profile, ignore_errors=True)
    result = out_dir / src.name
    if done.returncode != 0 or not result.exists():
        raise RuntimeError(f"LibreOffice failed ({done.returncode}): {done.stdout} {done.stderr}")
    shutil.rmtree(src_dir, ignore_errors=True)
    return result


def formula_values(xlsx: Path) -> dict[tuple[str, str], tuple[str, object]]:
    """{(sheet, cell): (formula, cached value)} for every formula cell of a workbook."""
    import openpyxl

    formulas = openpyxl.load_workbook(xlsx, data_only=False)
    values = openpyxl.load_workbook(xlsx, data_only=True)
    out = {}
    for ws in formulas.worksheets:
        vs = values[ws.title]
        for row in ws.iter_rows():
            for cell in row:
                if isinstance(cell.value, str) and cell.value.startswith("="):
                    out[(ws.title, cell.coordinate)] = (cell.value, vs[cell.coordinate].value)
    return out


def cell_values(xlsx: Path) -> dict[tuple[str, str], object]:
    """{(sheet, cell): value} as LibreOffice (or the writer) cached them."""
    import openpyxl

    wb = openpyxl.load_workbook(xlsx, data_only=True)
    return {
        (ws.title, c.coordinate): c.value
        for ws in wb.worksheets
        for row in ws.iter_rows()
        for c in row
        if c.value is not None
    }


def agree(a, b, relative: float = 1e-9) -> bool:
    """Two cell values the same to ``relative``: numbers, complex texts (``3+4i``: Excel keeps
    15 digits of each part, so the last may differ) by their modulus, other texts exactly."""
    from workbook.functions.complexes import parse_text

    numbers = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in (a, b))
    if numbers:
        return abs(a - b) <= relative * max(abs(a), abs(b)) + 1e-300
    if isinstance(a, str) and isinstance(b, str) and a != b and a[-1:] in "ij":
        za, zb = parse_text(a), parse_text(b)
        if za is not None and zb is not None:
            return abs(za - zb) <= relative * max(abs(za), abs(zb)) + 1e-300
    return str(a) == str(b)
