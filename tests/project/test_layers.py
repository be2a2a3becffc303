"""The layer contracts of pyproject.toml ([tool.importlinter]), run by import-linter: the
renderers (xlsx, report, notebook, the CSV and sweep writers) read the computed sheet and
import no typer, evaluator, numerics, programs, Sheet or Excel printer; the Excel printer and
the live check import no typer or evaluator; the compute stage and the Excel form import no
Sheet (the Sheet builds on them); EXPR's mpmath form does not import the reference built on
it. tests/compute/test_computed.py counts the calls. And no import cycle among the package's
modules (read by grimp, imports inside functions included)."""

from pathlib import Path

import pytest
from helpers.paths import ROOT


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
source_modules = ["workbook.compute.excelform"]
forbidden_modules = ["workbook.compute.excel"]
allow_indirect_imports = true
""",
        encoding="utf-8",
    )
    assert _lint(config) == 1


# -- no import cycle among the package's modules ------------------------------------------------
#: Cycles allowed, each as the set of modules it goes through: a strongly connected component
#: of the import graph is allowed when its modules are all in one of these sets. None is.
ALLOWED_CYCLES: tuple[frozenset[str], ...] = ()


def _graph(package: str):
    """The import graph of ``package``'s own modules, imports inside functions included
    (imports under ``if TYPE_CHECKING`` are left out: annotations only, never run)."""
    import grimp

    return grimp.build_graph(
        package, include_external_packages=False, exclude_type_checking_imports=True, cache_dir=None
    )


def _strongly_connected(graph) -> list[list[str]]:
    """The components of more than one module in which every module imports every other one,
    directly or not (Tarjan's algorithm, iterative)."""
    imports = {m: sorted(graph.find_modules_directly_imported_by(m)) for m in graph.modules}
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []
    for root in sorted(imports):
        if root in index:
            continue
        work = [(root, iter(imports[root]))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            module, following = work[-1]
            for nxt in following:
                if nxt not in index:
                    index[nxt] = low[nxt] = len(index)
                    stack.append(nxt)
                    on_stack.add(nxt)
                    work.append((nxt, iter(imports[nxt])))
                    break
                if nxt in on_stack:
                    low[module] = min(low[module], index[nxt])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[module])
                if low[module] == index[module]:
                    component = []
                    while True:
                        m = stack.pop()
                        on_stack.discard(m)
                        component.append(m)
                        if m == module:
                            break
                    if len(component) > 1:
                        found.append(sorted(component))
    return found


def _cycle_text(graph, component: list[str]) -> str:
    """One cycle through the component's first module, each import with its line:
    'a -> b (a:12 from .b import x) -> a (b:40 from .a import y)'."""
    first = component[0]
    inside = [m for m in graph.find_modules_directly_imported_by(first) if m in component]
    chain = [first, *graph.find_shortest_chain(importer=sorted(inside)[0], imported=first)]
    steps = [first]
    for a, b in zip(chain, chain[1:]):
        detail = graph.get_import_details(importer=a, imported=b)
        where = f" ({a}:{detail[0]['line_number']} {detail[0]['line_contents']})" if detail else ""
        steps.append(f"{b}{where}")
    return " -> ".join(steps)


def _cycles(package: str, allowed=()) -> list[str]:
    graph = _graph(package)
    return [
        _cycle_text(graph, c)
        for c in _strongly_connected(graph)
        if not any(set(c) <= a for a in allowed)
    ]


def test_the_package_has_no_import_cycle():
    """No module imports one that imports it back, directly or through others, even inside a
    function: a module below does not reach up (it is passed what it needs, or the shared
    piece lives in the lower module)."""
    pytest.importorskip("grimp")
    cycles = _cycles("workbook", ALLOWED_CYCLES)
    assert not cycles, "import cycles:\n" + "\n".join(cycles)


def test_an_import_cycle_is_reported(tmp_path, monkeypatch):
    """A cycle closed by an import inside a function is found and listed (the check above
    does not pass by accident); an allowed one is not."""
    pytest.importorskip("grimp")
    package = tmp_path / "cycled"
    package.mkdir()
    (package / "__init__.py").write_text("", encoding="utf-8")
    (package / "low.py").write_text(
        "def f():\n    from .high import g\n\n    return g\n", encoding="utf-8"
    )
    (package / "high.py").write_text("from .low import f\n\ng = f\n", encoding="utf-8")
    (package / "alone.py").write_text("from .low import f\n", encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path))
    (found,) = _cycles("cycled")
    assert found == (
        "cycled.high -> cycled.low (cycled.high:1 from .low import f)"
        " -> cycled.high (cycled.low:2 from .high import g)"
    )
    assert _cycles("cycled", (frozenset({"cycled.high", "cycled.low"}),)) == []
