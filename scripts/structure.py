"""What the house rules on structure count, read from the source (ast, nothing imported):
functions over 100 lines, private names used across modules (``from X import _y`` and
``X._y`` where X is an imported module, tests included) and modules over 1,000 lines.

    python scripts/structure.py [FOLDER ...]     (default: workbook tests scripts benchmarks)

Prints one line per finding and the counts; exits 0 (it measures, it does not judge).
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MAX_FUNCTION_LINES = 100
MAX_MODULE_LINES = 1000
#: The project's own top-level modules and packages (a private name of a third-party package
#: is that package's affair).
OWN = ("workbook", "tests", "helpers", "conftest", "test_", "scripts")


def module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[0] == "tests":  # the tests import one another by file name (tests/ on sys.path)
        parts = parts[1:]
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _imported(path: Path, node: ast.ImportFrom) -> str:
    if node.level == 0:
        return node.module or ""
    base = module_name(path).split(".")
    if path.name != "__init__.py":
        base = base[:-1]
    base = base[: len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def _private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def _own(module: str) -> bool:
    return module.startswith(OWN)


def private_uses(path: Path, tree: ast.AST) -> list[str]:
    """``from X import _y`` and ``m._y`` (m a module imported here) in one file."""
    found, modules = [], {}
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            source = _imported(path, node)
            for alias in node.names:
                if _private(alias.name) and _own(source):
                    found.append(f"{node.lineno}: from {source} import {alias.name}")
                else:
                    modules[alias.asname or alias.name] = f"{source}.{alias.name}"
        elif isinstance(node, ast.Import):
            for alias in node.names:
                modules[alias.asname or alias.name.split(".")[0]] = alias.name
    for node in ast.walk(tree):
        if (
            isinstance(node, ast.Attribute)
            and _private(node.attr)
            and isinstance(node.value, ast.Name)
            and _own(modules.get(node.value.id, "-"))
        ):
            found.append(f"{node.lineno}: {node.value.id}.{node.attr} ({modules[node.value.id]})")
    return sorted(set(found), key=lambda f: int(f.split(":")[0]))


def long_functions(tree: ast.AST) -> list[str]:
    """Functions (methods and nested functions included) over MAX_FUNCTION_LINES lines."""
    return [
        f"{n.lineno}: {n.name} ({n.end_lineno - n.lineno + 1} lines)"
        for n in ast.walk(tree)
        if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))
        and n.end_lineno - n.lineno + 1 > MAX_FUNCTION_LINES
    ]


def main(folders: list[str]) -> int:
    counts = {"functions": 0, "private": 0, "modules": 0}
    for folder in folders:
        for path in sorted((ROOT / folder).rglob("*.py")):
            text = path.read_text(encoding="utf-8")
            tree = ast.parse(text)
            rel = path.relative_to(ROOT)
            lines = text.count("\n")
            if lines > MAX_MODULE_LINES and folder == "workbook":
                print(f"module     {rel} ({lines} lines)")
                counts["modules"] += 1
            for item in long_functions(tree):
                print(f"function   {rel}:{item}")
                counts["functions"] += 1
            for item in private_uses(path, tree):
                print(f"private    {rel}:{item}")
                counts["private"] += 1
    print(
        f"{counts['functions']} functions over {MAX_FUNCTION_LINES} lines, "
        f"{counts['private']} private names used across modules, "
        f"{counts['modules']} modules of the package over {MAX_MODULE_LINES} lines"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:] or ["workbook", "tests", "scripts", "benchmarks"]))
