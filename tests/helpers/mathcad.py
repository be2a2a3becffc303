"""Mathcad worksheets for the importer's tests beside tests/helpers/mathcad_xml.py: a region of any
body, a worksheet without settings, Prime's identifiers, and the check's JSON."""

from __future__ import annotations

import json
from pathlib import Path

from helpers.mathcad_xml import ML
from workbook.cli import main


def region(rid: int, body: str) -> str:
    """A definition region holding ``body`` as it is."""
    return (
        f'<region region-id="{rid}" left="0" top="{rid * 20}" align-y="{rid * 20}">'
        f'<math><ml:define xmlns:ml="{ML}">{body}</ml:define></math></region>'
    )


def bare_worksheet(*regions: str) -> str:
    """A Mathcad 15 worksheet of ``regions``, without its settings."""
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n<worksheet '
        'xmlns="http://schemas.mathsoft.com/worksheet30" '
        f'xmlns:ml="{ML}"><regions>{"".join(regions)}</regions></worksheet>'
    )


def check_json(toml: Path, capsys) -> dict:
    """``workbook check TOML --json``, its JSON."""
    capsys.readouterr()
    main(["check", str(toml), "--json"])
    return json.loads(capsys.readouterr().out)


def prime_ident(name: str, label: str = "VARIABLE") -> str:
    """An identifier as Mathcad Prime writes it, with its label."""
    return f'<ml:id labels="{label}">{name}</ml:id>'
