"""Charts of a report: the sheet's ``[[charts]]`` drawn by matplotlib as inline SVG.

matplotlib is imported here only (reports draw charts; ``workbook run`` does not). A
``Figure`` is drawn without pyplot, so no display is needed and the backend a notebook chose
is left alone. The data are the computed sheet's (:mod:`workbook.compute.computed`): the same range
values and columns the workbook writes, or the block table a series names.
"""

from __future__ import annotations

import io
import re

import numpy as np

_STYLES = {"solid": "-", "dash": "--", "dot": ":", "none": "none"}
WIDTH_IN, HEIGHT_IN = 6.6, 3.7  # fits the A4 text width


def series_data(sheet, chart, s) -> tuple[np.ndarray, np.ndarray]:
    """x and y of one series of a computed sheet, as the engine computed them."""
    series = sheet.series[(chart.name, chart.series.index(s))]
    if isinstance(series, BaseException):
        raise series
    return np.asarray(series.x, dtype=float), np.asarray(series.y, dtype=float)


def chart_svg(sheet, chart) -> str:
    """The chart as an ``<svg>`` element (no XML header), text kept as text."""
    import matplotlib
    from matplotlib.figure import Figure

    data = [series_data(sheet, chart, s) for s in chart.series]
    with matplotlib.rc_context(
        {
            "svg.fonttype": "none",
            "svg.hashsalt": f"{sheet.name}-{chart.name}",
            "font.size": 9,
            "font.family": "DejaVu Sans",
        }
    ):
        fig = Figure(figsize=(WIDTH_IN, HEIGHT_IN if not chart.equal_axes else WIDTH_IN))
        ax = fig.subplots()
        ax2 = ax.twinx() if any(s.axis == "secondary" for s in chart.series) else None
        handles = []
        for i, (s, (x, y)) in enumerate(zip(chart.series, data)):
            target = ax2 if (s.axis == "secondary" and ax2 is not None) else ax
            style = _STYLES.get(s.line, "-")
            (h,) = target.plot(
                x,
                y,
                linestyle=style,
                marker="o" if s.marker or style == "none" else None,
                markersize=3.5,
                linewidth=1.6,
                color=f"C{i}",
                label=s.name,
            )
            handles.append(h)
        ax.set_xlabel(chart.x_title or (chart.x.title if chart.x else ""))
        ax.set_ylabel(chart.y_title)
        if ax2 is not None:
            ax2.set_ylabel(chart.y2_title)
        for a in (ax, ax2):
            if a is None:
                continue
            if chart.log_x:
                a.set_xscale("log")
            if chart.log_y:
                a.set_yscale("log")
        if chart.equal_axes:
            ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, color="#d9d9d9", linewidth=0.6)
        if len(handles) > 1 or ax2 is not None:
            ax.legend(
                handles=handles,
                loc="upper center",
                bbox_to_anchor=(0.5, -0.16),
                ncol=min(len(handles), 3),
                frameon=False,
                fontsize=8,
            )
        fig.tight_layout()
        buf = io.StringIO()
        fig.savefig(buf, format="svg", metadata={"Date": None, "Creator": None})
    text = buf.getvalue()
    text = text[text.index("<svg") :]
    text = re.sub(r"<metadata>.*?</metadata>", "", text, flags=re.S)
    # scale with the page: the viewBox keeps the drawing, CSS sets the size
    return re.sub(r'<svg([^>]*?) width="[^"]*" height="[^"]*"', r"<svg\1", text, count=1)
