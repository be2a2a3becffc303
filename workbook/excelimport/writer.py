"""Writing the translation: NAME.toml (by tomli-w) and NAME.excel.csv, Excel's cached values
as printed values. Definitions the engine refuses at load are listed and left out."""

from __future__ import annotations

import csv
import io
import re
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import WorkbookError
from ..language.csvcells import csv_text as spreadsheet_text
from ..language.csvcells import unescaped
from ..language.spec import SheetSpec
from ..mathcad.writer import ABS_TOLERANCE, REL_TOLERANCE
from ..mathcad.writer import write as write_files
from .book import Definition, Translation
from .runs import ROW

MAX_LOAD_ROUNDS = 60  # loads of the worksheet while refused definitions are left out


@dataclass
class ImportResult:
    """What an import wrote: the worksheet, its files, counts and what was not translated."""

    toml: Path
    files: list[Path]
    definitions: int
    functions: int
    printed: int
    not_translated: list[tuple[str, str]] = field(default_factory=list)
    cells: dict[str, tuple[str, float | None]] = field(default_factory=dict)  # ref -> printed row

    def line(self) -> str:
        extra = (
            f"; {len(self.not_translated)} listed as not translated" if self.not_translated else ""
        )
        return (
            f"wrote {self.toml} ({self.definitions} inputs and definitions, {self.functions} VBA "
            f"functions, {self.printed} of Excel's cached values as printed values{extra})"
        )


def _comment(text: str, width: int = 96) -> list[str]:
    """TOML comment lines of at most ``width`` characters."""
    import textwrap

    return ["# " + line for line in textwrap.wrap(text, width - 2) or [""]]


def _sheet_name(path: Path) -> str:
    name = re.sub(r"[^A-Za-z0-9_-]+", "-", path.stem).strip("-").lower()
    return name or "imported"


def csv_text(text: str) -> str:
    """A text from the imported file as a CSV cell that no spreadsheet reads as a formula
    (``=cmd|' /C calc'!A0`` is written ``'=cmd|' /C calc'!A0``: the rule of
    ``language.csvcells.csv_text``), on one line."""
    return spreadsheet_text(text.replace("\r", " ").replace("\n", " "))


def uncompared(text: str) -> str | None:
    """Why a cached text is not compared (None: it is): one that spans lines (written on one
    line), one that the CSV's escape does not give back (an apostrophe before = + - @, which
    the reader of printed values takes for the escape), or one that the printed values would
    read as a number. A text escaped for spreadsheets (``'=x``, ``' + F``) is read back
    without its apostrophe, so it is compared."""
    if "\n" in text or "\r" in text:
        return "a text over several lines: written on one line, not compared"
    if unescaped(spreadsheet_text(text)) != text:
        return "a text with an apostrophe the CSV's escape would take for its own: not compared"
    try:
        float(text)
    except ValueError:
        return None
    return "a text that reads as a number: not compared"


def _own_formula(tr: Translation, ref: str, text: str) -> bool:
    """Whether the cached text of the formula cell ``ref`` is its own formula (``=A1*2``): a
    workbook saved before Excel computed the cell, whose value is no result to compare."""
    from openpyxl.utils.cell import column_index_from_string, coordinate_from_string

    sheet, _, address = ref.rpartition("!")
    letters, row = coordinate_from_string(address)
    cell = tr.book.cell(sheet, row, column_index_from_string(letters))
    return cell is not None and cell.formula is not None and text.strip() == "=" + cell.formula


def _cached(value) -> tuple[str, str] | None:
    """(kind, CSV text) of a cached value: a number, a text, an error; None if empty.
    TRUE and FALSE are the numbers 1 and 0, as a comparison gives them."""
    if isinstance(value, bool):
        return ("number", "1.0" if value else "0.0")
    if value is None:
        return None
    if isinstance(value, (int, float)):
        return ("number", repr(float(value)))
    if isinstance(value, str):
        if value.startswith("#") and value.upper().rstrip("!?") in (
            "#DIV/0", "#N/A", "#NAME", "#NULL", "#NUM", "#REF", "#VALUE", "#GETTING_DATA",
        ):  # fmt: skip
            return ("error", value)
        if not value.strip():
            return None
        return ("text", value)
    return None


