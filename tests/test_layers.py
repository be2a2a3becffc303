"""The layer contracts of pyproject.toml ([tool.importlinter]), run by import-linter: the
renderers (xlsx, report, notebook, the CSV and sweep writers) read the computed sheet and
import no typer, evaluator, numerics, programs, Sheet or Excel printer; the Excel printer and
the live check import no typer or evaluator. tests/test_computed.py counts the calls."""

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def _lint(config: Path) -> int:
    from importlinter.cli import lint_imports

    return lint_imports(config_filename=str(config), no_cache=True)


def test_the_renderers_keep_the_layer_contract():
    pytest.importorskip("importlinter")
    assert _lint(ROOT / "pyproject.toml") == 0


def test_a_broken_contract_is_reported(tmp_path):
    """The same kind of contract on an import that exists (the Excel form imports the
    printer) is reported broken: the contract above is not kept by accident."""
    pytest.importorskip("importlinter")
    config = tmp_path / "contract.toml"
    config.write_text(
        """
[tool.importlinter]
root_package = "workbook"
exclude_type_checking_imports = true

[[tool.importlinter.contracts]]
name = "the Excel form does not import the printer"
type = "forbidden"
source_modules = ["workbook.excelform"]
forbidden_modules = ["workbook.excel"]
allow_indirect_imports = true
""",
        encoding="utf-8",
    )
    assert _lint(config) == 1
