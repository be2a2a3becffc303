#!/usr/bin/env python
"""Render one page of a template's report as docs/pictures/report-<name>.png.

    python scripts/render_report_picture.py                    # concave-cam, page 1
    python scripts/render_report_picture.py r0-synthesis --page 2

Writes the report with ``workbook report NAME --pdf`` (headless Chromium) into a temporary
folder and turns the page into PNG with poppler's pdftoppm. Needs chromium and
poppler-utils.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "docs" / "pictures"
DPI = 80


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("name", nargs="?", default="concave-cam")
    p.add_argument("--page", type=int, default=1)
    args = p.parse_args(argv)
    if not shutil.which("pdftoppm"):
        print("needs pdftoppm: apt-get install poppler-utils", file=sys.stderr)
        return 2
    import workbook
    from workbook.outputs.report import write_report

    with tempfile.TemporaryDirectory(prefix="report-picture-") as tmp:
        html, pdf = write_report(workbook.load(args.name), Path(tmp) / "r.html", pdf=True)
        stem = Path(tmp) / "page"
        cmd = ["pdftoppm", "-r", str(DPI), "-png", "-singlefile"]
        cmd += ["-f", str(args.page), "-l", str(args.page), str(pdf), str(stem)]
        subprocess.run(cmd, check=True)
        target = OUT / f"report-{args.name}.png"
        shutil.copy(stem.with_suffix(".png"), target)
    print(f"wrote {target.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