def render(tr: Translation, skip: dict[str, str]) -> tuple[str, str, dict]:
    """(TOML text, CSV text, counts) of the translation without the names in ``skip``."""
    import tomli_w

    name = _sheet_name(tr.path)
    doc: dict = {
        "sheet": {
            "name": name,
            "title": f"Imported from the Excel workbook {tr.path.name}",
            "source": f"Excel workbook {tr.path.name}",
            "origin": 0,
        }
    }
    inputs = {
        n: {"value": v, "note": note} for n, (_, v, note) in tr.inputs.items() if n not in skip
    }
    arguments: dict = {}
    definitions: dict = {}
    for n, (cell, text) in tr.texts.items():
        if n not in skip:
            definitions[n] = {
                "expr": f'"{text}"',
                "note": f"{cell.ref} (text)",
            }
    _vba_functions(tr, skip, arguments, definitions)
    rows = []
    run_rows: list = []
    tables: dict = {}
    elements: list = []
    for vname, text in tr.vectors.items():
        if vname not in skip:
            definitions[vname] = {
                "expr": text,
                "note": "a column of numbers a filled-down formula reads",
            }
    for d in tr.definitions:
        if d.problem or d.name in skip:
            continue
        cached = _cached(d.cell.value)
        note = f"{d.cell.ref}: ={d.cell.formula}"[:300]
        if d.element is not None:
            if d.element[0] in skip:
                continue
            elements.append((d, cached))
            continue
        if d.run is not None:  # a filled-down column: a function of the row
            run = d.run
            definitions[f"{d.name}({ROW})"] = {
                "expr": d.text,
                "note": f"{run.count} cells filled down from {note}",
            }
            arguments[ROW] = {"unit": "", "note": "the row of a filled-down column, from 0"}
            span = (d.cell.sheet, run.first, run.count)
            if span not in tables:  # the filled-down columns of the same rows: one table
                tables[span] = {
                    "name": f"table_{d.name}",
                    "title": f"{d.cell.sheet}: rows {run.first} to {run.last}, filled down",
                    "range": f"{ROW} := 0 .. {run.count - 1}",
                    "columns": [],
                }
            tables[span]["columns"].append({"expr": d.name, "title": d.name})
            for k, key in enumerate(run.keys()):
                cell = tr.book.cell(*key)
                cached = _cached(cell.value) if cell is not None else None
                if cached is not None:
                    run_rows.append((d.name, str(k), cached, cell.ref))
            continue
        definitions[d.name] = {"expr": d.text, "note": note}
        if d.block is not None:  # the first cell of an array formula: its element 0
            elements.append((Definition(d.name, d.cell, element=(d.name, 0)), cached))
        elif cached is not None:
            rows.append((d.name, "", cached, d.cell.ref))
    exprs = " ".join(v["expr"] for v in definitions.values() if "expr" in v)
    used = set(_WORD.findall(exprs))
    for text, rname in tr.ranges.items():
        if rname not in skip and rname in used:
            definitions[rname] = {"expr": text, "note": "the cells of a range that formulas read"}
    at_rows = _array_elements(tr, elements, arguments, definitions)
    if inputs:
        doc["inputs"] = inputs
    if arguments:
        doc["arguments"] = arguments
    if definitions:
        doc["definitions"] = definitions
    if tables:
        doc["tables"] = list(tables.values())
    files, printed, counts = _printed_files(tr, name, skip, rows, at_rows, run_rows)
    if printed:
        doc["printed"] = printed
    toml = "\n".join(_head(tr, skip)) + "\n\n" + tomli_w.dumps(doc, multiline_strings=True)
    return toml, files, counts


def _vba_functions(tr: Translation, skip: dict, arguments: dict, definitions: dict) -> None:
    """Each translated VBA Function as a program definition, its parameters as arguments."""
    for info in tr.functions.values():
        if info.problem or info.final in skip:
            continue
        params = list(info.params) + list(info.given.values())
        for p in params:
            arguments.setdefault(p, {"unit": ""})
        key = f"{info.final}({', '.join(params)})" if params else info.final
        if info.refs:
            from .vbarefs import refs_name, refs_program

            changed = ", ".join(info.proc.params[k].name for k in info.refs)
            definitions[f"{refs_name(info)}({', '.join(params)})"] = {
                "program": refs_program(info) + "\n",
                "note": f"VBA Function {info.proc.name} (module {info.proc.module}), with the "
                f"parameters it changes by reference: [its value, {changed}]",
            }
        definitions[key] = {
            "program": info.program + "\n",
            "note": f"VBA Function {info.proc.name} (module {info.proc.module})"
            + (
                f"; left out, without effect on its value: {', '.join(sorted(info.dropped))}"
                if info.dropped
                else ""
            ),
        }


