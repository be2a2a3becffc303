"""Mathcad programs (the Add Line operator) as programs of the language.

A program becomes lines of statements (``a := ...``, ``for i in 1 .. n``, ``while ...``,
``if ...`` blocks, ``value if condition``, ``value otherwise``, ``return``, ``break``,
``continue``), one block indented under its header. Locals are names of their own (never a
name of the sheet). Prime's try / on error is ``try`` and ``on error`` over their blocks,
where what counts as an error is the same in Mathcad and the engine (:func:`unsure_builtin`). What
the language's programs cannot hold (a loop over a vector) is untranslatable.
"""

from __future__ import annotations

from ..language import expr as ex
from . import names as nm
from .reader import MNode
from .symbols import Sym, Untranslatable, matrix_size
from .symbols import key as name_key
from .translation import Item

Line = tuple[int, list]  # (indent, parts: text or expression trees)

_SIMPLE = ("localDefine", "return", "break", "continue")


class ProgramTranslator:
    """One Mathcad program (its locals shared by all its lines)."""

    def __init__(self, tr, local: dict, expressions):
        """``tr``: the worksheet's Translator; ``expressions``: the class that translates one
        expression in a scope (``expressions(tr, scope)``)."""
        self.tr = tr
        self.expressions = expressions
        self.params = dict(local)
        self.scope = dict(local)  # parameters, then locals as they are assigned
        self.locals: dict[tuple[str, str], Sym] = {}
        self.loops = 0  # loops around the statement being translated
        self.taken: set[str] = set()  # identifiers of the program's names
        self.assignments: dict[tuple[str, str], int] = {}  # whole assignments of each name
        self.zero_started: set[tuple[str, str]] = set()  # locals Mathcad starts at 0

    def lines(self, program: MNode) -> list[Line]:
        program = _one_index_locals(program, set(self.params))
        body = program.children if program.tag == "program" else [program]
        self.taken = {nm.identifier(*name_key(n)) for n in _walk(program) if n.tag == "id"}
        self.assignments = _assignments(body)
        out: list[Line] = []
        self._copies(body, out)
        self._zero_starts(body, out)
        self._block(body, 0, out, tail=True)
        return out

    # -- what Mathcad gives every program before its first line ---------------------------------
    def _copies(self, body: list[MNode], out: list[Line]) -> None:
        """Mathcad's parameters are the program's own copies: one whose elements the program
        sets, or that it sets inside a block (so that a later line reads it on every path),
        becomes a local copy on the first line (``A_local := A``)."""
        whole, elements = _targets(body)
        for key, sym in self.params.items():
            if key in elements or whole.get(key):
                copy = self._fresh(f"{sym.base}_local")
                self.locals[key] = copy
                self.scope[key] = copy
                out.append((0, [ex.Name(copy.token()), " := ", ex.Name(sym.token())]))

    def _zero_starts(self, body: list[MNode], out: list[Line]) -> None:
        """Mathcad starts every local at 0: a local the program reads before it has given it
        on some path (``s := s + x``, or set in one branch only) starts at 0 on the first
        line (``s := 0``). A vector made by its elements (``l[rows(l) + 1] := x``) is 0
        until its first element is set in the language too; it gets the line only where the
        program reads it whole first (``if res != 0``), so that the program says so."""
        whole, elements = _targets(body)
        assigned = set(whole) | elements
        given = set(self.params) | set(self.locals)
        given |= {k for k, s in self.tr.scope.items() if s.kind != "func"}
        flagged: list[tuple[str, str]] = []

        def read(node: MNode, have: set, own=None) -> None:
            for key, indexed in _reads(node):
                if key not in assigned or key in have or key in flagged or key == own:
                    continue
                if indexed and key in elements:
                    continue
                flagged.append(key)

        def run(stmts: list[MNode], have: set | None) -> set | None:
            i = 0
            while i < len(stmts) and have is not None:
                s = stmts[i]
                nxt = stmts[i + 1] if i + 1 < len(stmts) else None
                if s.tag == "ifThen":
                    cond, then = s.children
                    read(cond, have)
                    a = run(_statements(then), set(have))
                    if nxt is not None and nxt.tag == "otherwise":
                        b = run(_statements(nxt.children[0]), set(have))
                        have = b if a is None else a if b is None else a & b
                        i += 2
                        continue
                elif s.tag == "otherwise":
                    run(_statements(s.children[0]), set(have))
                elif s.tag == "for":
                    var, over, loop = s.children
                    read(over, have)
                    have = have | {name_key(var)} if var.tag == "id" else have
                    run(_statements(loop), set(have))
                elif s.tag == "while":
                    read(s.children[0], have)
                    run(_statements(s.children[1]), set(have))
                elif s.tag == "tryCatch" and len(s.children) == 2:
                    # the try block may stop at any line: the on error block starts from
                    # what was given before it
                    a = run(_statements(s.children[0]), set(have))
                    b = run(_statements(s.children[1]), set(have))
                    have = b if a is None else a if b is None else a & b
                elif s.tag == "localDefine":
                    lhs, rhs = s.children
                    read(rhs, have)
                    if lhs.tag == "id":
                        have = have | {name_key(lhs)}
                    elif lhs.tag == "matrix":
                        have = have | {name_key(c) for c in lhs.children if c.tag == "id"}
                    elif lhs.tag == "apply" and len(lhs.children) == 3:
                        target = lhs.children[1]
                        own = name_key(target) if target.tag == "id" else None
                        read(lhs.children[2], have, own)
                        if own is not None:
                            have = have | {own}
                elif s.tag in ("return", "break", "continue"):
                    for c in s.children:
                        read(c, have)
                    have = None
                elif s.tag == "program":
                    have = run(s.children, have)
                elif not (s.tag == "id" and name_key(s) in elements):  # a value line
                    read(s, have)
                i += 1
            return have

        run(body, given)
        self.zero_started = set(flagged)
        for key in flagged:
            sym = self._local_key(key)
            out.append((0, [ex.Name(sym.token()), " := ", ex.Number(0.0)]))

    # -- statements ---------------------------------------------------------------------------
    def _block(self, stmts: list[MNode], indent: int, out: list[Line], tail: bool) -> None:
        """``tail``: nothing runs after this block in the program (a ``break`` outside any
        loop there ends the program without a value, as in Mathcad)."""
        if not stmts:
            raise Untranslatable("an empty program block")
        i = 0
        while i < len(stmts):
            s = stmts[i]
            nxt = stmts[i + 1] if i + 1 < len(stmts) else None
            if s.tag == "ifThen" and nxt is not None and nxt.tag == "otherwise":
                last = tail and i + 2 >= len(stmts)
                other = nxt.children[0]
                if self.loops == 0 and (_is_break(s.children[1]) or _is_break(other)):
                    self._stopping_if(s, other, indent, out, last)
                elif (
                    self._one_line(s.children[1])
                    and self._one_line(other)
                    and other.tag not in _SIMPLE
                ):
                    self._stmt(s, indent, out, last)
                    self._stmt(nxt, indent, out, last)
                else:  # block form: if ... / otherwise
                    self._if_block(s, indent, out, last)
                    out.append((indent, ["otherwise"]))
                    self._body(other, indent + 4, out, last)
                i += 2
                continue
            self._stmt(s, indent, out, tail and i == len(stmts) - 1)
            i += 1

    def _stopping_if(self, s: MNode, other: MNode, indent: int, out: list[Line], last: bool):
        """``if C: break`` / ``otherwise: X`` (or the other way round) outside any loop: the
        branch that breaks ends the program without a value; the other is kept (``X if not
        C``)."""
        if not last:
            raise Untranslatable(_BREAK_WHY)
        cond, then = s.children
        if _is_break(then) and _is_break(other):
            return
        if _is_break(other):
            self._stmt(s, indent, out, last)
            return
        negated = _negate(self._cond(cond))
        if self._one_line(other) and other.tag not in ("break", "continue"):
            out.append((indent, [*self._simple(other), " if ", negated]))
        else:
            out.append((indent, ["if ", negated]))
            self._body(other, indent + 4, out, last)

    def _one_line(self, body: MNode) -> bool:
        if body.tag == "localDefine" and body.children[0].tag == "matrix":
            return False  # destructuring: several lines
        if body.tag == "localDefine" and _is_column(body.children[0]):
            return False  # a column: a loop
        return body.tag != "program" and body.tag not in ("for", "while", "ifThen")

    def _body(self, body: MNode, indent: int, out: list[Line], tail: bool = False) -> None:
        start = len(out)
        self._block(body.children if body.tag == "program" else [body], indent, out, tail)
        if len(out) == start:
            raise Untranslatable("a block that only stops the program (break outside a loop)")

    def _if_block(self, s: MNode, indent: int, out: list[Line], tail: bool = False) -> None:
        cond, body = s.children
        out.append((indent, ["if ", self._cond(cond)]))
        self._body(body, indent + 4, out, tail)

    def _stmt(self, s: MNode, indent: int, out: list[Line], tail: bool = False) -> None:
        tag = s.tag
        if tag == "localDefine":
            for extra, parts in self._assign(s):
                out.append((indent + extra, parts))
        elif tag == "return":
            out.append((indent, ["return ", self._expr(s.children[0])]))
        elif tag in ("break", "continue"):
            if self.loops == 0:
                if tag == "continue" or not tail:
                    raise Untranslatable(_BREAK_WHY if tag == "break" else _CONTINUE_WHY)
                return  # the program ends here without a value, as Mathcad's stops
            out.append((indent, [tag]))
        elif tag == "ifThen":
            cond, body = s.children
            if self.loops == 0 and _is_break(body):
                if not tail:
                    raise Untranslatable(_BREAK_WHY)
                return  # it ends the program either way: without a value
            if body.tag in _SIMPLE or self._one_line(body):
                parts = self._simple(body)
                out.append((indent, [*parts, " if ", self._cond(cond)]))
            else:
                self._if_block(s, indent, out, tail)
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
            self._loop_body(body, indent + 4, out)
        elif tag == "while":
            cond, body = s.children
            out.append((indent, ["while ", self._cond(cond)]))
            self._loop_body(body, indent + 4, out)
        elif tag == "program":
            self._block(s.children, indent, out, tail)
        elif tag == "tryCatch":
            self._try(s, indent, out)
        elif tag == "onError":
            raise Untranslatable(_ON_ERROR_WHY)
        else:
            out.append((indent, [self._expr(s)]))

    def _try(self, s: MNode, indent: int, out: list[Line]) -> None:
        """Prime's try / on error: the try block runs; if an error is raised in it, the on
        error block runs from there. Translated only where the try block (and what it reads
        of the worksheet) raises an error where Mathcad does (:func:`unsure_builtin`)."""
        if len(s.children) != 2:
            raise Untranslatable("a try / on error without its two blocks")
        body, handler = s.children
        start = len(out)
        out.append((indent, ["try"]))
        self._body(body, indent + 4, out)
        why = self._unsure([p for _, parts in out[start:] for p in parts if not isinstance(p, str)])
        if why:
            raise Untranslatable(f"a try / on error whose try block {why}")
        out.append((indent, ["on error"]))
        self._body(handler, indent + 4, out)

    def _unsure(self, trees: list[ex.Node]) -> str:
        """Why an error raised in ``trees`` (and in the worksheet's definitions and functions
        they read) may not be Mathcad's: '' where it is."""
        items = {i.sym.token(): i for i in self.tr.out.items if i.sym is not None}
        solved = {
            sym.token(): sym
            for i in self.tr.out.items
            if i.kind == "solve"
            for sym, _ in i.solve[0]
        }
        by_token = {sym.token(): sym for sym in self.tr.out.syms}
        seen: set[str] = set()
        todo = list(trees)
        while todo:
            for node in ex.walk(todo.pop()):
                name = node.func if isinstance(node, ex.Call) else getattr(node, "id", None)
                why = unsure_builtin(node.func) if isinstance(node, ex.Call) else ""
                if why:
                    return f"calls {node.func}(): {why}"
                if isinstance(node, ex.Binary) and node.op == "^" and not _whole(node.right):
                    return (
                        "raises to a power that is not a whole number written (Mathcad's power "
                        "of a negative number is complex, the engine's an error)"
                    )
                if name in solved:
                    return (
                        f"reads {solved[name].mathcad}, a solve block's solution (whether a "
                        "solver fails is that solver's own)"
                    )
                if name in items and name not in seen:
                    seen.add(name)
                    todo += _item_trees(items[name])
                elif name in by_token and by_token[name].kind == "func" and name not in items:
                    return f"calls {by_token[name].mathcad}, whose body is not known here"
        return ""

    def _loop_body(self, body: MNode, indent: int, out: list[Line]) -> None:
        self.loops += 1
        try:
            self._body(body, indent, out)
        finally:
            self.loops -= 1

    def _simple(self, body: MNode) -> list:
        if body.tag == "localDefine":
            lines = self._assign(body)
            if len(lines) != 1:
                raise Untranslatable("an assignment of several lines on an 'if' line")
            return lines[0][1]
        if body.tag == "return":
            return ["return ", self._expr(body.children[0])]
        if body.tag in ("break", "continue"):
            return [body.tag]
        return [self._expr(body)]

    def _assign(self, s: MNode) -> list[tuple[int, list]]:
        """The lines of one assignment: (indent under the statement's, parts)."""
        lhs, rhs = s.children
        if lhs.tag == "apply" and len(lhs.children) == 3 and lhs.children[0].tag == "indexer":
            return [(0, self._element(lhs, rhs))]
        if _is_column(lhs):
            return self._column(lhs, rhs)
        if lhs.tag == "matrix":
            return self._destructure(lhs, rhs)
        if lhs.tag == "function":
            self._local_function(lhs, rhs)
            return []
        if lhs.tag != "id":
            raise Untranslatable("an assignment to something that is not a name in a program")
        if rhs.tag == "program":
            value = self._subprogram(lhs, rhs)
            return [(0, [self._local(lhs), " := ", value])]
        if _runtime_matrix(rhs, self.scope):
            tmp = ex.Name(self._fresh("matrix").token())
            return [*self._matrix_lines(tmp, rhs), (0, [self._local(lhs), " := ", tmp])]
        value = self._expr(rhs)  # the right side sees the local's previous value
        return [(0, [self._local(lhs), " := ", value])]

    def _subprogram(self, lhs: MNode, rhs: MNode) -> ex.Node:
        """k <- program: the inner program's value (Mathcad's: that of the last line it ran,
        a false ``if`` line running nothing) as a function of the sheet's of its own, called
        with the parameters it reads; one that runs no value line is then an error of that
        function, never a value. It may read the program's parameters and the sheet's names,
        not the program's locals, nor set a name of the program."""
        inner = rhs.children
        whole, elements = _targets(inner)
        sets = (set(whole) | elements) & (set(self.scope) | set(self.params))
        read = {key for key, _ in _reads(rhs)} - set(whole) - elements
        locals_read = sorted(s.mathcad for k, s in self.locals.items() if k in read)
        if sets or locals_read:
            names = sorted(self.scope[k].mathcad for k in sets if k in self.scope) + locals_read
            raise Untranslatable(
                f"a program as the value of a local that reads or sets the program's "
                f"{', '.join(names)}"
            )
        # the parameters the local functions it may call read are its parameters too
        tokens = {
            t
            for s in self.scope.values()
            if s.token() in self.tr.inline
            for t in ex.names(self.tr.inline[s.token()][1])
        }
        params = [(k, s) for k, s in self.params.items() if k in read or s.token() in tokens]
        fixed_locals = [s.mathcad for s in self.locals.values() if s.token() in tokens]
        if fixed_locals:
            raise Untranslatable(
                "a program as the value of a local that calls a local function reading the "
                f"program's {', '.join(sorted(fixed_locals))}"
            )
        scope = dict(params)
        scope |= {k: s for k, s in self.scope.items() if s.kind == "func"}  # local functions
        # a program of the language (not pieces): its arguments may be arrays
        parts = {"program": ProgramTranslator(self.tr, scope, self.expressions).lines(rhs)}
        base = f"{nm.identifier(*name_key(lhs))}_value"
        if not params:
            sym = self.tr.new_sym("var", base, base, self.tr.region, generated=True)
            self.tr.out.items.append(Item("definition", self.tr.region, sym=sym, **parts))
            return ex.Name(sym.token())
        sym = self.tr.new_sym("func", base, base, self.tr.region, generated=True)
        psyms = [s for _, s in params]
        self.tr.out.items.append(Item("function", self.tr.region, sym=sym, params=psyms, **parts))
        args = tuple(ex.Name(s.token()) for s in psyms)
        self.tr.calls.setdefault(sym, []).append(args)
        return ex.Call(sym.token(), args)

    def _local_function(self, lhs: MNode, rhs: MNode) -> None:
        """f(x, y) <- EXPR: a local function, written out at each call (``f(2, 3)`` is EXPR
        with x = 2, y = 3). Its EXPR may read its parameters and the sheet's names, not the
        program's locals (whose values may change between the definition and a call)."""
        fname, bound = lhs.children[0], lhs.find("boundVars")
        if fname.tag != "id" or bound is None or any(p.tag != "id" for p in bound.children):
            raise Untranslatable("a local function whose name or parameters are not names")
        params = {}
        for p in bound.children:
            key = name_key(p)
            params[key] = self.tr.new_sym("param", nm.identifier(*key), nm.mathcad_text(*key))
        et = self.expressions(self.tr, {**self.scope, **params})
        body = et.value(rhs)
        if et.ranges:
            raise Untranslatable("a local function over a range variable")
        # a local given once, before this line and never again, has one value at every
        # call; a parameter too (one the program sets is a local copy)
        fixed = {
            s.token()
            for k, s in self.locals.items()
            if self.assignments.get(k) == 1 and k not in self.zero_started and k not in self.params
        }
        program_locals = {s.token() for s in self.locals.values()} - fixed
        read = ex.names(body) & program_locals
        if read:
            names = sorted(s.mathcad for s in self.locals.values() if s.token() in read)
            raise Untranslatable(
                f"a local function that reads the program's {', '.join(names)}, which the "
                "program sets more than once"
            )
        sym = self.tr.new_sym(
            "func", nm.identifier(*name_key(fname)), nm.mathcad_text(*name_key(fname))
        )
        self.tr.inline[sym.token()] = ([q.token() for q in params.values()], body)
        self.scope[name_key(fname)] = sym

    def _element(self, lhs: MNode, rhs: MNode) -> list:
        """v[i] <- value: an element of a local vector; one the program has not given, or
        an index beyond its length, makes or grows it (the language does where the length
        is known at load, and says why not where it is not)."""
        target = lhs.children[1]
        while target.tag == "parens" and target.children:
            target = target.children[0]
        if target.tag != "id":
            raise Untranslatable("an element assignment to something that is not a name")
        value = self._expr(rhs)  # the right side sees the vector before the assignment
        self._target(target)
        index = self._expr(lhs)  # v[i] as an expression: the index tree, shifted by ORIGIN
        return [index, " := ", value]

    def _target(self, target: MNode) -> ex.Node:
        """The local whose elements an assignment sets (made if the program has not)."""
        if name_key(target) not in self.locals and name_key(target) in self.scope:
            raise Untranslatable(
                "an element assignment to a vector the program has not given (Mathcad "
                "copies the argument or the sheet's vector into a local)"
            )
        return self._local(target)

    def _column(self, lhs: MNode, rhs: MNode) -> list[tuple[int, list]]:
        """M<j> <- v: column j of a local matrix, element by element (a loop over v)."""
        target, j = lhs.children[1], lhs.children[2]
        if target.tag != "id":
            raise Untranslatable("a column assignment to something that is not a name")
        value = self._expr(rhs)  # the right side sees the matrix before the assignment
        lines: list[tuple[int, list]] = []
        if not isinstance(value, ex.Name):
            tmp = self._fresh("column")
            lines.append((0, [ex.Name(tmp.token()), " := ", value]))
            value = ex.Name(tmp.token())
        column = self._shifted(self._expr(j))
        m = self._target(target)
        k = ex.Name(self._fresh("k").token())
        o = self.tr.sheet_origin
        last: ex.Node = ex.Call("rows", (value,))
        if o != 1:
            last = ex.Binary("+" if o > 1 else "-", last, ex.Number(float(abs(o - 1))))
        lines.append((0, ["for ", k, " in ", ex.Number(float(o)), " .. ", last]))
        lines.append((4, [ex.Index(m, (k, column)), " := ", ex.Index(value, (k,))]))
        return lines

    def _destructure(self, lhs: MNode, rhs: MNode) -> list[tuple[int, list]]:
        """[a; b; c] <- value: each name an element of the value (a local of its own first),
        at Mathcad's ORIGIN."""
        rows, cols = matrix_size(lhs)
        names = lhs.children
        if rows * cols != len(names) or not names:
            raise Untranslatable("a matrix of names whose size does not match its elements")
        if any(n.tag != "id" for n in names):
            raise Untranslatable("an assignment to a matrix of something that is not names")
        if (
            rhs.tag == "matrix"
            and matrix_size(rhs) == (rows, cols)
            and len(rhs.children) == len(names)
        ):
            return self._destructure_literal(names, rhs.children)
        value = self._expr(rhs)
        tmp = ex.Name(self._fresh("parts").token())
        lines: list[tuple[int, list]] = [(0, [tmp, " := ", value])]
        o = self.tr.sheet_origin
        for c in range(cols):
            for r in range(rows):
                at = (r,) if cols == 1 else (r, c)
                index = tuple(ex.Number(float(o + a)) for a in at)
                name = self._local(names[c * rows + r])
                lines.append((0, [name, " := ", ex.Index(tmp, index)]))
        return lines

    def _destructure_literal(self, names: list[MNode], values: list[MNode]) -> list[Line]:
        """[a; b] <- [A; B]: each name its element, every element computed before any name
        is set (as Mathcad computes the right side first)."""
        lines: list[Line] = []
        temps = []
        for value in values:
            tmp = ex.Name(self._fresh("part").token())
            if _runtime_matrix(value, self.scope):
                lines += self._matrix_lines(tmp, value)
            else:
                lines.append((0, [tmp, " := ", self._expr(value)]))
            temps.append(tmp)
        for name, tmp in zip(names, temps):
            lines.append((0, [self._local(name), " := ", tmp]))
        return lines

    def _matrix_lines(self, target: ex.Name, rhs: MNode) -> list[Line]:
        """target <- matrix(m, n, f) whose size the program computes: its elements f(i, j),
        i and j from 0 (whatever ORIGIN), set one by one in a matrix made by them. At an
        ORIGIN other than 0, only a function that does not read its arguments (as for a
        size known at import)."""
        m, n, f = rhs.children[1].children
        sym = self.scope.get(name_key(f)) or self.tr.scope.get(name_key(f))
        if sym is None or sym.kind != "func":
            raise Untranslatable("matrix(m, n, f) whose f is not the name of a function")
        if sym.broken:
            raise Untranslatable(f"uses {sym.mathcad}, which is not translated: {sym.broken}")
        if self.tr.origin != 0 and not self.tr.ignores_arguments(sym):
            raise Untranslatable(
                f"matrix(m, n, f) at ORIGIN {self.tr.origin} of a function of its indices "
                "(which indices Mathcad gives f there is not known)"
            )
        rows, cols = self._expr(m), self._expr(n)
        i, j = (ex.Name(self._fresh(b).token()) for b in ("i", "j"))
        if sym.token() in self.tr.inline:
            value = self.tr.local_call(sym, (i, j))
        else:
            self.tr.calls.setdefault(sym, []).append((i, j))
            value = ex.Call(sym.token(), (i, j))
        o = ex.Number(float(self.tr.sheet_origin))
        one = ex.Number(1.0)
        zero = ex.Number(0.0)
        at = (ex.Binary("+", i, o), ex.Binary("+", j, o))
        return [
            (0, [target, " := ", zero]),
            (0, ["for ", i, " in ", zero, " .. ", ex.Binary("-", rows, one)]),
            (4, ["for ", j, " in ", zero, " .. ", ex.Binary("-", cols, one)]),
            (8, [ex.Index(target, at), " := ", value]),
        ]

    def _shifted(self, index: ex.Node) -> ex.Node:
        shift = self.tr.sheet_origin - self.tr.origin  # ORIGIN redefined after the first index
        return ex.Binary("+", index, ex.Number(float(shift))) if shift else index

    def _local(self, node: MNode) -> ex.Node:
        if node.tag != "id":
            raise Untranslatable("a program local that is not a name")
        return ex.Name(self._local_key(name_key(node)).token())

    def _local_key(self, key: tuple[str, str]) -> Sym:
        sym = self.locals.get(key)
        if sym is None:
            sym = self.tr.new_sym("local", nm.identifier(*key), nm.mathcad_text(*key))
            self.locals[key] = sym
            self.scope[key] = sym
        return sym

    def _fresh(self, base: str) -> Sym:
        """A local of the translation's own, named unlike every name of the program."""
        name, n = base, 2
        while name in self.taken:
            name, n = f"{base}_{n}", n + 1
        self.taken.add(name)
        return self.tr.new_sym("local", name, name, generated=True)

    def _range(self, rng: MNode) -> list:
        first = rng.children[0]
        if first.tag == "sequence":
            a, b = (self._expr(c) for c in first.children[:2])
            head = [a, ", ", b]
        else:
            head = [self._expr(first)]
        return [*head, " .. ", self._expr(rng.children[1])]

    def _translator(self):
        return self.expressions(self.tr, self.scope)

    def _expr(self, node: MNode) -> ex.Node:
        et = self._translator()
        tree = et.value(node)
        if et.ranges:
            raise Untranslatable("a program over a range variable")
        return tree

    def _cond(self, node: MNode) -> ex.Node:
        et = self._translator()
        tree = et.condition(node)
        if et.ranges:
            raise Untranslatable("a program over a range variable")
        return tree


