"""``workbook import BOOK.xlsm``: an Excel workbook and its VBA functions as a worksheet.

``book.py`` decides what the worksheet holds (inputs from the constant cells formulas read,
definitions from formula cells, functions from VBA Functions) and ``writer.py`` writes it
with Excel's cached values as printed values. See docs/excel-import.md.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path


@dataclass
class ImportResult:
    toml: Path
    files: list[Path]
    definitions: int
    functions: int
    printed: int
    not_translated: list[tuple[str, str]] = field(default_factory=list)
    cells: dict[str, tuple[str, float | None]] = field(default_factory=dict)  # ref -> printed row

    def line(self) -> str:
        extra = (
            f"; {len(self.not_translated)} listed as not translated" if self.not_translated else ""
        )
        return (
            f"wrote {self.toml} ({self.definitions} inputs and definitions, {self.functions} VBA "
            f"functions, {self.printed} of Excel's cached values as printed values{extra})"
        )


def import_file(
    file: str, out: str = ".", *, vba: list[str] | None = None, force: bool = False
) -> ImportResult:
    """Translate an Excel workbook (and VBA from ``vba`` files) into DIR/NAME.toml."""
    from .book import translate_book
    from .writer import write

    path = Path(file)
    translation = translate_book(path, [Path(v) for v in vba or []])
    return write(translation, Path(out), force=force)
