"""Mathcad's math trees (:class:`~workbook.mathcad.reader.MNode`) as the translator reads them:
the shapes of stored results, their units and values, the idioms it recognises (an ``if``
call, a chain of equations, an n-th derivative's order), the operators' tables, and small
rewrites of the language's trees (renaming, substituting)."""

from __future__ import annotations

import math

from ..language import expr as ex
from .context import TranslatorContext
from .functions import ORIGIN_FUNCTIONS, WRITERS
from .reader import MNode, Region
from .symbols import Untranslatable, matrix_size, whole_number
from .symbols import key as _key
from .units import FORMULA_UNITS, result_unit

BINARY = {"plus": "+", "minus": "-", "mult": "*", "div": "/", "pow": "^"}
COMPARE = {
    "equal": "==",
    "lessThan": "<",
    "greaterThan": ">",
    "lessOrEqual": "<=",
    "greaterOrEqual": ">=",
    "notEqual": "!=",
}


def shows_array(evaluation: MNode) -> bool:
    """Whether the result Mathcad stored for ``evaluation`` is a vector or matrix."""
    result = evaluation.find("result")
    return result is None or any(has_tag(c, "matrix") for c in result.children)


def has_tag(node: MNode, tag: str) -> bool:
    return node.tag == tag or any(has_tag(c, tag) for c in node.children)


def mentions(node: MNode, key: tuple[str, str]) -> bool:
    """Whether the Mathcad name ``key`` occurs in ``node``."""
    if node.tag == "id" and _key(node) == key:
        return True
    return any(mentions(c, key) for c in node.children)


def derivative_order(degree: MNode | None) -> int:
    """The order of Mathcad's derivative from its ``degree`` (none, or an empty placeholder
    as Prime writes it: the first); an order that is not a whole number written in the
    worksheet (1 to 5, as Mathcad's numerical derivative allows) is refused, never read as
    the first."""
    if degree is None:
        return 1
    kids = degree.children
    if kids and all(c.tag == "placeholder" for c in kids):
        return 1
    if not kids:  # the order as the element's text
        text = degree.text
    elif len(kids) == 1 and kids[0].tag == "real":
        text = kids[0].text
    else:
        text = ""
    try:
        value = float(text.strip())
    except ValueError:
        value = 0.5
    if value.is_integer() and 1 <= value <= 5:
        return int(value)
    raise Untranslatable("a derivative whose order is not a whole number from 1 to 5 written in it")


def equal_chain(node: MNode) -> list[tuple[MNode, MNode]]:
    """The equations of Mathcad's ``a = b = c`` (stored as ``(a = b) = c``): ``[(a, b), (b,
    c)]``; of ``a = b``, ``[(a, b)]``."""
    left, right = node.children[1], node.children[2]
    if left.tag == "apply" and len(left.children) == 3 and left.children[0].tag == "equal":
        inner = equal_chain(left)
        return [*inner, (inner[-1][1], right)]
    return [(left, right)]


def rename(node: ex.Node, mapping: dict[str, str]) -> ex.Node:
    """The tree with names (and called functions) replaced as mapped."""
    if isinstance(node, ex.Name):
        return ex.Name(mapping.get(node.id, node.id))
    node = ex.map_children(node, lambda c: rename(c, mapping))
    if isinstance(node, ex.Call):
        return ex.Call(mapping.get(node.func, node.func), node.args)
    return node


def eigenvals_argument(node: MNode) -> MNode | None:
    """M of ``eigenvals(M)`` (None: ``node`` is not that call)."""
    node = unparen(node)
    if node.tag != "apply" or len(node.children) != 2 or node.children[0].tag != "id":
        return None
    if _key(node.children[0]) != ("eigenvals", ""):
        return None
    arg = node.children[1]
    if arg.tag == "sequence":
        return arg.children[0] if len(arg.children) == 1 else None
    return arg


def shown_rows(evaluation: MNode | None) -> int | None:
    """The rows of the array Mathcad stored for ``v[i] := ... =`` (None: none stored)."""
    result = evaluation.find("result") if evaluation is not None else None
    if result is None or not result.children or result.children[0].tag != "matrix":
        return None
    try:
        return matrix_size(result.children[0])[0]
    except Untranslatable:
        return None


def substitute(node: ex.Node, values: dict[str, ex.Node]) -> ex.Node:
    """The tree with the names in ``values`` replaced by their trees."""
    if isinstance(node, ex.Name):
        return values.get(node.id, node)
    return ex.map_children(node, lambda c: substitute(c, values))


