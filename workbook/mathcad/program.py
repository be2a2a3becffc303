"""Mathcad programs (the Add Line operator) as programs of the language.

A program becomes lines of statements (``a := ...``, ``for i in 1 .. n``, ``while ...``,
``if ...`` blocks, ``value if condition``, ``value otherwise``, ``return``, ``break``,
``continue``), one block indented under its header. Locals are names of their own (never a
name of the sheet). What the language's programs cannot hold (a loop over a vector,
try/catch) is untranslatable.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .. import expr as ex
from . import names as nm
from .symbols import Sym, Untranslatable, what
from .symbols import key as name_key

if TYPE_CHECKING:
    from .reader import MNode

Line = tuple[int, list]  # (indent, parts: text or expression trees)

_SIMPLE = ("localDefine", "return", "break", "continue")


def available() -> bool:
    """Whether the language has programs (a definition may be a program)."""
    from ..template import Definition

    return "program" in getattr(Definition, "__dataclass_fields__", {})


class ProgramTranslator:
    """One Mathcad program (its locals shared by all its lines)."""

    def __init__(self, tr, local: dict, expressions):
        """``tr``: the worksheet's Translator; ``expressions``: the class that translates one
        expression in a scope (``expressions(tr, scope)``)."""
        if not available():
            raise Untranslatable("a program (programs are not in the language yet)")
        self.tr = tr
        self.expressions = expressions
        self.scope = dict(local)  # parameters, then locals as they are assigned
        self.locals: dict[tuple[str, str], Sym] = {}

    def lines(self, program: MNode) -> list[Line]:
        out: list[Line] = []
        self._block(program.children if program.tag == "program" else [program], 0, out)
        return out

    # -- statements ---------------------------------------------------------------------------
    def _block(self, stmts: list[MNode], indent: int, out: list[Line]) -> None:
        if not stmts:
            raise Untranslatable("an empty program block")
        i = 0
        while i < len(stmts):
            s = stmts[i]
            nxt = stmts[i + 1] if i + 1 < len(stmts) else None
            if s.tag == "ifThen" and nxt is not None and nxt.tag == "otherwise":
                other = nxt.children[0]
                if (
                    self._one_line(s.children[1])
                    and self._one_line(other)
                    and other.tag not in _SIMPLE
                ):
                    self._stmt(s, indent, out)
                    self._stmt(nxt, indent, out)
                else:  # block form: if ... / otherwise
                    self._if_block(s, indent, out)
                    out.append((indent, ["otherwise"]))
                    self._body(nxt.children[0], indent + 4, out)
                i += 2
                continue
            self._stmt(s, indent, out)
            i += 1

    def _one_line(self, body: MNode) -> bool:
        return body.tag != "program" and body.tag not in ("for", "while", "ifThen")

    def _body(self, body: MNode, indent: int, out: list[Line]) -> None:
        self._block(body.children if body.tag == "program" else [body], indent, out)

    def _if_block(self, s: MNode, indent: int, out: list[Line]) -> None:
        cond, body = s.children
        out.append((indent, ["if ", self._expr(cond)]))
        self._body(body, indent + 4, out)

    def _stmt(self, s: MNode, indent: int, out: list[Line]) -> None:
        tag = s.tag
        if tag == "localDefine":
            out.append((indent, self._assign(s)))
        elif tag == "return":
            out.append((indent, ["return ", self._expr(s.children[0])]))
        elif tag in ("break", "continue"):
            out.append((indent, [tag]))
        elif tag == "ifThen":
            cond, body = s.children
            if body.tag in _SIMPLE or self._one_line(body):
                parts = self._simple(body)
                out.append((indent, [*parts, " if ", self._expr(cond)]))
            else:
                self._if_block(s, indent, out)
        elif tag == "otherwise":
            body = s.children[0]
            if not self._one_line(body) or body.tag in _SIMPLE:
                raise Untranslatable("an 'otherwise' that is not a value after an 'if' line")
            out.append((indent, [self._expr(body), " otherwise"]))
        elif tag == "for":
            var, over, body = s.children
            if over.tag != "range":
                raise Untranslatable("a for loop over the elements of a vector")
            head = self._range(over)
            out.append((indent, ["for ", self._local(var), " in ", *head]))
            self._body(body, indent + 4, out)
        elif tag == "while":
            cond, body = s.children
            out.append((indent, ["while ", self._expr(cond)]))
            self._body(body, indent + 4, out)
        elif tag == "program":
            self._block(s.children, indent, out)
        elif tag in ("tryCatch", "onError"):
            raise Untranslatable(f"{what(tag)} in a program")
        else:
            out.append((indent, [self._expr(s)]))

    def _simple(self, body: MNode) -> list:
        if body.tag == "localDefine":
            return self._assign(body)
        if body.tag == "return":
            return ["return ", self._expr(body.children[0])]
        if body.tag in ("break", "continue"):
            return [body.tag]
        return [self._expr(body)]

    def _assign(self, s: MNode) -> list:
        lhs, rhs = s.children
        if lhs.tag == "apply" and len(lhs.children) == 3 and lhs.children[0].tag == "indexer":
            return self._element(lhs, rhs)
        if lhs.tag != "id":
            raise Untranslatable("an assignment to something that is not a name in a program")
        value = self._expr(rhs)  # the right side sees the local's previous value
        return [self._local(lhs), " := ", value]

    def _element(self, lhs: MNode, rhs: MNode) -> list:
        """v[i] <- value: an element of a local vector; one the program has not given, or
        an index beyond its length, makes or grows it (the language does where the length
        is known at load, and says why not where it is not)."""
        target = lhs.children[1]
        if target.tag != "id":
            raise Untranslatable("an element assignment to something that is not a name")
        value = self._expr(rhs)  # the right side sees the vector before the assignment
        if name_key(target) not in self.locals:
            if name_key(target) in self.scope:  # a parameter or a name of the sheet
                raise Untranslatable(
                    "an element assignment to a vector the program has not given (Mathcad "
                    "copies the argument or the sheet's vector into a local)"
                )
            self._local(target)
        index = self._expr(lhs)  # v[i] as an expression: the index tree, shifted by ORIGIN
        return [index, " := ", value]

    def _local(self, node: MNode) -> ex.Node:
        if node.tag != "id":
            raise Untranslatable("a program local that is not a name")
        key = name_key(node)
        sym = self.locals.get(key)
        if sym is None:
            sym = self.tr.new_sym("local", nm.identifier(*key), nm.mathcad_text(*key))
            self.locals[key] = sym
            self.scope[key] = sym
        return ex.Name(sym.token())

    def _range(self, rng: MNode) -> list:
        first = rng.children[0]
        if first.tag == "sequence":
            a, b = (self._expr(c) for c in first.children[:2])
            head = [a, ", ", b]
        else:
            head = [self._expr(first)]
        return [*head, " .. ", self._expr(rng.children[1])]

    def _expr(self, node: MNode) -> ex.Node:
        et = self.expressions(self.tr, self.scope)
        tree = et.visit(node)
        if et.ranges:
            raise Untranslatable("a program over a range variable")
        return tree
