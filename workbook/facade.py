"""The Sheet of the Python API: the engine's Sheet with its outputs (the workbook, the report,
the Jupyter view), computed once per Sheet.

The engine's :class:`workbook.engine.sheet.Sheet` evaluates; the compute stage and the
renderers build on it. This class sits above all three, so that no stage imports one above
it: ``workbook.load`` and ``workbook.loads`` give it, and ``with_inputs`` and ``with_parts``
keep it. The renderers are imported when first used (``import workbook`` stays light).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from .compute.checks import sheet_report
from .compute.computed import ComputedSheet, compute
from .engine import sheet as engine
from .errors import WorkbookError


class Sheet(engine.Sheet):
    """A worksheet with its outputs: ``write_xlsx``, ``report``, the Jupyter view, each read
    from the sheet computed once (:meth:`computed`)."""

    def another(self, values: dict[str, Any], parts) -> Sheet:
        return Sheet(self.full_spec, values, self.typer, parts, self.typed)

    def check(self):
        """Compare with the printed values; returns a :class:`workbook.compute.checks.Report`,
        made once per Sheet (the workbook's and the report's Checks read it)."""
        return sheet_report(self)

    def computed(
        self, *, excel: bool = False, command: str | None = None, verify: bool = True
    ) -> ComputedSheet:
        """This sheet computed, once per Sheet and kind: as the report and the notebook view
        show it, or with ``excel`` as the workbook writes it (once per ``command`` and
        ``verify``). A Sheet does not change (other inputs or parts are another Sheet), so
        what is computed is reused."""
        key = ("computed", excel, command if excel else None, verify if excel else None)
        return self.once(key, lambda: compute(self, excel=excel, command=command, verify=verify))

    def write_xlsx(
        self,
        path,
        *,
        force: bool = False,
        command: str | None = None,
        report=None,
        verify: bool = True,
        refusals: list | None = None,
    ) -> Path:
        """Write the workbook (atomically); returns the path written. ``report``: the check
        report if already made; ``verify``: check every live formula with an independent
        evaluator first (one that disagrees is written as the engine's value, and appended
        to ``refusals`` when given)."""
        from .outputs.atomic import check_target
        from .outputs.xlsx import write_workbook

        check_target(Path(path), force=force)  # before any work
        if report is None or report is self.made(("check",)):
            computed = self.computed(excel=True, command=command, verify=verify)
        else:  # a report made elsewhere: this workbook's own
            computed = compute(self, report=report, excel=True, command=command, verify=verify)
        if refusals is not None:
            refusals.extend(computed.excel.refusals)
        return write_workbook(computed, Path(path), force=force)

    def report(self, path=None, pdf: bool = False, **options) -> Path:
        """Write the calculation as a document: ``path`` (default ``reports/NAME.html``) and,
        with ``pdf``, the PDF beside it (needs Chromium). Returns the HTML path."""
        from .outputs.report import report_targets, write_report

        path, _ = report_targets(self.name, path, pdf=pdf, force=options.get("force", False))
        return write_report(self.computed(), path, pdf=pdf, **options)[0]

    def _repr_html_(self) -> str:
        from .outputs.notebook import error_html, sheet_html

        try:
            computed = self.computed()
        except WorkbookError as err:  # shown in place of the sheet
            return error_html(self.name, err)
        return sheet_html(computed)