def unsure_builtin(name: str) -> str:
    """Why an error a built-in of the language raises may not be where Mathcad raises one
    ('' where it is): one with a restricted domain (``sqrt`` of a negative number: Mathcad's
    value is complex, the engine's an error), or one that binds a variable (a solver or a
    numerical method, whose failure is its own), as the registry's entry says."""
    from ..numerics.registry import REGISTRY

    entry = REGISTRY.get(name)
    if entry is None:
        return ""
    if entry.binds:
        return "whether a solver or a numerical method fails is its own"
    if entry.domain:
        return (
            f"the engine raises an error at {entry.domain[0].kind}, where Mathcad's value may "
            "be complex or its error another"
        )
    return ""


_ON_ERROR_WHY = (
    "Mathcad 15's on error in a program (which of its operands is the one tried is not shown "
    "by any worksheet measured)"
)


def _whole(node: ex.Node) -> bool:
    """A whole number written (``2``, ``-1``)."""
    if isinstance(node, ex.Unary) and node.op == "-":
        node = node.operand
    return isinstance(node, ex.Number) and float(node.value).is_integer()


def _item_trees(item: Item) -> list[ex.Node]:
    """The expressions of a translated definition or function."""
    out = [item.body] if item.body is not None else []
    out += [t for piece in item.pieces or [] for t in piece if t is not None]
    out += [p for _, parts in item.program or [] for p in parts if not isinstance(p, str)]
    return out