def _array_elements(tr: Translation, elements, arguments: dict, definitions: dict) -> list:
    """The cells of array formulas: the function NAME_at(k) gives element k of NAME; the
    printed rows of the cells' cached values."""
    at_rows = []
    made = set()
    masters = {d.name: d for d in tr.definitions}
    for d, cached in elements:
        fn = f"{d.element[0]}_at"
        if fn not in made:
            made.add(fn)
            master = masters[d.element[0]]
            n_rows, cols = master.block or (1, 1)
            x = d.element[0]
            element = f"{x}[floor(k_at/{cols}), mod(k_at, {cols})]"
            if n_rows == 1 and not master.cell.formula.upper().startswith("MMULT("):
                # a row of cells shows a VBA function's array: a vector (a 1-D array) or
                # a matrix of one row (a 2-D array), known when it runs
                element = f"({x}[k_at] if cols({x}) == 1 otherwise {x}[0, k_at])"
            definitions[f"{fn}(k_at)"] = {
                "expr": element,
                "note": f"the cells of the array formula {d.element[0]}, one by one",
            }
            arguments["k_at"] = {"unit": "", "note": "the position of a cell in its array formula"}
        if cached is not None:
            at_rows.append((fn, str(d.element[1]), cached, d.cell.ref))
    return at_rows


def _head(tr: Translation, skip: dict) -> list[str]:
    """The comment lines that open the worksheet: what it holds, whether Excel's cached
    values may be stale, and what was not translated."""
    head = [
        f"# Imported from {tr.path.name} by `workbook import`: inputs from the constant cells",
        "# that formulas read, definitions from formula cells, functions from VBA Functions,",
        "# and Excel's cached values as printed values (`workbook check` compares them).",
        "# Excel has no units: the numbers are plain; a unit a label names is proposed in a note.",
    ]
    if tr.book.stale:
        head += _comment(
            "Excel saved this workbook before it finished calculating (calcCompleted=0, "
            "manual calculation): a cached value may be older than its inputs, so a value "
            "not reproduced is to be checked by hand."
        )
    listed = list(tr.listed) + [(k, v) for k, v in skip.items()]
    if listed:
        head.append("#")
        head.append(f"# Not translated ({len(listed)}; their cells count as not reproduced):")
        for what, why in listed[:400]:
            head += _comment(f"  {what}: {why}")
        if len(listed) > 400:
            head.append(f"#   ... and {len(listed) - 400} more")
    return head


def _printed_files(tr: Translation, name: str, skip: dict, rows, at_rows, run_rows):
    """(files {name: CSV text}, the [[printed]] entries, counts) of Excel's cached values: the
    translated cells by kind (cells, cells of array formulas, filled-down columns), the
    differences of nearly equal numbers by their size, and the cells not translated."""
    counts: dict = {"numbers": 0, "texts": 0, "errors": 0, "cells": {}}
    printed = []
    files = {}
    reasons: dict[str, str] = {}  # cell -> why its cached value is not compared
    memo: dict = {}
    groups = []
    for label, group, arg in (("", rows, None), (".at", at_rows, "k_at"), (".rows", run_rows, ROW)):
        plain, by_decade = _split_cancelling(tr, group, memo)
        groups.append((label, plain, arg, ABS_TOLERANCE, ""))
        for dec, part in sorted(by_decade.items()):
            groups.append(
                (
                    f"{label}.cancel-e{dec}",
                    part,
                    arg,
                    REL_TOLERANCE * 10.0**dec,
                    f", differences of numbers of up to 1e{dec} (compared to their tolerance)",
                )
            )
    for label, group, arg, tolerance, what in groups:
        if not group:
            continue
        out = io.StringIO()
        w = csv.writer(out, lineterminator="\n")
        out.write(
            "# Excel's cached values of the translated cells (imported by `workbook import`)\n"
        )
        w.writerow(["name", "argument", "value", "unit"])
        for n, at, (kind, text), ref in group:
            counts[kind + "s"] += 1
            if kind == "error":
                out.write(f"# {csv_text(ref)}: Excel shows {text} (an error value: not compared)\n")
                continue
            if kind == "text" and uncompared(text):
                reasons[ref] = uncompared(text)
                continue
            if kind == "text" and _own_formula(tr, ref, text):
                reasons[ref] = (
                    "Excel's cached value is the cell's own formula as a text (not computed): "
                    "not compared"
                )
                continue
            out.write(f"# {csv_text(ref)}\n")
            w.writerow([n, at, csv_text(text) if kind == "text" else text, ""])
            counts["cells"][ref] = (n, float(at) if at else None)
        fname = f"{name}.excel{label}.csv"
        files[fname] = out.getvalue()
        entry = {
            "file": fname,
            "title": "Excel's cached values"
            + {None: "", "k_at": " of the cells of array formulas", ROW: " of filled-down columns"}[
                arg
            ]
            + what,
            "rel_tolerance": REL_TOLERANCE,
            "tolerance": tolerance,
        }
        if arg:
            entry["argument"] = arg
        printed.append(entry)
    group = _not_translated_rows(tr, skip, counts, reasons)
    if group:
        fname = f"{name}.excel.not-translated.csv"
        files[fname] = group
        printed.append(
            {
                "file": fname,
                "title": "Excel's cached values of the formula cells not translated",
                "rel_tolerance": REL_TOLERANCE,
                "tolerance": ABS_TOLERANCE,
            }
        )
    return files, printed, counts


