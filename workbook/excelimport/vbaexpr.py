"""VBA expressions: a tokenizer and a precedence parser into small tuples.

Nodes: ``("num", text)``, ``("str", text)``, ``("id", name)``, ``("call", base, args)``
(an argument is a node, ``None`` when left out, or ``("named", name, node)``),
``("mem", base, name)``, ``("bin", op, left, right)``, ``("un", op, operand)``.
Operators are kept as VBA spells them, keywords in lower case (``and``, ``mod``, ``not``).
"""

from __future__ import annotations

import re


class VbaSyntax(Exception):
    """A VBA expression this reader cannot parse."""


_TOKEN = re.compile(
    r"""\s*(?:
      (?P<hex>&H[0-9A-Fa-f]+&?)
    | (?P<num>(?:\d+\.?\d*|\.\d+)(?:[eEdD][+-]?\d+)?[#!@%&]?)
    | (?P<str>"(?:[^"]|"")*")
    | (?P<date>\#[^#]*\#)
    | (?P<id>\[[^\]]+\]|[A-Za-z_][A-Za-z0-9_]*[$%!#@&]?)
    | (?P<op>:=|<=|>=|<>|=<|=>|[-+*/\\^&=<>(),.!:])
    )""",
    re.X,
)

_KEYWORD_OPS = {"and", "or", "not", "xor", "mod", "is", "like", "eqv", "imp"}

#: binary precedence (higher binds tighter); VBA: ^ > unary - > * / > \ > Mod > + - > & >
#: comparisons > Not > And > Or > Xor > Eqv > Imp
BINARY = {
    "imp": 1,
    "eqv": 2,
    "xor": 3,
    "or": 4,
    "and": 5,
    "=": 7,
    "<>": 7,
    "<": 7,
    ">": 7,
    "<=": 7,
    ">=": 7,
    "is": 7,
    "like": 7,
    "&": 8,
    "+": 9,
    "-": 9,
    "mod": 10,
    "\\": 11,
    "*": 12,
    "/": 12,
    "^": 14,
}
NOT_LEVEL = 6
NEG_LEVEL = 13


def tokens(text: str) -> list[tuple[str, str]]:
    out = []
    pos = 0
    text = text.rstrip()
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if not m or m.end() == pos:
            raise VbaSyntax(f"cannot read {text[pos : pos + 20]!r}")
        pos = m.end()
        kind = m.lastgroup
        value = m.group(kind)
        if kind == "id" and value.lower() in _KEYWORD_OPS:
            kind, value = "op", value.lower()
        elif kind == "op":
            value = {"=<": "<=", "=>": ">="}.get(value, value)
        out.append((kind, value))
    return out


class Parser:
    def __init__(self, text: str):
        self.toks = tokens(text)
        self.i = 0

    def peek(self, k: int = 0):
        j = self.i + k
        return self.toks[j] if j < len(self.toks) else ("end", "")

    def take(self):
        t = self.peek()
        self.i += 1
        return t

    def expect(self, value: str):
        t = self.take()
        if t[1] != value:
            raise VbaSyntax(f"expected {value!r}, found {t[1]!r}")

    def at_end(self) -> bool:
        return self.i >= len(self.toks)

    def expr(self, level: int = 0):
        kind, value = self.peek()
        if kind == "op" and value == "not":
            self.take()
            left = ("un", "not", self.expr(NOT_LEVEL))
        elif kind == "op" and value in ("-", "+"):
            self.take()
            left = ("un", value, self.expr(NEG_LEVEL))
        else:
            left = self.postfix()
        while True:
            kind, value = self.peek()
            if kind != "op" or value not in BINARY:
                return left
            prec = BINARY[value]
            if prec <= level:
                return left
            self.take()
            if value == "is" and self.peek()[1] == "not":  # Is Not Nothing
                self.take()
                value = "isnot"
            right = self.expr(prec)  # all VBA binary operators are left-associative
            left = ("bin", value, left, right)

    def postfix(self):
        node = self.primary()
        while True:
            kind, value = self.peek()
            if value == "(" and kind == "op":
                self.take()
                node = ("call", node, self.args())
            elif value in (".", "!") and kind == "op":
                self.take()
                k2, name = self.take()
                if k2 != "id":
                    raise VbaSyntax(f"a member name expected after '.', found {name!r}")
                node = ("mem", node, name)
            else:
                return node

    def args(self) -> list:
        out: list = []
        if self.peek()[1] == ")":
            self.take()
            return out
        while True:
            if self.peek()[1] in (",", ")"):
                out.append(None)
            elif self.peek()[0] == "id" and self.peek(1)[1] == ":=":
                name = self.take()[1]
                self.take()
                out.append(("named", name, self.expr()))
            else:
                out.append(self.expr())
            t = self.take()
            if t[1] == ")":
                return out
            if t[1] != ",":
                raise VbaSyntax(f"expected ',' or ')', found {t[1]!r}")

    def primary(self):
        kind, value = self.take()
        if kind == "num":
            return ("num", value.rstrip("#!@%&").replace("d", "e").replace("D", "e"))
        if kind == "hex":
            return ("num", str(int(value[2:].rstrip("&"), 16)))
        if kind == "str":
            return ("str", value[1:-1].replace('""', '"'))
        if kind == "id":
            return ("id", value.rstrip("$%!#@&"))
        if kind == "op" and value == "(":
            inner = self.expr()
            self.expect(")")
            return ("paren", inner)
        if kind == "op" and value == ".":  # a member of a With block
            k2, name = self.take()
            return ("mem", ("id", "__with__"), name)
        raise VbaSyntax(f"unexpected {value or 'end of line'!r}")


def parse(text: str):
    """The expression tree of VBA text (VbaSyntax if it is not one whole expression)."""
    p = Parser(text)
    node = p.expr()
    if not p.at_end():
        raise VbaSyntax(f"unexpected {p.peek()[1]!r}")
    return node


def strip(node):
    """The node without the brackets written around it."""
    while node is not None and node[0] == "paren":
        node = node[1]
    return node