_BREAK_WHY = "a break outside any loop (Mathcad stops the program there) before the program's end"
_CONTINUE_WHY = "a continue outside any loop"

_NEGATED = {"==": "!=", "!=": "==", "<": ">=", ">=": "<", ">": "<=", "<=": ">"}


def _negate(cond: ex.Node) -> ex.Node:
    if isinstance(cond, ex.Compare) and len(cond.ops) == 1:
        return ex.Compare((_NEGATED[cond.ops[0]],), cond.operands)
    return ex.Unary("not", cond)


def _assignments(body: list[MNode]) -> dict[tuple[str, str], int]:
    """How many statements of the program give each name a whole value (assignments,
    destructuring, loop variables), wherever they are."""
    counts: dict[tuple[str, str], int] = {}
    for stmt in body:
        for node in _walk(stmt):
            names: list[MNode] = []
            if node.tag == "localDefine":
                lhs = node.children[0]
                names = (
                    [lhs] if lhs.tag == "id" else list(lhs.children) if lhs.tag == "matrix" else []
                )
            elif node.tag == "for":
                names = [node.children[0]]
            for n in names:
                if n.tag == "id":
                    counts[name_key(n)] = counts.get(name_key(n), 0) + 1
    return counts


def _runtime_matrix(node: MNode, scope: dict) -> bool:
    """Is ``node`` matrix(m, n, f) whose m or n reads a name of the program (a size known
    only when it runs)?"""
    if node.tag != "apply" or len(node.children) != 2 or node.children[0].tag != "id":
        return False
    if name_key(node.children[0]) != ("matrix", "") or node.children[1].tag != "sequence":
        return False
    args = node.children[1].children
    if len(args) != 3 or name_key(node.children[0]) in scope:
        return False
    return any(key in scope for a in args[:2] for key, _ in _reads(a))


