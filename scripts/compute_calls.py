"""Calls of the typer and of the expression parser made after a worksheet is loaded, while it
is computed and written.

    python scripts/compute_calls.py                 # every template and tests/data sheet
    python scripts/compute_calls.py concave-cam tests/data/arrays.toml

Each sheet is loaded, then counted (cProfile) while ``compute(sheet, excel=True)`` computes it
and its workbook is written, and while ``compute(sheet)`` computes it again for the report and
the report's HTML is rendered (what ``workbook run`` and ``workbook report`` do after the load).
The typer is every function of ``workbook/language/typecheck.py`` and of its bases
(``typearrays.py``, ``unitrules.py``): after the load the compute stage reads the typed
definitions (``workbook.language.typeddefs.TypedDefinitions``), which ask the typer only for a
tree not typed yet, so "typer" counts every call of the typer's code (0: every read found its
tree); "typing" counts the calls that type a tree (``Typer.expression``, a ``visit_`` method,
a conversion, a definition's body). A parse is a call of
``workbook.language.expr.parse``; a printed-value file read, of ``printed.read_printed``.
"""

from __future__ import annotations

import cProfile
import pstats
import sys
import tempfile
import warnings
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the checkout's package, run as a script or from the tests

import workbook  # noqa: E402

#: the typer and its bases: a call of any of their functions is a call of the typer
TYPER = (
    "workbook/language/typecheck.py",
    "workbook/language/typearrays.py",
    "workbook/language/unitrules.py",
)
PARSE = ("workbook/language/expr.py", "parse")
PRINTED = ("workbook/language/printed.py", "read_printed")
#: the functions shown by name in the table (the others of the typer are summed in "typer")
SHOWN = ("typecheck.expression", "typecheck.scalar", "typecheck.function")
#: the typer's functions that type a tree (the others return trees typed before, or answer
#: questions about units and names): "typing" counts these and every visit_ method
#: (a failure remembered is raised again without typing: Typer.specialized is not counted)
TYPING = ("expression", "typed_body", "convert", "plain", "program_body")


def sheets() -> list[str]:
    """Every template by name and every sheet of tests/data by path."""
    data = sorted(str(p.relative_to(ROOT)) for p in (ROOT / "tests" / "data").glob("*.toml"))
    return sorted(workbook.list_templates()) + data


def counted(run) -> Counter:
    """Calls ``run()`` makes into the typer, the parser and the printed-value reader."""
    profile = cProfile.Profile()
    profile.enable()
    try:
        run()
    finally:
        profile.disable()
    out: Counter = Counter()
    for (file, _, function), (_, calls, *_) in pstats.Stats(profile).stats.items():
        path = file.replace("\\", "/")
        if any(path.endswith("/" + m) for m in TYPER):
            out["typer"] += calls
            out[f"{Path(path).stem}.{function}"] += calls
            if function in TYPING or function.startswith("visit_"):
                out["typing"] += calls
        elif path.endswith("/" + PARSE[0]) and function == PARSE[1]:
            out["parse"] += calls
        elif path.endswith("/" + PRINTED[0]) and function == PRINTED[1]:
            out["printed"] += calls
    return out


def compute_and_write(sheet, folder: Path) -> None:
    """What the command line does after the load: the workbook, then the report."""
    from workbook.compute.computed import compute
    from workbook.outputs.report import render
    from workbook.outputs.xlsx import write_workbook

    write_workbook(compute(sheet, excel=True), folder / f"{sheet.name}.xlsx", force=True)
    render(compute(sheet))


def calls(name: str) -> Counter:
    """The calls of computing and writing sheet ``name`` (a template's name or a path), after
    its load."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sheet = workbook.load(ROOT / name if name.endswith(".toml") else name)
        with tempfile.TemporaryDirectory() as folder:
            return counted(lambda: compute_and_write(sheet, Path(folder)))


def main(names: list[str]) -> None:
    heads = ["sheet", "typer", "typing", *(s.split(".")[1] for s in SHOWN), "parse", "printed"]
    print(" | ".join(heads))
    for name in names or sheets():
        found = calls(name)
        row = [name, found["typer"], found["typing"], *(found[s] for s in SHOWN), found["parse"]]
        print(" | ".join(str(v) for v in [*row, found["printed"]]))


if __name__ == "__main__":
    main(sys.argv[1:])
