"""MathML: a formula as written by hand, printed from the expression tree.

:class:`MathML` walks the parsed tree (:mod:`workbook.language.expr`) with one ``visit_<Node>`` per
node kind. Given a ``values`` callback it prints the same formula with the values
substituted (inputs and scalar definitions as the engine computed them). Each visit returns a
:class:`Box`: the markup, a rough width in em (so that long formulas can be scaled to the
page) and the precedence that decides parentheses (the one table of :mod:`workbook.language.expr`).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from dataclasses import dataclass
from html import escape

import numpy as np

# the registry's dict (workbook.numerics.registry.REGISTRY) read from its home, below the
# numerics a renderer does not import: a computed sheet's built-ins are all registered
from ...functions.entry import ENTRIES
from ...language import expr as ex
from ...language.visitor import Visitor

PREC = ex.PREC  # the one precedence table of the language
ATOM = PREC["atom"]  # a name, a number, a call, a parenthesised group
FRAC = PREC["neg"] + 0.5  # a stacked fraction: needs brackets only as the base of a power
PRECISION = 6  # significant digits of a computed value

GREEK = {
    n: chr(c)
    for n, c in {
        "alpha": 0x3B1,
        "beta": 0x3B2,
        "gamma": 0x3B3,
        "delta": 0x3B4,
        "epsilon": 0x3B5,
        "zeta": 0x3B6,
        "eta": 0x3B7,
        "theta": 0x3B8,
        "iota": 0x3B9,
        "kappa": 0x3BA,
        "lambda": 0x3BB,
        "mu": 0x3BC,
        "nu": 0x3BD,
        "xi": 0x3BE,
        "pi": 0x3C0,
        "rho": 0x3C1,
        "sigma": 0x3C3,
        "tau": 0x3C4,
        "upsilon": 0x3C5,
        "phi": 0x3C6,
        "chi": 0x3C7,
        "psi": 0x3C8,
        "omega": 0x3C9,
        "Gamma": 0x393,
        "Delta": 0x394,
        "Theta": 0x398,
        "Lambda": 0x39B,
        "Xi": 0x39E,
        "Pi": 0x3A0,
        "Sigma": 0x3A3,
        "Upsilon": 0x3A5,
        "Phi": 0x3A6,
        "Psi": 0x3A8,
        "Omega": 0x3A9,
    }.items()
}

_CMP = {"<": "<", "<=": "\u2264", ">": ">", ">=": "\u2265", "==": "=", "!=": "\u2260"}
_MINUS = "\u2212"
_TIMES = "\u22c5"
_APPLY = "<mo>\u2061</mo>"  # function application (no visible space)
_NAME = re.compile(r"^([A-Za-z]+?)([0-9]*)(?:_([A-Za-z0-9_]+))?$")
_TAG = re.compile(r"<[^>]*>|\{[^}]*\}")


@dataclass(frozen=True)
class Box:
    """Printed markup with its rough width (em) and precedence."""

    xml: str
    width: float
    prec: float = ATOM
    numeric: bool = False  # starts with a number: 2·a is written 2a only after a number

    def row(self) -> str:
        return f"<mrow>{self.xml}</mrow>"


def _mo(op: str, space: float = 0.9) -> Box:
    return Box(f"<mo>{escape(op)}</mo>", space)


def _mi(text: str) -> Box:
    width = 0.55 if len(text) == 1 else 0.48 * len(text)
    return Box(f"<mi>{escape(text)}</mi>", width)


def _parens(box: Box, open_: str = "(", close: str = ")") -> Box:
    # Brackets stretch only around tall content: Chromium drops stretched brackets from the
    # table headers it repeats on a new page (seen in the printed PDF).
    tall = any(tag in box.xml for tag in ("<mfrac", "<mtable", "<munder", "<msqrt"))
    mo = "<mo>" if tall else "<mo stretchy='false'>"
    return Box(f"<mrow>{mo}{open_}</mo>{box.xml}{mo}{close}</mo></mrow>", box.width + 0.7)


def _join(*boxes: Box, prec: float = ATOM, numeric: bool | None = None) -> Box:
    return Box(
        "".join(b.xml for b in boxes),
        sum(b.width for b in boxes),
        prec,
        boxes[0].numeric if numeric is None and boxes else bool(numeric),
    )


def name_box(name: str) -> Box:
    """A worksheet name as written by hand: ``R3`` as R with subscript 3, ``phi`` as φ,
    ``phi1_max`` as φ with subscript 1,max."""
    m = _NAME.match(name)
    if not m:
        return _mi(name)
    base, digits, rest = m.group(1), m.group(2), m.group(3)
    subs = ([digits] if digits else []) + (rest.split("_") if rest else [])
    head = _mi(GREEK.get(base, base))
    if not subs:
        return head
    parts = []
    for i, s in enumerate(subs):
        if i:
            parts.append("<mo separator='true'>,</mo>")
        if s.isdigit():
            parts.append(f"<mn>{s}</mn>")
        else:
            parts.append(f"<mi>{escape(GREEK.get(s, s))}</mi>")
    sub_width = 0.7 * (sum(len(GREEK.get(s, s)) * 0.5 for s in subs) + 0.3 * (len(subs) - 1))
    return Box(f"<msub>{head.xml}<mrow>{''.join(parts)}</mrow></msub>", head.width + sub_width)


def number_text(value: float, digits: int = PRECISION) -> tuple[str, int | None]:
    """Mantissa text and power of ten (None: plain) of ``value`` at ``digits`` significant."""
    text = f"{value:.{digits}g}"
    if "e" in text:
        mant, _, exp = text.partition("e")
        return mant, int(exp)
    return text, None


def number_box(value: float | complex, digits: int = PRECISION) -> Box:
    """A number as MathML: ``−1.5×10⁻⁵``; NaN and infinity as words; a complex number as
    a + bi (``10 − 16.1 i``)."""
    if isinstance(value, complex):
        return complex_box(value, digits)
    if not math.isfinite(value):
        word = "not a number" if math.isnan(value) else ("\u221e" if value > 0 else "\u2212\u221e")
        return Box(f"<mtext>{word}</mtext>", 0.5 * len(word), numeric=True)
    mant, exp = number_text(abs(value), digits)
    xml = f"<mn>{mant}</mn>"
    width = 0.5 * len(mant)
    prec = ATOM
    if exp is not None:
        xml += f"<mo>\u00d7</mo><msup><mn>10</mn><mn>{str(exp).replace('-', _MINUS)}</mn></msup>"
        width += 2.2 + 0.35 * len(str(exp))
        prec = PREC["*"]
    if value < 0:
        xml = f"<mo>{_MINUS}</mo>{xml}"
        width += 0.8
        prec = PREC["neg"]
    return Box(f"<mrow>{xml}</mrow>", width, prec, numeric=True)


def polar_box(z: complex, digits: int = PRECISION) -> Box:
    """``r∠phi°`` (``5∠53.1301°``): the modulus, then the angle in degrees."""
    r = number_box(abs(z), digits)
    phi = number_box(math.degrees(math.atan2(z.imag, z.real)) + 0.0, digits)
    xml = f"<mrow>{r.xml}<mo>\u2220</mo>{phi.xml}<mo>\u00b0</mo></mrow>"
    return Box(xml, r.width + phi.width + 1.4, PREC["+"], numeric=True)


def complex_box(z: complex, digits: int = PRECISION) -> Box:
    """``a + bi`` (``3 + 4i``, ``−2i``, ``7``): a sum for the precedence of what is around it."""
    i = Box("<mi>i</mi>", 0.4)
    if z.imag == 0:
        return number_box(z.real, digits)
    im = number_box(abs(z.imag), digits)
    im = i if im.xml == "<mrow><mn>1</mn></mrow>" else _join(im, i, prec=PREC["*"])
    if z.real == 0:
        if z.imag > 0:
            return Box(im.xml, im.width, PREC["*"], numeric=True)
        return Box(f"<mrow><mo>{_MINUS}</mo>{im.xml}</mrow>", im.width + 0.8, PREC["neg"], True)
    re = number_box(z.real, digits)
    sign = _MINUS if z.imag < 0 else "+"
    xml = f"<mrow>{re.xml}<mo>{sign}</mo>{im.xml}</mrow>"
    return Box(xml, re.width + 1.2 + im.width, PREC["+"], numeric=True)


def unit_box(text: str, typeset: bool = True) -> Box:
    """A unit as printed by :func:`workbook.language.units.pretty` (``m/s^2``, ``1/s``, ``N*m``)
    typeset in upright letters by :func:`workbook.language.units.typeset_factors`: ``m/s²``,
    ``W/(m²·K)``, ``°C``, ``Δ°C``, ``Ω``, ``µm``. A text that is not a unit (a label), or
    ``typeset=False`` (a quantity inside a formula, shown with the names written), keeps its
    names: ``W/(m²·K)``, ``degC``."""
    if not text:
        return Box("", 0.0)
    shown = _typeset_unit(text) if typeset else None
    if shown is not None:
        return shown
    num, _, den = text.partition("/")
    if den.startswith("(") and den.endswith(")"):
        den = den[1:-1]

    def factors(part: str) -> tuple[str, float]:
        out, width = [], 0.0
        for i, f in enumerate(p for p in re.split(r"\s*[*·]\s*|\s+", part) if p):
            sym, _, power = f.partition("^")
            if i:
                out.append(f"<mo lspace='0.1em' rspace='0.1em'>{_TIMES}</mo>")
                width += 0.3
            mi = f"<mi mathvariant='normal'>{escape(sym)}</mi>"
            width += 0.55 * len(sym)
            if power:
                mi = f"<msup>{mi}<mn>{escape(power.replace('-', _MINUS))}</mn></msup>"
                width += 0.4 * len(power)
            out.append(mi)
        return "".join(out), width

    top, width = factors(num)
    xml = top
    if den:
        bottom, w2 = factors(den)
        if re.search(r"[*·\s]", den.strip()):  # W/(m²·K): the bar divides the whole product
            bottom, w2 = f"<mo>(</mo>{bottom}<mo>)</mo>", w2 + 0.6
        xml += f"<mo lspace='0' rspace='0'>/</mo>{bottom}"
        width += w2 + 0.4
    return Box(f"<mrow class='unit'>{xml}</mrow>", width)


def _typeset_unit(text: str) -> Box | None:
    """The unit ``text`` typeset, or None when it is not a unit the reader knows."""
    from ...language import units as un

    found = un.shown_factors(text)
    if found is None:
        return None
    top, bottom = found

    def factors(part: list[tuple[str, float]]) -> tuple[str, float]:
        out, width = [], 0.0
        for i, (sym, power) in enumerate(part):
            if i:
                out.append(f"<mo lspace='0.1em' rspace='0.1em'>{_TIMES}</mo>")
                width += 0.3
            mi = f"<mi mathvariant='normal'>{escape(sym)}</mi>"
            width += 0.55 * len(sym)
            if power != 1:
                shown = f"{power:g}"
                mi = f"<msup>{mi}<mn>{escape(shown)}</mn></msup>"
                width += 0.4 * len(shown)
            out.append(mi)
        return "".join(out), width

    xml, width = factors(top) if top else ("<mn>1</mn>", 0.5)
    if bottom:
        below, w2 = factors(bottom)
        if len(bottom) > 1:  # W/(m²·K): the bar divides by the whole product
            below, w2 = f"<mo>(</mo>{below}<mo>)</mo>", w2 + 0.6
        xml += f"<mo lspace='0' rspace='0'>/</mo>{below}"
        width += w2 + 0.4
    return Box(f"<mrow class='unit'>{xml}</mrow>", width)


def quantity_box(
    value: float, unit: str, digits: int = PRECISION, attrs: str = "", polar: bool = False
) -> Box:
    """A value with its unit, as substituted or as a result: ``20 mm``; ``attrs`` are
    extra attributes of its element (a result is marked ``class='result'``); a complex
    value with ``polar`` as r∠phi."""
    polar = polar and isinstance(value, complex)
    num = polar_box(value, digits) if polar else number_box(value, digits)
    attrs = attrs or "class='value'"
    if unit and num.prec < PREC["*"]:  # (3 + 4i) ohm
        num = Box(_parens(num).xml, num.width + 0.7, ATOM, numeric=True)
    if not unit:
        return Box(f"<mrow {attrs}>{num.xml}</mrow>", num.width, num.prec, numeric=True)
    u = unit_box(unit)
    xml = f"<mrow {attrs}>{num.xml}<mspace width='0.25em'/>{u.xml}</mrow>"
    # a negative value keeps its sign's precedence: 22 °C − (−8 °C), 2·(−3 mm)
    prec = PREC["neg"] if num.prec == PREC["neg"] else min(num.prec, PREC["*"])
    return Box(xml, num.width + 0.25 + u.width, prec, numeric=True)


#: Elements of one vector or matrix shown in the report (a 2,000,001-element vector made a
#: 90 MB page); a larger one is named with its size instead, never shown cut.
MAX_SHOWN_ELEMENTS = 10_000


def _elements(values) -> int:
    """Numbers in ``values``, those of its nested arrays included."""
    if np.ndim(values) != 2:
        return 1
    arr = np.asarray(values)
    if arr.dtype.kind != "O":
        return int(arr.size)
    return sum(_elements(v) for v in arr.ravel())


def matrix_box(values, unit: str, digits: int = PRECISION) -> Box:
    """A vector or matrix of numbers in brackets, with its unit after; an element that is
    itself an array (a nested array) is a bracketed matrix in its place. One of more than
    :data:`MAX_SHOWN_ELEMENTS` elements is a text naming its size."""
    count = _elements(values)
    if count > MAX_SHOWN_ELEMENTS:
        r, c = np.shape(values)
        what = f"a vector of {r:,}" if c == 1 else f"a {r:,} x {c:,} matrix"
        return text_box(
            f"[{what} ({count:,} numbers): more than {MAX_SHOWN_ELEMENTS:,}, not shown]"
            + (f" {unit}" if unit else "")
        )

    def element(v) -> Box:
        if np.ndim(v) == 2:
            return matrix_box(v, "", digits)
        return number_box(complex(v) if np.iscomplexobj(v) else float(v), digits)

    rows = [[element(v) for v in row] for row in values]
    widths = [max(r[j].width for r in rows) for j in range(len(rows[0]))]
    xml = "".join("<mtr>" + "".join(f"<mtd>{b.xml}</mtd>" for b in r) + "</mtr>" for r in rows)
    box = _parens(Box(f"<mtable>{xml}</mtable>", sum(widths) + 0.6 * len(widths)), "[", "]")
    if not unit:
        return box
    u = unit_box(unit)
    return Box(f"{box.xml}<mspace width='0.25em'/>{u.xml}", box.width + 0.25 + u.width)


def text_box(text: str, cls: str = "") -> Box:
    attr = f" class='{cls}'" if cls else ""
    return Box(f"<mtext{attr}>{escape(text)}</mtext>", 0.5 * len(text))


#: What a substituted name shows: a number and its unit, or a choice's word.
Value = tuple[float, str] | str


class MathML(Visitor):
    """Print an expression tree (:mod:`workbook.language.expr`) as MathML boxes.

    ``values(name)`` gives the value to substitute for a name (or None to keep the name):
    the same printer prints the formula as written and with the values put in.
    """

    def __init__(self, values: Callable[[str], Value | None] | None = None):
        self.values = values
        self.inline = 0  # inside an exponent: division as a slash, not stacked
        self.bound: set[str] = set()  # variables bound by an enclosing sum(): never values

    def box(self, node: ex.Node) -> Box:
        return self.visit(node)

    def wrap(self, node: ex.Node, min_prec: float) -> Box:
        b = self.visit(node)
        return _parens(b) if b.prec < min_prec else b

    # -- leaves -----------------------------------------------------------------------------
    def visit_Number(self, node: ex.Number) -> Box:
        v = node.value
        if v.is_integer() and abs(v) < 1e15:
            return Box(f"<mn>{int(v)}</mn>", 0.5 * len(str(int(v))), numeric=True)
        return number_box(v, 15)

    def visit_Imaginary(self, node: ex.Imaginary) -> Box:
        """``4i`` as written: the number, then an italic i."""
        num = self.visit_Number(ex.Number(node.value))
        return Box(f"<mrow>{num.xml}<mi>i</mi></mrow>", num.width + 0.4, num.prec, numeric=True)

    def visit_Quantity(self, node: ex.Quantity) -> Box:
        """``20 mm`` as written: the number, then its unit in upright letters."""
        num = self.visit_Number(ex.Number(node.value))
        u = unit_box(node.unit, typeset=False)
        xml = f"<mrow class='literal'>{num.xml}<mspace width='0.2em'/>{u.xml}</mrow>"
        return Box(xml, num.width + 0.2 + u.width, PREC["*"], numeric=True)

    def visit_Text(self, node: ex.Text) -> Box:
        return text_box(f"\u201c{node.value}\u201d")

    def visit_Name(self, node: ex.Name) -> Box:
        value = self.values(node.id) if self.values and node.id not in self.bound else None
        if value is None:
            return name_box(node.id)
        if isinstance(value, str):
            return text_box(f"\u201c{value}\u201d")
        return quantity_box(*value, attrs=f"class='value' data-name='{escape(node.id)}'")

    # -- operators ---------------------------------------------------------------------------
    def visit_Unary(self, node: ex.Unary) -> Box:
        if node.op == "not":
            inner = self.wrap(node.operand, PREC["not"] + 1)
            return _join(text_box("not\u00a0"), inner, prec=PREC["not"], numeric=False)
        inner = self.wrap(node.operand, PREC["neg"] + 1)
        if node.op == "+":
            return Box(inner.xml, inner.width, PREC["neg"])
        return _join(_mo(_MINUS, 0.8), inner, prec=PREC["neg"], numeric=inner.numeric)

    def visit_Binary(self, node: ex.Binary) -> Box:
        op = node.op
        if op == "^":
            return self._power(node)
        if op == "/" and not self.inline:
            num, den = self.box(node.left), self.box(node.right)
            xml = f"<mfrac>{num.row()}{den.row()}</mfrac>"
            return Box(xml, max(num.width, den.width) + 0.3, FRAC)
        p = PREC[op]
        left = self.wrap(node.left, p)
        right = self.wrap(node.right, p + 1)
        if right.prec == PREC["neg"]:
            right = _parens(right)  # a − (−b), 2·(−x)
        if op == "*":
            if (
                self.values is None  # with values put in, every product shows its dot
                and left.numeric
                and not right.numeric
                and left.prec >= PREC["neg"]
                and _leftmost(node.right) not in ("e", "E")  # 2e would read as a number
                and not _starts_with_number(right.xml)  # 2⁢10^e would read as 210^e
                and not (isinstance(node.left, ex.Number) and node.left.value == 0)  # 0⋅α
                and not isinstance(node.left, ex.Imaginary)  # 1i⋅ω, as Mathcad shows it
            ):
                sign = Box("<mo>\u2062</mo>", 0.1)  # 2a: invisible times after a number
            else:
                sign = _mo(_TIMES, 0.6)
        elif op == "/":
            sign = _mo("/", 0.4)
        else:
            sign = _mo(_MINUS if op == "-" else "+")
        return _join(left, sign, right, prec=p)

    def _power(self, node: ex.Binary) -> Box:
        p = PREC["^"]
        base_node, exp_node = node.left, node.right
        self.inline += 1
        try:
            exp = self.box(exp_node)
        finally:
            self.inline -= 1
        entry = ENTRIES.get(base_node.func) if isinstance(base_node, ex.Call) else None
        if (
            entry is not None
            and entry.mathml_powered
            and isinstance(exp_node, ex.Number)
            and exp_node.value > 0
            and len(base_node.args) == 1
        ):  # sin(x)^2 as sin²(x)
            arg = _parens(self.box(base_node.args[0]))
            head = f"<msup><mi>{base_node.func}</mi>{exp.row()}</msup>"
            return Box(head + _APPLY + arg.xml, 0.5 * len(base_node.func) + arg.width + 0.5)
        base = self.wrap(base_node, p + 1)
        return Box(f"<msup>{base.row()}{exp.row()}</msup>", base.width + 0.7 * exp.width, p)

    def visit_Compare(self, node: ex.Compare) -> Box:
        p = PREC["cmp"]
        boxes = [self.wrap(node.operands[0], p + 1)]
        for op, o in zip(node.ops, node.operands[1:]):
            boxes += [_mo(_CMP[op]), self.wrap(o, p + 1)]
        return _join(*boxes, prec=p, numeric=False)

    def visit_Logic(self, node: ex.Logic) -> Box:
        p = PREC[node.op]
        boxes = []
        for i, v in enumerate(node.values):
            if i:
                boxes.append(text_box(f"\u00a0{node.op}\u00a0"))
            boxes.append(self.wrap(v, p + 1))
        return _join(*boxes, prec=p, numeric=False)

    def visit_Matrix(self, node: ex.Matrix) -> Box:
        cells = [[self.box(e) for e in row] for row in node.rows]
        widths = [max(r[j].width for r in cells) for j in range(len(cells[0]))]
        rows = "".join(
            "<mtr>" + "".join(f"<mtd>{b.row()}</mtd>" for b in r) + "</mtr>" for r in cells
        )
        return _parens(Box(f"<mtable>{rows}</mtable>", sum(widths) + 0.6 * len(widths)), "[", "]")

    def visit_Index(self, node: ex.Index) -> Box:
        target = self.wrap(node.target, ATOM)
        idx = [self.box(i) for i in node.indices]
        inner = _join(
            *[x for k, b in enumerate(idx) for x in ((_mo(",", 0.3),) if k else ()) + (b,)]
        )
        # class 'index': an element of a vector or matrix, not a name with a subscript
        xml = f"<msub class='index'>{target.row()}{inner.row()}</msub>"
        return Box(xml, target.width + 0.7 * inner.width)

    def visit_IfElse(self, node: ex.IfElse) -> Box:
        p = PREC["or"] - 1
        return _join(
            self.wrap(node.value, p + 1),
            text_box("\u00a0if\u00a0"),
            self.wrap(node.condition, p + 1),
            text_box(",\u00a0otherwise\u00a0"),
            self.wrap(node.other, p),
            prec=p,
            numeric=False,
        )

    def visit_Call(self, node: ex.Call) -> Box:
        func = node.func
        entry = ENTRIES.get(func)
        if entry is None and func in ("max_over", "min_over") and len(node.args) == 2:
            table, column = node.args
            # the largest value of a table's column: max with the table's name below
            label = f"<mtext>table {escape(_text(table))}</mtext>"
            head = f"<munder><mi>{func[:3]}</mi>{label}</munder>"
            col = _parens(self.box(column))
            xml = f"<mrow class='over'>{head}{_APPLY}{col.xml}</mrow>"
            return Box(xml, 2.0 + col.width + 0.3 * len(_text(table)))
        bound = set()
        if entry is not None and entry.binds is not None:
            var = node.args[entry.binds[1]] if len(node.args) > entry.binds[1] else None
            bound = {var.id} - self.bound if isinstance(var, ex.Name) else set()
        self.bound |= bound
        try:
            args = [self.box(a) for a in node.args]
        finally:
            self.bound -= bound
        if entry is not None and entry.mathml and _fits(entry.mathml, len(args)):
            return self._registered(func, entry.mathml, args)
        # the sheet's own functions and solver blocks are named like values (R3 as R₃)
        head = _mi(func) if entry is not None else name_box(func)
        group = _parens(_commas(args))
        return Box(head.xml + _APPLY + group.xml, head.width + group.width)

    def _registered(self, func: str, template: str, args: list[Box]) -> Box:
        """A built-in's call written as its registry entry says (``{0}``, ``{0:group}``,
        ``{args}``); each argument is marked for the reader of the report's tests."""
        marked = [
            Box(f"<mrow data-arg='{i}'>{a.xml}</mrow>", a.width, a.prec) for i, a in enumerate(args)
        ]
        xml = template.format(*(_Arg(b) for b in marked), args=_Arg(_commas(marked)))
        visible = len(_TAG.sub("", template))
        width = sum(a.width for a in args) + 0.5 * visible + 0.7
        trailing = template.rstrip().endswith("}")  # an operand at the end: binds like a product
        return Box(f"<mrow data-call='{func}'>{xml}</mrow>", width, PREC["*"] if trailing else ATOM)

    # -- piecewise ---------------------------------------------------------------------------
    def pieces(self, branches) -> Box:
        """A piecewise definition as a brace: one row per piece, ``value  if condition``."""
        rows, widths, cond_widths = [], [], []
        for b in branches:
            value = self.box(b.value)
            if b.condition is None:
                cond = text_box("otherwise")
            else:
                c = self.box(b.condition)
                cond = _join(text_box("if\u00a0"), c)
            rows.append(f"<mtr><mtd>{value.row()}</mtd><mtd>{cond.row()}</mtd></mtr>")
            widths.append(value.width)
            cond_widths.append(cond.width)
        xml = f"<mrow><mo stretchy='true'>{{</mo><mtable>{''.join(rows)}</mtable></mrow>"
        return Box(xml, max(widths, default=0) + max(cond_widths, default=0) + 2.0)


