#!/usr/bin/env python
"""Render each scene's main chart as docs/pictures/<scene>.png, from the generated workbook.

    python scripts/render_pictures.py                 # every installed template
    python scripts/render_pictures.py concave-cam     # some of them

For each template: write its workbook with only the main chart on the Charts sheet (the
template's ``[sheet] main_chart = "name"``, else the first chart titled "Fig. ...", else the
first chart), hide every other sheet, let LibreOffice (headless) print it to PDF, turn the
page into PNG with poppler (pdftoppm to find the chart, pdftocairo to crop it), and list the
pictures in docs/pictures/index.md with the figure of the paper each one matches.

Needs LibreOffice (soffice) and poppler-utils (pdftoppm, pdftocairo).
"""

from __future__ import annotations

import argparse
import copy
import re
import shutil
import subprocess
import sys
import tempfile
import time
import zipfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "docs" / "pictures"
DPI = 130


def main_chart(spec):
    """The chart that stands for the scene."""
    wanted = spec.meta.get("main_chart")
    if wanted:
        for c in spec.charts:
            if c.name == wanted:
                return c
        raise SystemExit(f"{spec.name}: [sheet] main_chart = {wanted!r} is not a chart")
    for c in spec.charts:
        if re.match(r"^\s*Fig\.?\s*\d", c.title):
            return c
    return spec.charts[0] if spec.charts else None


def figure_of(title: str) -> str:
    m = re.match(r"^\s*(Fig\.?\s*[0-9]+[a-z]?)", title)
    return m.group(1) if m else ""


def only_charts_visible(xlsx: Path) -> None:
    """Hide every sheet but Charts and make Charts the active one (rewrites the zip)."""
    tmp = xlsx.with_suffix(".tmp.xlsx")
    with zipfile.ZipFile(xlsx) as zin, zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "xl/workbook.xml":
                text = data.decode("utf-8")
                sheets = re.findall(r"<sheet [^>]*/>", text)
                names = [re.search(r'name="([^"]*)"', s).group(1) for s in sheets]
                index = names.index("Charts")
                for s, name in zip(sheets, names):
                    if name != "Charts":
                        text = text.replace(s, s.replace("<sheet ", '<sheet state="hidden" ', 1))
                text = re.sub(r'activeTab="\d+"', f'activeTab="{index}"', text)
                if "activeTab=" not in text:
                    text = text.replace("<workbookView ", f'<workbookView activeTab="{index}" ', 1)
                text = re.sub(r'firstSheet="\d+"', f'firstSheet="{index}"', text)
                data = text.encode("utf-8")
            elif re.match(r"xl/worksheets/sheet\d+\.xml", item.filename):
                # only the active sheet may be 'selected'; print landscape, one page wide
                text = data.decode("utf-8").replace('tabSelected="1"', 'tabSelected="0"')
                if "<sheetPr" not in text:
                    text = re.sub(
                        r"(<worksheet [^>]*>)",
                        r'\1<sheetPr><pageSetUpPr fitToPage="1"/></sheetPr>',
                        text,
                        count=1,
                    )
                if "<pageSetup" not in text:
                    text = re.sub(
                        r"(<pageMargins [^>]*/>)",
                        r'\1<pageSetup paperSize="9" orientation="landscape" fitToWidth="1" '
                        r'fitToHeight="0"/>',
                        text,
                        count=1,
                    )
                data = text.encode("utf-8")
            zout.writestr(item, data)
    tmp.replace(xlsx)


def to_pdf(xlsx: Path, out_dir: Path) -> Path:
    exe = shutil.which("soffice") or shutil.which("libreoffice")
    if exe is None:
        raise SystemExit("LibreOffice is not installed (apt-get install -y libreoffice-calc-nogui)")
    profile = Path(tempfile.mkdtemp(prefix="lo-profile-"))
    try:
        subprocess.run(
            [
                exe,
                f"-env:UserInstallation={profile.as_uri()}",
                "--headless",
                "--norestore",
                "--convert-to",
                "pdf",
                "--outdir",
                str(out_dir),
                str(xlsx),
            ],
            check=True,
            capture_output=True,
            timeout=240,
        )
    finally:
        shutil.rmtree(profile, ignore_errors=True)
    pdf = out_dir / (xlsx.stem + ".pdf")
    if not pdf.exists():
        raise SystemExit(f"LibreOffice wrote no PDF for {xlsx}")
    return pdf


def read_pgm(path: Path) -> np.ndarray:
    data = path.read_bytes()
    # header: P5 <w> <h> <max>, then bytes
    parts = data.split(maxsplit=4)
    if parts[0] != b"P5":
        raise SystemExit(f"{path}: not a binary PGM")
    w, h = int(parts[1]), int(parts[2])
    return np.frombuffer(parts[4][: w * h], dtype=np.uint8).reshape(h, w)


