"""The Checks and About sheets of a workbook: the printed values against the computed ones
(with the engine's pass/FAIL test as a live formula), findings, the live forms of numerical
built-ins with their differences, and what the workbook holds and how it was checked."""

from __future__ import annotations

import math

from .. import verdicts as V
from ..errors import NotLive, WorkbookError
from ..functions.constants import CONSTANTS, shadowed
from ..version import __version__
from .checks import tolerances
from .excelsheets import write_labels
from .livecheck import RELATIVE, ROWS_CHECKED


def write_checks(w, report) -> None:
    """The Checks sheet of the layout ``w`` (an ExcelLayout): each printed value against the
    computed one (live where it can be), the findings, the live forms and unused inputs."""
    ws = w.ws("Checks")
    heads = [
        "Source",
        "Name",
        "At",
        "Unit",
        "Printed",
        "Computed",
        "Abs error",
        "Rel error",
        "Tolerance",
        "Verdict",
        "Note",
    ]
    write_labels(ws, 0, 0, heads, w.fmt["header"])
    ws.set_column(0, 0, 34)
    ws.set_column(4, 8, 12)
    ws.set_column(9, 9, 10)
    ws.set_column(10, 10, 80)
    row = 1
    for r in report.rows:
        ws.write_string(row, 0, r.source)
        ws.write_string(row, 1, r.name)
        if r.at is not None:
            ws.write_number(row, 2, r.at)
        ws.write_string(row, 3, r.unit)
        if isinstance(r.printed, str):  # a printed text and what the sheet gives
            ws.write_string(row, 4, r.printed)
            ws.write_string(row, 5, r.computed_text or "")
        else:
            ws.write_number(row, 4, r.printed, w.fmt["number"])
        live = False
        if r.computed is not None:
            live = _write_checked_value(w, ws, row, r)
        E, F = f"E{row + 1}", f"F{row + 1}"
        if r.computed is not None:
            ws.write_formula(row, 6, f"=ABS({F}-{E})", w.fmt["sci"], abs(r.computed - r.printed))
            if r.printed != 0:
                ws.write_formula(
                    row,
                    7,
                    f"=ABS({F}-{E})/ABS({E})",
                    w.fmt["pct"],
                    abs(r.computed - r.printed) / abs(r.printed),
                )
            w.formula_cells += 1 + (r.printed != 0)
        bound, rel = tolerances(r.printed, r.tolerance, r.rel_tolerance)
        shown = []
        if bound is not None:
            shown.append(f"{r.tolerance if r.tolerance is not None else bound:g}")
        if rel is not None:
            shown.append(f"{100 * rel:g}%")
        tol_text = " or ".join(shown)
        ws.write_string(row, 8, tol_text)
        fmt = w.fmt["pass"] if r.verdict in V.NOT_FAILED else w.fmt["fail"]
        if live and r.role == "check" and r.verdict in ("pass", "FAIL"):
            # the engine's own test (checks.within): within the absolute OR the relative bound
            tests = []
            if bound is not None:
                tests.append(f"G{row + 1}<={bound!r}")
            if rel is not None:
                tests.append(f"G{row + 1}<={rel!r}*ABS({E})")
            test = tests[0] if len(tests) == 1 else f"OR({','.join(tests)})"
            ws.write_formula(row, 9, f'=IF({test},"pass","FAIL")', fmt, r.verdict)
            w.formula_cells += 1
        else:
            ws.write_string(row, 9, r.verdict, fmt)
        ws.write_string(row, 10, r.note)
        row += 1
    if report.findings:
        row = _write_findings(w, ws, row + 1, report.findings)
    if w.live_forms:
        row = _write_live_forms(w, ws, row + 1)
    if report.unused_inputs:
        row += 1
        ws.write_string(
            row,
            0,
            "Inputs that no output uses: " + ", ".join(report.unused_inputs),
            w.fmt["note"],
        )
    ws.freeze_panes(1, 0)


def _write_findings(w, ws, row: int, findings) -> int:
    """The findings under their title from ``row``; the row after them."""
    ws.write_string(row, 0, "Findings", w.fmt["title"])
    write_labels(
        ws,
        row + 1,
        0,
        ["Topic", "What", "", "Unit", "Value", "", "", "", "", "Verdict", "Note"],
        w.fmt["header"],
    )
    row += 2
    for f in findings:
        ws.write_string(row, 0, f.topic)
        ws.write_string(row, 1, f.what, w.fmt["wrap"])
        ws.write_string(row, 3, f.unit)
        if f.value is not None and math.isfinite(f.value):
            ws.write_number(row, 4, float(f.value), w.fmt["number"])
        fmt = w.fmt["fail"] if f.verdict in V.FINDING_FLAGGED else w.fmt["pass"]
        ws.write_string(row, 9, f.verdict, fmt)
        ws.write_string(row, 10, f.note, w.fmt["wrap"])
        row += 1
    return row


