"""Mathcad X-Y plots: the expressions of each trace, decoded from the plot's binary item.

Mathcad 11-15 keep a plot's definition in a ``<binaryContent>`` item (base64 of gzip): a
serialised expression tree whose records are, in pre-order::

    [id] 32 [op: u16] 00 00 [side] [parent] [payload]

``side`` says whether the record is the left (0x40) or right (0x80) operand of its parent
(low bits: 0x24 a name, 0x34 a number, 0x36 a number Mathcad chose itself); a leaf (op
0x0f02) has the payload ``00 00`` then its text in UTF-16 (a name: ``[n+1][n]``, a number:
``[n+1][01][n]``); zero bytes close records. The root (0xc119) holds the y axis (left, with a
second y axis) and the x axis (right), each ``pair(pair(limits, markers), expressions)``; the
expressions are a comma list (one per trace). Operators of an expression decode to the
elements of the worksheet's XML (``apply``, ``id``, ``real``), so that a trace translates like
any other expression. An operator not listed here is reported, never guessed.
"""

from __future__ import annotations

import base64
import struct
import zlib

from .reader import MNode
from .symbols import Untranslatable

#: largest decompressed plot item (a plot's tree is a few kB)
MAX_PLOT_BYTES = 1_000_000

_LEAF, _EMPTY, _ROOT, _PAIR, _COMMA = 0x0F02, 0x0F00, 0xC119, 0xC19F, 0xC30A
_APPLY, _ARGS, _NEG, _INDEX, _COLUMN = 0xCE12, 0x708E, 0x4B95, 0xFD04, 0xFD34
#: binary operators -> the tag of Mathcad's XML
_BINARY = {0xCA06: "mult", 0xCC05: "pow"}


class _Rec:
    __slots__ = ("op", "side", "value", "left", "right")

    def __init__(self, op: int, side: int, value: str | None):
        self.op, self.side, self.value = op, side, value
        self.left: _Rec | None = None
        self.right: _Rec | None = None


def payload(encoded: str, what: str = "a plot") -> bytes:
    """The bytes of a binary item (base64 of gzip) of ``what``, at most MAX_PLOT_BYTES."""
    try:
        raw = base64.b64decode(encoded, validate=False)
        d = zlib.decompressobj(16 + zlib.MAX_WBITS)
        data = d.decompress(raw, MAX_PLOT_BYTES)
    except (ValueError, zlib.error):
        raise Untranslatable(f"{what} whose binary item is not gzip (not decoded)") from None
    if d.unconsumed_tail:
        raise Untranslatable(f"{what} whose binary item is larger than {MAX_PLOT_BYTES} bytes")
    return data


def x_limits(data: bytes) -> tuple[float, float] | None:
    """The x axis's limits (lower, upper) the user set, or None where Mathcad chooses them."""
    root = _tree(data)
    try:
        upper, lower = root.right.left.left.left, root.right.left.left.right
    except AttributeError:
        return None
    values = [_limit(r) for r in (lower, upper)]
    if None in values or values[0] >= values[1]:
        return None
    return values[0], values[1]


def _limit(rec: _Rec | None) -> float | None:
    sign = 1.0
    if rec is not None and rec.op == _NEG:
        sign, rec = -1.0, rec.right
    if rec is None or rec.op != _LEAF or not rec.side & 0x10 or (rec.side & 0x3F) == 0x36:
        return None  # an expression, or a number Mathcad chose itself
    try:
        return sign * float(rec.value or "")
    except ValueError:
        return None


def traces(data: bytes) -> tuple[list[tuple[MNode, MNode]], bool]:
    """(x, y) expressions of each trace of an X-Y or polar plot, as Mathcad's XML elements,
    and whether the plot is polar (its r(theta) traces become x = r cos(theta), y = r
    sin(theta))."""
    root = _tree(data)
    if root.op != _ROOT or root.left is None or root.right is None:
        raise Untranslatable("a plot that is not an X-Y or polar plot (a 3-D plot)")
    polar = _polar(data)
    block = root.left if polar else root.left.left if root.left.op == _PAIR else None
    ys = _axis(block, "radius" if polar else "y")
    xs = _axis(root.right, "angle" if polar else "x")
    if len(xs) == 1:
        xs = xs * len(ys)
    if len(xs) != len(ys):
        raise Untranslatable(f"a plot of {len(ys)} y expressions against {len(xs)} x expressions")
    pairs = [(_node(x), _node(y)) for x, y in zip(xs, ys)]
    if polar:
        pairs = [
            (_apply("mult", [r, _call("cos", t)]), _apply("mult", [r, _call("sin", t)]))
            for t, r in pairs
        ]
    return pairs, polar


