"""Program text to statements: one statement a line, a block indented under its header."""

from __future__ import annotations

import io
import re
import tokenize
from dataclasses import dataclass

from ..errors import LimitError, TemplateError
from ..language import expr as ex
from .statements import (
    Assign,
    Break,
    Continue,
    For,
    If,
    Program,
    Return,
    SetItem,
    Stmt,
    Try,
    Value,
    While,
    walk,
)

#: Longest program text and deepest block nesting.
MAX_PROGRAM_TEXT = 100_000
MAX_BLOCK_DEPTH = 50


# -- parsing ----------------------------------------------------------------------------------
@dataclass
class _Line:
    number: int
    indent: int
    text: str


def parse(text: str, *, what: str = "program") -> Program:
    """Parse program text into statements (raises TemplateError naming the line)."""
    if not isinstance(text, str):
        raise TemplateError(f"{what}: a program is text (a multi-line string)")
    if len(text) > MAX_PROGRAM_TEXT:
        raise LimitError(f"{what}: program is {len(text)} characters (limit {MAX_PROGRAM_TEXT})")
    lines = []
    for number, raw in enumerate(text.splitlines(), start=1):
        body = _strip_comment(raw, what, number).rstrip()
        if not body.strip():
            continue
        if "\t" in body[: len(body) - len(body.lstrip())]:
            raise TemplateError(f"{what}, line {number}: indent with spaces, not tabs")
        lines.append(_Line(number, len(body) - len(body.lstrip()), body.strip()))
    if not lines:
        raise TemplateError(f"{what}: empty program")
    block, rest = _block(lines, 0, lines[0].indent, what, 0)
    if rest != len(lines):  # pragma: no cover - _block consumes everything at top level
        raise TemplateError(f"{what}, line {lines[rest].number}: unexpected indent")
    _check_tries(block, what)
    _check_loops(block, False, what)
    return Program(block, text)


def _check_loops(block: tuple[Stmt, ...], inside: bool, what: str) -> None:
    """'break' and 'continue' only inside a loop."""
    for s in block:
        if isinstance(s, (Break, Continue)) and not inside:
            word = "break" if isinstance(s, Break) else "continue"
            raise TemplateError(f"{what}, line {s.line}: '{word}' outside a loop")
        if isinstance(s, If):
            for _, b in s.branches:
                _check_loops(b, inside, what)
            if s.otherwise:
                _check_loops(s.otherwise, inside, what)
        elif isinstance(s, (For, While)):
            _check_loops(s.body, True, what)
        elif isinstance(s, Try):
            _check_loops(s.body, inside, what)
            _check_loops(s.handler, inside, what)


def _check_tries(block: tuple[Stmt, ...], what: str) -> None:
    """Every 'try' has its 'on error' block."""
    for s in walk(block):
        if isinstance(s, Try) and not s.handler:
            raise TemplateError(f"{what}, line {s.line}: 'try' without its 'on error' block")


def _strip_comment(raw: str, what: str, number: int) -> str:
    """The line without a trailing ``# comment`` (a '#' inside a string stays)."""
    if "#" not in raw:
        return raw
    quote = None
    for i, ch in enumerate(raw):
        if quote:
            if ch == quote:
                quote = None
        elif ch in "\"'":
            quote = ch
        elif ch == "#":
            return raw[:i]
    return raw


def _block(lines: list[_Line], i: int, indent: int, what: str, depth: int):
    if depth > MAX_BLOCK_DEPTH:
        raise LimitError(f"{what}: blocks nested more than {MAX_BLOCK_DEPTH} deep")
    out: list[Stmt] = []
    while i < len(lines):
        ln = lines[i]
        if ln.indent < indent:
            break
        if ln.indent > indent:
            raise TemplateError(f"{what}, line {ln.number}: unexpected indent")
        where = f"{what}, line {ln.number}"
        head, tail = _keyword(ln.text)
        i += 1
        if head in ("try", "on error"):
            if tail.removesuffix(":").strip():
                raise TemplateError(f"{where}: '{head}' takes nothing after it")
            body, i = _body(lines, i, ln, what, depth)
            if head == "try":
                out.append(Try(ln.number, body, ()))
            else:
                prev = out[-1] if out else None
                if not isinstance(prev, Try) or prev.handler:
                    raise TemplateError(f"{where}: 'on error' without a 'try' before it")
                out[-1] = Try(prev.line, prev.body, body)
            continue
        if head in ("if", "for", "while", "else", "otherwise", "else if"):
            is_header = head != "otherwise" or not tail
            if head == "otherwise" and tail:
                raise TemplateError(f"{where}: write 'VALUE otherwise' or 'otherwise' alone")
        else:
            is_header = False
        if is_header:
            body, i = _body(lines, i, ln, what, depth)
            cond_text = tail.removesuffix(":").strip()
            if head == "if":
                out.append(If(ln.number, ((_expr(cond_text, where), body),), None))
            elif head in ("else if", "else", "otherwise"):
                prev = out[-1] if out else None
                if not isinstance(prev, If) or prev.otherwise is not None:
                    raise TemplateError(f"{where}: '{head}' without an 'if' before it")
                if head == "else if":
                    branches = (*prev.branches, (_expr(cond_text, where), body))
                    out[-1] = If(prev.line, branches, None)
                else:
                    if cond_text:
                        raise TemplateError(f"{where}: '{head}' takes no condition")
                    out[-1] = If(prev.line, prev.branches, body)
            elif head == "for":
                out.append(_for(cond_text, body, ln.number, where))
            else:
                out.append(While(ln.number, _expr(cond_text, where), body))
            continue
        if i < len(lines) and lines[i].indent > indent:
            raise TemplateError(
                f"{what}, line {lines[i].number}: unexpected indent (only if, else if, "
                "otherwise, for, while, try and on error take an indented block)"
            )
        stmt = _simple(ln, where, out)
        if stmt is not None:
            out.append(stmt)
    return tuple(out), i


