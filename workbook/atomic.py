"""Write output files so that an error or Ctrl-C never leaves a half-written file."""

from __future__ import annotations

import contextlib
import os
import tempfile
import zipfile
from pathlib import Path

from .errors import InputError


def check_target(path: Path, *, kind: str = "xlsx", force: bool = False) -> None:
    """Refuse a directory, a missing parent folder, or an existing file of another kind."""
    if path.is_dir():
        raise InputError(
            f"output path {path} is a directory; give a file name like {path}/report.{kind}"
        )
    if not path.parent.exists():
        raise InputError(f"output folder {path.parent} does not exist")
    if path.exists() and not force and kind == "xlsx" and not _is_xlsx(path):
        raise InputError(f"{path} exists and is not an xlsx workbook; use --force to overwrite it")


def _is_xlsx(path: Path) -> bool:
    try:
        with zipfile.ZipFile(path) as z:
            return "[Content_Types].xml" in z.namelist()
    except (zipfile.BadZipFile, OSError):
        return False


def _mode_for(path: Path) -> int:
    """Keep an existing file's permissions; a new file gets the usual 0666 less the umask."""
    try:
        return path.stat().st_mode & 0o7777
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


@contextlib.contextmanager
def replacing(path: Path):
    """Yield a temporary path beside ``path``; move it into place only if the block succeeds."""
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".partial", dir=path.parent)
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        yield tmp_path
        os.chmod(tmp_path, _mode_for(path))
        os.replace(tmp_path, path)
    except BaseException:  # includes KeyboardInterrupt: the old file stays as it was
        with contextlib.suppress(OSError):
            tmp_path.unlink()
        raise
