"""``On Error GoTo LABEL`` in a VBA function, as documented: an error in the function (or in
what it calls) jumps to the label. Where the code at the label only gives the function an
error value (``CVErr(...)``) or raises the error again (``Err.Raise``), choosing between them
by ``Err.Number``, the cell shows an error value whatever the error was: the translation is
the code before the label, and an error there leaves the function without a value, as the
cell has none. A handler that gives a number, resumes, or does anything else is refused."""

from __future__ import annotations

import re

from .vbamembers import NotTranslated

_GOTO = re.compile(r"^on\s+error\s+goto\s+([A-Za-z_]\w*):?$", re.I)
_HANDLER_LINES = (
    re.compile(r"^(?:else\s*)?if\s+err\.number\s*(?:=|<>)\s*[\w.()-]+\s+then$", re.I),
    re.compile(r"^(?:else|end\s+if|exit\s+function)$", re.I),
    re.compile(r"^err\.raise\b", re.I),
)


#: Excel's error values as ``Err.Number`` could hold them: only where ``Err.Raise`` raised one
#: (none is the number of an error of VBA itself, such as 11, division by zero)
XL_ERRORS = {
    "xlerrdiv0": 2007, "xlerrna": 2042, "xlerrname": 2029, "xlerrnull": 2000,
    "xlerrnum": 2036, "xlerrref": 2023, "xlerrvalue": 2015,
}  # fmt: skip
_BRANCH = re.compile(r"^(?:else\s*)?if\s+err\.number\s*=\s*([\w.]+)\s+then$", re.I)
_RAISE = re.compile(r"\berr\.raise\s*\(?\s*([\w.]+)", re.I)


def raised_errors(procs) -> set[str] | None:
    """The Excel error values (``xlErrNA``...) that ``Err.Raise`` raises in the procedures'
    lines; None where one raises a number of another kind (then any may be)."""
    out: set[str] = set()
    by_number = {v: k for k, v in XL_ERRORS.items()}
    for proc in procs:
        for m in (m for _, text in proc.lines for m in _RAISE.finditer(text)):
            what = m.group(1).lower().removeprefix("excel.")
            rest = m.string[m.end() :].lstrip()
            if rest and rest[0] not in ",):'":  # a number computed (vbObjectError + 7)
                return None
            if what == "err.number":  # raised again: a number some error had already
                continue
            if what in XL_ERRORS:
                out.add(what)
            elif what.isdigit() and int(what) in by_number:
                out.add(by_number[int(what)])
            elif not what.isdigit() or 2000 <= int(what) <= 2042:
                return None
    return out


def cut_error_handler(
    name: str, body: list[tuple[int, str]], raised: set[str] | None = None
) -> list[tuple[int, str]]:
    """The body without its ``On Error GoTo`` line and its handler, where the handler gives
    only error values (else NotTranslated, naming the line); the body as it is without one.
    A branch ``If Err.Number = xlErrDiv0 Then`` of an Excel error value that no ``Err.Raise``
    of the project (``raised``, None if unknown) raises is never taken, whatever it does."""
    starts = [k for k, (_, text) in enumerate(body) if _GOTO.match(text.strip())]
    if not starts:
        return body
    if len(starts) > 1:
        raise NotTranslated(f"line {body[starts[1]][0]}: a second On Error GoTo")
    h = starts[0]
    label = _GOTO.match(body[h][1].strip()).group(1)
    at = next(
        (k for k, (_, t) in enumerate(body) if t.strip().lower() == f"{label.lower()}:"), None
    )
    if at is None or at < h:
        raise NotTranslated(f"line {body[h][0]}: On Error GoTo {label} without its label")
    if at == 0 or body[at - 1][1].strip().lower() != "exit function":
        raise NotTranslated(
            f"line {body[at][0]}: the code runs on into the error path at {label} (no Exit "
            "Function before it)"
        )
    error_value = re.compile(rf"^{re.escape(name)}\s*=\s*CVErr\s*\(.*\)$", re.I)
    dead = False  # in a branch for an Err.Number that no error in the project has
    for number, text in body[at + 1 :]:
        text = text.strip()
        branch = _BRANCH.match(text)
        if branch is not None or re.fullmatch(r"else|end\s+if", text, re.I):
            key = None if branch is None else branch.group(1).lower().removeprefix("excel.")
            dead = raised is not None and key in XL_ERRORS and key not in raised
        if dead:
            continue
        if not (error_value.match(text) or any(p.match(text) for p in _HANDLER_LINES)):
            raise NotTranslated(
                f"line {number}: On Error GoTo {label}: the error path does more than give an "
                f"error value ({text[:60]!r})"
            )
    return body[:h] + body[h + 1 : at]
