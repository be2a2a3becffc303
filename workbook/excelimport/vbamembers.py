"""Members in VBA expressions: ``Application.WorksheetFunction.Max(...)`` and the other
calls of Excel's functions, ``.Rows.Count`` and ``.Value`` of a range argument,
``Module.Function(...)``, and the fields of a ``Type`` record (a vector of the language, one
element a field, in the order the ``Type`` declares them)."""

from __future__ import annotations

import re

from .functions import EXCEL, EXCEL_VARIADIC
from .vbaexpr import strip


def is_transpose(node) -> bool:
    """``Application.Transpose(...)`` or ``WorksheetFunction.Transpose(...)``."""
    if node[0] != "call" or strip(node[1])[0] != "mem":
        return False
    member = strip(node[1])
    return member[2].lower() == "transpose" and strip(member[1])[0] in ("id", "mem")


class NotTranslated(Exception):
    """A construct this translation does not take (the reason is the message)."""


def record_types(code: str) -> dict[str, list[tuple[str, str]]]:
    """{lower-case Type name: [(lower-case field, lower-case type)]} of a module's ``Type``
    blocks."""
    out = {}
    for m in re.finditer(
        r"^[ \t]*(?:Public[ \t]+|Private[ \t]+)?Type[ \t]+(\w+)[ \t]*\r?\n"
        r"(.*?)^[ \t]*End[ \t]+Type\b",
        code,
        re.I | re.M | re.S,
    ):
        fields = []
        for line in m.group(2).splitlines():
            line = line.split("'")[0].strip()
            if not line:
                continue
            f = re.fullmatch(r"(\w+)(\s*\([^)]*\))?(?:\s+As\s+(\w+))?", line, re.I)
            fields.append(
                (f.group(1).lower(), "array" if f.group(2) else (f.group(3) or "variant").lower())
                if f
                else ("", "unknown")
            )
        out[m.group(1).lower()] = fields
    return out


