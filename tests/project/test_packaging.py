"""The package list of pyproject.toml names every subpackage (a plain install needs them)."""

from helpers.paths import ROOT

try:
    import tomllib
except ImportError:  # Python 3.10
    import tomli as tomllib


def test_every_subpackage_is_installed():
    listed = set(
        tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["setuptools"][
            "packages"
        ]
    )
    found = {
        ".".join(init.parent.relative_to(ROOT).parts)
        for init in (ROOT / "workbook").rglob("__init__.py")
    }
    assert found - listed == set()