def _polar(data: bytes) -> bool:
    """The plot's kind, from its graphData record: 0x2002 X-Y, 0x2006 (bit 4) polar."""
    at = data.find(b"graphData")
    if at < 0 or len(data) < at + 24:
        raise Untranslatable("a plot whose kind is not decoded (no graphData)")
    return bool(data[at + 9 + 14] & 0x04)


def _axis(block: _Rec | None, which: str) -> list[_Rec]:
    if block is None or block.op != _PAIR or block.right is None:
        raise Untranslatable(f"a plot whose {which} axis is not decoded")
    out: list[_Rec] = []
    node = block.right
    while node.op == _COMMA:  # left-associated: ((a, b), c)
        out.append(node.right)
        node = node.left
    out.append(node)
    out.reverse()
    if any(n is None or n.op == _EMPTY for n in out):
        raise Untranslatable(f"a plot with an empty {which} expression")
    return out


def _tree(data: bytes) -> _Rec:
    start = data.find(b"\x32\x19\xc1") - 1  # the root record: [id] 32 19 c1
    end = data.find(b"\x0fd2_graph_format")
    if start < 0 or end < 0:
        raise Untranslatable("a plot whose expression tree is not found (not an X-Y plot)")
    records: dict[int, _Rec] = {}
    first = data[start]
    nid, pos = first, start
    try:
        while pos < end:
            p = _at_id(data, pos, nid)
            if p is None:
                break
            op = struct.unpack_from("<H", data, p)[0]
            side = data[p + 4]
            parent, p = _number(data, p + 5)
            value = None
            if op == _LEAF:
                value, p = _leaf(data, p + 2, bool(side & 0x10))
            rec = _Rec(op, side, value)
            records[nid] = rec
            if nid != first:
                up = records.get(parent)
                if up is None:
                    raise Untranslatable("a plot whose expression tree is not decoded")
                setattr(up, "right" if side & 0x80 else "left", rec)
            nid += 1
            while p < end and data[p] == 0:
                p += 1
            pos = p
    except (IndexError, struct.error, UnicodeDecodeError):
        raise Untranslatable("a plot whose expression tree is not decoded") from None
    if first not in records:
        raise Untranslatable("a plot whose expression tree is not decoded")
    return records[first]


def _at_id(data: bytes, pos: int, nid: int) -> int | None:
    """Where the record ``nid`` starting at ``pos`` continues after its id and 0x32."""
    if nid < 0x40 and data[pos] == nid and data[pos + 1] == 0x32:
        return pos + 2
    if data[pos] == 0x40 and data[pos + 1] == nid and data[pos + 2] == 0x32:
        return pos + 3  # ids from 0x40 on are escaped: 40 xx
    return None


def _number(data: bytes, p: int) -> tuple[int, int]:
    if data[p] == 0x40 and data[p + 1] >= 0x40:
        return data[p + 1], p + 2
    return data[p], p + 1


def _leaf(data: bytes, p: int, number: bool) -> tuple[str, int]:
    n = data[p + 2] if number else data[p + 1]
    p += 3 if number else 2
    return data[p : p + 2 * n].decode("utf-16le"), p + 2 * n


def _node(rec: _Rec) -> MNode:
    """A record as the element Mathcad's XML has for the same expression."""
    if rec.op == _LEAF:
        if rec.side & 0x10:
            return MNode("real", {}, rec.value or "", [])
        text, _, sub = (rec.value or "").partition(".")
        return MNode("id", {"subscript": sub} if sub else {}, text, [])
    kids = [c for c in (rec.left, rec.right) if c is not None]
    if rec.op == _NEG and len(kids) == 1:
        return _apply("neg", [_node(kids[0])])
    if rec.op == _INDEX and len(kids) == 2:
        return _apply("indexer", [_node(k) for k in kids])
    if rec.op == _COLUMN and len(kids) == 2:
        return _apply("matcol", [_node(k) for k in kids])
    if rec.op in _BINARY and len(kids) == 2:
        return _apply(_BINARY[rec.op], [_node(k) for k in kids])
    if rec.op == _APPLY and rec.left is not None and rec.right is not None:
        args = rec.right.right if rec.right.op == _ARGS else rec.right
        if args is None:
            raise Untranslatable("a plot with a function call without arguments")
        flat = []
        while args.op == _COMMA:
            flat.append(args.right)
            args = args.left
        flat.append(args)
        flat = [_node(a) for a in reversed(flat)]
        return MNode("apply", {}, "", [_node(rec.left), *flat])
    raise Untranslatable(f"a plot whose expression has an operator not decoded (0x{rec.op:04x})")


def _call(name: str, arg: MNode) -> MNode:
    return MNode("apply", {}, "", [MNode("id", {}, name, []), arg])


def _apply(tag: str, args: list[MNode]) -> MNode:
    return MNode("apply", {}, "", [MNode(tag, {}, "", []), *args])