def chart_box(gray: np.ndarray, min_height: int) -> tuple[int, int, int, int]:
    """(x, y, w, h) of the first tall band of ink: the chart (not the page header)."""
    ink = gray < 245
    rows = ink.any(axis=1)
    bands, start, gap = [], None, 0
    for i, r in enumerate(rows):
        if r:
            if start is None:
                start = i
            gap = 0
        elif start is not None:
            gap += 1
            if gap > 4:
                bands.append((start, i - gap))
                start, gap = None, 0
    if start is not None:
        bands.append((start, len(rows) - 1))
    band = next(((a, b) for a, b in bands if b - a >= min_height), None)
    if band is None:
        raise SystemExit("no chart found on the page")
    a, b = band
    cols = np.flatnonzero(ink[a : b + 1].any(axis=0))
    pad = 6
    x0, x1 = max(cols[0] - pad, 0), min(cols[-1] + pad, gray.shape[1] - 1)
    y0, y1 = max(a - pad, 0), min(b + pad, gray.shape[0] - 1)
    return x0, y0, x1 - x0 + 1, y1 - y0 + 1


def to_png(pdf: Path, png: Path) -> tuple[int, int]:
    for tool in ("pdftoppm", "pdftocairo"):
        if shutil.which(tool) is None:
            raise SystemExit(f"{tool} is missing (apt-get install -y poppler-utils)")
    work = pdf.parent
    subprocess.run(
        [
            "pdftoppm",
            "-r",
            str(DPI),
            "-f",
            "1",
            "-l",
            "1",
            "-gray",
            "-singlefile",
            str(pdf),
            str(work / "page"),
        ],
        check=True,
    )
    gray = read_pgm(work / "page.pgm")
    x, y, w, h = chart_box(gray, min_height=DPI)  # a chart is taller than an inch
    stem = png.with_suffix("")
    subprocess.run(
        [
            "pdftocairo",
            "-png",
            "-r",
            str(DPI),
            "-f",
            "1",
            "-l",
            "1",
            "-singlefile",
            "-x",
            str(x),
            "-y",
            str(y),
            "-W",
            str(w),
            "-H",
            str(h),
            str(pdf),
            str(stem),
        ],
        check=True,
    )
    return w, h


def render(name: str, out_dir: Path) -> dict | None:
    import workbook
    from workbook.facade import Sheet

    sheet = workbook.load(name)
    chart = main_chart(sheet.spec)
    if chart is None:
        print(f"{name}: no chart", file=sys.stderr)
        return None
    spec = copy.copy(sheet.spec)
    spec.charts = [chart]
    spec.tables = list(sheet.spec.tables)
    one = Sheet(spec, sheet.values, sheet.typer)
    with tempfile.TemporaryDirectory(prefix=f"pictures-{name}-") as tmp:
        tmp = Path(tmp)
        xlsx = one.write_xlsx(tmp / f"{name}.xlsx", command=f"workbook run {name}")
        only_charts_visible(xlsx)
        pdf = to_pdf(xlsx, tmp)
        png = out_dir / f"{name}.png"
        w, h = to_png(pdf, png)
    return {
        "scene": name,
        "chart": chart.name,
        "title": chart.title,
        "figure": figure_of(chart.title),
        "png": png,
        "size": (w, h),
    }


def write_index(rows: list[dict], out_dir: Path) -> Path:
    lines = [
        "# Pictures: each scene's main chart",
        "",
        "Rendered from the generated workbooks by LibreOffice:",
        "`python scripts/render_pictures.py`.",
        "",
        "| scene | figure of the paper | chart |",
        "| --- | --- | --- |",
    ]
    for r in rows:
        rel = r["png"].name
        lines.append(
            f"| `{r['scene']}` | {r['figure'] or '(no printed figure)'} | ![{r['title']}]({rel}) |"
        )
    path = out_dir / "index.md"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def main(argv=None) -> int:
    import workbook

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("names", nargs="*", help="templates (default: all installed)")
    p.add_argument("--out", default=str(OUT), help="folder of the pictures (docs/pictures)")
    args = p.parse_args(argv)
    out_dir = Path(args.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    names = args.names or list(workbook.list_templates())
    rows = []
    for name in names:
        start = time.perf_counter()
        row = render(name, out_dir)
        if row:
            rows.append(row)
            print(
                f"{row['png']}: {row['title']} ({row['size'][0]}x{row['size'][1]} px, "
                f"{time.perf_counter() - start:.1f} s)"
            )
    if not args.names:
        print(write_index(rows, out_dir))
    else:  # keep the scenes rendered before in the index
        known = {r["scene"]: r for r in _read_index(out_dir)}
        known.update({r["scene"]: r for r in rows})
        print(write_index([known[k] for k in sorted(known)], out_dir))
    return 0


def _read_index(out_dir: Path) -> list[dict]:
    path = out_dir / "index.md"
    if not path.exists():
        return []
    rows = []
    for line in path.read_text(encoding="utf-8").splitlines():
        m = re.match(r"^\| `([^`]+)` \| (.*?) \| !\[(.*?)\]\((.*?)\) \|$", line)
        if m and (out_dir / m.group(4)).exists():
            fig = "" if m.group(2) == "(no printed figure)" else m.group(2)
            rows.append(
                {
                    "scene": m.group(1),
                    "figure": fig,
                    "title": m.group(3),
                    "png": out_dir / m.group(4),
                }
            )
    return rows


if __name__ == "__main__":
    sys.exit(main())
