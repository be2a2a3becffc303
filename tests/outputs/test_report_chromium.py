"""Every installed template's report in headless Chromium: laid out as math, inside the
A4 width, printed to a PDF whose every page carries its number (slow: about 10 s each)."""

from __future__ import annotations

import os
import shutil

import pytest
from helpers.chromium import measure, pdf_pages, pdf_text, screenshots

import workbook
from workbook.compute.computed import compute
from workbook.outputs.report import write_report
from workbook.outputs.report.pdf import chromium

if chromium() is None and os.environ.get("CI"):
    raise RuntimeError("CI must run the report tests in Chromium: install chromium")
pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(chromium() is None, reason="Chromium is not installed"),
]
if os.environ.get("CI") and not shutil.which("pdftoppm"):
    raise RuntimeError("CI must look at the report's pages: install poppler-utils")


@pytest.mark.parametrize("name", list(workbook.list_templates()))
def test_the_report_prints_on_a4(name, tmp_path):
    sheet = workbook.load(name)
    html, pdf = write_report(compute(sheet), tmp_path / f"{name}.html", pdf=True)
    found = measure(html.read_text(encoding="utf-8"))
    assert found["display"] == "math"  # Chromium lays <math> out as MathML
    assert found["stacked"] > 0 and found["flat"] == 0, found  # fractions are stacked
    assert found["width"] == 688  # the 182 mm text block at 96 dpi
    assert found["overflow"] == [], found["overflow"]  # nothing wider than the page
    pages = pdf_pages(pdf)
    assert pages >= 2
    text = pdf_text(pdf)
    if text is not None:
        for k in range(1, pages + 1):  # the footer numbers every page
            assert f"page {k} of {pages}" in text
        assert "1. Inputs" in text and "2. Calculation" in text
        assert "Regenerate this document with" in text  # the last page is there
    shots = screenshots(pdf, tmp_path)
    if shots:
        import matplotlib.image

        assert len(shots) == pages
        for png in shots:
            img = matplotlib.image.imread(png)
            height, width = img.shape[:2]
            assert abs(height / width - 297 / 210) < 0.01  # A4
            assert img[..., :3].min() < 0.5  # something is printed on it