def _is_break(body: MNode) -> bool:
    while body.tag == "program" and len(body.children) == 1:
        body = body.children[0]
    return body.tag == "break"


def _is_column(lhs: MNode) -> bool:
    return lhs.tag == "apply" and len(lhs.children) == 3 and lhs.children[0].tag == "matcol"


def _walk(node: MNode):
    yield node
    for c in node.children:
        yield from _walk(c)


def _statements(body: MNode) -> list[MNode]:
    return body.children if body.tag == "program" else [body]


def _one_index_locals(program: MNode, params: set) -> MNode:
    """The program with each local vector that it uses only at one index, a parameter the
    program does not assign (``K[i] <- M``, ``(K[i])[a, b] <- x``, ``K[i]`` read), made a
    local of its own (``K_i``): Mathcad builds that vector, but only its element i is ever
    set or read, so the element is the local (the language sets no element of an element)."""
    whole, elements = _targets(_statements(program))
    uses: dict[tuple[str, str], set] = {}

    def scan(node: MNode) -> None:
        if node.tag == "apply" and len(node.children) == 3 and node.children[0].tag == "indexer":
            target, index = node.children[1], node.children[2]
            if target.tag == "id":
                at = name_key(index) if index.tag == "id" else None
                uses.setdefault(name_key(target), set()).add(at)
                scan(index)
                return
        if node.tag == "id":
            uses.setdefault(name_key(node), set()).add(None)
        for c in node.children:
            scan(c)

    scan(program)
    single = {
        key: next(iter(at))
        for key, at in uses.items()
        if key in elements
        and key not in whole
        and key not in params
        and len(at) == 1
        and next(iter(at)) in params
        and next(iter(at)) not in whole
    }
    if not single:
        return program

    def rewrite(node: MNode) -> MNode:
        if node.tag == "apply" and len(node.children) == 3 and node.children[0].tag == "indexer":
            target = node.children[1]
            if target.tag == "id" and name_key(target) in single:
                text, sub = name_key(target)
                index = single[name_key(target)]
                attrs = dict(target.attrs)
                attrs["subscript"] = "_".join(p for p in (sub, *index) if p)
                return MNode("id", attrs, text, [], target.line)
        return MNode(
            node.tag, node.attrs, node.text, [rewrite(c) for c in node.children], node.line
        )

    return rewrite(program)