def writer(node: MNode, arity: int) -> tuple[str, str, MNode | None] | None:
    """(function, file, value) of a call of a Mathcad function that writes a file with a
    literal file name: ``WRITEPRN("f")`` (arity 1, the value is the right side of ``:=``)
    or ``WRITEPRN("f", M)`` (arity 2); None for anything else."""
    if node.tag != "apply" or len(node.children) != 2 or node.children[0].tag != "id":
        return None
    func = _key(node.children[0])
    if func[1] or func[0] not in WRITERS:
        return None
    args = node.children[1]
    args = args.children if args.tag == "sequence" else [args]
    if len(args) != arity or args[0].tag != "str":
        return None
    return func[0], args[0].text, args[1] if arity == 2 else None


def is_indexer(node: MNode) -> bool:
    return node.tag == "apply" and len(node.children) == 3 and node.children[0].tag == "indexer"


#: the solver Mathcad's Find used (its AutoSelect stores the one that succeeded) -> the
#: [[solve]] method that reaches the same root: Mathcad's Levenberg-Marquardt is MINPACK's;
#: where it fell back to its conjugate-gradient solver (the Levenberg-Marquardt root missed a
#: condition), the root nearest the guess that meets the conditions is the one it reports in
#: the worksheets measured; the others (linear, quasi-Newton): the default method
METHODS = {"levenberg": "levenberg-marquardt", "conjugate": "nearest"}

#: at most this many columns of a matrix are stacked for histogram()
MAX_STACKED_COLUMNS = 1000

#: steps of the range of a quick plot (an x that the worksheet has not defined)
QUICK_PLOT_STEPS = 200
KNOWN = {*FORMULA_UNITS, "π", "e"}

INEQUALITY = {"lessThan", "greaterThan", "lessOrEqual", "greaterOrEqual"}


def has_index(node: MNode) -> bool:
    if node.tag in ("indexer", "matcol"):
        return True
    if node.tag == "id" and node.text.strip() in ORIGIN_FUNCTIONS:
        return True  # a function whose indices count from ORIGIN
    return any(has_index(c) for c in node.children)


def first_index_origin(origin: int, regions: list[Region]) -> int:
    """ORIGIN where the worksheet first indexes an array (the worksheet's origin)."""
    for r in regions:
        if r.math is None:
            continue
        m = r.math
        if m.tag == "define" and len(m.children) == 2:
            lhs, rhs = m.children
            if lhs.tag == "id" and _key(lhs) == ("ORIGIN", "") and rhs.tag == "real":
                origin = int(float(rhs.text))
                continue
        if has_index(m):
            return origin
    return origin


def if_args(node: MNode) -> list[MNode]:
    args = node.children[1:]
    if len(args) == 1 and args[0].tag == "sequence":
        args = args[0].children
    return args


def is_if(node: MNode) -> bool:
    """Mathcad's function if(cond, a, b)."""
    return (
        node.tag == "apply"
        and bool(node.children)
        and node.children[0].tag == "id"
        and node.children[0].text.strip() == "if"
        and not node.children[0].attrs.get("subscript")
        and len(if_args(node)) == 3
    )


def symbolic_result(node: MNode) -> MNode:
    """A symbolic evaluation (→) stands for the expression Mathcad found: that one is used."""
    if node.tag == "symEval":
        res = node.find("symResult")
        if res is not None and len(res.children) == 1:
            return res.children[0]
        raise Untranslatable("a symbolic evaluation without its result")
    return node


def symbolic_numbers(node: MNode) -> MNode | None:
    """The result of a symbolic evaluation (→) without keywords, as a stored result, where
    Mathcad found a number or a matrix of numbers; else None (an expression is no value to
    compare, and a keyword such as ``float, 3`` rounds the result)."""
    if len(node.children) != 2 or node.children[1].tag != "symResult":
        return None
    found = node.children[1].children
    if len(found) != 1:
        return None

    def number(n: MNode) -> MNode | None:
        if n.tag == "real":
            return n
        if n.tag == "apply" and len(n.children) == 2 and n.children[0].tag == "neg":
            inner = number(n.children[1])
            if inner is not None and not inner.text.strip().startswith("-"):
                return MNode("real", {}, "-" + inner.text.strip(), [], inner.line)
        return None

    value = found[0]
    if value.tag == "matrix":
        cells = [number(c) for c in value.children]
        if not cells or any(c is None for c in cells):
            return None
        return MNode("matrix", dict(value.attrs), "", cells, value.line)
    return number(value)


def has_matrix(tree: ex.Node) -> bool:
    """Is a vector or matrix written inside ``tree``?"""
    return any(isinstance(n, ex.Matrix) for n in ex.walk(tree))


