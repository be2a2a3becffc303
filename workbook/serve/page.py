"""The pages of ``workbook serve``: a worksheet's live page (the inputs as a form, the
buttons, the report) and a folder's list of worksheets. Every text of the worksheet is
escaped; the page's one script is the server's own file (``live.js``)."""

from __future__ import annotations

from html import escape

from ..errors import WorkbookError
from ..language import units as un
from ..outputs.report.html import CSS

#: The policy of every page: no inline script, nothing fetched from elsewhere.
CSP = (
    "default-src 'none'; script-src 'self'; style-src 'self' 'unsafe-inline'; "
    "img-src 'self' data:; connect-src 'self'; form-action 'none'; base-uri 'none'; "
    "frame-ancestors 'none'"
)

PAGE_CSS = """
body { font-family: sans-serif; margin: 0; }
#wb-bar { position: sticky; top: 0; background: #f4f4f4; border-bottom: 1px solid #ccc;
  padding: 6px 12px; z-index: 2; }
#wb-error { background: #fde8e8; color: #8a1010; border: 1px solid #e0a0a0; padding: 6px 10px;
  margin: 6px 0; white-space: pre-wrap; font-family: monospace; }
#wb-inputs { display: flex; flex-wrap: wrap; gap: 4px 14px; margin: 4px 0; }
#wb-inputs label { white-space: nowrap; font-size: 90%; }
#wb-inputs input[data-field=value] { width: 7em; }
#wb-inputs input[data-field=unit] { width: 5em; }
.wb-refused input, .wb-refused select { outline: 2px solid #c00; }
.wb-input-error { color: #a00; }
body.wb-failed #wb-report { opacity: 0.55; }
#wb-status { margin-left: 1em; font-size: 90%; }
#wb-report { padding: 0 12px; }
figure.wb-stale svg { opacity: 0.4; }
body.wb-failed .wb-stopped { outline: 2px solid #c00; background: #fff0f0; opacity: 1; }
"""


def error_text(err: WorkbookError | None) -> str | None:
    """One paragraph naming the file, line and definition (as the command line prints it)."""
    return None if err is None else str(err)


def _number(value: float) -> str:
    return f"{value:.12g}"


def inputs_form(sheet) -> str:
    """The inputs of a Sheet as form fields: value and unit, a choice as a select."""
    if sheet is None:
        return ""
    out = []
    for name, spec in sheet.spec.inputs.items():
        value = sheet.values[name]
        head = f"<label data-input='{escape(name)}'><b>{escape(name)}</b> "
        if spec.options:
            options = "".join(
                f"<option{' selected' if o == value else ''}>{escape(o)}</option>"
                for o in spec.options
            )
            field = f"<select name='{escape(name)}'>{options}</select>"
        else:
            unit = "" if spec.unit.dimensionless else un.pretty(spec.unit)
            field = (
                f"<input name='{escape(name)}' data-field='value' inputmode='decimal' "
                f"value='{escape(_number(float(value.to(spec.unit).magnitude)))}'> "
                + (
                    f"<input data-field='unit' value='{escape(unit)}' aria-label='unit'>"
                    if unit
                    else escape(spec.label)
                )
            )
        title = f" title='{escape(spec.note)}'" if spec.note else ""
        out.append(
            head.replace("<label", f"<label{title}", 1)
            + field
            + " <span class='wb-input-error'></span></label>"
        )
    return "".join(out)


def sheet_page(live, token: str) -> str:
    """The live page of one worksheet (the state it has now; the script keeps it current)."""
    error = error_text(live.error) or ""
    title = live.name
    if live.sheet is not None:
        title = live.sheet.spec.title or live.name
    return (
        "<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'>"
        "<meta name='referrer' content='no-referrer'>"
        f"<title>{escape(title)} (live)</title><style>{PAGE_CSS}{CSS}</style>"
        f"<script src='/static/live.js?token={escape(token)}' defer></script></head>\n"
        f"<body data-token='{escape(token)}' data-sheet='{escape(live.path.name)}' "
        f"data-version='{live.version}'>"
        "<div id='wb-bar'>"
        f"<div id='wb-error'{'' if error else ' hidden'}>{escape(error)}</div>"
        f"<form id='wb-inputs'>{inputs_form(live.sheet)}</form>"
        "<button type='button' data-action='write-xlsx'>Write the workbook (xlsx)</button> "
        "<button type='button' data-action='write-pdf'>Print the report (PDF)</button> "
        "<button type='button' data-action='save-inputs'>Write the inputs to the file</button>"
        "<span id='wb-status'></span></div>\n"
        f"<main class='workbook-report' id='wb-report'>{live.html}</main>"
        "</body></html>\n"
    )


def folder_page(folder, files: list[str], token: str) -> str:
    """The list of a folder's worksheets, each a link to its live page."""
    items = "".join(
        f"<li><a href='/sheet/{escape(name)}?token={escape(token)}'>{escape(name)}</a></li>"
        for name in files
    )
    return (
        "<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'>"
        "<meta name='referrer' content='no-referrer'>"
        f"<title>{escape(str(folder))}</title><style>{PAGE_CSS}</style></head>\n"
        f"<body><main><h1>Worksheets in {escape(str(folder))}</h1>"
        f"<ul id='wb-sheets'>{items or '<li>(no .toml file here)</li>'}</ul></main></body></html>\n"
    )