def _split_cancelling(tr: Translation, group: list, memo: dict) -> tuple[list, dict]:
    """The rows of ``group`` compared as they are, and {power of ten: rows} of the cells whose
    value is a difference of nearly equal numbers of that size (see cancellation.py)."""
    from .cancellation import decade

    plain, by_decade = [], {}
    for row in group:
        _, _, (kind, text), ref = row
        found = decade(tr.book, ref, float(text), memo) if kind == "number" else None
        if found is None:
            plain.append(row)
        else:
            by_decade.setdefault(found, []).append(row)
    return plain, by_decade


def _not_translated_rows(tr: Translation, skip: dict, counts: dict, reasons: dict) -> str:
    """The CSV of the formula cells with a cached value (a number or a text) that no
    translated definition gives: each is a printed value whose name says the cell and why, so
    that ``workbook check`` counts it as not computable, with its reason."""
    for d in tr.definitions:
        why = d.problem or skip.get(d.name) or (d.element and skip.get(d.element[0]))
        if why:
            reasons.setdefault(d.cell.ref, why)
            if d.run is not None:
                for key in d.run.keys():
                    reasons.setdefault(f"{key[0]}!{_addr(key[1], key[2])}", why)
    for what, why in tr.listed:
        reasons.setdefault(what.split(" (")[0], why)  # "Sheet 1!B3 (name)": the cell
    out = io.StringIO()
    w = csv.writer(out, lineterminator="\n")
    out.write("# Excel's cached values of formula cells not translated (not computable)\n")
    w.writerow(["name", "argument", "value", "unit"])
    n = 0
    for cells in tr.book.sheets.values():
        for key in sorted(cells):
            cell = cells[key]
            if cell.formula is None or cell.ref in counts["cells"]:
                continue
            cached = _cached(cell.value)
            if cached is None or cached[0] == "error":
                continue
            why = reasons.get(cell.ref, "beyond the formulas translated")
            why = re.sub(r"\s+", " ", why)[:160]
            value = csv_text(cached[1]) if cached[0] == "text" else cached[1]
            w.writerow([csv_text(f"{cell.ref} (not translated: {why})"), "", value, ""])
            counts["cells"][cell.ref] = None
            n += 1
    counts["not translated"] = n
    return out.getvalue() if n else ""


def _addr(row: int, col: int) -> str:
    from openpyxl.utils import get_column_letter

    return f"{get_column_letter(col)}{row}"


