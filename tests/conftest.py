import sys
from pathlib import Path

import pytest

TESTS = Path(__file__).parent
DATA = TESTS / "data"
sys.path.insert(0, str(TESTS))


@pytest.fixture(scope="session")
def concave():
    import workbook

    return workbook.load("concave-cam")


# The smallest sheet with an input, an argument and a function: tests add tables and charts.
SINE = """
[inputs]
R = "10 mm"

[arguments]
phi = { unit = "deg" }

[definitions]
"y(phi)" = "R*sin(phi)"
"""

SINE_TABLE = (
    SINE
    + """
[[tables]]
name = "t"
range = "phi := 0, 10 .. 90"
columns = { y = "mm" }
"""
)


def write_template(tmp_path: Path, text: str, name: str = "t.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path