_OPENING = re.compile(r"^(?:\s*<(?:mrow|msup|msub|msubsup|mfrac|mstyle|mpadded)(?:\s[^>]*)?>)*\s*")


def _starts_with_number(xml: str) -> bool:
    """Whether the first thing ``xml`` shows is a number (``<mn>``), also as the base of a
    power or the numerator of a fraction: after a number it needs a visible times."""
    return xml[_OPENING.match(xml).end() :].startswith("<mn")


def _leftmost(node: ex.Node) -> str:
    """The first name or number printed for ``node`` (the left spine of the tree)."""
    while True:
        if isinstance(node, ex.Binary):
            node = node.left
        elif isinstance(node, ex.Name):
            return node.id
        elif isinstance(node, ex.Call):
            return node.func
        else:
            return ""


class _Arg:
    """An argument in a registry template: ``{0:group}`` brackets it below a product."""

    def __init__(self, box: Box):
        self.box = box

    def __format__(self, spec: str) -> str:
        if spec == "group" and self.box.prec < PREC["*"]:
            return _parens(self.box).xml
        return self.box.xml


def _fits(template: str, n: int) -> bool:
    """A registry template writes a call of ``n`` arguments only if it shows each of them
    (diff(f, x, 2) is not written as the first derivative)."""
    if "{args" in template:
        return True
    shown = {int(i) for i in re.findall(r"\{(\d+)", template)}
    return shown == set(range(n))


def _commas(boxes: list[Box]) -> Box:
    inner: list[Box] = []
    for i, b in enumerate(boxes):
        if i:
            inner.append(Box("<mo separator='true'>,</mo>", 0.5))
        inner.append(b)
    return _join(*inner) if inner else Box("", 0.0)


def _text(node: ex.Node) -> str:
    return node.id if isinstance(node, ex.Name) else ex.to_text(node)


def math_element(*boxes: Box, cls: str = "") -> str:
    """A ``<math>`` element of the boxes, in display style."""
    attr = f" class='{cls}'" if cls else ""
    return f"<math{attr}>{''.join(b.xml for b in boxes)}</math>"