def _refusals(toml: str, files: dict, path: Path) -> tuple[dict[str, str], SheetSpec | None]:
    """({definition: why} of what the engine refuses at load, empty when the worksheet loads;
    the worksheet's spec when it reads): every definition is typed, so one load finds them
    all. Read and typed in memory: ``path`` (where it will be written) only names it, and the
    printed-value files are read from their texts in ``files``."""
    from ..engine.sheet import Sheet
    from ..language import typecheck as tc
    from ..language.printed import printed_from_text
    from ..language.template import parse_spec
    from ..numerics.registry import BUILTINS

    try:
        spec = parse_spec(toml, path)
        for printed in spec.printed:
            printed.read = printed_from_text(printed, files[printed.file.name])
        units = {n: (None if i.options else i.unit) for n, i in spec.inputs.items()}
        typer = tc.Typer(spec, units, BUILTINS)
    except WorkbookError as err:
        return _located(err, toml), None
    found: dict[str, str] = {}
    for n, d in spec.definitions.items():
        if d.is_function:
            continue
        try:
            typer.scalar(n)
        except WorkbookError as err:
            culprit = err.definition if err.definition in spec.definitions else n
            found.setdefault(culprit.split("(")[0], f"the engine refuses it: {err.message}")
        except RecursionError:
            found.setdefault(n, "the engine refuses it: nested too deeply")
    if found:
        return found, spec
    try:  # what the load types besides the definitions: tables, the printed rows' formulas
        Sheet(spec, typer=typer).check_units()
    except WorkbookError as err:
        return _located(err, toml), spec
    return {}, spec


def _located(err: WorkbookError, toml: str) -> dict[str, str]:
    what = err.definition
    lines = toml.splitlines()
    if what is None and err.line and err.line <= len(lines):
        m = re.match(r'^\[?(?:definitions|inputs)?\.?"?([A-Za-z_]\w*)', lines[err.line - 1])
        what = m.group(1) if m else None
    if what is None:
        raise WorkbookError(f"the translated worksheet does not load: {err.message}") from None
    return {what.split("(")[0]: f"the engine refuses it: {err.message}"}


def write(tr: Translation, out_dir: Path, *, force: bool):
    """Write NAME.toml and its CSV files (existing ones need --force)."""
    from ..mathcad.writer import Rendered

    name = _sheet_name(tr.path)
    skip: dict[str, str] = {}
    users: dict | None = None  # of the first spec read: it holds every later one
    for _ in range(MAX_LOAD_ROUNDS):
        toml, files, counts = render(tr, skip)
        refused, spec = _refusals(toml, files, out_dir / f"{name}.toml")
        if not refused:
            break
        if users is None and spec is not None:
            users = _users(spec)
        for what, why in refused.items():
            if what in skip:
                raise WorkbookError(f"the translated worksheet does not load: {why}")
            skip[what] = why
        for what in refused:
            _drop_dependents(users or {}, what, skip)
    else:
        raise WorkbookError(
            f"the translated worksheet still does not load after leaving out {len(skip)} "
            "definitions"
        )
    rendered = Rendered(name, toml, files)
    paths = write_files(rendered, out_dir, force=force)
    n_fn = sum(1 for i in tr.functions.values() if not i.problem and i.final not in skip)
    n_def = len(tr.inputs) + sum(1 for d in tr.definitions if not d.problem and d.name not in skip)
    return ImportResult(
        toml=paths[0],
        files=paths,
        definitions=n_def,
        functions=n_fn,
        printed=counts["numbers"] + counts["texts"] + counts.get("not translated", 0),
        not_translated=list(tr.listed) + list(skip.items()),
        cells=counts["cells"],
    )


def _users(spec: SheetSpec) -> dict[str, dict[str, None]]:
    """{name: the definitions whose formulas or programs name it, in the worksheet's order} of
    a translated worksheet, read from its parsed trees (``NAME_at``, the element of an array
    formula's cell, stands for NAME too)."""
    from ..language.uses import direct_names

    users: dict[str, dict[str, None]] = {}
    for key, d in spec.definitions.items():
        for used in direct_names(spec, d):
            users.setdefault(used, {})[key] = None
            if used.endswith("_at"):
                users.setdefault(used[:-3], {})[key] = None
    return users


def _drop_dependents(users: dict[str, dict[str, None]], name: str, skip: dict[str, str]) -> None:
    """Leave out the definitions and functions that use ``name`` (they would be refused
    next), and those that use them."""
    todo = [name]
    while todo:
        for user in users.get(todo.pop(), ()):
            if user not in skip:
                skip[user] = f"uses {name}, left out"
                todo.append(user)


_WORD = re.compile(r"[A-Za-z_]\w*")
