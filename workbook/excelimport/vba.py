"""VBA source read from a workbook, an add-in or exported modules (read, never run): its
modules, their procedures as logical lines, and what a worksheet cannot hold (listed)."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import InputError, LimitError
from ..limits import regular_file

MAX_MODULE_CHARS = 2_000_000  # the source of one module
MAX_MODULES = 500
MAX_VBA_FILE_BYTES = 200_000_000

_PROC = re.compile(
    r"^(?:(Public|Private|Friend)\s+)?(?:Static\s+)?(Function|Sub|Property\s+(?:Get|Let|Set))\s+"
    r"([A-Za-z_][A-Za-z0-9_]*)\s*(?:\((.*)\))?\s*(?:As\s+([A-Za-z_][A-Za-z0-9_.]*)(\(\))?)?\s*$",
    re.I,
)
_END = re.compile(r"^End\s+(Function|Sub|Property)\b", re.I)
_EVENT = re.compile(
    r"^(Workbook|Worksheet|Chart|UserForm|Auto)_|_(Click|Change|Activate|Open|Close|"
    r"Initialize|Calculate|BeforeClose|SelectionChange|Terminate)$",
    re.I,
)


@dataclass
class Param:
    name: str
    type: str = "Variant"
    optional: bool = False
    default: str | None = None
    array: bool = False  # declared name() (an array)
    rest: bool = False  # ParamArray: the arguments from here on, as one array from 0
    byval: bool = False  # declared ByVal (VBA passes every other argument by reference)


@dataclass
class Procedure:
    kind: str  # Function | Sub | Property
    name: str
    module: str
    params: list[Param]
    returns: str
    private: bool
    lines: list[tuple[int, str]]  # (line in the module, logical line) of the body
    line: int = 0


@dataclass
class Module:
    name: str
    code: str
    document: bool  # a sheet, ThisWorkbook, class or form module
    procedures: list[Procedure] = field(default_factory=list)
    declarations: list[tuple[int, str]] = field(default_factory=list)  # module-level lines


def read_modules(path: Path) -> list[Module]:
    """The VBA modules of a workbook/add-in, or one exported .bas/.cls/.frm module."""
    regular_file(path, what="VBA source", max_bytes=MAX_VBA_FILE_BYTES)
    if path.suffix.lower() in (".bas", ".cls", ".frm", ".vb", ".txt"):
        regular_file(path, what="VBA module", max_bytes=MAX_MODULE_CHARS)
        raw = path.read_bytes()
        for enc in ("utf-8-sig", "cp1252", "latin-1"):
            try:
                text = raw.decode(enc)
                break
            except UnicodeDecodeError:
                continue
        m = re.search(r'^Attribute VB_Name = "([^"]+)"', text, re.M)
        return [module_of(m.group(1) if m else path.stem, text)]
    try:
        from oletools.olevba import VBA_Parser
    except ImportError:  # pragma: no cover - a runtime dependency
        raise InputError("reading VBA needs oletools (pip install oletools)") from None
    import logging

    logging.getLogger("olevba").setLevel(logging.CRITICAL)
    try:
        vp = VBA_Parser(str(path))
    except Exception as exc:  # noqa: BLE001 - not an OLE/zip file olevba knows
        raise InputError(f"{path}: cannot read its VBA ({type(exc).__name__}: {exc})") from None
    out: list[Module] = []
    try:
        if not vp.detect_vba_macros():
            return []
        for _f, stream, _v, code in vp.extract_macros():
            if len(out) >= MAX_MODULES:
                raise LimitError(f"{path} has more than {MAX_MODULES} VBA modules")
            text = code if isinstance(code, str) else code.decode("latin-1")
            if len(text) > MAX_MODULE_CHARS:
                raise LimitError(
                    f"{path}: VBA module {stream} has {len(text):,} characters "
                    f"(limit {MAX_MODULE_CHARS:,})"
                )
            m = re.search(r'^Attribute VB_Name = "([^"]+)"', text, re.M)
            out.append(module_of(m.group(1) if m else stream.split("/")[-1], text))
    except LimitError:
        raise
    except Exception as exc:  # noqa: BLE001 - a damaged VBA project
        raise InputError(f"{path}: cannot read its VBA ({type(exc).__name__}: {exc})") from None
    finally:
        vp.close()
    return out


def module_of(name: str, code: str) -> Module:
    document = code.lstrip().startswith("VERSION") or bool(
        re.search(r"^Attribute VB_(Base|GlobalNameSpace|Creatable|PredeclaredId)\b", code, re.M)
    )
    mod = Module(name, code, document)
    current: Procedure | None = None
    for number, line in logical_lines(code):
        if line.lower().startswith("attribute "):
            continue
        if current is None:
            m = _PROC.match(line)
            if m:
                scope, kind, pname, params, returns, arr = m.groups()
                current = Procedure(
                    kind=kind.split()[0].capitalize(),
                    name=pname,
                    module=name,
                    params=parse_params(params or ""),
                    returns=(returns or "Variant") + ("()" if arr else ""),
                    private=(scope or "").lower() == "private",
                    lines=[],
                    line=number,
                )
            else:
                mod.declarations.append((number, line))
        elif _END.match(line):
            mod.procedures.append(current)
            current = None
        else:
            current.lines.append((number, line))
    return mod


def parse_params(text: str) -> list[Param]:
    out = []
    for part in split_top(text, ","):
        part = part.strip()
        if not part:
            continue
        optional = is_rest = byval = False
        words = part.split()
        while words and words[0].lower() in ("optional", "byval", "byref", "paramarray"):
            if words[0].lower() == "optional":
                optional = True
            if words[0].lower() == "byval":
                byval = True
            if words[0].lower() == "paramarray":
                optional = is_rest = True
            words.pop(0)
        rest = " ".join(words)
        default = None
        if "=" in rest:
            rest, default = (s.strip() for s in rest.split("=", 1))
        m = re.match(r"([A-Za-z_][A-Za-z0-9_]*)\s*(\(\))?\s*(?:As\s+([A-Za-z_.]+))?", rest, re.I)
        if not m:
            continue
        out.append(
            Param(
                m.group(1),
                m.group(3) or "Variant",
                optional,
                default,
                bool(m.group(2)),
                is_rest,
                byval,
            )
        )
    return out


def split_top(text: str, sep: str) -> list[str]:
    """Split at ``sep`` outside brackets and strings."""
    out, depth, cur, quote = [], 0, [], False
    for ch in text:
        if ch == '"':
            quote = not quote
        elif not quote:
            if ch == "(":
                depth += 1
            elif ch == ")":
                depth -= 1
            elif ch == sep and depth == 0:
                out.append("".join(cur))
                cur = []
                continue
        cur.append(ch)
    out.append("".join(cur))
    return out


def _strip_comment(line: str) -> str:
    quote = False
    for i, ch in enumerate(line):
        if ch == '"':
            quote = not quote
        elif ch == "'" and not quote:
            return line[:i].rstrip()
    if re.match(r"^\s*Rem(\s|$)", line, re.I):
        return ""
    return line.rstrip()


def logical_lines(code: str) -> list[tuple[int, str]]:
    """(first physical line, statement) of each statement: comments dropped, `` _``
    continuations joined, ``:`` separated statements split (a label ``name:`` kept)."""
    out: list[tuple[int, str]] = []
    pending, start = "", 0
    for number, raw in enumerate(code.splitlines(), start=1):
        line = _strip_comment(raw)
        if not pending:
            start = number
        if line.endswith(" _") or line == "_":
            pending += line[:-1] + " "
            continue
        line = (pending + line).strip()
        pending = ""
        if not line:
            continue
        for piece in _split_colons(line):
            if piece:
                out.append((start, piece))
    return out


def _split_colons(line: str) -> list[str]:
    parts, cur, quote = [], [], False
    for i, ch in enumerate(line):
        if ch == '"':
            quote = not quote
        if ch == ":" and not quote and not line[i + 1 : i + 2] == "=":
            parts.append("".join(cur).strip())
            cur = []
            continue
        cur.append(ch)
    parts.append("".join(cur).strip())
    if re.match(r"^[A-Za-z_][A-Za-z0-9_]*:$", line):  # a label
        return [line]
    # a single-line If keeps its statements together: If c Then a: b
    if re.match(r"^If\b.*\bThen\s+\S", line, re.I):
        return [line]
    return parts


def is_event(proc: Procedure) -> bool:
    return bool(_EVENT.search(proc.name))


def _assigns(text: str, name: str) -> bool:
    """Whether a logical line gives the variable ``name`` (or an element of it) a value: an
    assignment at the start of a statement, a For loop over it, a ReDim of it."""
    n = re.escape(name)
    start = r"(?:^|:|\bThen\b|\bElse\b)\s*(?:(?:Let|Set)\s+)?"
    return bool(
        re.search(start + n + r"\s*(?:\([^=]*\))?\s*=(?!=)", text, re.I)
        or re.search(r"\bFor\s+(?:Each\s+)?" + n + r"\b", text, re.I)
        or re.search(r"\bReDim\s+(?:Preserve\s+)?" + n + r"\b", text, re.I)
    )


def _call_arguments(text: str, callee: str) -> list[list[str]]:
    """The argument texts of every call ``callee(...)`` in a line (split at top-level commas)."""
    out = []
    for m in re.finditer(r"\b" + re.escape(callee) + r"\s*\(", text, re.I):
        depth, i = 1, m.end()
        while i < len(text) and depth:
            depth += {"(": 1, ")": -1}.get(text[i], 0)
            i += 1
        out.append([a.strip() for a in split_top(text[m.end() : i - 1], ",")])
    return out


def changed_by_reference(procedures: list[Procedure]) -> dict[str, set[int]]:
    """{lower-case procedure name: the positions of its parameters passed by reference (not
    ByVal) that it changes}: assigned in its body, or passed on as a variable to such a
    parameter of another procedure. VBA's caller sees those changes in its own variable."""
    out = {
        p.name.lower(): {
            k
            for k, q in enumerate(p.params)
            if not q.byval and any(_assigns(t, q.name) for _, t in p.lines)
        }
        for p in procedures
    }
    by_name = {p.name.lower(): p for p in procedures}
    changed = True
    while changed:
        changed = False
        for p in procedures:
            mine = out[p.name.lower()]
            for k, q in enumerate(p.params):
                if k in mine or q.byval:
                    continue
                for callee, positions in out.items():
                    if not positions or callee == p.name.lower():
                        continue
                    for _, text in p.lines:
                        for args in _call_arguments(text, by_name[callee].name):
                            if any(
                                j < len(args) and args[j].lower() == q.name.lower()
                                for j in positions
                            ):
                                mine.add(k)
                                changed = True
    return out
