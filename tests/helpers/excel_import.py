"""Import a workbook a test wrote and check the translation, as a user would."""

from __future__ import annotations

import json
from pathlib import Path

from workbook.cli import main


def import_book(path: Path) -> Path:
    """``workbook import PATH --out FOLDER/out`` (exit 0 asserted): the translated worksheet."""
    out = path.parent / "out"
    assert main(["import", str(path), "--out", str(out)]) == 0
    return out / (path.stem + ".toml")


def import_and_check(path, tmp_path, capsys) -> tuple[dict, str]:
    """``workbook import PATH`` (exit 0 asserted), then ``workbook check --json`` of the
    translation: its JSON report and the translated worksheet's text."""
    out = tmp_path / "out"
    assert main(["import", str(path), "--out", str(out)]) == 0
    toml = next(out.glob("*.toml"))
    capsys.readouterr()
    main(["check", str(toml), "--json"])
    return json.loads(capsys.readouterr().out), toml.read_text(encoding="utf-8")


COUNTS = ("printed", "reproduced", "failed", "not_computable")


def check_counts(toml, capsys) -> tuple[int, dict]:
    """``workbook check TOML --json``: its exit status and its four counts."""
    capsys.readouterr()
    status = main(["check", str(toml), "--json"])
    report = json.loads(capsys.readouterr().out)
    return status, {k: report[k] for k in COUNTS}