def _targets(body: list[MNode]) -> tuple[dict, set]:
    """Names a program assigns: {name: set inside a block?} for whole assignments (and loop
    variables), and the names whose elements or columns it sets."""
    whole: dict[tuple[str, str], bool] = {}
    elements: set[tuple[str, str]] = set()

    def visit(stmts: list[MNode], inner: bool) -> None:
        for s in stmts:
            if s.tag == "localDefine":
                lhs = s.children[0]
                if lhs.tag == "id":
                    whole[name_key(lhs)] = whole.get(name_key(lhs), False) or inner
                elif lhs.tag == "matrix":
                    for c in lhs.children:
                        if c.tag == "id":
                            whole[name_key(c)] = whole.get(name_key(c), False) or inner
                elif lhs.tag == "apply" and len(lhs.children) == 3 and lhs.children[1].tag == "id":
                    elements.add(name_key(lhs.children[1]))
            elif s.tag == "for":
                var = s.children[0]
                if var.tag == "id":
                    whole[name_key(var)] = True
                visit(_statements(s.children[2]), True)
            elif s.tag in ("ifThen", "while"):
                visit(_statements(s.children[1]), True)
            elif s.tag == "otherwise":
                visit(_statements(s.children[0]), True)
            elif s.tag == "tryCatch":
                for block in s.children:
                    visit(_statements(block), True)
            elif s.tag == "program":
                visit(s.children, inner)

    visit(body, False)
    return whole, elements


def _reads(node: MNode):
    """(name, read as an array whose element or column is taken?) of each name ``node``
    reads (not the names of the functions it calls)."""
    if node.tag == "id":
        yield name_key(node), False
        return
    children = node.children
    if node.tag == "apply" and children:
        head = children[0]
        if head.tag in ("indexer", "matcol") and len(children) == 3:
            target = children[1]
            while target.tag == "parens" and target.children:
                target = target.children[0]
            if target.tag == "id":
                yield name_key(target), True
            else:
                yield from _reads(target)
            yield from _reads(children[2])
            return
        if head.tag == "id":
            children = children[1:]
    if node.tag in ("lambda", "boundVars"):
        return
    for c in children:
        yield from _reads(c)
