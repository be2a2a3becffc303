"""Excel 97-2003 workbooks (.xls, BIFF8): the cell formulas come from a conversion to .xlsx by
LibreOffice (headless, in a private folder and profile, with a time limit), and Excel's cached
values from the file's own FORMULA records (LibreOffice computes again on loading, and cannot
compute a VBA function). The VBA is read from the .xls itself, as for any workbook."""

from __future__ import annotations

import shutil
import struct
import subprocess
from pathlib import Path

from ..errors import InputError

#: seconds LibreOffice may take to convert one workbook
CONVERT_SECONDS = 180
_BOF, _EOF, _SHEET, _FORMULA, _STRING = 0x0809, 0x000A, 0x0085, 0x0006, 0x0207
_ERRORS = {0x00: "#NULL!", 0x07: "#DIV/0!", 0x0F: "#VALUE!", 0x17: "#REF!", 0x1D: "#NAME?",
           0x24: "#NUM!", 0x2A: "#N/A"}  # fmt: skip


def soffice() -> str:
    """The LibreOffice program, or exit 2 naming what to install."""
    found = shutil.which("soffice") or shutil.which("libreoffice")
    if found is None:
        raise InputError(
            "reading an Excel 97-2003 (.xls) workbook needs LibreOffice (soffice) to convert "
            "its cell formulas: install it, or save the workbook as .xlsm in Excel"
        )
    return found


def convert(path: Path, folder: Path) -> Path:
    """``path`` converted to ``folder/NAME.xlsx`` by LibreOffice headless."""
    program = soffice()
    profile = folder / "profile"
    profile.mkdir(exist_ok=True)
    try:
        subprocess.run(
            [
                program,
                f"-env:UserInstallation={profile.resolve().as_uri()}",
                "--headless",
                "--norestore",
                "--convert-to",
                "xlsx",
                "--outdir",
                str(folder),
                str(path.resolve()),
            ],
            capture_output=True,
            timeout=CONVERT_SECONDS,
            check=False,
            stdin=subprocess.DEVNULL,
        )
    except subprocess.TimeoutExpired:
        raise InputError(
            f"{path}: LibreOffice did not convert it within {CONVERT_SECONDS} s"
        ) from None
    out = folder / (path.stem + ".xlsx")
    if not out.is_file():
        raise InputError(f"{path}: LibreOffice could not convert it to .xlsx")
    return out


def cached_values(path: Path) -> list[tuple[str, dict[tuple[int, int], object]]]:
    """[(sheet name, {(row, column) from 1: Excel's cached value})] of the formula cells, in
    the order of the sheets: a number, a text, True/False, an error value's text."""
    import olefile

    try:
        with olefile.OleFileIO(str(path)) as ole:
            name = next(
                (s for s in ("Workbook", "Book") if ole.exists(s)), None
            )  # BIFF8, else BIFF5
            if name is None:
                raise InputError(f"{path}: no Workbook stream (not an Excel 97-2003 file)")
            data = ole.openstream(name).read()
    except (OSError, ValueError) as exc:
        raise InputError(f"{path}: cannot read it as an Excel 97-2003 file ({exc})") from None
    sheets: list[tuple[int, str]] = []
    for rtype, _, body in _records(data, 0):
        if rtype == _SHEET and len(body) >= 8:
            offset, kind = struct.unpack_from("<IB", body, 0)[0], body[5]
            if kind == 0:  # a worksheet (not a chart or macro sheet)
                sheets.append((offset, _short_string(body, 6)))
        if rtype == _EOF:
            break
    out = []
    for offset, sheet in sheets:
        values: dict[tuple[int, int], object] = {}
        pending = None
        for rtype, _, body in _records(data, offset):
            if rtype == _FORMULA and len(body) >= 14:
                row, col = struct.unpack_from("<HH", body, 0)
                result = body[6:14]
                pending = None
                if result[6:8] != b"\xff\xff":
                    values[(row + 1, col + 1)] = struct.unpack("<d", result)[0]
                elif result[0] == 0:
                    pending = (row + 1, col + 1)  # a text: the STRING record that follows
                elif result[0] == 1:
                    values[(row + 1, col + 1)] = bool(result[2])
                elif result[0] == 2:
                    values[(row + 1, col + 1)] = _ERRORS.get(result[2], "#VALUE!")
                elif result[0] == 3:
                    values[(row + 1, col + 1)] = ""
            elif rtype == _STRING and pending is not None:
                values[pending] = _long_string(body)
                pending = None
            elif rtype == _EOF:
                break
        out.append((sheet, values))
    return out


def _records(data: bytes, offset: int):
    """(type, offset, body) of the BIFF records from ``offset``."""
    pos = offset
    while pos + 4 <= len(data):
        rtype, size = struct.unpack_from("<HH", data, pos)
        yield rtype, pos, data[pos + 4 : pos + 4 + size]
        pos += 4 + size


def _short_string(body: bytes, at: int) -> str:
    count, flags = body[at], body[at + 1]
    raw = body[at + 2 :]
    if flags & 1:
        return raw[: 2 * count].decode("utf-16-le", "replace")
    return raw[:count].decode("latin-1")


def _long_string(body: bytes) -> str:
    if len(body) < 3:
        return ""
    count, flags = struct.unpack_from("<HB", body, 0)
    raw = body[3:]
    if flags & 1:
        return raw[: 2 * count].decode("utf-16-le", "replace")
    return raw[:count].decode("latin-1")