class Members:
    """The translation of member expressions (mixed into the Translator of vbaprogram)."""

    def record(self, typ: str) -> list[tuple[str, str]]:
        """The fields of a Type whose fields are numbers (else NotTranslated)."""
        fields = self.record_types[typ.lower()]
        for name, kind in fields:
            if kind not in ("double", "single", "currency", "decimal", "boolean", "variant"):
                raise NotTranslated(f"the Type {typ}: its field {name or '?'} is a {kind}")
        return fields

    def zeros(self, typ: str) -> str:
        """A new record of the Type: every field 0, as VBA starts it."""
        return "[" + ", ".join("0" for _ in self.record(typ)) + "]"

    def error_value(self) -> str:
        """What the function returns to have no value: ``1/0``, or a record of the Type it
        returns whose first field is ``1/0`` (a program gives one shape of value)."""
        fields = self.records_of.get(self.proc.name.lower())
        if fields is None:
            return "1/0"
        return "[" + ", ".join(["1/0"] + ["0"] * (len(fields) - 1)) + "]"

    def field_index(self, obj, attr: str) -> tuple[str, int] | None:
        """(local, index) of ``p.field`` where p is a local of a Type record."""
        obj = strip(obj)
        if obj[0] != "id":
            return None
        key = obj[1].lower()
        fields = self.records_of.get(key)
        if fields is None:
            return None
        names = [f for f, _ in fields]
        if attr.lower() not in names:
            raise NotTranslated(f"{obj[1]}.{attr}: not a field of its Type")
        local = self.ret if key == self.proc.name.lower() else self.local(obj[1])
        return local, names.index(attr.lower())

    def member(self, node, args) -> str:
        _, obj, attr = node
        found = self.field_index(obj, attr)
        if found is not None and not args:
            return f"{found[0]}[{found[1]}]"
        low = attr.lower()
        obj = strip(obj)
        chain = _chain(node)
        if chain and chain[0].lower() in ("application", "worksheetfunction", "math"):
            fn = chain[-1].upper()
            if chain[0].lower() == "math":
                return self.call(("call", ("id", chain[-1]), args))
            if fn == "TRANSPOSE":
                raise NotTranslated("Transpose other than assigned to a variable")
            return self.excel_call(fn, args)
        if obj[0] == "id" and obj[1].lower() in self.arrays:
            arr = self.arrays[obj[1].lower()]
            src = self.local(obj[1])
            if low in ("value", "value2") and not args:
                return src
            if low == "count":
                return f"rows({src})*cols({src})" if arr.is_range else f"rows({src})"
            if low in ("cells", "item") and args:
                return f"{src}[{self.indices(obj[1].lower(), args)}]"
        if (  # r.Cells(i, j).Value, r.Item(i).Value: the element itself
            low in ("value", "value2")
            and not args
            and obj[0] == "call"
            and strip(obj[1])[0] == "mem"
            and strip(obj[1])[2].lower() in ("cells", "item")
        ):
            return self.member(strip(obj[1]), obj[2])
        if obj[0] == "mem" and low == "count" and obj[2].lower() in ("rows", "columns"):
            inner = strip(obj[1])
            if inner[0] == "id" and inner[1].lower() in self.arrays:
                src = self.local(inner[1])
                return f"rows({src})" if obj[2].lower() == "rows" else f"cols({src})"
        if obj[0] == "id" and low in {f for f in self.functions}:  # Module.Function(...)
            return self._call_function(low, args)
        raise NotTranslated(f"{'.'.join(chain) or attr}: an object or a property")

    def transpose_into(self, target: str, node, indent: int) -> None:
        """``target = Application.Transpose(x)`` of a range or an array, as VBA gives it: a
        1-D array (the language's column, indexed from 1) where the result has one row, so
        that a column range becomes a 1-D array, a row range a column (2-D) and that column
        again a 1-D array; a 1-D array, read as a row, becomes a column (2-D). In every case
        the language's value is x where x has one column, else transpose(x)."""
        args = node[2]
        arg = strip(args[0]) if len(args) == 1 and args[0] is not None else None
        if arg is not None and is_transpose(arg):
            src = self.temp("t")
            self.transpose_into(src, arg, indent)
        elif arg is not None and arg[0] == "id" and arg[1].lower() in self.arrays:
            src = self.value(arg)
        else:
            raise NotTranslated("Transpose of other than a range argument or an array")
        self.emit(indent, f"if cols({src}) == 1")
        self.emit(indent + 1, f"{target} := {src}")
        self.emit(indent, "otherwise")
        self.emit(indent + 1, f"{target} := transpose({src})")

    def excel_call(self, fn: str, args) -> str:
        if fn in EXCEL_VARIADIC:
            vals = [self.value(a) for a in args if a is not None]
            how = EXCEL_VARIADIC[fn]
            if how == "+":
                raise NotTranslated("WorksheetFunction.Sum (of ranges)")
            if how == "mean":
                return f"mean([{', '.join(vals)}])" if len(vals) > 1 else f"mean({vals[0]})"
            return f"{how}({', '.join(vals)})"
        if fn in EXCEL:
            return self._template(EXCEL[fn], args, fn)
        from ..functions.excel_functions import FUNCTIONS

        if fn not in FUNCTIONS and fn.replace("_", ".") not in FUNCTIONS:
            # no such method: VBA stops with run-time error 438 where the call runs, and the
            # cell shows #VALUE!
            return "(1/0)"
        raise NotTranslated(f"WorksheetFunction.{fn}: not mapped")


def _chain(node) -> list[str]:
    out = []
    while node[0] == "mem":
        out.append(node[2])
        node = strip(node[1])
    if node[0] == "id":
        out.append(node[1])
        chain = out[::-1]
        # ThisWorkbook.Application.WorksheetFunction.Max: the same Application
        if (
            len(chain) > 2
            and chain[0].lower() == "thisworkbook"
            and chain[1].lower() == "application"
        ):
            chain = chain[1:]
        return chain
    return []
