"""Import a workbook a test wrote and check the translation, as a user would."""

from __future__ import annotations

import json

from workbook.cli import main


def import_and_check(path, tmp_path, capsys) -> tuple[dict, str]:
    """``workbook import PATH`` (exit 0 asserted), then ``workbook check --json`` of the
    translation: its JSON report and the translated worksheet's text."""
    out = tmp_path / "out"
    assert main(["import", str(path), "--out", str(out)]) == 0
    toml = next(out.glob("*.toml"))
    capsys.readouterr()
    main(["check", str(toml), "--json"])
    return json.loads(capsys.readouterr().out), toml.read_text(encoding="utf-8")
