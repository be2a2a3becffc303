"""How written workbooks look: cell formats and chart styling, shared by every xlsx writer."""

from __future__ import annotations

import copy

# xlsxwriter format properties by role
FORMATS: dict[str, dict] = {
    "title": {"bold": True, "font_size": 13},
    "header": {"bold": True, "bottom": 1, "text_wrap": True, "valign": "top"},
    "input": {"bg_color": "#FFF2CC", "font_color": "#0000FF", "border": 1, "num_format": "General"},
    "value": {"num_format": "0.000###"},
    "number": {"num_format": "General"},
    "note": {"italic": True, "font_color": "#595959"},
    "pct": {"num_format": "0.000%"},
    "sci": {"num_format": "0.00E+00"},
    "pass": {"font_color": "#006100", "bg_color": "#C6EFCE"},
    "fail": {"font_color": "#9C0006", "bg_color": "#FFC7CE"},
    "wrap": {"text_wrap": True, "valign": "top"},
    # a value that does not follow an edit of the inputs, and a live cell that reads one
    "frozen": {"bg_color": "#D9D9D9", "italic": True, "num_format": "General"},
    "stale": {"bg_color": "#FCE4D6", "num_format": "General"},
    # a live range's row-count guard: 0 while the count holds, shown as a word
    "guard": {"italic": True, "font_color": "#595959", "num_format": '0;-0;"rows ok"'},
}

GRIDLINES = {"visible": True, "line": {"color": "#D9D9D9"}}
MARKER = {"type": "circle", "size": 4}
NO_MARKER = {"type": "none"}
CHART_SIZE = {"width": 760, "height": 430}
SQUARE_CHART_SIZE = {"width": 620, "height": 620}  # charts with equal axes


def add_formats(wb) -> dict:
    """The workbook's formats by role (``fmt["header"]``, ``fmt["fail"]``...)."""
    return {role: wb.add_format(props) for role, props in FORMATS.items()}


def scatter_chart(wb, *, markers: bool = False):
    """A new scatter chart with straight lines (and markers on every point if ``markers``)."""
    return wb.add_chart(
        {"type": "scatter", "subtype": "straight_with_markers" if markers else "straight"}
    )


def axis(name: str, **options) -> dict:
    """Axis options: the title ``name``, light major gridlines, then ``options``."""
    return {"name": name, **options, "major_gridlines": copy.deepcopy(GRIDLINES)}


def place_chart(ws, row: int, chart, size: dict = CHART_SIZE, *, legend: bool = True) -> int:
    """Size ``chart``, give it a legend below (or none) and insert it on ``ws`` at ``row``.

    Returns the row where the next chart goes."""
    chart.set_legend({"position": "bottom"} if legend else {"none": True})
    chart.set_size(size)
    ws.insert_chart(row, 0, chart)
    return row + int(size["height"] / 20) + 2
