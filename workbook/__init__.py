"""workbook: unit-checked worksheets that write live Excel workbooks.

>>> import workbook
>>> sheet = workbook.load("concave-cam")
>>> sheet.evaluate("h1", phi=[0, 5])          # doctest: +SKIP
"""

from __future__ import annotations

from pathlib import Path

from .data import list_templates
from .errors import WorkbookError
from .version import __version__

__all__ = ["load", "list_templates", "template_path", "Sheet", "WorkbookError", "__version__"]


def template_path(name_or_path: str | Path) -> Path:
    """Resolve a template name (``concave-cam``) or a path to a .toml file."""
    from .errors import TemplateError

    text = str(name_or_path)
    if text.endswith(".toml") or "/" in text or "\\" in text:
        path = Path(text)
        if not path.is_file():
            raise TemplateError(f"no template file {text}")
        return path
    found = list_templates()
    if text not in found:
        from .fields import nearest

        hint = nearest(text, found)
        if Path(text + ".toml").is_file():
            hint = f" (a file {text}.toml is here: write ./{text}.toml)"
        raise TemplateError(f"no template named '{text}'{hint} (installed: {', '.join(found)})")
    return found[text]


def load(name_or_path: str | Path, parts=None):
    """Load a template by name or path and check its units; returns a :class:`Sheet`.

    ``parts`` chooses the template's optional parts to compute and write: None (only what is
    in no part), a part name, several names, or ``"all"``."""
    from .sheet import Sheet
    from .template import load_spec

    path = template_path(name_or_path)
    return Sheet(load_spec(path), parts=parts)


def __getattr__(name):
    if name == "Sheet":
        from .sheet import Sheet

        return Sheet
    raise AttributeError(name)
