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

__all__ = [
    "load",
    "loads",
    "list_templates",
    "template_path",
    "Sheet",
    "WorkbookError",
    "__version__",
]


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
        from .language.fields import nearest

        hint = nearest(text, found)
        if Path(text + ".toml").is_file():
            hint = f" (a file {text}.toml is here: write ./{text}.toml)"
        raise TemplateError(f"no template named '{text}'{hint} (installed: {', '.join(found)})")
    return found[text]


def load(name_or_path: str | Path, parts=None):
    """Load a template by name or path and check its units; returns a :class:`Sheet`.

    ``parts`` chooses the template's optional parts to compute and write: None (only what is
    in no part), a part name, several names, or ``"all"``."""
    from .facade import Sheet
    from .language.template import load_spec

    path = template_path(name_or_path)
    return Sheet(load_spec(path), parts=parts)


def loads(text: str, name: str = "sheet", folder: str | Path = ".", parts=None):
    """A :class:`Sheet` from template text (TOML), its units checked, as :func:`load` gives
    from a file. Messages name ``FOLDER/NAME.toml`` (no file is read or written), and files
    the text names ([data] CSV) are read from ``folder``."""
    from .errors import LimitError
    from .facade import Sheet
    from .language.template import MAX_TEMPLATE_BYTES, parse_spec

    if len(text.encode("utf-8")) > MAX_TEMPLATE_BYTES:
        raise LimitError(f"template text is larger than {MAX_TEMPLATE_BYTES:,} bytes")
    return Sheet(parse_spec(text, Path(folder) / f"{name}.toml", name), parts=parts)


def __getattr__(name):
    if name == "Sheet":
        from .facade import Sheet

        return Sheet
    raise AttributeError(name)
