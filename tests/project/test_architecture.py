"""docs/architecture.md names every module of the package, and only modules that exist: a new
module is described where a newcomer looks for it."""

from __future__ import annotations

import re
import sys

from helpers.paths import ROOT

DOC = ROOT / "docs" / "architecture.md"
PACKAGE = ROOT / "workbook"


def _rows() -> list[tuple[str, str]]:
    """(first cell, the whole row) of each row of the table "What each module owns"."""
    text = DOC.read_text(encoding="utf-8")
    section = text.split("## What each module owns", 1)[1].split("\n## ", 1)[0]
    rows = [line for line in section.splitlines() if line.startswith("| `")]
    return [(row.split("|")[1], row) for row in rows]


def _named(cell: str) -> set[str]:
    return set(re.findall(r"`([\w/]+(?:\.py|/))`", cell))


def modules() -> list[str]:
    """Every module of the package as a path under workbook/ ("engine/sheet.py",
    "numerics/roots.py"); a subpackage as its folder ("numerics/")."""
    out = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).as_posix()
        if rel == "__init__.py":
            continue
        out.append(rel[: -len("__init__.py")] if path.name == "__init__.py" else rel)
    return out


def _documented(anywhere: bool = True) -> set[str]:
    """The modules the table names: a module of the package in a row (with ``anywhere``
    False: in a row's first cell), a module of a subpackage as ``name.py`` in the row of
    ``pkg/``."""
    out: set[str] = set()
    for first, row in _rows():
        heads = _named(first)
        out |= heads | ({n for n in _named(row) if "/" not in n} if anywhere else set())
        for pkg in (h for h in heads if h.endswith("/")):
            out |= {pkg + n for n in _named(row) if "/" not in n}
    return out


def test_every_module_is_named_in_the_architecture():
    missing = [m for m in modules() if m not in _documented()]
    assert not missing, f"docs/architecture.md does not name: {', '.join(missing)}"


def test_the_architecture_names_no_module_that_does_not_exist():
    existing = set(modules())
    stale = sorted(m for m in _documented(anywhere=False) if m not in existing)
    assert not stale, f"docs/architecture.md names modules that do not exist: {', '.join(stale)}"


def test_a_new_module_is_missed(tmp_path, monkeypatch):
    """The check sees a module the table does not name (it does not pass by accident)."""
    before = {m for m in modules() if m not in _documented()}
    fake = tmp_path / "workbook"
    for m in modules():
        target = fake / (m + "__init__.py" if m.endswith("/") else m)
        target.parent.mkdir(parents=True, exist_ok=True)
        target.touch()
    (fake / "__init__.py").touch()
    (fake / "numerics" / "brand_new.py").touch()
    monkeypatch.setattr(sys.modules[__name__], "PACKAGE", fake)
    missing = {m for m in modules() if m not in _documented()}
    assert missing - before == {"numerics/brand_new.py"}


def test_the_names_it_gives_exist():
    """Every ``workbook.module.name`` the document gives is a module or an attribute of one
    (``Sheet.evaluate``, ``Evaluator.sharing()``: the attribute of a class too)."""
    import importlib

    text = DOC.read_text(encoding="utf-8")
    dotted = set(re.findall(r"\bworkbook(?:\.[A-Za-z_]\w*)+", text))
    assert len(dotted) > 5
    wrong = []
    for name in sorted(dotted):
        parts = name.split(".")
        for cut in range(len(parts), 0, -1):  # the longest prefix that is a module
            try:
                obj = importlib.import_module(".".join(parts[:cut]))
            except ModuleNotFoundError:
                continue
            break
        for attr in parts[cut:]:
            if not hasattr(obj, attr):
                wrong.append(name)
                break
            obj = getattr(obj, attr)
    assert not wrong, f"docs/architecture.md names what the code does not have: {wrong}"


def test_the_load_walk_counts_moves_and_climbs_back_up():
    # scripts/load_walk.py measures how often loading calls back into a module below on the
    # stack; a declared check calling the Sheet is one such climb in concave-cam
    sys.path.insert(0, str(ROOT / "scripts"))
    try:
        import load_walk
    finally:
        sys.path.pop(0)
    import workbook

    workbook.load("concave-cam")
    found = load_walk.walk(lambda: workbook.load("concave-cam"))
    assert {
        "workbook.engine.sheet",
        "workbook.language.typecheck",
        "workbook.language.template",
    } <= found.rooms
    assert found.climbs <= found.moves
    assert found.climbs_by_pair().get(("workbook.language.checkspec", "workbook.engine.sheet")) == 1


# the stage folders of the tests, as README.md lists them
TEST_FOLDERS = {
    "language", "numerics", "compute", "outputs", "importers", "live", "hardening", "scenes",
    "project",
}  # fmt: skip


def test_every_test_module_is_in_a_stage_folder_and_imports_no_other():
    tests = ROOT / "tests"
    found = sorted(tests.rglob("test_*.py"))
    assert found, "no test module found"
    stray = [p.relative_to(tests).as_posix() for p in found if p.parent.name not in TEST_FOLDERS]
    assert stray == [], f"test modules outside the stage folders {sorted(TEST_FOLDERS)}"
    importing = []
    for path in found:
        for line in path.read_text(encoding="utf-8").splitlines():
            if re.match(r"\s*(from|import)\s+(test_\w+|conftest)\b", line):
                importing.append(f"{path.name}: {line.strip()}")
    assert importing == [], "a test module imports another (shared code goes to tests/helpers)"
    loose = sorted(p.name for p in tests.glob("*.py") if p.name != "conftest.py")
    assert loose == [], "shared test code lives in tests/helpers, not at the tests root"
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert all(f"`{name}/`" in readme for name in TEST_FOLDERS), "README lists the test folders"
