"""Cell formulas to expressions of the language.

Formulas are parsed by the ``formulas`` package (its tokenizer and its operator precedence,
which are Excel's); the tree it builds is walked here. A reference becomes the name of the
cell (or a vector/matrix of names for a range), a call of a VBA function the call of its
translation, Excel's functions their mapped forms (``functions.EXCEL``).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from .aggregates import AGGREGATES, aggregate
from .criteria import FUNCTIONS as CRITERIA
from .criteria import criteria_function
from .formula_terms import FormulaProblem, Ref, holds_number, row_relative, text_problem
from .functions import EXCEL, VOLATILE
from .information import INFORMATION, information
from .joins import TEXT_PARTS, text_part

#: a prefix that calls into an add-in or another workbook: [1]!f( or 'Book.xlam'!f(
_LINK = re.compile(
    r"(?:\[\d+\]|'[^']*\.xla[m]?'|[A-Za-z0-9_.\- ]+\.xla[m]?)!(?=[A-Za-z_][\w.]*\()", re.I
)
MAX_RANGE_CELLS = 100_000
#: rows of a VLOOKUP table at most (a chain of as many conditions)
MAX_LOOKUP_ROWS = 200
#: a formula that is one cell's reference: =D63, =Sheet2!$B$4, ='Load table'!C7
_PLAIN_REF = re.compile(r"(?:'?([^'!]+)'?!)?\$?([A-Za-z]{1,3})\$?(\d+)")


@dataclass
class Parsed:
    tree: tuple
    linked: bool = False  # called a function through an external link (not followed)


def parse_formula(text: str) -> Parsed:
    """The tree of an Excel formula (the text after '=')."""
    import formulas
    from formulas.errors import FormulaError
    from formulas.tokens.function import Function
    from formulas.tokens.operator import Operator

    linked = bool(_LINK.search(text))
    text = _LINK.sub("", text)

    class TreeBuilder:
        def __init__(self, match=None, **_):
            self.stack: list = []

        def append(self, token):
            if isinstance(token, (Operator, Function)):
                n = token.get_n_args
                if n > len(self.stack):
                    raise FormulaError()
                args = self.stack[len(self.stack) - n :] if n else []
                del self.stack[len(self.stack) - n :]
                kind = "fn" if isinstance(token, Function) else "op"
                self.stack.append((kind, token.name, args))
            else:
                self.stack.append(("leaf", type(token).__name__, token))

        def pop(self):
            return self.stack.pop()

        def __len__(self):
            return len(self.stack)

        def finish(self):
            pass

    parser = formulas.Parser()
    parser.ast_builder = TreeBuilder
    try:
        _, builder = parser.ast("=" + text)
    except Exception as exc:  # noqa: BLE001 - the parser's own errors
        raise FormulaProblem(f"cannot parse the formula ({type(exc).__name__})") from None
    return Parsed(builder.stack[0], linked)


@dataclass
class FormulaText:
    text: str
    refs: list[Ref] = field(default_factory=list)
    udfs: set[str] = field(default_factory=set)  # lower-case VBA names called
    # empty cells an IS-function's answer takes to stay empty (never an input of the sheet)
    empty_cells: list = field(default_factory=list)


class FormulaTranslator:
    """Walks a formula tree; ``name_of(sheet, row, col)`` gives a cell's name."""

    def __init__(
        self,
        book,
        sheet: str,
        name_of,
        functions: dict,
        names: dict,
        block=None,
        ranges=None,
        moving: dict | None = None,
        seen: set | None = None,
        rows: int = 1,
        in_array: bool = False,
    ) -> None:
        self.book = book
        self.in_array = in_array or block is not None  # Excel computes it as an array formula
        # the kinds ("number", "text", ...) of Excel's cached values of the cells this formula
        # computes (each row of a filled-down column), and the rows it is filled down over
        self.seen = seen
        self.rows = rows
        self.tails: set[int] = set()  # the nodes whose value is the formula's value
        # a filled-down column: {(sheet, row, col) of the first row: the name that moves}, for
        # the references whose row is relative (``M183``, never ``$M$183``)
        self.moving = moving or {}
        self.depth = 0  # defined names whose formula is being translated, one in another
        self.block = block  # (rows, columns) of the cells of a multi-cell array formula
        # ((rows, columns), k) while one element of an array formula's ranges is translated:
        # every range of that shape reads its k-th cell (aggregates.py, IF inside MIN)
        self.element: tuple[tuple[int, int], int] | None = None
        # {matrix literal: name}: a range that formulas read is one definition, named here
        self.ranges = ranges
        self.sheet = sheet
        self.name_of = name_of
        self.functions = functions
        self.defined = {k.lower(): v for k, v in names.items()}
        self.out = FormulaText("")

    def translate(self, tree) -> FormulaText:
        self.tails.add(id(tree))
        self.out.text = self.value(tree)
        return self.out

    def matrix_inverse(self, args) -> str:
        """``MINVERSE(A)`` of a square range of at least 2x2, in an array formula of A's
        shape."""
        if len(args) != 1 or args[0][0] != "leaf" or args[0][1] != "Range":
            raise FormulaProblem("MINVERSE of other than a range")
        ref = self.ref_of(args[0][2])
        n = ref.r2 - ref.r1 + 1
        if n != ref.c2 - ref.c1 + 1 or n < 2:
            raise FormulaProblem("MINVERSE of other than a square range of 2x2 or more")
        if self.block != (n, n):
            raise FormulaProblem(f"MINVERSE whose {n}x{n} inverse is not shown in as many cells")
        return f"inverse({self.reference(args[0][2])})"

    def matrix_product(self, args) -> str:
        """``MMULT(A, B)`` of two ranges, in an array formula whose cells are the product's
        shape (each cell then shows its element, never another's)."""
        refs = [self.ref_of(a[2]) if a[0] == "leaf" and a[1] == "Range" else None for a in args]
        if len(args) != 2 or None in refs:
            raise FormulaProblem("MMULT of other than two ranges")
        a, b = refs
        ra, ca = a.r2 - a.r1 + 1, a.c2 - a.c1 + 1
        rb, cb = b.r2 - b.r1 + 1, b.c2 - b.c1 + 1
        if ca != rb:
            raise FormulaProblem(f"MMULT of a {ra}x{ca} by a {rb}x{cb} range (#VALUE! in Excel)")
        if self.block != (ra, cb):
            raise FormulaProblem(
                f"MMULT whose {ra}x{cb} product is not shown in as many cells of an array formula"
            )
        if ca == 1 and cb == 1:
            raise FormulaProblem("MMULT of a column by one cell")  # the language's dot product
        return f"{self.reference(args[0][2])}*{self.reference(args[1][2])}"

    # Excel precedence levels for brackets: 1 comparison, 2 &, 3 + -, 4 * /, 5 ^, 6 unary, 7 %
    def value(self, node, ctx: int = 0) -> str:
        kind, name, payload = node
        if kind == "leaf":
            return self.leaf(name, payload)
        if kind == "op":
            return self.operator(name, payload, ctx)
        if name.upper() == "IF":
            from .kinds import if_of_kinds

            return if_of_kinds(self, node)
        return self.function(name, payload)

    def leaf(self, kind: str, token) -> str:
        if kind == "Number":
            text = token.name
            if text.upper() in ("TRUE", "FALSE"):
                return "1" if text.upper() == "TRUE" else "0"
            return text
        if kind == "String":
            value = token.name
            problem = text_problem(value)
            if problem:
                raise FormulaProblem(problem)
            return f'"{value}"'
        if kind == "Range":
            return self.reference(token)
        if kind == "Error":
            raise FormulaProblem(f"the error value {token.name} written in the formula")
        raise FormulaProblem(f"a {kind} in the formula")

    def ref_of(self, token) -> Ref:
        attr = token.attr
        if "r1" not in attr:  # a defined name
            key = str(attr.get("ref", token.name)).lower()
            if key not in self.defined:
                raise FormulaProblem(f"the name {attr.get('ref', token.name)} (not a cell range)")
            sheet, ref = self.defined[key]
            return _parse_ref(sheet, ref)
        sheet = self.sheet
        if attr.get("sheet_id"):
            if "[" in str(attr.get("sheet_id")):
                raise FormulaProblem("a reference into another workbook (an external link)")
            found = self.book.sheet_named(str(attr.get("sheet") or attr["sheet_id"]))
            if found is None:
                raise FormulaProblem(f"a reference to the sheet {attr.get('sheet')}")
            sheet = found
        r1, r2 = int(attr["r1"]), int(attr["r2"])
        c1, c2 = _col(attr["c1"]), _col(attr["c2"])
        if r1 < 1 or (r2 - r1 + 1) * (c2 - c1 + 1) > MAX_RANGE_CELLS:
            raise FormulaProblem(f"a reference to whole rows or columns ({token.name})")
        if attr.get("anchor") == "#" or str(attr.get("ref", "")).endswith("#"):
            return self.spill(sheet, r1, c1, token.name)
        return Ref(sheet, min(r1, r2), min(c1, c2), max(r1, r2), max(c1, c2))

    def spill(self, sheet: str, row: int, col: int, text: str) -> Ref:
        """``C496#`` (``ANCHORARRAY``): the cells of the array formula whose first cell is
        C496, as Excel saved its extent; never the anchor cell alone."""
        from openpyxl.utils.cell import range_boundaries

        cell = self.book.cell(sheet, row, col)
        if cell is None or cell.array is None:
            raise FormulaProblem(f"the spilled range {text} of a cell that is no array formula")
        c1, r1, c2, r2 = range_boundaries(cell.array)
        if (r1, c1) != (row, col):
            raise FormulaProblem(f"the spilled range {text} of a cell inside an array formula")
        return Ref(sheet, r1, c1, r2, c2)

    def reference(self, token) -> str:
        if self.is_name_formula(token):
            return self.name_formula(token)
        ref = self.ref_of(token)
        if self.element is not None and not ref.single:
            shape, k = self.element
            if (ref.r2 - ref.r1 + 1, ref.c2 - ref.c1 + 1) != shape:
                raise FormulaProblem("an array formula over ranges of different sizes")
            r, c = ref.r1 + k // shape[1], ref.c1 + k % shape[1]
            self.out.refs.append(Ref(ref.sheet, r, c, r, c))
            return self.name_of(ref.sheet, r, c)
        self.out.refs.append(ref)
        if ref.single:
            return self.single(ref, token)
        rows = [
            [self.name_of(ref.sheet, r, c) for c in range(ref.c1, ref.c2 + 1)]
            for r in range(ref.r1, ref.r2 + 1)
        ]
        return self.shared("[" + ", ".join("[" + ", ".join(row) + "]" for row in rows) + "]", ref)

    def single(self, ref: Ref, token) -> str:
        """The name of one cell a reference reads: in a filled-down column, the moving name
        when the reference's row is relative and the cell is the one that moves."""
        key = (ref.sheet, ref.r1, ref.c1)
        if key in self.moving and row_relative(token):
            ref.moved = True  # type: ignore[attr-defined]
            return self.moving[key]
        return self.name_of(ref.sheet, ref.r1, ref.c1)

    def is_name_formula(self, token) -> bool:
        """A defined name that is a constant or a formula, not one range."""
        attr = getattr(token, "attr", {})
        if "r1" in attr:
            return False
        key = str(attr.get("ref", token.name)).lower()
        return key not in self.defined and key in self.name_texts()

    def name_texts(self) -> dict[str, str]:
        return {k.lower(): v for k, v in getattr(self.book, "name_formulas", {}).items()}

    def name_formula(self, token) -> str:
        """A defined name's constant or formula, translated where it is used (its references
        are those of the name: absolute, on the sheet the name writes)."""
        text = self.name_texts()[str(token.attr.get("ref", token.name)).lower()]
        if self.depth > 20:
            raise FormulaProblem(f"the defined name {token.name}: names nested too deeply")
        self.depth += 1
        try:
            tree = parse_formula(text).tree
            return f"({self.value(tree, 0)})"
        except FormulaProblem as exc:
            raise FormulaProblem(f"the defined name {token.name} ({text[:40]}): {exc}") from None
        finally:
            self.depth -= 1

    def shared(self, literal: str, ref: Ref) -> str:
        """The name of the definition of a range's matrix (one for every formula that reads
        the same cells), or the literal itself when no names are kept."""
        if self.ranges is None:
            return literal
        name = self.ranges.get(literal)
        if name is None:
            from openpyxl.utils import get_column_letter

            sheet = re.sub(r"[^A-Za-z0-9_]+", "", ref.sheet)[:12]
            corner = f"{get_column_letter(ref.c1)}{ref.r1}_{get_column_letter(ref.c2)}{ref.r2}"
            name = f"range_{sheet}_{corner}"
            while name in self.ranges.values():
                name += "_2"
            self.ranges[literal] = name
        return name

    def cells_of(self, node, numbers_only: bool = False) -> list[str] | None:
        """The names of a range argument, in reading order (None if not a reference).

        With ``numbers_only`` (Excel's SUM, AVERAGE, MIN, MAX, COUNT, STDEV...), the cells that
        Excel leaves out of a reference are left out: empty cells, texts and TRUE/FALSE (of a
        formula cell, as its cached value shows)."""
        if node[0] == "leaf" and node[1] == "Range" and not self.is_name_formula(node[2]):
            ref = self.ref_of(node[2])
            self.out.refs.append(ref)
            if ref.single:
                key = (ref.sheet, ref.r1, ref.c1)
                if key in self.moving and row_relative(node[2]):
                    return [self.single(ref, node[2])]
            names = []
            for r in range(ref.r1, ref.r2 + 1):
                for c in range(ref.c1, ref.c2 + 1):
                    if numbers_only and not holds_number(self.book.cell(ref.sheet, r, c)):
                        continue
                    names.append(self.name_of(ref.sheet, r, c))
            return names
        return None

    def operator(self, op: str, args, ctx: int) -> str:
        levels = {"+": 3, "-": 3, "*": 4, "/": 4, "^": 5}
        if op in levels or op in ("u-", "u+", "%"):
            from .kinds import never_a_number

            if any(never_a_number(self, a) for a in args):
                return "(1/0)"  # a text in arithmetic: #VALUE! in Excel
        if op in ("u-", "u+"):
            inner = self.value(args[0], 6)
            text = f"-{inner}" if op == "u-" else inner
            return f"({text})" if ctx >= 5 or ctx > 0 else text
        if op == "%":
            return f"{self.value(args[0], 7)}/100"
        if op in levels:
            level = levels[op]
            if op == "^":  # Excel's ^ is left-associative
                return _br(f"{self.value(args[0], 6)}^{self.value(args[1], 6)}", level, ctx)
            right_ctx = level + 1 if op in ("-", "/") else level
            sep = f" {op} " if level == 3 else op
            return _br(
                f"{self.value(args[0], level)}{sep}{self.value(args[1], right_ctx)}", level, ctx
            )
        if op in ("=", "<>", "<", ">", "<=", ">="):
            return f"(1 if {self.condition(('op', op, args))} otherwise 0)"
        if op == "&":
            from .joins import join

            return join(self, [("op", op, args)])
        raise FormulaProblem(f"the operator {op}")

    def condition(self, node) -> str:
        kind, name, args = node
        ops = {"=": "==", "<>": "!=", "<": "<", ">": ">", "<=": "<=", ">=": ">="}
        if kind == "op" and name in ops:
            from .kinds import compared

            found = compared(self, name, args)
            if found is not None:
                return found
            return f"{self.value(args[0], 3)} {ops[name]} {self.value(args[1], 3)}"
        if kind == "fn" and name.upper() in ("AND", "OR"):
            joined = f" {name.lower()} ".join(f"({self.condition(a)})" for a in args)
            return joined
        if kind == "fn" and name.upper() == "NOT":
            return f"not ({self.condition(args[0])})"
        if kind == "leaf" and name == "Number" and args.name.upper() in ("TRUE", "FALSE"):
            return "1 == 1" if args.name.upper() == "TRUE" else "1 == 0"
        if kind == "fn" and name.upper() in INFORMATION:
            return information(self, name.upper(), args)
        return f"{self.value(node, 3)} != 0"

    def function(self, name: str, args) -> str:
        upper = name.upper()
        short = name.split(".")[-1]
        if short.lower() in self.functions:
            return self.udf(short.lower(), args)
        if upper == "OFFSET":
            return self.offset(args)
        if upper in VOLATILE:
            raise FormulaProblem(
                f"the volatile function {upper} (its value changes at every recalculation)"
            )
        if upper == "IF":
            if len(args) != 3:
                raise FormulaProblem("IF without a value for FALSE")
            cond = self.condition(args[0])
            return f"({self.value(args[1], 1)} if {cond} otherwise {self.value(args[2], 1)})"
        if upper in ("AND", "OR", "NOT") or upper in INFORMATION:
            return f"(1 if {self.condition(('fn', name, args))} otherwise 0)"
        if upper in AGGREGATES:
            return aggregate(self, upper, args)
        if upper in EXCEL:
            text, arities = EXCEL[upper]
            if len(args) not in arities:
                raise FormulaProblem(f"{upper} with {len(args)} arguments")
            out = text.format(*[self.value(a, 0) for a in args])
            return out if re.fullmatch(r"\w+\([^()]*\)", text) else f"({out})"
        if upper == "MMULT":
            return f"({self.matrix_product(args)})"
        if upper == "MINVERSE":
            return self.matrix_inverse(args)
        if upper in CRITERIA:
            return criteria_function(self, upper, args)
        if upper == "VLOOKUP":
            return self.vlookup(args)
        if upper == "IFERROR":
            return self.if_error(args)
        if upper == "CONVERT":
            return self.convert(args)
        if upper == "SUMPRODUCT":
            return self.sum_product(args)
        if upper in ("MATCH", "INDEX", "HLOOKUP"):
            from . import lookups

            return getattr(lookups, upper.lower())(self, args)
        if upper in TEXT_PARTS:
            return text_part(self, upper, args)
        if upper in ("CONCATENATE", "_XLFN.CONCAT", "CONCAT", "CHAR"):
            from .joins import join

            return join(self, [("fn", name, args)])
        if upper == "_XLFN.TEXTSPLIT":
            from .statics import text_split

            return text_split(self, args)
        if upper == "ARRAY":
            raise FormulaProblem("an array constant")
        raise FormulaProblem(f"the Excel function {upper} (not mapped)")

    def sum_product(self, args) -> str:
        """``SUMPRODUCT(A, B, ...)`` of ranges of one shape: the sum over their cells of the
        products, Excel reading a text, an empty cell or TRUE/FALSE as 0 (an empty cell is its
        input 0; a term with a constant text or TRUE/FALSE is 0 and left out). A formula cell
        that gives other than a number is refused (an error value there is Excel's value)."""
        from .kinds import cell_kind_in

        refs = [self.ref_of(a[2]) if a[0] == "leaf" and a[1] == "Range" else None for a in args]
        if not args or None in refs or any(self.is_name_formula(a[2]) for a in args):
            raise FormulaProblem("SUMPRODUCT of other than ranges")
        shapes = {(r.r2 - r.r1, r.c2 - r.c1) for r in refs}
        if len(shapes) != 1:
            raise FormulaProblem("SUMPRODUCT of ranges of different sizes (#VALUE! in Excel)")
        (rows, cols) = shapes.pop()
        terms = []
        for dr in range(rows + 1):
            for dc in range(cols + 1):
                factors = []
                for ref in refs:
                    r, c = ref.r1 + dr, ref.c1 + dc
                    cell = self.book.cell(ref.sheet, r, c)
                    if cell is not None and cell.formula is not None:
                        if cell_kind_in(self, cell, 0) != "number":
                            raise FormulaProblem("SUMPRODUCT over a formula that gives no number")
                    elif cell is not None and not isinstance(cell.value, (int, float)):
                        factors = None  # a text or TRUE/FALSE: Excel's 0
                        break
                    elif cell is not None and isinstance(cell.value, bool):
                        factors = None
                        break
                    self.out.refs.append(Ref(ref.sheet, r, c, r, c))
                    factors.append(self.name_of(ref.sheet, r, c))
                if factors:
                    terms.append("*".join(factors))
        return "(" + " + ".join(terms) + ")" if terms else "0"

    def convert(self, args) -> str:
        """``CONVERT(x, "in", "m")`` of units written in the formula: x times Excel's factor
        (and an offset for temperatures)."""
        from .convert import convert

        if len(args) != 3 or any(a[0] != "leaf" or a[1] != "String" for a in args[1:]):
            raise FormulaProblem("CONVERT of units other than texts written in the formula")
        return convert(self.value(args[0], 4), args[1][2].name, args[2][2].name)

    def if_error(self, args) -> str:
        """``IFERROR(x, alt)`` where x is numbers and cells joined by + - * /, ``^`` by a
        number, ``SQRT``, ``LN``, ``LOG10`` and ``ABS``: each error x can have is a condition on
        its parts (a divisor 0, a root of a negative number, a logarithm of a number not above
        0, 0 to a power not above 0, a negative number to a fractional power), and the value
        is alt where one holds (a cell of x that holds an error value leaves the whole formula
        without a value, never another number)."""
        if len(args) != 2:
            raise FormulaProblem(f"IFERROR with {len(args)} arguments")
        errors: list[str] = []
        self.arithmetic_only(args[0], errors)
        x, alt = self.value(args[0], 1), self.value(args[1], 1)
        if not errors:
            return x
        where = " or ".join(dict.fromkeys(errors))
        return f"({alt} if {where} otherwise {x})"

    def arithmetic_only(self, node, errors: list[str]) -> None:
        """Refuse what IFERROR's error could come from other than the conditions gathered in
        ``errors`` (each translated: where it holds, Excel's x is an error value)."""
        kind, name, payload = node
        if kind == "leaf" and name == "Number" and payload.name.upper() not in ("TRUE", "FALSE"):
            return
        if kind == "leaf" and name == "Range" and not self.is_name_formula(payload):
            if not self.ref_of(payload).single:
                raise FormulaProblem("IFERROR of a range")
            return
        if kind == "op" and name == "^" and len(payload) == 2:
            power, sign = payload[1], 1.0
            if power[0] == "op" and power[1] == "u-":
                power, sign = power[2][0], -1.0
            p = None
            if power[0] == "leaf" and power[1] == "Number":
                if power[2].name.upper() not in ("TRUE", "FALSE"):
                    p = sign * float(power[2].name)
            if p is None:
                raise FormulaProblem("IFERROR of a power other than by a number")
            self.arithmetic_only(payload[0], errors)
            base = self.value(payload[0], 3)
            if p <= 0:
                errors.append(f"{base} == 0")
            if p != int(p):
                errors.append(f"{base} < 0")
            return
        if kind == "op" and name in ("+", "-", "*", "/", "u-", "u+", "%"):
            for a in payload:
                self.arithmetic_only(a, errors)
            if name == "/":
                errors.append(f"{self.value(payload[1], 3)} == 0")
            return
        upper = name.upper() if kind == "fn" else ""
        if upper == "LOG" and len(payload) == 1:
            upper = "LOG10"
        if upper in ERROR_WHERE and len(payload) == 1:
            self.arithmetic_only(payload[0], errors)
            if ERROR_WHERE[upper]:
                errors.append(ERROR_WHERE[upper].format(self.value(payload[0], 3)))
            return
        if upper == "PI" and not payload:
            return
        if upper in ("VLOOKUP", "HLOOKUP", "MATCH"):  # #N/A where no key is x
            from .lookups import lookup_misses

            if upper != "MATCH":
                self.arithmetic_only(payload[2], errors)  # the column (row) k
            if payload and payload[0][:2] != ("leaf", "String"):
                self.arithmetic_only(payload[0], errors)
            missed = lookup_misses(self, upper, payload)
            if missed is not None:
                errors.append(missed)
            return
        if upper == "ATAN2" and len(payload) == 2:  # #DIV/0! at the origin
            for a in payload:
                self.arithmetic_only(a, errors)
            x, y = (self.value(a, 3) for a in payload)
            errors.append(f"{x} == 0 and {y} == 0")
            return
        raise FormulaProblem(
            "IFERROR of other than + - * /, ^ by a number, "
            + ", ".join(ERROR_WHERE)
            + ", ATAN2, PI(), exact VLOOKUP, HLOOKUP and MATCH of numbers and cells (the "
            "language has no error value to catch)"
        )

    def offset(self, args) -> str:
        """``OFFSET(cell, rows, columns)``: the cell it reached when Excel computed it (from
        Excel's cached values of the cells its offsets read), guarded: where the offsets
        compute to other values the value is an error, never another cell's number. An
        offset may be ``MATCH(x, range, 0)`` over a range of texts: its guard is x's value."""
        if len(args) not in (3, 5) or args[0][0] != "leaf" or args[0][1] != "Range":
            raise FormulaProblem("OFFSET of other than one cell by rows and columns")
        if len(args) == 5 and any(self.static(a) != 1 for a in args[3:]):
            raise FormulaProblem("OFFSET to a range of more than one cell")
        ref = self.ref_of(args[0][2])
        if not ref.single:
            raise FormulaProblem("OFFSET of a range")
        from .lookups import offset_by_match

        chain = offset_by_match(self, ref, args[1], args[2])
        if chain is not None:
            return chain
        guards, moves = [], []
        for a in args[1:3]:
            value = self.static(a)
            if value != int(value):
                raise FormulaProblem("OFFSET by a fraction of a cell")
            moves.append(int(value))
            if not (a[0] == "leaf" and a[1] == "Number"):
                guards.append(self.guard(a, value))
        row, col = ref.r1 + moves[0], ref.c1 + moves[1]
        if row < 1 or col < 1:
            raise FormulaProblem("OFFSET outside the sheet (#REF! in Excel)")
        target = self.book.cell(ref.sheet, row, col)
        if guards and target is not None and isinstance(target.value, str):
            raise FormulaProblem("OFFSET to a text, guarded")
        self.out.refs.append(Ref(ref.sheet, row, col, row, col))
        name = self.name_of(ref.sheet, row, col)
        if not guards:
            return name
        return f"({name} if {' and '.join(guards)} otherwise 1/0)"

    def guard(self, node, value: float) -> str:
        """A condition that holds where ``node`` computes to ``value`` (Excel's)."""
        if node[0] == "fn" and node[1].upper() == "MATCH":
            lookup = node[2][0]
            seen = self.static_any(lookup)
            shown = f'"{seen}"' if isinstance(seen, str) else repr(float(seen))
            return f"{self.value(lookup, 3)} == {shown}"
        return f"{self.value(node, 3)} == {float(value)!r}"

    def static_any(self, node):
        """The value of a plain reference or literal from Excel's cached values (a text or a
        number)."""
        kind, name, payload = node
        if kind == "leaf" and name == "String":
            return payload.name
        if kind == "leaf" and name == "Range":
            ref = self.ref_of(payload)
            if not ref.single:
                raise FormulaProblem("a range where one cell is wanted")
            cell = self.book.cell(ref.sheet, ref.r1, ref.c1)
            value = None if cell is None else cell.value
            if value is None or isinstance(value, bool):
                return float(bool(value))
            if isinstance(value, str):
                if value.startswith("#"):
                    raise FormulaProblem(f"reads {ref.sheet}!{cell.address}, an error value")
                return value
            return float(value)
        return self.static(node)

    def static(self, node) -> float:
        """The number ``node`` computes to from Excel's cached values (an OFFSET's offsets):
        numbers, cells, + - * / ^ and MATCH(x, range of texts, 0)."""
        kind, name, payload = node
        if kind == "leaf" and name == "Number":
            word = payload.name.upper()
            return 1.0 if word == "TRUE" else 0.0 if word == "FALSE" else float(payload.name)
        if kind == "leaf" and name == "Range":
            value = self.static_any(node)
            if isinstance(value, str):
                raise FormulaProblem("an offset that reads a text")
            return value
        if kind == "op" and name in ("+", "-", "*", "/", "^") and len(payload) == 2:
            a, b = self.static(payload[0]), self.static(payload[1])
            if name == "/" and b == 0:
                raise FormulaProblem("an offset divided by zero")
            return {"+": a + b, "-": a - b, "*": a * b, "/": a / b if b else 0.0, "^": a**b}[name]
        if kind == "op" and name in ("u-", "u+"):
            v = self.static(payload[0])
            return -v if name == "u-" else v
        if kind == "fn" and name.upper() == "MATCH":
            return self.match(payload)
        raise FormulaProblem("an offset this translation does not compute")

    def match(self, args) -> float:
        """``MATCH(x, range, 0)``: the position of x in a row or column of constant texts
        (texts equal but for case, as Excel); the texts are definitions that never change."""
        if len(args) != 3 or self.static(args[2]) != 0:
            raise FormulaProblem("MATCH other than an exact one")
        rng = args[1]
        if rng[0] != "leaf" or rng[1] != "Range":
            raise FormulaProblem("MATCH in other than a range")
        ref = self.ref_of(rng[2])
        if ref.r1 != ref.r2 and ref.c1 != ref.c2:
            raise FormulaProblem("MATCH in a block of rows and columns")
        seen = self.static_any(args[0])
        if not isinstance(seen, str) or re.search(r"[*?~]", seen):
            raise FormulaProblem("MATCH of other than a text without a pattern")
        k = 0
        for r in range(ref.r1, ref.r2 + 1):
            for c in range(ref.c1, ref.c2 + 1):
                k += 1
                cell = self.book.cell(ref.sheet, r, c)
                if cell is None or cell.value is None:
                    continue
                if cell.formula is not None or not isinstance(cell.value, str):
                    raise FormulaProblem("MATCH in a range that holds other than constant texts")
                if cell.value.casefold() == seen.casefold():
                    return float(k)
        raise FormulaProblem("MATCH that finds nothing (#N/A in Excel)")

    def vlookup(self, args) -> str:
        """``VLOOKUP(x, table, k[, exact])`` over a first column of numbers: a chain of
        conditions on x. The approximate match (the default) takes the last row whose first
        cell is at most x, which is Excel's answer where that column ascends: the chain is
        guarded by the column ascending, and x below the first row is an error (#N/A)."""
        from .lookups import known_number
        from .statics import found, guarded, position

        if len(args) not in (3, 4) or args[1][0] != "leaf" or args[1][1] != "Range":
            raise FormulaProblem("VLOOKUP of other than a table range")
        k, guard = position(self, args[2])
        exact = len(args) == 4 and self.static(args[3]) == 0
        ref = self.ref_of(args[1][2])
        col = ref.c1 + int(k) - 1
        if not ref.c1 <= col <= ref.c2:
            raise FormulaProblem("VLOOKUP of a column outside its table (#REF! in Excel)")
        if exact:
            keys = [(ref.sheet, r, ref.c1) for r in range(ref.r1, ref.r2 + 1)]
            i = found(self, args[0], keys)
            if i is not None:
                if i < 0:
                    return "(1/0)"
                row = ref.r1 + i
                self.out.refs.append(Ref(ref.sheet, row, col, row, col))
                return guarded(self.name_of(ref.sheet, row, col), guard)
        if ref.r2 - ref.r1 + 1 > MAX_LOOKUP_ROWS:
            raise FormulaProblem(f"VLOOKUP in more than {MAX_LOOKUP_ROWS} rows")
        if guard is not None:
            raise FormulaProblem("VLOOKUP of a number whose column a MATCH computes")
        x = self.value(args[0], 3)
        keys, values = [], []
        for r in range(ref.r1, ref.r2 + 1):
            cell = self.book.cell(ref.sheet, r, ref.c1)
            if cell is None or cell.value is None or cell.formula is not None:
                raise FormulaProblem("VLOOKUP whose first column holds other than constants")
            if isinstance(cell.value, str) and exact and known_number(self, args[0]):
                continue  # a text never equals a number: passed over
            if not isinstance(cell.value, (int, float)) or isinstance(cell.value, bool):
                raise FormulaProblem("VLOOKUP whose first column holds texts")
            self.out.refs.append(Ref(ref.sheet, r, ref.c1, r, ref.c1))
            self.out.refs.append(Ref(ref.sheet, r, col, r, col))
            keys.append(self.name_of(ref.sheet, r, ref.c1))
            values.append(self.name_of(ref.sheet, r, col))
        text = "1/0"
        if exact:
            for key, value in reversed(list(zip(keys, values))):
                text = f"({value} if {x} == {key} otherwise {text})"
            return text
        for key, value in zip(keys, values):
            text = f"({value} if {x} >= {key} otherwise {text})"
        ascending = " and ".join(f"{a} <= {b}" for a, b in zip(keys, keys[1:])) or "1 == 1"
        return f"({text} if {ascending} otherwise 1/0)"

    def constant_behind(self, sheet: str, row: int, col: int):
        """The constant a cell holds, or that a chain of plain references (``=D63``) leads
        to (None for an empty cell); a cell that computes is refused."""
        for _ in range(20):
            cell = self.book.cell(sheet, row, col)
            if cell is None or cell.formula is None:
                return None if cell is None else cell.value
            m = _PLAIN_REF.fullmatch(cell.formula.strip())
            if m is None:
                raise FormulaProblem("a criteria range that holds formulas")
            if m.group(1):
                sheet = self.book.sheet_named(m.group(1))
                if sheet is None:
                    raise FormulaProblem(f"a reference to the sheet {m.group(1)}")
            row, col = int(m.group(3)), _col(m.group(2))
        raise FormulaProblem("a criteria range of a chain of references")

    def udf(self, key: str, args) -> str:
        info = self.functions[key]
        if info.problem:
            raise FormulaProblem(f"calls {info.proc.name}, not translated: {info.problem}")
        self.out.udfs.add(key)
        params = info.proc.params
        if params and params[-1].rest:  # ParamArray: the rest of the arguments, one array
            if len(args) < len(params):
                raise FormulaProblem(f"{info.proc.name} called without its ParamArray values")
            packed = [self.value(a) for a in args[len(params) - 1 :]]
            args = list(args[: len(params) - 1]) + [
                ("leaf", "Packed", "[" + ", ".join(packed) + "]")
            ]
        if len(args) > len(params):  # Excel shows #VALUE!: the cell has no value
            return "(1/0)"
        texts, flags = [], []
        from .vbaexpr import VbaSyntax
        from .vbamembers import NotTranslated
        from .vbatypes import default_text

        for k, p in enumerate(params):
            a = args[k] if k < len(args) else None
            given = a is not None and not (a[0] == "leaf" and a[1] == "Empty")
            if given and a[1] == "Packed":
                texts.append(a[2])
                continue
            if not given:
                if not p.optional:
                    raise FormulaProblem(f"{info.proc.name} called without {p.name}")
                if p.default is None and not (
                    k < len(info.params) and info.params[k] in info.given
                ):
                    raise FormulaProblem(f"{info.proc.name} called without the Optional {p.name}")
                try:
                    texts.append(default_text(p))
                except (NotTranslated, VbaSyntax) as exc:
                    raise FormulaProblem(f"the default of {p.name}: {exc}") from None
            elif a[0] == "leaf" and a[1] == "Range" and p.type.lower() in ("range", "variant"):
                ref = self.ref_of(a[2])
                if p.type.lower() == "range" or not ref.single:
                    self.out.refs.append(ref)
                    rows = [
                        "["
                        + ", ".join(
                            self.name_of(ref.sheet, r, c) for c in range(ref.c1, ref.c2 + 1)
                        )
                        + "]"
                        for r in range(ref.r1, ref.r2 + 1)
                    ]
                    texts.append(self.shared("[" + ", ".join(rows) + "]", ref))  # a matrix
                else:
                    texts.append(self.value(a))
            else:
                texts.append(self.value(a))
            if k < len(info.params) and info.params[k] in info.given:
                flags.append("1" if given else "0")
        if not texts + flags:  # a function without arguments is a definition
            return info.final
        return f"{info.final}({', '.join(texts + flags)})"