def _write_live_forms(w, ws, row: int) -> int:
    """Each live approximate form (an integral's Gauss-Legendre sum, a root's bisection
    chain, an extremum's golden-section steps) and its difference from the engine's value
    at the written inputs; for a scalar the live value and the difference are formulas."""
    ws.write_string(row, 0, "Live forms of numerical built-ins", w.fmt["title"])
    heads = ["Where", "What", "Form", "", "Engine", "Live", "Difference", "Relative"]
    write_labels(ws, row + 1, 0, heads + ["", "", "Note"], w.fmt["header"])
    row += 2
    for where, what, diff, engine in w.live_forms:
        ws.write_string(row, 0, where)
        ws.write_string(row, 1, what, w.fmt["wrap"])
        ws.write_string(row, 2, ", ".join(f"{f}()" for f in diff.forms))
        if engine is not None:
            ws.write_number(row, 4, engine, w.fmt["number"])
            ws.write_formula(row, 5, f"={where}", w.fmt["number"], diff.value)
            ws.write_formula(row, 6, f"=ABS(F{row + 1}-E{row + 1})", w.fmt["sci"], diff.largest)
            note = "engine: its value at the inputs written here; live: the cell as it is now"
        else:
            ws.write_number(row, 6, diff.largest, w.fmt["sci"])
            note = "largest over the column at the inputs written here"
        ws.write_number(row, 7, diff.relative, w.fmt["sci"])
        ws.write_string(row, 10, note, w.fmt["wrap"])
        w.formula_cells += 2 if engine is not None else 0
        row += 1
    return row


def _write_checked_value(w, ws, row, r) -> bool:
    """Computed value as a live formula: the function at the printed argument, in its unit."""
    try:
        t = w.sheet.typed_printed(r.name, r.at, r.argument, r.unit)
        _write_cell_plain(w, ws, row, 5, t, r.computed)
        return True
    except NotLive:
        ws.write_number(row, 5, r.computed, w.fmt["number"])
        return False
    except WorkbookError:
        ws.write_number(row, 5, r.computed, w.fmt["number"])
        return False


def _write_cell_plain(w, ws, row, col, t, value):
    formula = w.printer.formula(t, {})
    ws.write_formula(row, col, formula, w.fmt["number"], value)
    w.formula_cells += 1


def _checked_text(w) -> str:
    """What the independent check of the live formulas did (livecheck.py)."""
    v = w.verified
    if v is None:
        return "not checked"
    text = (
        f"{v.checked} formula computations, every formula cell ({ROWS_CHECKED} rows of "
        "each table column), by an evaluator independent of the engine and of the "
        "formula printer (its own reader of Excel formulas; the formulas package for the "
        f"functions that reader lacks), agree with the engine to {RELATIVE:g} relative"
    )
    if v.plain:
        text += f"; {v.plain} of scalar arithmetic only, or helper cells, are not computed"
    if v.refusals:
        text += f"; {len(v.refusals)} that did not are values, with a comment"
    if v.unchecked:
        text += "; not computed by it: " + "; ".join(
            f"{n} cells ({why})" for why, n in sorted(v.unchecked.items())
        )
    return text


def write_about(w) -> None:
    """The About sheet of the layout ``w``: the worksheet, the engine, how to regenerate,
    what is live and what the independent check of the formulas did."""
    ws = w.ws("About")
    spec = w.sheet.spec
    ws.set_column(0, 0, 22)
    ws.set_column(1, 1, 110)
    rows = [
        ("Worksheet", spec.title),
        ("Template", spec.name),
        ("Source", spec.source),
        ("Description", spec.description),
        ("Engine", f"workbook {__version__}"),
        ("Regenerate with", w.command),
        ("Live formulas", f"{w.formula_cells} cells recalculate when an input changes"),
        ("Values, not formulas", ", ".join(sorted(set(w.not_live))) or "none"),
        ("Formulas checked", _checked_text(w)),
        (
            "Units",
            "Every column header names its unit; input cells are in the unit beside them.",
        ),
        ("Macros", "none"),
    ]
    if w.names.renamed:
        rows.append(
            (
                "Renamed for Excel",
                "; ".join(f"{k} is {v}" for k, v in w.names.renamed.items())
                + " (Excel's defined names ignore case and must not read as cells or "
                "functions)",
            )
        )
    own = shadowed(spec)
    if own:
        rows.append(
            (
                "Built-in constants",
                "; ".join(f"{n} is this worksheet's own, not {CONSTANTS[n].doc}" for n in own),
            )
        )
    for name, part in w.sheet.full_spec.parts.items():
        state = (
            "included"
            if name in w.sheet.parts
            else f"left out (not computed); add it with --part {name}"
        )
        rows.append((f"Part {name}", f"{part.title}: {state}"))
    rows += [(str(k), str(v)) for k, v in spec.meta.get("about", {}).items()]
    ws.write_string(0, 0, spec.title, w.fmt["title"])
    for i, (k, v) in enumerate(rows, start=2):
        ws.write_string(i, 0, k, w.fmt["header"])
        ws.write_string(i, 1, v, w.fmt["wrap"])
