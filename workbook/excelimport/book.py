"""What the worksheet of an Excel workbook holds: names of cells, inputs, definitions from
formula cells, functions from VBA, and what is listed as not translated (with why)."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from .cells import FormulaTranslator, parse_formula
from .formula_terms import FormulaProblem, text_problem
from .kinds import cell_kind
from .reader import Book, Cell, read_book
from .runs import ROW, Run, find_runs
from .subwrites import cells_written
from .vba import Module, changed_by_reference, is_event, read_modules
from .vbamembers import NotTranslated, record_types
from .vbaprogram import KEYWORDS, FunctionInfo, Translator

#: formulas translated at most (those that call VBA functions first; a multi-cell array
#: formula counts once)
MAX_DEFINITIONS = 4000
#: formula cells translated at most (the cells of formulas filled down included)
MAX_FORMULA_CELLS = 40_000
#: constant cells imported as inputs at most
MAX_INPUTS = 4000
_UNIT_IN_LABEL = re.compile(r"[\(\[]\s*([^\)\]]{1,16}?)\s*[\)\]]")
_UNIT_IN_FORMAT = re.compile(r'"\s*([^"]{1,12}?)\s*"\s*$')


@dataclass
class Definition:
    name: str
    cell: Cell
    text: str | None = None  # the expression
    problem: str | None = None
    element: tuple[str, int] | None = None  # (array formula's name, k) of a cell of a block
    run: Run | None = None  # a filled-down column: the definition is a function of the row
    block: tuple[int, int] | None = None  # (rows, columns) of the array formula's cells
    #: the empty cells an IS-function's answer takes to stay empty (never inputs of the sheet)
    empty_cells: list = field(default_factory=list)


@dataclass
class Translation:
    path: Path
    book: Book
    modules: list[Module]
    functions: dict[str, FunctionInfo] = field(default_factory=dict)
    inputs: dict[str, tuple[Cell | None, str, str]] = field(default_factory=dict)  # value, note
    texts: dict[str, tuple[Cell, str]] = field(default_factory=dict)
    definitions: list[Definition] = field(default_factory=list)
    listed: list[tuple[str, str]] = field(default_factory=list)  # (what, why)
    cell_names: dict[tuple[str, int, int], str] = field(default_factory=dict)
    runs: dict[tuple[str, int, int], Run] = field(default_factory=dict)  # cell -> its run
    vectors: dict[str, str] = field(default_factory=dict)  # name -> vector literal
    ranges: dict[str, str] = field(default_factory=dict)  # matrix literal of a range -> name
    #: cells whose value a VBA Sub writes -> the Sub's name
    written: dict[tuple[str, int, int], str] = field(default_factory=dict)
    unparsed: dict[tuple[str, int, int], str] = field(default_factory=dict)  # cell -> why


def language_reserved() -> set[str]:
    from ..numerics.registry import REGISTRY

    return {n.lower() for n in REGISTRY} | KEYWORDS


def translate_book(path: Path, vba_files: list[Path]) -> Translation:
    book = read_book(path)
    modules = (
        read_modules(path)
        if path.suffix.lower() in (".xlsm", ".xls", ".xlam", ".xla", ".xlsb")
        else []
    )
    for extra in vba_files:
        modules += read_modules(extra)
    tr = Translation(path, book, modules)
    tr.listed += book.skipped
    reserved = language_reserved()
    _collect_functions(tr, reserved)
    cells = _formula_cells(tr)
    tr.written = cells_written(modules, list(book.sheets))
    book.sub_written = tr.written
    parsed = {}
    for cell in cells:
        sub = tr.written.get(_key(cell))
        if sub is not None:  # its cached value may be the macro's: no formula computes it
            why = (
                f"written by the macro Sub {sub} (its value is the macro's result, which no "
                "formula computes)"
            )
            tr.unparsed[_key(cell)] = why
            tr.listed.append((cell.ref, why))
            continue
        try:
            if cell.ref in book.formula_problems:
                raise FormulaProblem(book.formula_problems[cell.ref])
            parsed[_key(cell)] = parse_formula(cell.formula)
        except FormulaProblem as exc:
            tr.listed.append((cell.ref, str(exc)))
    book.trees = {key: p.tree for key, p in parsed.items()}  # what kind a formula gives
    # which cells formulas read (names are given after, in reading order)
    read: list[tuple[str, int, int]] = []

    def record(sheet, row, col):
        read.append((sheet, row, col))
        return "x"

    for cell in cells:
        if _key(cell) in parsed and cell.array_master in (None, (cell.row, cell.col)):
            try:
                FormulaTranslator(
                    book,
                    cell.sheet,
                    record,
                    tr.functions,
                    book.names,
                    _block(cell),
                    seen={cell_kind(cell)},
                    in_array=cell.in_array,
                ).translate(parsed[_key(cell)].tree)
            except FormulaProblem:
                pass
            except Exception:  # noqa: BLE001 - listed with its reason when translated below
                pass
    _name_cells(tr, cells, read, reserved)
    _runs(tr, cells, parsed, reserved)
    _name_params(tr, reserved)
    _translate_functions(tr, reserved)
    _translate_cells(tr, cells, parsed)
    return tr


def _block(cell: Cell) -> tuple[int, int] | None:
    """(rows, columns) of the cells of the multi-cell array formula ``cell`` is in."""
    if cell.array is None:
        return None
    from openpyxl.utils.cell import range_boundaries

    c1, r1, c2, r2 = range_boundaries(cell.array)
    return (r2 - r1 + 1, c2 - c1 + 1)


def _key(cell: Cell) -> tuple[str, int, int]:
    return (cell.sheet, cell.row, cell.col)


def _collect_functions(tr: Translation, reserved: set[str]) -> None:
    taken = set(reserved)
    records: dict = {}
    for mod in tr.modules:
        records.update(record_types(mod.code))
    for mod in tr.modules:
        option_base = any(
            re.match(r"^Option\s+Base\s+1", line, re.I) for _, line in mod.declarations
        )
        for _, line in mod.declarations:
            low = line.lower()
            if re.match(r"^(public\s+|private\s+)?declare\b", low):
                tr.listed.append(
                    (f"VBA module {mod.name}", f"declares a DLL function: {line[:80]}")
                )
            if "solver" in low:
                tr.listed.append((f"VBA module {mod.name}", f"Solver: {line[:80]}"))
        for proc in mod.procedures:
            where = f"VBA {proc.kind} {proc.name} (module {mod.name})"
            body = "\n".join(t for _, t in proc.lines)
            if re.search(r"\bSolver\w*\b", body):
                tr.listed.append((where, "runs Solver (a Solver model is not translated)"))
            if proc.kind != "Function" or (mod.document and not _host(mod)) or is_event(proc):
                why = (
                    "an event procedure"
                    if is_event(proc)
                    else "a Sub (it writes cells or runs commands)"
                    if proc.kind == "Sub"
                    else "in a class or form module"
                    if mod.document
                    else "a Property"
                )
                if re.search(
                    r"\b(Open|Print #|Write #|Kill|Dir\(|FileCopy|UserForm|\.Show)\b", body
                ):
                    why += "; reads or writes files or shows a form"
                tr.listed.append((where, why))
                continue
            key = proc.name.lower()
            if key in tr.functions:
                continue  # the first definition wins, as Excel finds it first
            final = re.sub(r"[^A-Za-z0-9_]", "_", proc.name)
            while final.lower() in taken:
                final += "_"
            taken.add(final.lower())
            info = FunctionInfo(proc, final, [])
            info.option_base = 1 if option_base else 0  # type: ignore[attr-defined]
            info.consts = _module_consts(mod) + [  # type: ignore[attr-defined]
                line
                for other in tr.modules
                if other is not mod and not other.document
                for line in _module_consts(other)
                if re.match(r"^(public|global)\s+const\b", line, re.I)
            ]
            info.module_vars = {  # type: ignore[attr-defined]
                **{  # a Public variable of another module is seen here too
                    k: v
                    for other in tr.modules
                    if other is not mod and not other.document  # a class's fields are its own
                    for k, v in _module_vars(other, public_only=True).items()
                },
                **_module_vars(mod),
            }
            info.record_types = records  # type: ignore[attr-defined]
            tr.functions[key] = info
    tr.reserved_functions = {i.final.lower() for i in tr.functions.values()}  # type: ignore[attr-defined]


#: the module of the workbook (ThisWorkbook) or of a worksheet, whose Public functions cells
#: call as ``=ThisWorkbook.f(...)`` or ``=Sheet1.f(...)``
_HOSTS = ("{00020819-", "{00020820-")


def _host(mod: Module) -> bool:
    """A ThisWorkbook or sheet module (not a class or a form)."""
    m = re.search(r'^Attribute VB_Base = "([^"]+)"', mod.code, re.M)
    return m is not None and any(h in m.group(1) for h in _HOSTS)


def _module_consts(mod: Module) -> list[str]:
    return [
        line
        for _, line in mod.declarations
        if re.match(r"^(public\s+|private\s+)?const\b", line, re.I)
    ]


def _module_vars(mod: Module, public_only: bool = False) -> dict[str, str]:
    """{lower-case name: its declaration as a local ``Dim``} of the module's variables (its
    Public and Global ones only, with ``public_only``)."""
    out = {}
    scopes = "public|global" if public_only else "dim|public|private|global|static"
    for _, line in mod.declarations:
        m = re.match(
            rf"^(?:{scopes})\s+(?!const\b|declare\b|function\b|sub\b|"
            r"type\b|enum\b|withevents\b)(.+)$",
            line,
            re.I,
        )
        if not m:
            continue
        for piece in _top_level_split(m.group(1)):
            name = re.match(r"\s*(\w+)", piece)
            if name:
                out[name.group(1).lower()] = "Dim " + piece.strip()
    return out


def _top_level_split(text: str) -> list[str]:
    """``a(1 To 3) As Double, b`` -> the declarations split at commas outside brackets."""
    parts, depth, start = [], 0, 0
    for i, ch in enumerate(text):
        depth += ch == "("
        depth -= ch == ")"
        if ch == "," and depth == 0:
            parts.append(text[start:i])
            start = i + 1
    return parts + [text[start:]]


def _assigns(lines, name: str) -> bool:
    """Whether a procedure's lines give the variable a value (``x = ...``, ``x(i) = ...``,
    ``Set x = ...``, ``ReDim x(...)``)."""
    target = re.compile(
        rf"^(?:set\s+|let\s+)?{re.escape(name)}\s*(?:\([^=]*\))?\s*=|^redim\s+(?:preserve\s+)?"
        rf"{re.escape(name)}\b",
        re.I,
    )
    return any(target.match(t.strip()) for _, t in lines)


def _module_state(tr: Translation, info: FunctionInfo, body: str) -> list[tuple[int, str]]:
    """The module variables the function uses, as locals, where its value does not depend on
    the order of calls: no other procedure gives the variable a value, and the function gives
    it one before it reads it (or never gives it one: it is always Empty). Otherwise
    NotTranslated, naming the variable."""
    out = []
    own = {p.name.lower() for p in info.proc.params} | {
        m.group(1).lower()
        for _, t in info.proc.lines
        for part in re.findall(r"(?i)^(?:dim|static|const)\s+(.*)$", t)
        for m in re.finditer(r"(?:^|,)\s*(\w+)", part)
    }  # an argument or a local of the same name hides the module's variable
    for name, decl in info.module_vars.items():  # type: ignore[attr-defined]
        if name in own or not re.search(rf"\b{re.escape(name)}\b", body, re.I):
            continue
        writers = [
            p.name
            for mod in tr.modules
            for p in mod.procedures
            if p is not info.proc and _assigns(p.lines, name)
        ]
        if writers:
            raise NotTranslated(
                f"uses the module variable {name}, which {writers[0]} gives a value (state "
                "kept between calls)"
            )
        if _assigns(info.proc.lines, name):
            first = next(
                t for _, t in info.proc.lines if re.search(rf"\b{re.escape(name)}\b", t, re.I)
            )
            rhs = first.split("=", 1)[1] if "=" in first else first
            if not _assigns([(0, first)], name) or re.search(rf"\b{re.escape(name)}\b", rhs, re.I):
                raise NotTranslated(
                    f"uses the module variable {name} before it gives it a value (state kept "
                    "between calls)"
                )
        out.append((0, decl))
    return out


def _const_name(line: str) -> str | None:
    m = re.search(r"(?i)\bconst\s+(\w+)", line)
    return m.group(1) if m else None


def _mentions(body: str, name: str) -> bool:
    return re.search(rf"\b{re.escape(name)}\b", body, re.I) is not None


def _formula_cells(tr: Translation) -> list[Cell]:
    """Formula cells to translate, in reading order: those that call a VBA function first,
    then the others, at most MAX_DEFINITIONS formulas (a multi-cell array formula is one
    formula: its other cells come with it; so is a formula filled down a column, whose cells
    below come with the first), and at most MAX_FORMULA_CELLS cells."""
    out = []
    for cells in tr.book.sheets.values():
        for r, c in sorted(cells):
            cell = cells[(r, c)]
            if cell.formula is not None:
                out.append(cell)
    below = {id(c) for c in out if _fills_down(tr.book, c)}
    formulas = [c for c in out if not _follows_master(c) and id(c) not in below]
    if len(formulas) <= MAX_DEFINITIONS and len(out) <= MAX_FORMULA_CELLS:
        return out
    names = set(tr.functions)
    calls = [
        c
        for c in formulas
        if any(re.search(rf"\b{re.escape(n)}\s*\(", c.formula, re.I) for n in names)
    ]
    chosen = {id(c) for c in calls[:MAX_DEFINITIONS]}
    for c in formulas:
        if len(chosen) >= MAX_DEFINITIONS:
            break
        chosen.add(id(c))
    kept_keys = set()
    kept = []
    for c in sorted(out, key=lambda c: (c.sheet, c.col, c.row)):  # a column top down
        key = (c.sheet, c.row, c.col)
        if (
            id(c) in chosen
            or (_follows_master(c) and (c.sheet, *c.array_master) in kept_keys)
            or (id(c) in below and (c.sheet, c.row - 1, c.col) in kept_keys)
        ):
            kept_keys.add(key)
    kept = [c for c in out if (c.sheet, c.row, c.col) in kept_keys][:MAX_FORMULA_CELLS]
    left = len(out) - len(kept)
    tr.listed.append(
        (
            f"{left:,} formula cells",
            f"beyond the {MAX_DEFINITIONS:,} formulas translated (those that call VBA "
            f"functions first; a formula filled down counts once), or the "
            f"{MAX_FORMULA_CELLS:,} cells",
        )
    )
    return kept


def _relative(formula: str, row: int) -> str:
    """The formula with each relative row written from ``row`` (R1C1's view of it), so that
    the cells of a formula filled down have one text."""
    return re.sub(
        r"(?<![A-Za-z_\d.])(\$?[A-Za-z]{1,3})(\$?)(\d+)(?![\d(])",
        lambda m: m.group(0) if m.group(2) else f"{m.group(1)}[{int(m.group(3)) - row}]",
        formula,
    )


def _fills_down(book: Book, cell: Cell) -> bool:
    """The cell above holds the same formula, filled down (not an array formula)."""
    if cell.array is not None:
        return False
    above = book.cell(cell.sheet, cell.row - 1, cell.col)
    if above is None or above.formula is None or above.array is not None:
        return False
    return _relative(above.formula, above.row) == _relative(cell.formula, cell.row)


def _follows_master(cell: Cell) -> bool:
    """A cell of a multi-cell array formula other than its first: translated with it."""
    return cell.array_master is not None and (cell.row, cell.col) != cell.array_master


def _ident(text: str) -> str | None:
    text = _UNIT_IN_LABEL.sub("", str(text))
    text = re.split(r"[:=]", text)[0]
    words = re.findall(r"[A-Za-z0-9]+", text)[:4]
    if not words:
        return None
    name = "_".join(words)[:32]
    if name[0].isdigit():
        name = "c_" + name
    return name


def _label(book: Book, sheet: str, row: int, col: int) -> str | None:
    for dc in (1, 2):
        cell = book.cell(sheet, row, col - dc)
        if cell is None:
            continue
        if cell.formula is None and isinstance(cell.value, str) and cell.value.strip():
            return cell.value.strip()
        break
    above = book.cell(sheet, row - 1, col)
    if above is not None and above.formula is None and isinstance(above.value, str):
        return above.value.strip() or None
    return None


def proposed_unit(label: str | None, number_format: str) -> str | None:
    """A unit named by the label (``Span (mm)``) or the number format (``0.0 "kN"``) that
    pint reads; proposed in a note, never applied."""
    from ..language import units as un

    found = []
    if label:
        found += _UNIT_IN_LABEL.findall(label)
    m = _UNIT_IN_FORMAT.search(number_format or "")
    if m:
        found.append(m.group(1))
    for text in found:
        text = text.strip().replace("°C", "degC").replace("°F", "degF").replace("°", "deg")
        if not text or text.isdigit():
            continue
        try:
            unit = un.unit(text, what="a unit")
        except Exception:  # noqa: BLE001 - not a unit: nothing proposed
            continue
        if str(unit) != "dimensionless":
            return text
    return None


def _name_cells(tr: Translation, cells: list[Cell], read, reserved: set[str]) -> None:
    book = tr.book
    taken = set(reserved) | {i.final.lower() for i in tr.functions.values()}
    many = len({s for s, _, _ in read} | {c.sheet for c in cells}) > 1
    by_cell = {}
    for name, (sheet, ref) in book.names.items():
        if ":" not in ref:
            from openpyxl.utils.cell import column_index_from_string, coordinate_from_string

            try:
                letters, row = coordinate_from_string(ref)
            except Exception:  # noqa: BLE001 - not one cell
                continue
            by_cell.setdefault((sheet, row, column_index_from_string(letters)), name)
    wanted = sorted(
        set(read) | {_key(c) for c in cells},
        key=lambda k: (list(book.sheets).index(k[0]) if k[0] in book.sheets else 0, k[1], k[2]),
    )
    for key in wanted:
        sheet, row, col = key
        base = by_cell.get(key)
        if base is not None:
            base = re.sub(r"[^A-Za-z0-9_]", "_", base)
        else:
            base = _ident(_label(book, sheet, row, col) or "")
        if base is None:
            from openpyxl.utils import get_column_letter

            base = f"{get_column_letter(col)}{row}"
            if many:
                prefix = re.sub(r"[^A-Za-z0-9]", "", sheet)[:12]
                if not prefix or prefix[0].isdigit():  # a name starts with a letter
                    prefix = "S" + prefix
                base = f"{prefix}_{base}"
        name, n = base, 2
        while name.lower() in taken:
            name = f"{base}_{n}"
            n += 1
        taken.add(name.lower())
        tr.cell_names[key] = name


def _runs(tr: Translation, cells: list[Cell], parsed, reserved: set[str]) -> None:
    """Filled-down columns: one function of the row each (see runs.py)."""
    book = tr.book

    def ref_of(token, sheet):
        return FormulaTranslator(book, sheet, None, {}, book.names).ref_of(token)

    runs = find_runs(book, cells, parsed, ref_of)
    spans = {(r.sheet, r.col, r.first, r.count): r for r in runs}
    valid = set(spans)
    changed = True
    while changed:  # a run reading a column that is neither numbers nor a valid run is not one
        changed = False
        for span in list(valid):
            run = spans[span]
            for sheet, col, offset in run.moving.values():
                other = (sheet, col, run.first + offset, run.count)
                if other in valid:
                    continue
                if other in spans or not _constant_column(
                    book, sheet, col, run.first + offset, run.count
                ):
                    valid.discard(span)
                    changed = True
                    break
    in_runs = {key for span in valid for key in spans[span].keys()}
    taken = {n.lower() for k, n in tr.cell_names.items() if k not in in_runs} | set(reserved)
    taken |= {i.final.lower() for i in tr.functions.values()}
    for span in sorted(valid, key=lambda s: (s[0], s[2], s[1])):
        run = spans[span]
        header = book.cell(run.sheet, run.first - 1, run.col)
        base = (
            _ident(header.value) if header is not None and isinstance(header.value, str) else None
        )
        base = base or f"col_{_addr(run.first, run.col)}"
        run.name = _unique(base, taken)
        for k, key in enumerate(run.keys()):
            tr.cell_names[key] = f"{run.name}({k})"
            tr.runs[key] = run
    for span in sorted(valid, key=lambda s: (s[0], s[2], s[1])):  # names as on every run
        run = spans[span]
        columns = {}
        for key, (sheet, col, offset) in run.moving.items():
            other = spans.get((sheet, col, run.first + offset, run.count))
            if other is not None and other.name:
                columns[key] = f"{other.name}({ROW})"
                continue
            header = book.cell(sheet, run.first + offset - 1, col)
            base = (
                _ident(header.value)
                if header is not None and isinstance(header.value, str)
                else None
            )
            vname = _unique((base or f"col_{_addr(run.first + offset, col)}") + "_col", taken)
            values = [
                book.cell(sheet, r, col).value
                for r in range(run.first + offset, run.first + offset + run.count)
            ]
            tr.vectors[vname] = "[" + ", ".join(repr(float(v)) for v in values) + "]"
            columns[key] = f"{vname}[{ROW}]"
        run.moving = columns


def _constant_column(book: Book, sheet: str, col: int, first: int, count: int) -> bool:
    for r in range(first, first + count):
        cell = book.cell(sheet, r, col)
        if cell is None or cell.formula is not None or isinstance(cell.value, bool):
            return False
        if not isinstance(cell.value, (int, float)):
            return False
    return True


def _unique(base: str, taken: set[str]) -> str:
    name, n = base, 2
    while name.lower() in taken:
        name = f"{base}_{n}"
        n += 1
    taken.add(name.lower())
    return name


def _name_params(tr: Translation, reserved: set[str]) -> None:
    # a parameter may take a built-in's name (Re, a Reynolds number, beside Re(z)): inside
    # the function it is the value, and a call of that name is still the built-in
    taken = set(KEYWORDS) | {n.lower() for n in tr.cell_names.values()}
    taken |= {i.final.lower() for i in tr.functions.values()}
    for info in tr.functions.values():
        used: set[str] = set()
        body = "\n".join(t for _, t in info.proc.lines)
        for p in info.proc.params:
            name = re.sub(r"[^A-Za-z0-9_]", "_", p.name)
            while name.lower() in taken or name.lower() in used:
                name += "_"
            used.add(name.lower())
            info.params.append(name)
        for p, final in zip(info.proc.params, info.params):
            if p.optional and re.search(
                rf"\bIsMissing\s*\(\s*{re.escape(p.name)}\s*\)", body, re.I
            ):
                flag = f"{final}_given"
                while flag.lower() in taken or flag.lower() in used:
                    flag += "_"
                used.add(flag.lower())
                info.given[final] = flag


#: rounds of translating the VBA functions at most (each knows the array bounds of the last)
MAX_ROUNDS = 5


def _translate_functions(tr: Translation, reserved: set[str]) -> None:
    # the sheet's names: cells, filled-down columns (``x(0)`` is the column x) and the
    # vectors of their constant columns
    sheet_names = {n.split("(")[0].lower() for n in tr.cell_names.values()}
    sheet_names |= {v.lower() for v in tr.vectors}
    all_params = {
        p.lower() for i in tr.functions.values() for p in list(i.params) + list(i.given.values())
    }
    # the second round knows the lower bound of the arrays callees give, and of the arrays
    # callers give each array parameter; more rounds until those bounds settle
    changed = changed_by_reference([i.proc for i in tr.functions.values()])
    for _round in range(MAX_ROUNDS):
        settled = _round > 0 and all(i.arg_bases == i.used_bases for i in tr.functions.values())
        if settled and _round >= 2:
            break
        for info in tr.functions.values():
            info.used_bases, info.arg_bases = info.arg_bases, {}
        for info in tr.functions.values():
            own = {p.lower() for p in list(info.params) + list(info.given.values())}
            block = (
                reserved
                | sheet_names
                | (all_params - own)
                | {i.final.lower() for i in tr.functions.values()}
            )
            t = Translator(info, tr.functions, block)
            t.changed_params = changed
            t.option_base = info.option_base  # type: ignore[attr-defined]
            body = "\n".join(x for _, x in info.proc.lines)
            info.problem, info.calls, info.dropped = None, set(), set()
            try:
                state = _module_state(tr, info, body)
                consts = [
                    c for c in info.consts if _const_name(c) and _mentions(body, _const_name(c))
                ]  # type: ignore[attr-defined]
                t.prefix = [
                    (0, re.sub(r"^(public|private|global)\s+", "", c, flags=re.I)) for c in consts
                ] + state
                info.program = t.translate()
            except NotTranslated as exc:
                info.problem = str(exc)
            except Exception as exc:  # noqa: BLE001 - a construct the reader did not foresee
                info.problem = f"not translated ({type(exc).__name__}: {exc})"
    for info in tr.functions.values():
        if info.arg_bases != info.used_bases and not info.problem:
            info.problem = "the lower bounds of the arrays its callers give do not settle"
    changed = True
    while changed:  # a function that calls one not translated is not translated either
        changed = False
        for info in tr.functions.values():
            if info.problem:
                continue
            for callee in sorted(info.calls):  # sorted: the same reason on every run
                other = tr.functions.get(callee)
                if other is not None and other.problem:
                    info.problem = f"calls {other.proc.name}, not translated"
                    changed = True
                    break
    for info in tr.functions.values():
        if info.problem:
            tr.listed.append(
                (f"VBA Function {info.proc.name} (module {info.proc.module})", info.problem)
            )


def _translate_cells(tr: Translation, cells: list[Cell], parsed) -> None:
    book = tr.book
    used: dict[tuple[str, int, int], None] = {}

    def name_of(sheet, row, col):
        used[(sheet, row, col)] = None
        cell = book.cell(sheet, row, col)
        if cell is not None and cell.array is not None and cell.formula is not None:
            # a cell of a multi-cell array formula shows one element of the array
            from openpyxl.utils.cell import range_boundaries

            c1, r1, c2, _ = range_boundaries(cell.array)
            master = tr.cell_names.get((sheet, *cell.array_master))
            if master is not None:
                return f"{master}_at({(row - r1) * (c2 - c1 + 1) + col - c1})"
        return tr.cell_names.get((sheet, row, col)) or f"missing_{row}_{col}"

    formula_keys = {_key(c) for c in cells}
    by_key: dict[tuple[str, int, int], Definition] = {}
    for cell in cells:
        key = _key(cell)
        run = tr.runs.get(key)
        if run is not None and key != (run.sheet, run.first, run.col):
            by_key[key] = by_key[(run.sheet, run.first, run.col)]  # the run's definition
            continue
        d = Definition(run.name if run else tr.cell_names[key], cell, run=run)
        by_key[key] = d
        if key not in parsed:
            d.problem = tr.unparsed.get(key, "cannot parse the formula")
            continue
        if cell.array is not None and cell.array_master != (cell.row, cell.col):
            master = by_key.get((cell.sheet, *cell.array_master))
            if master is None:
                d.problem = "part of an array formula whose first cell is not translated"
            else:
                from openpyxl.utils.cell import range_boundaries

                c1, r1, c2, r2 = range_boundaries(cell.array)
                width = c2 - c1 + 1
                d.element = (master.name, (cell.row - r1) * width + cell.col - c1)
                master.block = (r2 - r1 + 1, width)
            tr.definitions.append(d)
            continue
        try:
            ft = FormulaTranslator(
                book,
                cell.sheet,
                name_of,
                tr.functions,
                book.names,
                _block(cell),
                tr.ranges,
                moving=run.moving if run is not None else None,
                seen={cell_kind(book.cell(*k)) for k in (run.keys() if run else [key])},
                rows=run.count if run is not None else 1,
                in_array=cell.in_array,
            )
            d.text = ft.translate(parsed[key].tree).text
            if parsed[key].linked:
                d.note_link = True  # type: ignore[attr-defined]
            d.reads = [  # type: ignore[attr-defined]
                (ref.sheet, r, c)
                for ref in ft.out.refs
                for r in range(ref.r1, ref.r2 + 1)
                for c in range(ref.c1, ref.c2 + 1)
                if not getattr(ref, "moved", False)
            ]
            d.empty_cells = ft.out.empty_cells
        except FormulaProblem as exc:
            d.problem = str(exc)
        except Exception as exc:  # noqa: BLE001 - a formula the translation did not foresee
            d.problem = f"not translated ({type(exc).__name__}: {exc})"
        tr.definitions.append(d)
    _bound_inputs(tr, formula_keys)
    _spread_problems(tr, by_key)
    _constant_inputs(tr, formula_keys)
    if _empty_inputs(tr):
        _spread_problems(tr, by_key)
    for d in tr.definitions:
        if d.problem:
            tr.listed.append((f"{d.cell.ref} ={d.cell.formula[:60]}", d.problem))


def _empty_inputs(tr: Translation) -> bool:
    """An IS-function's answer for an empty cell holds while the cell stays empty: where a
    translated formula reads the cell too, it is an input, which may be given a value, and
    the formula of the IS-function is listed (its input, if read by it alone, stays unused)."""
    changed = False
    for d in tr.definitions:
        if d.problem:
            continue
        for k in d.empty_cells:
            name = tr.cell_names.get(k)
            if name is not None and name in tr.inputs:
                d.problem = (
                    f"an IS-function of the empty cell {k[0]}!{_addr(k[1], k[2])}, which is an "
                    "input of the worksheet (a value given to it would change the answer)"
                )
                changed = True
                break
    return changed


def _bound_inputs(tr: Translation, formula_keys: set) -> None:
    """Inputs are bounded: a formula that would take the count past MAX_INPUTS is listed."""
    constants: set = set()
    for d in tr.definitions:
        if d.problem:
            continue
        new = {k for k in getattr(d, "reads", []) if k not in formula_keys} - constants
        if len(constants) + len(new) > MAX_INPUTS:
            d.problem = f"reads more constant cells than the {MAX_INPUTS:,} inputs imported"
            continue
        constants |= new


def _spread_problems(tr: Translation, by_key: dict) -> None:
    """A formula reading a formula cell that is not translated is not translated either."""
    by_name = {}
    for d in tr.definitions:
        by_name.setdefault(d.name, d)
    changed = True
    while changed:
        changed = False
        for d in tr.definitions:
            if d.problem:
                continue
            if d.element is not None:
                master = by_name.get(d.element[0])
                if master is not None and master.problem:
                    d.problem = f"part of the array formula {master.name}, not translated"
                    changed = True
                continue
            for k in getattr(d, "reads", []):
                other = by_key.get(k)
                if other is not None and other.problem:
                    d.problem = f"reads {other.name} ({other.cell.ref}), not translated"
                    changed = True
                    break


def _constant_inputs(tr: Translation, formula_keys: set) -> None:
    """The inputs: the constant cells that translated formulas read (a number, a flag or a
    text; any other value leaves out the formulas that read it)."""
    book = tr.book
    for d in tr.definitions:
        if d.problem:
            continue
        for k in getattr(d, "reads", []):
            if k in formula_keys:
                continue
            name = tr.cell_names.get(k)
            if name is None or name in tr.inputs or name in tr.texts:
                continue
            cell = book.cell(*k)
            label = _label(book, *k)
            where = f"{k[0]}!{_addr(k[1], k[2])}" + (f": {label}" if label else "")
            if cell is None or cell.value is None:
                tr.inputs[name] = (cell, "0", f"{where} (an empty cell, 0 in Excel)")
            elif isinstance(cell.value, bool):
                tr.inputs[name] = (cell, "1" if cell.value else "0", f"{where} (TRUE/FALSE)")
            elif isinstance(cell.value, (int, float)):
                unit = proposed_unit(label, cell.number_format)
                note = where + (f"; unit proposed: {unit}" if unit else "")
                if k in tr.written:
                    note += f"; written by the macro Sub {tr.written[k]}"
                tr.inputs[name] = (
                    cell,
                    repr(float(cell.value)) if isinstance(cell.value, float) else str(cell.value),
                    note,
                )
            elif isinstance(cell.value, str) and text_problem(cell.value) is None:
                tr.texts[name] = (cell, cell.value)
            else:  # never a stand-in value: the formulas that read it are left out
                what = (
                    text_problem(cell.value)
                    if isinstance(cell.value, str)
                    else (f"a {type(cell.value).__name__}, not a number")
                )
                tr.listed.append((f"{cell.ref} ({name})", f"{what}: not translated"))


def _addr(row: int, col: int) -> str:
    from openpyxl.utils import get_column_letter

    return f"{get_column_letter(col)}{row}"


def translate_vba(code: str, module: str = "Module1") -> dict[str, FunctionInfo]:
    """The Functions of VBA source text, translated (each with its program or its problem)."""
    from .vba import module_of

    tr = Translation(Path(module + ".bas"), Book(Path(module + ".bas")), [module_of(module, code)])
    reserved = language_reserved()
    _collect_functions(tr, reserved)
    _name_params(tr, reserved)
    _translate_functions(tr, reserved)
    return {info.proc.name: info for info in tr.functions.values()}