#: Excel's functions of one number inside IFERROR, and where each gives an error value
#: (None: never, for a number): a root of a negative number, a logarithm of one not above 0,
#: an arc sine beyond 1, an exponential beyond the largest number, and the sine, cosine and
#: tangent of 2^27 or more, which Excel refuses (#NUM!)
ERROR_WHERE = {
    "SQRT": "{} < 0",
    "LN": "{} <= 0",
    "LOG10": "{} <= 0",
    "ABS": None,
    "ATAN": None,
    "ASIN": "abs({}) > 1",
    "ACOS": "abs({}) > 1",
    "EXP": "{} > 709.782712893384",
    "SIN": "abs({}) >= 134217728",
    "COS": "abs({}) >= 134217728",
    "TAN": "abs({}) >= 134217728",
}


def _br(text: str, level: int, ctx: int) -> str:
    return f"({text})" if level < ctx else text


def _col(letters: str) -> int:
    from openpyxl.utils import column_index_from_string

    return column_index_from_string(str(letters).replace("$", ""))


def _parse_ref(sheet: str, ref: str) -> Ref:
    from openpyxl.utils.cell import range_boundaries

    c1, r1, c2, r2 = range_boundaries(ref.replace("$", ""))
    if None in (c1, r1, c2, r2):
        raise FormulaProblem(f"the name for {ref} (whole rows or columns)")
    return Ref(sheet, r1, c1, r2, c2)
