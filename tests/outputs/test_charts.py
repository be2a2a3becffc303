"""Native charts: every series is drawn from the cells of its own x and y expressions."""

import re
import zipfile

import numpy as np
import openpyxl
import pytest
from helpers.sheets import SINE

CIRCLE = (
    SINE
    + """
[[tables]]
name = "t"
range = "phi := 0, 30 .. 360"
columns = { y = "mm" }

[[charts]]
name = "shapes"
range = "phi := 0, 30 .. 360"
series = [
  { x = "R*cos(phi)", x_unit = "mm", y = "y", unit = "mm", name = "circle" },
  { y = "y", unit = "mm", name = "against phi" },
]

[[charts]]
name = "doubled"
range = "phi := 0, 30 .. 360"
x = { expr = "2*phi", title = "twice the angle, deg" }
series = [{ y = "y", unit = "mm", name = "y" }]
"""
)


def series_refs(path) -> list[tuple[str, str]]:
    """(x range, y range) of every series, chart by chart, as written in the xlsx."""
    out = []
    with zipfile.ZipFile(path) as z:
        names = sorted(
            (n for n in z.namelist() if re.match(r"xl/charts/chart\d+\.xml", n)),
            key=lambda n: int(re.search(r"(\d+)", n).group(1)),
        )
        for name in names:
            xml = z.read(name).decode()
            for ser in re.findall(r"<c:ser>.*?</c:ser>", xml, flags=re.S):
                x = re.search(r"<c:xVal>.*?<c:f>([^<]*)</c:f>", ser, flags=re.S).group(1)
                y = re.search(r"<c:yVal>.*?<c:f>([^<]*)</c:f>", ser, flags=re.S).group(1)
                out.append((x, y))
    return out


def numbers(path, ref: str) -> np.ndarray:
    """The cached values of a range like 'Chart data'!$B$3:$B$15."""
    from helpers.recalc import cell_values

    sheet, rng = ref.split("!")
    ws = openpyxl.load_workbook(path)[sheet.strip("'")]
    values = cell_values(path)
    return np.array([values[(ws.title, row[0].coordinate)] for row in ws[rng.replace("$", "")]])


def test_series_x_expressions_are_drawn_from_their_own_cells(sheet_from, tmp_path):
    sheet = sheet_from(CIRCLE)
    path = sheet.write_xlsx(tmp_path / "c.xlsx")
    (cx, cy), (px, py), (dx, dy) = series_refs(path)
    phi = np.arange(0, 361, 30, dtype=float)
    assert numbers(path, cx) == pytest.approx(10 * np.cos(np.radians(phi)), abs=1e-12)
    assert numbers(path, cy) == pytest.approx(10 * np.sin(np.radians(phi)), abs=1e-12)
    assert numbers(path, px) == pytest.approx(phi)
    assert numbers(path, dx) == pytest.approx(2 * phi)
    assert numbers(path, dy) == pytest.approx(10 * np.sin(np.radians(phi)), abs=1e-12)
    # x = phi reuses the table's cells; the other x expressions get live columns of their own
    assert px.startswith("Listing!") and cx.startswith("'Chart data'!")
    ws = openpyxl.load_workbook(path)["Chart data"]
    column = cx.split("!")[1].split(":")[0].replace("$", "")
    assert str(ws[column].value).startswith("=R_*COS(")
