"""``workbook report``: the calculation as a document to hand in (HTML, and PDF by Chromium).

:func:`render` gives the HTML text; :func:`write_report` writes it (and the PDF) atomically.
The modules: :mod:`.mathml` prints formulas, :mod:`.html` builds the document,
:mod:`.charts` draws the charts (matplotlib, imported only here), :mod:`.pdf` prints.
"""

from __future__ import annotations

from pathlib import Path

from ...errors import InputError
from ..atomic import check_target, replacing
from .html import fragment, regenerate_command, render

__all__ = ["fragment", "regenerate_command", "render", "report_targets", "write_report"]

_GENERATOR = "<meta name='generator' content='workbook report"


def _check_output(path: Path, kind: str, force: bool) -> None:
    """Refuse a folder, a missing parent, or (without force) a file of another kind."""
    check_target(path, kind=kind, force=force)
    if force or not path.exists() or path.stat().st_size == 0:
        return
    with open(path, "rb") as fh:
        head = fh.read(4096)
    ours = head.startswith(b"%PDF") if kind == "pdf" else _GENERATOR.encode() in head
    if not ours:
        what = "a PDF" if kind == "pdf" else "a workbook report"
        raise InputError(f"{path} exists and is not {what}; use --force to overwrite it")


def report_targets(
    name: str, path: Path | str | None = None, *, pdf: bool = False, force: bool = False
) -> tuple[Path, str | None]:
    """The report's HTML path (default ``reports/NAME.html``) and, with ``pdf``, Chromium:
    both checked before any work (a missing Chromium or a file of another kind is said at
    once)."""
    if path is None:
        path = Path("reports") / f"{name}.html"
        path.parent.mkdir(parents=True, exist_ok=True)
    path = Path(path)
    if path.with_suffix(".pdf") == path:
        raise InputError(f"{path}: the report is HTML; give a .html path (the PDF goes beside it)")
    _check_output(path, "html", force)
    exe = None
    if pdf:
        from .pdf import require_chromium

        exe = require_chromium()
        _check_output(path.with_suffix(".pdf"), "pdf", force)
    return path, exe


def write_report(
    computed,
    path: Path | str | None = None,
    *,
    pdf: bool = False,
    force: bool = False,
    command: str | None = None,
    full_tables: bool = False,
) -> list[Path]:
    """Write the report of ``computed`` (a :class:`workbook.compute.computed.ComputedSheet`) to
    ``path`` (default ``reports/NAME.html``) and, with ``pdf``, the PDF beside it (same name,
    ``.pdf``). Returns the paths written."""
    path, exe = report_targets(computed.name, path, pdf=pdf, force=force)
    pdf_path = path.with_suffix(".pdf")
    text = render(computed, command=command, full_tables=full_tables)
    written = []
    with replacing(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
        if pdf:
            from .pdf import print_pdf

            # print from the finished text beside the target, then move both into place
            html_tmp = tmp.with_name(tmp.name + ".html")
            html_tmp.write_text(text, encoding="utf-8")
            try:
                with replacing(pdf_path) as pdf_tmp:
                    print_pdf(html_tmp, pdf_tmp, exe=exe)
            finally:
                html_tmp.unlink(missing_ok=True)
    written.append(path)
    if pdf:
        written.append(pdf_path)
    return written
