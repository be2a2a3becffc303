"""Where the installed data are: the templates and the unit definitions."""

from __future__ import annotations

from pathlib import Path


def data_dir(folder: str) -> Path:
    """The installed data folder ('templates' or 'units'), or the source tree's."""
    from importlib import resources

    package = {"templates": "workbook.templates", "units": "workbook.unitdefs"}[folder]
    try:
        return Path(str(resources.files(package)))
    except ModuleNotFoundError:  # running from a source checkout without installing
        return Path(__file__).resolve().parent.parent / folder


def list_templates() -> dict[str, Path]:
    """Installed templates: name -> path."""
    out = {}
    for entry in data_dir("templates").iterdir():
        if entry.name.endswith(".toml"):
            out[entry.name[: -len(".toml")]] = Path(str(entry))
    return dict(sorted(out.items()))
