"""Headless Chromium for the report tests: print to PDF, measure the layout, count pages.

The shipped report has no script. To measure it, a test injects a small script into a
temporary copy and reads what it found from the DOM that ``--dump-dom`` prints.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import tempfile
from pathlib import Path

from workbook.outputs.report.pdf import chromium, chromium_args

# Runs after the document is laid out: every element must end inside the text block
# (182 mm, the A4 width less the margins), and every fraction must be stacked
# (numerator above denominator), which only a MathML layout does.
_MEASURE = """
<script>
(function () {
  const main = document.querySelector('main.workbook-report');
  const box = main.getBoundingClientRect();
  const over = [];
  for (const el of main.querySelectorAll('math, table, figure, svg, pre, p, h1, h2, h3')) {
    const r = el.getBoundingClientRect();
    if (r.right > box.right + 1) {
      over.push({tag: el.tagName, text: el.textContent.slice(0, 60),
                 right: Math.round(r.right - box.left)});
    }
  }
  let stacked = 0, flat = 0;
  for (const f of main.querySelectorAll('mfrac')) {
    const [num, den] = f.children;
    const a = num.getBoundingClientRect(), b = den.getBoundingClientRect();
    if (a.bottom <= b.top + 1) { stacked++; } else { flat++; }
  }
  const maths = main.querySelectorAll('math');
  const display = maths.length ? getComputedStyle(maths[0]).display : '';
  main.setAttribute('data-measure', JSON.stringify({
    width: Math.round(box.width), overflow: over, stacked: stacked, flat: flat,
    maths: maths.length, display: display}));
})();
</script>
"""


def measure(html_text: str, timeout: float = 120) -> dict:
    """Lay the report out in Chromium (text block 182 mm wide) and return what the
    injected script found: overflowing elements, stacked and flat fractions."""
    exe = chromium()
    assert exe, "chromium is not installed"
    work = Path(tempfile.mkdtemp(prefix="report-measure-"))
    try:
        page = work / "page.html"
        page.write_text(html_text.replace("</body>", _MEASURE + "</body>"), encoding="utf-8")
        cmd = chromium_args(exe, work / "profile") + [
            "--window-size=1200,900",
            "--dump-dom",
            page.as_uri(),
        ]
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        m = re.search(r"data-measure=\"([^\"]*)\"", done.stdout)
        assert m, f"no measurement in Chromium's DOM: {done.stderr[-500:]}"
        import html

        return json.loads(html.unescape(m.group(1)))
    finally:
        shutil.rmtree(work, ignore_errors=True)


def pdf_pages(pdf: Path) -> int:
    """Number of pages of a PDF (pdfinfo if installed, else the page objects)."""
    if shutil.which("pdfinfo"):
        out = subprocess.run(["pdfinfo", str(pdf)], capture_output=True, text=True).stdout
        return int(re.search(r"^Pages:\s+(\d+)", out, re.M).group(1))
    return len(re.findall(rb"/Type\s*/Page\b", pdf.read_bytes()))


def pdf_text(pdf: Path) -> str | None:
    """The text of a PDF (pdftotext), or None without poppler."""
    if not shutil.which("pdftotext"):
        return None
    return subprocess.run(
        ["pdftotext", "-layout", str(pdf), "-"], capture_output=True, text=True
    ).stdout


def screenshots(pdf: Path, out_dir: Path, dpi: int = 50) -> list[Path]:
    """One PNG per page (pdftoppm); an empty list without poppler."""
    if not shutil.which("pdftoppm"):
        return []
    subprocess.run(
        ["pdftoppm", "-r", str(dpi), "-png", str(pdf), str(out_dir / "page")], check=True
    )
    return sorted(out_dir.glob("page-*.png"))
