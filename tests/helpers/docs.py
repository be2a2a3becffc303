"""The built-ins docs/language.md documents."""

from __future__ import annotations

import re
from pathlib import Path

DOC = Path(__file__).resolve().parents[2] / "docs" / "language.md"


def documented(text: str) -> list[str]:
    """The built-ins the reference lists (its line "Built-in functions: `...`")."""
    return re.search(r"Built-in functions: `([^`]*)`", text).group(1).split()
