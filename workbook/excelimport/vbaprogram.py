"""A VBA Function as a function of the language whose body is a program.

VBA's meaning is kept exactly or the function is listed as not translated, with the reason:
``For`` loops are written as ``while`` loops (VBA evaluates the bounds once and leaves the
counter one step past the end), integer variables round as VBA does (to even), ``True`` is
-1, arrays keep their lower bound (0, the ``To`` bound, 1 for ranges), ranges are matrices.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from .formula_terms import text_problem
from .functions import VBA
from .vba import Procedure, split_top
from .vbaerrors import cut_error_handler, raised_errors
from .vbaexpr import VbaSyntax, parse, strip
from .vbamembers import Members, NotTranslated, is_transpose
from .vbarefs import ByReference, refs_name
from .vbatypes import INTEGER_TYPES, NUMBER_TYPES, bankers, default_text

#: the language's words, which cannot be names
KEYWORDS = {
    "if", "else", "elif", "otherwise", "for", "in", "while", "break", "continue", "return",
    "and", "or", "not", "is", "lambda", "def", "class", "import", "from", "as", "with", "pass",
    "none", "true", "false", "try", "except", "finally", "raise", "global", "nonlocal", "del",
    "yield", "assert", "async", "await", "pi",
}  # fmt: skip
MAX_ZERO_ARRAY = 10_000  # elements of a Dim'd array written out as zeros


@dataclass
class FunctionInfo:
    """What callers need to know of a translated VBA function."""

    proc: Procedure
    final: str  # its name in the worksheet
    params: list[str]  # final names of the parameters
    given: dict[str, str] = field(default_factory=dict)  # param -> flag param (IsMissing)
    program: str = ""
    problem: str | None = None
    volatile: bool = False
    calls: set[str] = field(default_factory=set)  # lower-case VBA names it calls
    result_base: int = 0  # the lower bound of the array it gives
    refs: list[int] = field(default_factory=list)  # parameters its callers read back (refs_name)
    # {parameter index: lower bounds of the arrays VBA callers give it (None: not an array
    # this translation knows)}, collected while the callers are translated, and the ones the
    # function's own translation read (from the round before)
    arg_bases: dict[int, set] = field(default_factory=dict)
    used_bases: dict[int, set] = field(default_factory=dict)
    dropped: set[str] = field(default_factory=set)  # statements without effect on the value

    @property
    def arity(self) -> int:
        return len(self.params) + len(self.given)


@dataclass
class _Array:
    base: int
    dims: int  # 0: unknown
    is_range: bool = False


class Translator(Members, ByReference):
    """One VBA Function to program text (raises NotTranslated with the reason)."""

    def __init__(self, info: FunctionInfo, functions: dict[str, FunctionInfo], reserved: set):
        self.info = info
        self.proc = info.proc
        self.functions = functions
        self.reserved = {r.lower() for r in reserved}
        self.names: dict[str, str] = {}
        self.types: dict[str, str] = {}
        self.arrays: dict[str, _Array] = {}
        self.lines: list[str] = []
        self.counter = 0
        self.option_base = 0
        self.declared_numbers: list[str] = []
        self.written: set[str] = set()  # the locals the lines so far give a value
        self.read_empty: list[str] = []  # undeclared locals read before any value: Empty, 0
        self.prefix: list[tuple[int, str]] = []  # module-level Const lines it uses
        self.param_problem: str | None = None
        # {function: positions of its by-reference parameters it changes} (vba.py)
        self.changed_params: dict[str, set[int]] = {}
        for i, p in enumerate(self.proc.params):
            self.names[p.name.lower()] = info.params[i]
            self.types[p.name.lower()] = p.type.lower()
            bases = info.used_bases.get(i, set())
            if p.type.lower() == "range":
                self.arrays[p.name.lower()] = _Array(1, 0, True)
            elif p.array:
                # the lower bound of the arrays its callers give (0 where no VBA caller does)
                known = {b for b in bases if b is not None}
                if None in bases or len(known) > 1:
                    self.param_problem = (
                        f"the array parameter {p.name} is given arrays of different or "
                        "unknown lower bounds"
                    )
                self.arrays[p.name.lower()] = _Array(min(known) if known else 0, 0)
            elif p.type.lower() == "variant" and len(bases) == 1 and None not in bases:
                # a Variant every VBA caller gives an array of one lower bound
                self.arrays[p.name.lower()] = _Array(next(iter(bases)), 0)
        self.ret = self.local(self.proc.name + "_value", fresh=True)
        self.record_types = getattr(info, "record_types", {})
        self.records_of: dict[str, list] = {}  # local (lower case) -> its Type's fields
        if self.proc.returns.lower() in self.record_types:
            self.records_of[self.proc.name.lower()] = self.record(self.proc.returns)

    # -- names -------------------------------------------------------------------------
    def local(self, vba_name: str, fresh: bool = False) -> str:
        key = vba_name.lower()
        if not fresh and key in self.names:
            return self.names[key]
        base = re.sub(r"[^A-Za-z0-9_]", "_", vba_name)
        name, n = base, 1
        taken = {v.lower() for v in self.names.values()}
        while name.lower() in self.reserved or name.lower() in taken or name.lower() in KEYWORDS:
            name = f"{base}_{n}" if n > 1 else base + "_"
            n += 1
        self.names[key if not fresh else f"\0{key}"] = name
        return name

    def temp(self, what: str) -> str:
        self.counter += 1
        return self.local(f"{what}_{self.counter}", fresh=True)

    # -- statements --------------------------------------------------------------------
    def translate(self) -> str:
        if self.param_problem:
            raise NotTranslated(self.param_problem)
        raised = raised_errors(f.proc for f in self.functions.values())
        body = list(self.prefix) + cut_error_handler(self.proc.name, list(self.proc.lines), raised)
        self.body = body
        self.at = 0
        self.assigned = False
        rhs_of_result = [
            text.split("=", 1)[1].strip()
            for _, text in body
            if re.match(rf"^{re.escape(self.proc.name)}\s*=", text, re.I)
        ]
        self.text_function = self.proc.returns.lower() == "string" or (
            bool(rhs_of_result) and all(r.startswith('"') for r in rhs_of_result)
        )
        self.error_flag = None
        error_value = re.compile(
            rf"^(?:If\b.*\bThen\s+)?{re.escape(self.proc.name)}\s*=\s*(?:CVErr\b|\")", re.I
        )
        if not self.text_function and any(
            error_value.match(text) and not self._tail(j) for j, (_, text) in enumerate(body)
        ):  # an error value (or a message) that a later value may replace
            self.error_flag = self.local("is_error", fresh=True)
        ret_type = self.proc.returns.lower()
        for i, p in enumerate(self.proc.params):
            if p.type.lower() in INTEGER_TYPES:  # VBA rounds a number passed to an Integer
                name = self.info.params[i]
                self.lines.append(f"{name} := {bankers(name)}")
        if ret_type in NUMBER_TYPES or ret_type == "boolean":
            self.lines.append(f"{self.ret} := 0")
        elif ret_type in self.record_types:
            self.lines.append(f"{self.ret} := {self.zeros(ret_type)}")
        start = len(self.lines)
        self.block(body, 0, 0, ())
        # VBA gives every declared number 0 when the function starts (Dim does not run)
        inits = [f"{self.names[k]} := 0" for k in self.declared_numbers if k in self.names]
        inits += [f"{n} := 0" for n in dict.fromkeys(self.read_empty) if f"{n} := 0" not in inits]
        self.lines[start:start] = inits
        if self.error_flag is not None:
            inits.append(f"{self.error_flag} := 0")
            self.lines[start:start] = [inits[-1]]
            self.lines.append(f"return 1/0 if {self.error_flag} != 0")
        if self.assigned or not self.text_function:
            self.lines.append(self.ret)
        return "\n".join(self.lines)

    def emit(self, indent: int, text: str) -> None:
        self.lines.append("    " * indent + text)
        m = re.match(r"(\w+)\s*(?:\[[^\]]*\])?\s*:=", text)
        if m:
            self.written.add(m.group(1))

    def block(self, lines, i: int, indent: int, stop: tuple[str, ...]) -> int:
        """Translate statements from lines[i] until one that starts with a word of ``stop``
        (returned index points at it)."""
        start = len(self.lines)
        while i < len(lines):
            number, text = lines[i]
            low = text.lower()
            if stop and re.match(r"^(" + "|".join(stop) + r")\b", low):
                break
            if lines is self.body:
                self.at = i
            try:
                i = self.statement(lines, i, indent)
            except NotTranslated as exc:
                raise NotTranslated(f"line {number}: {exc}") from None
            except VbaSyntax as exc:
                raise NotTranslated(f"line {number}: cannot read {text!r} ({exc})") from None
        if len(self.lines) == start:  # an empty block: a statement that does nothing
            self.emit(indent, f"{self.temp('nothing')} := 0")
        return i

    def statement(self, lines, i: int, indent: int) -> int:
        _, text = lines[i]
        low = text.lower()
        word = low.split()[0] if low.split() else ""
        if re.match(r"^(dim|static|private|public|const)\b", low):
            self.declare(text, indent)
            return i + 1
        if word == "redim":
            self.redim(text, indent)
            return i + 1
        if word == "if":
            return self.if_(lines, i, indent)
        if low.startswith("select case"):
            return self.select(lines, i, indent)
        if word == "for":
            return self.for_(lines, i, indent)
        if word == "do":
            return self.do(lines, i, indent)
        if word == "while":
            cond = self.cond(parse(text[5:]))
            self.emit(indent, f"while {cond}")
            j = self.block(lines, i + 1, indent + 1, ("wend",))
            if j >= len(lines):
                raise NotTranslated("While without Wend")
            return j + 1
        if low in ("exit for", "exit do"):
            self.emit(indent, "break")
            return i + 1
        if low == "exit function":
            if self.error_flag is not None:
                self.emit(indent, f"return 1/0 if {self.error_flag} != 0")
            self.emit(indent, f"return {self.ret}")
            return i + 1
        if word == "msgbox" or low.startswith("msgbox("):
            self.info.dropped.add("MsgBox")  # a message shown: no effect on the value
            return i + 1
        if word == "on":
            if re.match(r"^on\s+error\s+goto\s+0$", low):
                return i + 1
            raise NotTranslated(f"{text}: an error path whose meaning a worksheet cannot keep")
        if low in ("application.volatile", "application.volatile true"):
            self.info.volatile = True
            return i + 1
        if word.startswith("err.raise") or low.startswith("err.raise"):
            self.emit(indent, f"return {self.error_value()}")  # the cell shows an error
            return i + 1
        if low.startswith("debug.print") or low.startswith("debug.assert"):
            return i + 1  # no effect on the value
        if word == "set":
            text = text[3:].strip()
            low = text.lower()
        if word in ("goto", "gosub", "resume", "with", "call", "stop", "end", "exit", "let"):
            if word == "let":
                return self.assign(text[3:].strip(), indent, i, lines)
            raise NotTranslated(f"{text.split()[0]}: not translated")
        if re.match(r"^[A-Za-z_][A-Za-z0-9_]*:$", text):
            raise NotTranslated(f"the label {text} (GoTo)")
        if "=" in text and self._assignment_split(text) is not None:
            return self.assign(text, indent, i, lines)
        raise NotTranslated(f"{text!r}: a call of a Sub or a statement with effects elsewhere")

    def _assignment_split(self, text: str):
        depth, quote = 0, False
        for k, ch in enumerate(text):
            if ch == '"':
                quote = not quote
            elif not quote:
                if ch == "(":
                    depth += 1
                elif ch == ")":
                    depth -= 1
                elif ch == "=" and depth == 0:
                    if text[k - 1 : k] in "<>:" and k > 0:
                        return None
                    return text[:k].strip(), text[k + 1 :].strip()
        return None

    def assign(self, text: str, indent: int, i: int, lines) -> int:
        left, right = self._assignment_split(text)
        target = strip(parse(left))
        rhs = strip(parse(right))
        if target[0] == "id":
            key = target[1].lower()
            if key == self.proc.name.lower():
                return self.assign_result(rhs, indent, i, lines)
            if key in self.functions and key not in self.names:
                raise NotTranslated(f"assigns to the name of another function {target[1]}")
            if key in self.arrays and self.arrays[key].is_range:
                raise NotTranslated(f"{target[1]} is a range given as an argument: writes cells")
            if self.assign_by_reference(target, rhs, indent):
                return i + 1
            if is_transpose(rhs):  # Application.Transpose(...): an array from 1
                self.transpose_into(self.local(target[1]), rhs, indent)
                self.arrays[key] = _Array(1, 0)
                return i + 1
            callee = strip(rhs[1]) if rhs[0] == "call" else None
            if callee is not None and callee[0] == "id" and callee[1].lower() == "cverr":
                # an error value in a local: VBA stops at its next use (a type mismatch), so
                # the function has no value from here (an error, where VBA might still give
                # one if the local were never read again: never a number VBA would not give)
                self.emit(indent, "return 1/0")
                return i + 1
            value = self.value(rhs)
            if rhs[0] == "mem" and rhs[2].lower() in ("value", "value2"):
                src = self._range_base(rhs[1])
                if src is not None:
                    self.arrays[key] = _Array(1, 2, True)
            elif rhs[0] == "id" and rhs[1].lower() in self.arrays:
                self.arrays[key] = self.arrays[rhs[1].lower()]
            elif (
                rhs[0] == "call"
                and strip(rhs[1]) == ("id", "Array")
                or (
                    rhs[0] == "call"
                    and strip(rhs[1])[0] == "id"
                    and strip(rhs[1])[1].lower() == "array"
                )
            ):  # Array(...) starts at Option Base
                self.arrays[key] = _Array(self.option_base, 1)
            elif self._callee(rhs) is not None:  # an array a VBA function gives, or a number
                self.arrays[key] = _Array(self._callee(rhs).result_base, 0)
            if self.types.get(key) in INTEGER_TYPES and not self._integral(rhs):
                value = bankers(value)
            self.emit(indent, f"{self.local(target[1])} := {value}")
            return i + 1
        if target[0] == "call" and target[1][0] == "id":
            key = target[1][1].lower()
            if key not in self.arrays:
                raise NotTranslated(f"{left}: writes to a cell or to an unknown array")
            arr = self.arrays[key]
            if arr.is_range:
                raise NotTranslated(f"{left}: writes into a range")
            index = self.indices(key, target[2])
            value = self.value(rhs)
            if self.types.get(key) in INTEGER_TYPES and not self._integral(rhs):
                value = bankers(value)
            self.emit(indent, f"{self.local(target[1][1])}[{index}] := {value}")
            return i + 1
        if target[0] == "mem":
            found = self.field_index(target[1], target[2])
            if found is not None:
                self.emit(indent, f"{found[0]}[{found[1]}] := {self.value(rhs)}")
                return i + 1
        raise NotTranslated(f"{left} = ...: writes to a cell, a property or an object")

    def assign_result(self, rhs, indent: int, i: int, lines) -> int:
        """``FunctionName = value``: the function's value (a text, or an error value, only
        where nothing runs after it: it is then what the function gives)."""
        if self.assign_by_reference(("id", self.proc.name), rhs, indent):
            return i + 1
        at = i if lines is self.body else self.at
        tail = self._tail(at)
        is_error = rhs[0] == "call" and rhs[1][0] == "id" and rhs[1][1].lower() == "cverr"
        if is_error or rhs[0] == "str":
            if not tail and (self.text_function or self.error_flag is None):
                raise NotTranslated("a text given where code runs after it")
            if not tail:  # a later value may replace the error value: a flag keeps it
                self.emit(indent, f"{self.error_flag} := 1")
                return i + 1
            if rhs[0] == "str" and self.text_function:
                self.emit(indent, f"return {self.value(rhs)}")
            else:  # Excel shows an error value (or a message): the function has no number
                self.emit(indent, "return 1/0")
            following = lines[i + 1][1].strip().lower() if i + 1 < len(lines) else ""
            return i + 2 if following == "exit function" else i + 1
        if self.text_function:
            raise NotTranslated("a function whose value is a text, given a value not a text")
        value = self.value(rhs)
        if rhs[0] == "id" and rhs[1].lower() in self.arrays:
            self.info.result_base = self.arrays[rhs[1].lower()].base
        if self.proc.returns.lower() in INTEGER_TYPES and not self._integral(rhs):
            value = bankers(value)  # VBA rounds the value of an Integer function
        self.emit(indent, f"{self.ret} := {value}")
        if self.error_flag is not None:
            self.emit(indent, f"{self.error_flag} := 0")
        self.assigned = True
        return i + 1

    def _tail(self, i: int) -> bool:
        """True if nothing runs after statement ``i`` of the body but the end of the function."""
        body = self.body
        j = i + 1
        while j < len(body):
            low = body[j][1].strip().lower()
            if low.startswith("end if") or low.startswith("end select"):
                j += 1
            elif low.startswith("elseif") or re.match(r"^else\b", low):
                j = self._matching(j, ("if",), "end if")
            elif re.match(r"^case\b", low):
                j = self._matching(j, ("select case",), "end select")
            elif low == "exit function":
                return True
            else:
                return False
        return True

    def _matching(self, j: int, opens: tuple[str, ...], close: str) -> int:
        """The index of the ``close`` line that ends the block line ``j`` is in."""
        depth = 0
        while j < len(self.body):
            low = self.body[j][1].strip().lower()
            if low.startswith(opens) and (opens != ("if",) or re.match(r"^if\b.*\bthen$", low)):
                depth += 1
            elif low.startswith(close):
                if depth == 0:
                    return j
                depth -= 1
            j += 1
        return j

    def _callee(self, node):
        """The FunctionInfo of a call of a VBA function (``f(...)``, ``Module.f(...)``)."""
        node = strip(node)
        if node[0] != "call":
            return None
        base = strip(node[1])
        if base[0] == "mem":
            base = ("id", base[2])
        if base[0] == "id" and base[1].lower() in self.functions:
            return self.functions[base[1].lower()]
        return None

    def _integral(self, node) -> bool:
        node = strip(node)
        if node[0] == "num":
            return re.fullmatch(r"\d+", node[1]) is not None
        if node[0] == "id":
            return self.types.get(node[1].lower()) in INTEGER_TYPES
        if node[0] == "bin" and node[1] in ("+", "-", "*"):
            return self._integral(node[2]) and self._integral(node[3])
        if node[0] == "bin" and node[1] in ("\\", "mod"):
            return True
        if node[0] == "un" and node[1] == "-":
            return self._integral(node[2])
        if node[0] == "call" and node[1][0] == "id":
            return node[1][1].lower() in ("int", "fix", "ubound", "lbound", "cint", "clng")
        return False

    def declare(self, text: str, indent: int) -> None:
        low = text.lower()
        is_const = low.startswith("const") or " const " in low
        body = re.sub(r"^(?:(?:dim|static|private|public|const)\s+)+", "", text, flags=re.I)
        for part in split_top(body, ","):
            part = part.strip()
            if not part:
                continue
            m = re.match(
                r"([A-Za-z_][A-Za-z0-9_]*)[$%!#@&]?\s*(?:\((.*)\))?\s*(?:As\s+(?:New\s+)?"
                r"([A-Za-z_][A-Za-z0-9_.]*))?\s*(?:\*\s*\d+)?\s*(?:=\s*(.*))?$",
                part,
                re.I,
            )
            if not m:
                raise NotTranslated(f"cannot read the declaration {part!r}")
            name, bounds, typ, value = m.groups()
            key = name.lower()
            self.types[key] = (typ or "variant").lower()
            final = self.local(name)
            if self.types[key] in self.record_types and bounds is None and value is None:
                self.records_of[key] = self.record(typ)
                self.emit(indent, f"{final} := {self.zeros(typ)}")
                continue
            if is_const or value is not None:
                if value is None:
                    raise NotTranslated(f"Const {name} without a value")
                self.emit(indent, f"{final} := {self.value(parse(value))}")
                continue
            if bounds is None:
                if self.types[key] in NUMBER_TYPES | {"boolean"} or (
                    self.types[key] == "variant" and self._read_first(name)
                ):
                    self.declared_numbers.append(key)
                continue
            if not bounds.strip():  # Dim a(): dynamic, given by ReDim
                self.arrays[key] = _Array(self.option_base, 0)
                continue
            self.dimension(name, bounds, indent, zero_fill=True)

    def _read_first(self, name: str) -> bool:
        """The first line after the declarations that names the Variant ``name`` reads it
        (``Do While Abs(P - ps) > 1e-5`` before ``ps = ...``): it is then Empty, which VBA
        reads as 0. A Variant given a value first keeps what it is given (maybe an array)."""
        word = re.compile(rf"\b{re.escape(name)}\b", re.I)
        for _, line in self.proc.lines:
            text = line.strip()
            if re.match(r"(?:dim|static|const|redim)\b", text, re.I) or not word.search(text):
                continue
            return re.match(rf"{re.escape(name)}\s*=(?!=)", text, re.I) is None
        return False

    def dimension(self, name: str, bounds: str, indent: int, zero_fill: bool) -> None:
        key = name.lower()
        final = self.local(name)
        dims = []
        for b in split_top(bounds, ","):
            m = re.match(r"(.*?)\s+To\s+(.*)$", b.strip(), re.I)
            low_text, high_text = (m.group(1), m.group(2)) if m else (None, b.strip())
            base = self.option_base
            if low_text is not None:
                node = strip(parse(low_text))
                if node[0] == "num" and re.fullmatch(r"-?\d+", node[1]):
                    base = int(node[1])
                elif node[0] == "un" and node[2][0] == "num":
                    base = -int(float(node[2][1]))
                else:
                    raise NotTranslated(f"the lower bound {low_text!r} of {name} is not a number")
            dims.append((base, self.value(parse(high_text))))
        if len({b for b, _ in dims}) > 1:
            raise NotTranslated(f"{name}: dimensions with different lower bounds")
        if len(dims) > 2:
            raise NotTranslated(f"{name}: an array of {len(dims)} dimensions")
        self.arrays[key] = _Array(dims[0][0], len(dims))
        if not zero_fill:
            return
        sizes = []
        for base, high in dims:
            try:
                sizes.append(int(float(high)) - base + 1)
            except ValueError:
                sizes = []
                break
        if sizes and 0 < sizes[0] * (sizes[1] if len(sizes) > 1 else 1) <= MAX_ZERO_ARRAY:
            if len(sizes) == 1:
                self.emit(indent, f"{final} := [{', '.join(['0'] * sizes[0])}]")
            else:
                row = "[" + ", ".join(["0"] * sizes[1]) + "]"
                self.emit(indent, f"{final} := [{', '.join([row] * sizes[0])}]")
            return
        # sizes known only when it runs: zeros element by element (VBA's fresh array)
        self.emit(indent, f"{final} := 0")
        k = self.temp("k")
        first = dims[0]
        self.emit(indent, f"for {k} in 0 .. {first[1]} - {first[0]}")
        if len(dims) == 1:
            self.emit(indent + 1, f"{final}[{k}] := 0")
        else:
            j = self.temp("j")
            self.emit(indent + 1, f"for {j} in 0 .. {dims[1][1]} - {dims[1][0]}")
            self.emit(indent + 2, f"{final}[{k}, {j}] := 0")

    def redim(self, text: str, indent: int) -> None:
        body = re.sub(r"^ReDim\s+", "", text, flags=re.I)
        preserve = bool(re.match(r"Preserve\s", body, re.I))
        body = re.sub(r"^Preserve\s+", "", body, flags=re.I)
        for part in split_top(body, ","):
            m = re.match(
                r"\s*([A-Za-z_][A-Za-z0-9_]*)\s*\((.*)\)\s*(?:As\s+(\w+))?\s*$", part, re.I
            )
            if not m:
                raise NotTranslated(f"cannot read ReDim {part!r}")
            name, bounds, typ = m.groups()
            if typ:
                self.types[name.lower()] = typ.lower()
            if preserve:
                dims = split_top(bounds, ",")
                if len(dims) != 1:
                    raise NotTranslated(f"ReDim Preserve {name} of more than one dimension")
                arr = self.arrays.get(name.lower())
                base = arr.base if arr else self.option_base
                if re.search(r"\sTo\s", dims[0], re.I):
                    raise NotTranslated(f"ReDim Preserve {name} with a lower bound")
                final = self.local(name)
                high = self.value(parse(dims[0]))
                # grows only (a shorter array would keep elements VBA drops)
                self.emit(indent, f"if rows({final}) > {high} - {base} + 1")
                self.emit(indent + 1, "return 1/0")
                self.emit(
                    indent,
                    f"{final}[{high} - {base}] := {final}[{high} - {base}] if "
                    f"rows({final}) > {high} - {base} otherwise 0",
                )
                self.arrays[name.lower()] = _Array(base, 1)
            else:
                self.dimension(name, bounds, indent, zero_fill=True)

    def if_(self, lines, i: int, indent: int) -> int:
        _, text = lines[i]
        m = re.match(r"^If\s+(.*?)\s+Then\b\s*(.*)$", text, re.I)
        if not m:
            raise NotTranslated(f"cannot read {text!r}")
        cond, rest = m.groups()
        if rest:  # single-line If c Then a [Else b]
            parts = re.split(r"\s+Else\s+", rest, maxsplit=1, flags=re.I)
            self.emit(indent, f"if {self.cond(parse(cond))}")
            self._inline(parts[0], indent + 1)
            if len(parts) > 1:
                self.emit(indent, "otherwise")
                self._inline(parts[1], indent + 1)
            return i + 1
        self.emit(indent, f"if {self.cond(parse(cond))}")
        j = self.block(lines, i + 1, indent + 1, ("elseif", "else", "end if"))
        while j < len(lines):
            _, t = lines[j]
            low = t.lower()
            if low.startswith("elseif"):
                m2 = re.match(r"^ElseIf\s+(.*?)\s+Then\s*$", t, re.I)
                if not m2:
                    raise NotTranslated(f"cannot read {t!r}")
                self.emit(indent, f"else if {self.cond(parse(m2.group(1)))}")
                j = self.block(lines, j + 1, indent + 1, ("elseif", "else", "end if"))
            elif re.match(r"^else\b", low):
                rest = t[4:].strip().lstrip(":").strip()
                self.emit(indent, "otherwise")
                if rest:
                    self._inline(rest, indent + 1)
                    j = self.block(lines, j + 1, indent + 1, ("end if",)) if False else j + 1
                    j = self._block_after(lines, j, indent + 1)
                else:
                    j = self.block(lines, j + 1, indent + 1, ("end if",))
            elif low.startswith("end if"):
                return j + 1
            else:
                break
        raise NotTranslated("If without End If")

    def _block_after(self, lines, j, indent):
        save = len(self.lines)
        j = self.block(lines, j, indent, ("end if",))
        if len(self.lines) == save + 1 and self.lines[-1].strip().endswith(":= 0"):
            self.lines.pop()  # the placeholder of an empty block: the inline statement is there
        return j

    def _inline(self, text: str, indent: int) -> None:
        pieces = [p.strip() for p in split_top(text, ":") if p.strip()]
        seq = [(0, p) for p in pieces]
        self.block(seq, 0, indent, ())

    def select(self, lines, i: int, indent: int) -> int:
        _, text = lines[i]
        subject = self.value(parse(text[len("select case") :].strip()))
        var = self.temp("case")
        self.emit(indent, f"{var} := {subject}")
        j = i + 1
        first = True
        while j < len(lines):
            _, t = lines[j]
            low = t.lower()
            if low.startswith("end select"):
                return j + 1
            if not low.startswith("case"):
                if first:
                    j += 1  # statements before the first Case never run
                    continue
                raise NotTranslated(f"cannot read {t!r} in Select Case")
            clause = t[4:].strip()
            if clause.lower() == "else" or clause.lower().startswith("else:"):
                self.emit(indent, "otherwise")
            else:
                conds = []
                for item in split_top(clause, ","):
                    item = item.strip()
                    m = re.match(r"^Is\s*(<=|>=|<>|=|<|>)\s*(.*)$", item, re.I)
                    if m:
                        conds.append(self._compare(m.group(1), var, parse(m.group(2))))
                        continue
                    m = re.match(r"^(.*?)\s+To\s+(.*)$", item, re.I)
                    if m:
                        lo, hi = self.value(parse(m.group(1))), self.value(parse(m.group(2)))
                        conds.append(f"({var} >= {lo} and {var} <= {hi})")
                        continue
                    conds.append(self._compare("=", var, parse(item)))
                self.emit(indent, f"{'if' if first else 'else if'} {' or '.join(conds)}")
            first = False
            j = self.block(lines, j + 1, indent + 1, ("case", "end select"))
        raise NotTranslated("Select Case without End Select")

    def _compare(self, op: str, left_text: str, right) -> str:
        ops = {"=": "==", "<>": "!=", "<": "<", ">": ">", "<=": "<=", ">=": ">="}
        return f"{left_text} {ops[op]} {self.value(right, 4)}"

    def for_(self, lines, i: int, indent: int) -> int:
        _, text = lines[i]
        m = re.match(r"^For\s+Each\s+(\w+)\s+In\s+(.*)$", text, re.I)
        if m:
            return self.for_each(lines, i, indent, m.group(1), m.group(2))
        m = re.match(r"^For\s+(\w+)\s*=\s*(.*?)\s+To\s+(.*?)(?:\s+Step\s+(.*))?$", text, re.I)
        if not m:
            raise NotTranslated(f"cannot read {text!r}")
        name, first, last, step = m.groups()
        var = self.local(name)
        first_v = self.value(parse(first))
        end = self.temp("last")
        self.emit(indent, f"{end} := {self.value(parse(last))}")
        step_v = self.value(parse(step)) if step else "1"
        step_node = strip(parse(step)) if step else ("num", "1")
        if self.types.get(name.lower()) in INTEGER_TYPES and not self._integral(parse(first)):
            first_v = bankers(first_v)
        self.emit(indent, f"{var} := {first_v}")
        if step_node[0] == "num":
            cmp = "<="
        elif step_node[0] == "un" and step_node[1] == "-" and strip(step_node[2])[0] == "num":
            cmp = ">="
        else:
            step_var = self.temp("step")
            self.lines.insert(len(self.lines) - 1, "    " * indent + f"{step_var} := {step_v}")
            step_v = step_var
            cmp = None
        if cmp:
            self.emit(indent, f"while {var} {cmp} {end}")
        else:
            self.emit(
                indent,
                f"while ({step_v} >= 0 and {var} <= {end}) or ({step_v} < 0 and {var} >= {end})",
            )
        j = self.block(lines, i + 1, indent + 1, ("next",))
        if j >= len(lines):
            raise NotTranslated("For without Next")
        if step_v.startswith("-") and re.fullmatch(r"-[\d.]+", step_v):
            self.emit(indent + 1, f"{var} := {var} - {step_v[1:]}")
        else:
            self.emit(indent + 1, f"{var} := {var} + {step_v}")
        return j + 1

    def for_each(self, lines, i, indent, name, source) -> int:
        node = strip(parse(source))
        key = node[1].lower() if node[0] == "id" else None
        if key is None or key not in self.arrays:
            raise NotTranslated(f"For Each over {source!r}: not an array or range argument")
        arr = self.arrays[key]
        src = self.local(node[1])
        var = self.local(name)
        r, c = self.temp("r"), self.temp("c")
        if arr.is_range or arr.dims == 2:
            # a Range is walked row by row, a VBA array column by column
            outer, inner = (r, c) if arr.is_range else (c, r)
            limits = {r: f"rows({src}) - 1", c: f"cols({src}) - 1"}
            self.emit(indent, f"for {outer} in 0 .. {limits[outer]}")
            self.emit(indent + 1, f"for {inner} in 0 .. {limits[inner]}")
            self.emit(indent + 2, f"{var} := {src}[{r}, {c}]")
            j = self.block(lines, i + 1, indent + 2, ("next",))
        else:
            self.emit(indent, f"for {r} in 0 .. last({src})")
            self.emit(indent + 1, f"{var} := {src}[{r}]")
            j = self.block(lines, i + 1, indent + 1, ("next",))
        if j >= len(lines):
            raise NotTranslated("For Each without Next")
        if any(ln.strip() == "break" for ln in self.lines[-50:]):
            raise NotTranslated("Exit For inside For Each (two loops here)")
        return j + 1

    def do(self, lines, i: int, indent: int) -> int:
        _, text = lines[i]
        m = re.match(r"^Do\s+(While|Until)\s+(.*)$", text, re.I)
        if m:
            cond = self.cond(parse(m.group(2)))
            if m.group(1).lower() == "until":
                cond = f"not ({cond})"
            self.emit(indent, f"while {cond}")
            j = self.block(lines, i + 1, indent + 1, ("loop",))
            if j >= len(lines) or lines[j][1].strip().lower() != "loop":
                raise NotTranslated("Do While/Until ... Loop with a second condition")
            return j + 1
        if text.strip().lower() != "do":
            raise NotTranslated(f"cannot read {text!r}")
        self.emit(indent, "while 1 == 1")
        j = self.block(lines, i + 1, indent + 1, ("loop",))
        if j >= len(lines):
            raise NotTranslated("Do without Loop")
        tail = lines[j][1].strip()
        m = re.match(r"^Loop\s+(While|Until)\s+(.*)$", tail, re.I)
        if m:
            cond = self.cond(parse(m.group(2)))
            if m.group(1).lower() == "while":
                cond = f"not ({cond})"
            self.emit(indent + 1, f"break if {cond}")
        elif tail.lower() != "loop":
            raise NotTranslated(f"cannot read {tail!r}")
        return j + 1

    # -- expressions -------------------------------------------------------------------
    def cond(self, node) -> str:
        node = strip(node)
        if node[0] == "bin" and node[1] in ("=", "<>", "<", ">", "<=", ">="):
            return self._compare(node[1], self.value(node[2], 4), node[3])
        if node[0] == "bin" and node[1] in ("and", "or"):
            return f"({self.cond(node[2])} {node[1]} {self.cond(node[3])})"
        if node[0] == "un" and node[1] == "not":
            return f"not ({self.cond(node[2])})"
        if node[0] == "id" and node[1].lower() == "true":
            return "1 == 1"
        if node[0] == "id" and node[1].lower() == "false":
            return "1 == 0"
        if node[0] == "call" and node[1][0] == "id" and node[1][1].lower() == "ismissing":
            arg = strip(node[2][0]) if node[2] else None
            if arg is None or arg[0] != "id" or arg[1].lower() not in self.names:
                raise NotTranslated("IsMissing of something not an argument")
            p = self.names[arg[1].lower()]
            flag = self.info.given.get(p)
            if flag is None:
                raise NotTranslated(f"IsMissing({arg[1]}) of an argument that is not Optional")
            return f"{flag} == 0"
        if node[0] == "bin" and node[1] in ("xor", "eqv", "imp", "is", "isnot", "like"):
            raise NotTranslated(f"the operator {node[1]}")
        return f"{self.value(node, 4)} != 0"

    def value(self, node, ctx: int = 0) -> str:
        """Text of a value; brackets where the surrounding operator (level ``ctx``) binds
        tighter: 1 or, 2 and, 3 not, 4 comparison, 5 + -, 6 * /, 7 unary, 8 ^."""
        node = strip(node)
        kind = node[0]
        if kind == "num":
            text = node[1]
            return text if not text.startswith(".") else "0" + text
        if kind == "str":
            problem = text_problem(node[1])
            if problem:
                raise NotTranslated(problem)
            return f'"{node[1]}"'
        if kind == "id":
            return self.name(node[1])
        if kind == "un":
            if node[1] == "not":
                return self._paren(f"-1 if {self.cond(node)} otherwise 0", 0, ctx)
            inner = self.value(node[2], 7)
            return self._paren(f"-{inner}" if node[1] == "-" else inner, 7, ctx)
        if kind == "bin":
            return self.binary(node, ctx)
        if kind == "call":
            return self.call(node)
        if kind == "mem":
            return self.member(node, [])
        raise NotTranslated(f"cannot translate {node!r}")

    @staticmethod
    def _paren(text: str, level: int, ctx: int) -> str:
        return f"({text})" if level < ctx or (level == 0 and ctx > 0) else text

    def binary(self, node, ctx: int) -> str:
        _, op, a, b = node
        if op in ("=", "<>", "<", ">", "<=", ">=", "and", "or"):
            return self._paren(f"-1 if {self.cond(node)} otherwise 0", 0, ctx)
        if op in ("+", "-"):
            return self._paren(f"{self.value(a, 5)} {op} {self.value(b, 6)}", 5, ctx)
        if op in ("*", "/"):
            return self._paren(f"{self.value(a, 6)}{op}{self.value(b, 7)}", 6, ctx)
        if op == "^":  # VBA's ^ is left-associative and binds tighter than unary minus
            return self._paren(f"{self.value(a, 9)}^{self.value(b, 9)}", 8, ctx)
        if op == "\\":
            x, y = bankers(self.value(a)), bankers(self.value(b))
            return f"trunc({x}/{y})"
        if op == "mod":
            return f"mod({bankers(self.value(a))}, {bankers(self.value(b))})"
        if op == "&":
            raise NotTranslated("joins texts (&)")
        raise NotTranslated(f"the operator {op}")

    def name(self, vba: str) -> str:
        key = vba.lower()
        if key in self.names:
            return self.names[key]
        if key == self.proc.name.lower():  # the function's own name reads its value so far
            return self.ret
        if key == "true":
            return "-1"
        if key == "false":
            return "0"
        if key in ("empty", "vbnullstring"):
            return "0" if key == "empty" else '""'
        if key in self.functions:
            return self._call_function(key, [])
        if key in ("pi",):
            raise NotTranslated("Pi is not a VBA name (an undeclared variable)")
        # an undeclared variable (VBA makes it Empty: 0 until given a value)
        local = self.local(vba)
        if local not in self.written:
            self.read_empty.append(local)
        return local

    def indices(self, key: str, args) -> str:
        arr = self.arrays[key]
        if any(a is None or a[0] == "named" for a in args):
            raise NotTranslated("an index left out")
        out = []
        for a in args:
            node = strip(a)
            if node[0] == "num" and re.fullmatch(r"\d+", node[1]):
                out.append(str(int(node[1]) - arr.base))
                continue
            v = self.value(a, 5)
            if arr.base:
                v = f"{v} - {arr.base}"
            out.append(v)
        if arr.is_range and len(out) == 1:
            raise NotTranslated("a range indexed by one number")
        return ", ".join(out)

    def _range_base(self, node):
        node = strip(node)
        if node[0] == "id" and node[1].lower() in self.arrays:
            return self.arrays[node[1].lower()]
        return None

    def call(self, node) -> str:
        _, base, args = node
        base = strip(base)
        if base[0] == "mem":
            return self.member(base, args)
        if base[0] != "id":
            raise NotTranslated("a call of an expression")
        key = base[1].lower()
        if key in self.arrays or (key in self.names and key not in self.functions):
            if key not in self.arrays:
                raise NotTranslated(f"{base[1]}(...) of a variable not known to be an array")
            return f"{self.names.get(key) or self.local(base[1])}[{self.indices(key, args)}]"
        if key in self.functions:
            return self._call_function(key, args)
        if key in VBA:
            return self._template(VBA[key], args, base[1])
        if key in ("ubound", "lbound"):
            return self.bound(key, args)
        if key == "iif":
            if len(args) != 3:
                raise NotTranslated("IIf takes three arguments")
            return (
                f"({self.value(args[1], 1)} if {self.cond(args[0])} "
                f"otherwise {self.value(args[2], 1)})"
            )
        if key in ("cint", "clng", "round"):
            if key == "round" and len(args) > 1:
                raise NotTranslated("Round to digits (VBA rounds half to even)")
            return bankers(self.value(args[0]))
        if key == "array":
            return "[" + ", ".join(self.value(a) for a in args) + "]"
        if key == "cverr":
            raise NotTranslated("CVErr outside an assignment to the function")
        raise NotTranslated(f"calls {base[1]}, not a function this translation knows")

    def bound(self, key: str, args) -> str:
        arg = strip(args[0]) if args else None
        if arg is None or arg[0] != "id" or arg[1].lower() not in self.arrays:
            raise NotTranslated(f"{key} of something not an array")
        arr = self.arrays[arg[1].lower()]
        dim = 1
        if len(args) > 1:
            d = strip(args[1])
            if d[0] != "num":
                raise NotTranslated("UBound of a dimension that is not a number")
            dim = int(float(d[1]))
        if key == "lbound":
            return str(arr.base)
        name = self.local(arg[1])
        size = f"rows({name})" if dim == 1 else f"cols({name})"
        return f"({size} - 1 + {arr.base})" if arr.base != 1 else size

    def _template(self, entry, args, name: str) -> str:
        text, arities = entry
        if len(args) not in arities or any(a is None for a in args):
            raise NotTranslated(f"{name} with {len(args)} arguments")
        out = text.format(*[self.value(a) for a in args])
        return out if re.fullmatch(r"\w+\([^()]*\)", text) else f"({out})"

    def _call_function(self, key: str, args, refs: list[int] | None = None) -> str:
        """The call of the VBA function ``key``; with ``refs`` (the positions of the
        parameters it changes by reference), of its ``_refs`` program, which also gives them."""
        info = self.functions[key]
        self.info.calls.add(key)
        if refs is not None:
            info.refs = refs
        params = info.proc.params
        if len(args) > len(params):
            raise NotTranslated(f"{info.proc.name} called with too many arguments")
        texts, flags = [], []
        for k, p in enumerate(params):
            a = args[k] if k < len(args) else None
            if a is not None and a[0] == "named":
                raise NotTranslated("named arguments")
            given = a is not None
            if given and refs is None and k in self.changed_params.get(key, ()):
                node = strip(a)
                element = node[0] == "call" and strip(node[1])[0] == "id"
                if node[0] == "id" or (element and strip(node[1])[1].lower() in self.arrays):
                    raise NotTranslated(
                        f"passes a variable to {info.proc.name}, which changes its parameter "
                        f"{p.name} (by reference): the caller's variable changes, which is not "
                        "translated"
                    )
            if not given:
                if not p.optional:
                    raise NotTranslated(f"{info.proc.name} called without {p.name}")
                texts.append(default_text(p))
            else:
                texts.append(self.value(a))
                if p.array or p.type.lower() == "variant":
                    node = strip(a)
                    arr = self.arrays.get(node[1].lower()) if node[0] == "id" else None
                    base = None if arr is None or arr.is_range else arr.base
                    info.arg_bases.setdefault(k, set()).add(base)
            if info.params[k] in info.given:
                flags.append("1" if given else "0")
        if refs is not None:
            return f"{refs_name(info)}({', '.join(texts + flags)})"
        if not texts + flags:  # a function without arguments is a definition
            return info.final
        return f"{info.final}({', '.join(texts + flags)})"
