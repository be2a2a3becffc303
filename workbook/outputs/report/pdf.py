"""Print a report's HTML to PDF with headless Chromium (A4, page numbers from CSS @page)."""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from pathlib import Path

from ...errors import InputError

CANDIDATES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")
TIMEOUT = 180  # seconds for one print


def chromium() -> str | None:
    """The Chromium executable (``WORKBOOK_CHROMIUM`` overrides the search), or None."""
    env = os.environ.get("WORKBOOK_CHROMIUM")
    if env:
        return shutil.which(env)
    return next((p for p in map(shutil.which, CANDIDATES) if p), None)


def require_chromium() -> str:
    """The Chromium executable, or a clear error saying how to install it."""
    exe = chromium()
    if exe is None:
        raise InputError(
            "--pdf needs Chromium to print the report (headless); install it with "
            "'apt-get install chromium' (Debian/Ubuntu), or leave out --pdf to write the HTML only"
        )
    return exe


def chromium_args(exe: str, profile: Path) -> list[str]:
    """The command line common to printing and screenshots: headless, a private profile."""
    args = [
        exe,
        "--headless",
        "--disable-gpu",
        "--no-first-run",
        "--disable-extensions",
        "--disable-background-networking",
        f"--user-data-dir={profile}",
    ]
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        args.append("--no-sandbox")  # Chromium refuses to run as root with its sandbox
    return args


def print_pdf(html_path: Path, pdf_path: Path, *, exe: str | None = None) -> Path:
    """Print ``html_path`` to ``pdf_path`` (the page size and numbers come from its CSS)."""
    exe = exe or require_chromium()
    with tempfile.TemporaryDirectory(prefix="workbook-chromium-") as profile:
        cmd = chromium_args(exe, Path(profile)) + [
            "--no-pdf-header-footer",
            f"--print-to-pdf={pdf_path}",
            Path(html_path).resolve().as_uri(),
        ]
        try:
            done = subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT)
        except subprocess.TimeoutExpired:
            raise InputError(f"Chromium did not print {html_path} within {TIMEOUT} s") from None
    if done.returncode != 0 or not pdf_path.exists() or pdf_path.stat().st_size == 0:
        tail = "\n".join(done.stderr.strip().splitlines()[-3:])
        raise InputError(
            f"Chromium could not print {html_path} to PDF (exit {done.returncode}): {tail}"
        )
    return pdf_path
