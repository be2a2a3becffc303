"""``workbook import BOOK.xlsm``: an Excel workbook and its VBA functions as a worksheet.

``book.py`` decides what the worksheet holds (inputs from the constant cells formulas read,
definitions from formula cells, functions from VBA Functions) and ``writer.py`` writes it
with Excel's cached values as printed values. See docs/excel-import.md.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .writer import ImportResult


def import_file(
    file: str, out: str = ".", *, vba: list[str] | None = None, force: bool = False
) -> ImportResult:
    """Translate an Excel workbook (and VBA from ``vba`` files) into DIR/NAME.toml."""
    from .book import translate_book
    from .writer import write

    path = Path(file)
    translation = translate_book(path, [Path(v) for v in vba or []])
    return write(translation, Path(out), force=force)