# -- stored values, units, literals ----------------------------------------------
def unit_monomial(node: MNode) -> str:
    if "text" in node.attrs:  # a unit its reader wrote as pint text (Mathcad Prime's)
        return node.attrs["text"]
    parts = []
    for ref in node.children:
        if ref.tag != "unitReference":
            continue
        name = result_unit(ref.attrs.get("unit", ""))
        num = whole_number(ref.attrs.get("power-numerator", "1"), "a unit's power")
        den = whole_number(ref.attrs.get("power-denominator", "1"), "a unit's power")
        if den == 0:
            raise Untranslatable("a unit's power with the denominator 0")
        power = num / den
        if power == 1:
            parts.append(name)
        else:
            p = int(power) if power.is_integer() else power
            parts.append(f"{name} ** {p}" if p > 0 else f"{name} ** ({p})")
    return " * ".join(parts)


def walk(node: MNode):
    """``node`` and every node under it."""
    yield node
    for c in node.children:
        yield from walk(c)


def is_nested(node: MNode) -> bool:
    """Is ``node`` a stored array whose elements are arrays (Mathcad's nested array)?"""
    return node.tag == "matrix" and any(c.tag == "matrix" for c in node.children)


def leaves(node: MNode, path: tuple = ()):
    """(path, unit, value) of every number or text of a stored nested array; the path has
    (row, column, rows, columns) of each array it passes, outermost first (Mathcad stores a
    matrix column by column)."""
    if node.tag != "matrix":
        unit, values = stored(node)
        if any(isinstance(v, complex) for v in values):
            raise Untranslatable("a complex number inside a nested array result")
        if len(values) != 1:
            raise Untranslatable("a nested array result with a matrix that has units")
        yield path, unit, values[0]
        return
    rows, cols = matrix_size(node)
    if rows * cols != len(node.children):
        raise Untranslatable("an array result whose size does not match its values")
    for n, child in enumerate(node.children):
        col, row = divmod(n, rows)
        yield from leaves(child, (*path, (row, col, rows, cols)))


def shape(node: MNode) -> tuple[int, int]:
    """(rows, cols) of a stored result: (1, 1) for a scalar."""
    inner = node.children[0] if node.tag == "unitedValue" and node.children else node
    if inner.tag == "matrix":
        return matrix_size(inner)
    return 1, 1


def stored(node: MNode) -> tuple[str, list[float | str]]:
    """(unit text, values) of a stored result: a number, a number with units, a matrix (its
    values column by column), a text."""
    if node.tag == "real":
        try:
            value = float(node.text)
        except ValueError:
            raise Untranslatable(f"a stored number {node.text.strip()[:40]!r}") from None
        if not math.isfinite(value):
            raise Untranslatable(f"a stored number that is not finite ({node.text.strip()})")
        return "", [value]
    if node.tag == "str":
        return "", [node.text]
    if node.tag == "unitedValue":
        inner = node.children[0]
        mono = node.find("unitMonomial")
        unit, values = stored(inner)
        return (unit_monomial(mono) if mono is not None else unit), values
    if node.tag == "matrix":
        values = []
        units = set()
        for c in node.children:
            if c.tag == "matrix":
                raise Untranslatable(
                    "a nested array result (an array of arrays is not in the language)"
                )
            u, v = stored(c)
            units.add(u)
            values += v
        if len(units) > 1:
            raise Untranslatable("a matrix result whose elements have different units")
        return (units.pop() if units else ""), values
    if node.tag == "unreadable":
        raise Untranslatable(node.attrs.get("why", "a stored result that cannot be read"))
    if node.tag == "complex":  # Mathcad's <complex><real/><imag/></complex>
        parts = {c.tag: c.text for c in node.children}
        try:
            z = complex(float(parts.get("real", "0")), float(parts["imag"]))
        except (KeyError, ValueError):
            raise Untranslatable("a stored complex number that cannot be read") from None
        if not (math.isfinite(z.real) and math.isfinite(z.imag)):
            raise Untranslatable("a stored complex number that is not finite")
        return "", [z]
    raise Untranslatable(f"a result of kind <{node.tag}>")


def override_unit(evaluation: MNode) -> str:
    """The display unit of a result whose unit was chosen (Mathcad's unit placeholder)."""
    if evaluation.find("unitOverride") is None:
        return ""
    result = evaluation.find("result")
    if result is None or not result.children or result.children[0].tag != "unitedValue":
        return ""
    mono = result.children[0].find("unitMonomial")
    return unit_monomial(mono) if mono is not None else ""