def _body(lines, i, header: _Line, what, depth):
    if i >= len(lines) or lines[i].indent <= header.indent:
        raise TemplateError(
            f"{what}, line {header.number}: '{header.text}' needs an indented block under it"
        )
    return _block(lines, i, lines[i].indent, what, depth + 1)


_KEYWORDS = re.compile(r"^(else\s+if|on\s+error|if|for|while|try|else|otherwise)\b\s*(.*)$")


def _keyword(text: str) -> tuple[str | None, str]:
    m = _KEYWORDS.match(text)
    if not m:
        return None, text
    return re.sub(r"\s+", " ", m.group(1)), m.group(2)


_FOR = re.compile(r"^([A-Za-z][A-Za-z0-9_]*)\s+(?:in|∈)\s+(.+)$")


def _for(text: str, body, number: int, where: str) -> For:
    from ..language.ranges import parse_range

    m = _FOR.match(text)
    if not m:
        raise TemplateError(f"{where}: write 'for i in FIRST .. LAST' (or FIRST, SECOND .. LAST)")
    rng = parse_range(f"{m.group(1)} := {m.group(2)}", what=where)
    return For(number, rng.var, rng.first, rng.second, rng.last, body)


def _simple(ln: _Line, where: str, out: list[Stmt]) -> Stmt | None:
    """A one-line statement; ``VALUE otherwise`` joins the ``if`` before it (returns None)."""
    text = ln.text.replace("←", ":=")
    marks = _top_keywords(text, where)
    ifs = [c for w, c in marks if w == "if"]
    others = [c for w, c in marks if w in ("else", "otherwise")]
    if others and not ifs:
        col = others[0]
        if text[col:].strip() != "otherwise":
            raise TemplateError(f"{where}: write 'VALUE otherwise' (nothing after otherwise)")
        prev = out[-1] if out else None
        if not isinstance(prev, If) or prev.otherwise is not None:
            raise TemplateError(f"{where}: 'otherwise' without an 'if' before it")
        out[-1] = If(prev.line, prev.branches, (_plain(text[:col].strip(), ln.number, where),))
        return None
    if ifs and not others:
        if len(ifs) > 1:
            raise TemplateError(f"{where}: more than one 'if' on a line")
        col = ifs[0]
        cond = _expr(text[col + 2 :].strip(), where)
        stmt = _plain(text[:col].strip(), ln.number, where)
        return If(ln.number, ((cond, (stmt,)),), None)
    return _plain(text, ln.number, where)  # an inline 'a if c otherwise b' is an expression


def _plain(text: str, number: int, where: str) -> Stmt:
    if not text:
        raise TemplateError(f"{where}: a statement is missing before 'if'/'otherwise'")
    word = text.split(None, 1)
    if word[0] == "return":
        if len(word) == 1:
            raise TemplateError(f"{where}: 'return' needs a value")
        return Return(number, _expr(word[1], where))
    if text == "break":
        return Break(number)
    if text == "continue":
        return Continue(number)
    if word[0] in ("break", "continue"):
        raise TemplateError(f"{where}: '{word[0]}' takes nothing after it (or 'if CONDITION')")
    if ":=" in text:
        name, _, value = text.partition(":=")
        name = name.strip()
        if "[" in name:
            target = _expr(name, where)
            if isinstance(target, ex.Index) and isinstance(target.target, ex.Name):
                return SetItem(number, target.target.id, target.indices, _expr(value, where))
        if not ex.is_identifier(name):
            raise TemplateError(
                f"{where}: cannot assign to {name!r} (a local is a plain name, or v[i], M[i, j])"
            )
        return Assign(number, name, _expr(value, where))
    if re.match(r"^[A-Za-z][A-Za-z0-9_]*\s*=[^=]", text):
        raise TemplateError(f"{where}: a local is given its value with ':=' (not '=')")
    return Value(number, _expr(text, where))


def _top_keywords(text: str, where: str) -> list[tuple[str, int]]:
    """(word, column) of 'if', 'else', 'otherwise' outside brackets and strings."""
    found, depth = [], 0
    try:
        for tok in tokenize.generate_tokens(io.StringIO(text).readline):
            if tok.type == tokenize.OP and tok.string in "([{":
                depth += 1
            elif tok.type == tokenize.OP and tok.string in ")]}":
                depth -= 1
            elif tok.type == tokenize.NAME and depth == 0:
                if tok.string in ("if", "else", "otherwise"):
                    found.append((tok.string, tok.start[1]))
    except (tokenize.TokenError, SyntaxError, IndentationError) as err:
        raise TemplateError(f"{where}: cannot read {text!r}: {err}") from None
    return found


def _expr(text: str, where: str) -> ex.Node:
    if not text.strip():
        raise TemplateError(f"{where}: an expression is missing")
    return ex.parse(text, what=where)