def unit_text(node: MNode) -> str | None:
    """pint text of a product of Mathcad units (m, kN/m^2), or None."""
    if node.tag == "id" and not node.attrs.get("subscript") and node.text.strip() in FORMULA_UNITS:
        return FORMULA_UNITS[node.text.strip()]
    if node.tag == "parens":
        inner = unit_text(node.children[0])
        return None if inner is None else f"({inner})"
    if node.tag == "apply" and len(node.children) == 3:
        op, a, b = node.children
        if op.tag in ("mult", "div"):
            ua, ub = unit_text(a), unit_text(b)
            if ua is not None and ub is not None:
                return f"{ua} {'*' if op.tag == 'mult' else '/'} {ub}"
        if op.tag == "pow" and b.tag == "real":
            ua = unit_text(a)
            if ua is not None:
                return f"{ua} ** {b.text.strip()}"
    return None


def quantity_text(node: MNode) -> str | None:
    """`24 m/s` for Mathcad's 24*m/s (a number times units), `1.3` for a number, else None."""
    if node.tag == "real":
        return node.text.strip()
    if node.tag == "apply" and node.children[0].tag == "neg" and len(node.children) == 2:
        inner = quantity_text(node.children[1])
        return None if inner is None else "-" + inner
    if (
        node.tag == "apply"
        and len(node.children) == 3
        and node.children[0].tag
        in (
            "mult",
            "div",
        )
    ):
        op, a, b = node.children
        if a.tag == "real":
            unit = unit_text(b)
            if unit is not None:
                if op.tag == "mult":
                    return f"{a.text.strip()} {unit}"
                return f"{a.text.strip()} / ({unit})"
    return None


def range_values(tr: TranslatorContext, first: MNode, second: MNode | None, last: MNode):
    """Mathcad's values of a range first, second .. last (up to last, not beyond), and the
    range's unit; the bounds must be values known at import (numbers, inputs, definitions)."""
    why = "a range whose bounds are not values known at import"
    try:
        a, c = tr.quantity(first, why), tr.quantity(last, why)
        b = tr.quantity(second, why) if second is not None else None
        unit = c.units if a.magnitude == 0 and not a.dimensionless else a.units
        if a.magnitude == 0 and a.dimensionless:
            unit = c.units
        a, c = (float(q.to(unit).magnitude) if q.magnitude != 0 else 0.0 for q in (a, c))
        b = float(b.to(unit).magnitude) if b is not None else (a + 1 if c >= a else a - 1)
    except Untranslatable:
        raise
    except Exception:  # noqa: BLE001 - pint's unit errors and numeric ones alike
        raise Untranslatable("a range whose bounds are not values known at import") from None
    if not all(math.isfinite(v) for v in (a, b, c)):
        raise Untranslatable("a range whose bounds are not finite numbers")
    step = b - a
    if step == 0:
        raise Untranslatable("a range with step 0")
    count = (c - a) / step * (1 + 1e-12) + 1e-9
    if not math.isfinite(count) or count > 100_000:
        raise Untranslatable("a range of more than 100,000 values")
    n = math.floor(count)
    if n < 0:
        raise Untranslatable("an empty range")
    if n > 100_000:
        raise Untranslatable("a range of more than 100,000 values")
    dimensionless = unit == "" or not str(unit) or unit.dimensionless
    return [a + k * step for k in range(n + 1)], ("" if dimensionless else str(unit))


# -- Mathcad's comparisons are numbers (1 or 0), its numbers conditions (true where not 0) --
def is_boolean(tree: ex.Node) -> bool:
    """Is ``tree`` a condition of the language (a comparison, and/or, not)?"""
    return isinstance(tree, (ex.Compare, ex.Logic)) or (
        isinstance(tree, ex.Unary) and tree.op == "not"
    )


def as_number(tree: ex.Node) -> ex.Node:
    """A condition where Mathcad uses its value: ``(1 if C otherwise 0)``."""
    if is_boolean(tree):
        return ex.IfElse(ex.Number(1.0), tree, ex.Number(0.0))
    return tree


def logic(op: str, values: list[ex.Node]) -> ex.Node:
    """``a and b and c`` (nested ands flattened)."""
    flat: list[ex.Node] = []
    for v in values:
        flat += list(v.values) if isinstance(v, ex.Logic) and v.op == op else [v]
    return ex.Logic(op, tuple(flat))


def unparen(node: MNode) -> MNode:
    while node.tag == "parens" and node.children:
        node = node.children[0]
    return node


def is_condition(node: MNode) -> bool:
    """Is ``node`` a comparison, and/or/not, or a product or sum of such (Mathcad's idioms
    for and, or)?"""
    node = unparen(node)
    if node.tag != "apply" or not node.children:
        return False
    op = node.children[0].tag
    if op in COMPARE or op in ("and", "or", "not"):
        return True
    return (
        op in ("mult", "plus")
        and len(node.children) == 3
        and all(is_condition(a) for a in node.children[1:])
    )
