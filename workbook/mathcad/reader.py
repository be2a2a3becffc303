"""Reading a Mathcad 11-15 worksheet (.xmcd, XML) safely into plain regions.

The file is untrusted. It is refused before parsing when it is too large, is a zip archive
(a Mathcad Prime .mcdx or a renamed archive: never decompressed), or declares a DTD or
entities (billion laughs, external entities); the XML parser itself runs with entity
expansion, DTD loading and network access off and its size guards on.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import InputError, LimitError

MAX_FILE_BYTES = 50_000_000  # the largest public Mathcad 15 worksheets are a few MB
MAX_ELEMENTS = 2_000_000  # elements of one worksheet
WS = "http://schemas.mathsoft.com/worksheet30"
ML = "http://schemas.mathsoft.com/math30"
UNITS = "http://schemas.mathsoft.com/units10"


@dataclass
class MNode:
    """One element of a math tree: local tag name, attributes, text, children."""

    tag: str
    attrs: dict[str, str]
    text: str
    children: list[MNode]
    line: int | None = None

    def find(self, tag: str) -> MNode | None:
        return next((c for c in self.children if c.tag == tag), None)


@dataclass
class Region:
    """A region of the worksheet in reading order."""

    id: str
    kind: str  # text | math | plot | reference | picture | other
    line: int | None
    top: float  # the baseline (align-y) from the top of the worksheet
    left: float
    text: str = ""  # text regions: the paragraph text
    math: MNode | None = None  # math regions: the expression (define, eval, ...)
    href: str = ""  # reference regions: the referenced file
    disabled: bool = False
    plot: MNode | None = None  # plot regions: the plot's data
    binary: str = ""  # plots, components: the binary item with their definition (base64)
    outputs: list[MNode] = field(default_factory=list)  # components: the names they define
    component: dict[str, str] = field(default_factory=dict)  # components: their attributes
    areas: tuple = ()  # (top, left) of each area the region is inside, outermost first
    # a Prime solve block's Given: the definitions of its guess values (they come before it)
    guesses: list[MNode] = field(default_factory=list)

    def order(self) -> tuple:
        """Mathcad's reading order: an area's regions come together, at the area's place
        (a collapsed area's regions may lie below the regions after it)."""
        return (*self.areas, (self.top, self.left))


@dataclass
class Worksheet:
    path: Path
    regions: list[Region] = field(default_factory=list)
    origin: int = 0  # ORIGIN (array-origin)
    generator: str = ""


def read(path: str | Path) -> Worksheet:
    """Read a .xmcd file into regions; a bad or hostile file is an InputError (exit 2)."""
    return parse_bytes(read_bounded(Path(path), "the Mathcad worksheet"), Path(path))


def read_bounded(path: Path, what: str, max_bytes: int = MAX_FILE_BYTES) -> bytes:
    """The bytes of a regular file of at most ``max_bytes``: a folder, a FIFO or a device
    (``/dev/zero``, a link to it) is refused before it is opened, a file that grows while it
    is read is cut off at the limit and refused."""
    from ..limits import regular_file

    regular_file(path, what=what, max_bytes=max_bytes)
    try:
        with open(path, "rb") as f:
            data = f.read(max_bytes + 1)
    except OSError as exc:
        raise InputError(f"{what} {path}: cannot read it ({exc.strerror})") from None
    if len(data) > max_bytes:
        raise LimitError(f"{what} {path} is more than {max_bytes:,} bytes (limit)")
    return data


def parse_bytes(data: bytes, path: Path) -> Worksheet:
    """Parse the bytes of a .xmcd file (see :func:`read`)."""
    _screen(data, path)
    from lxml import etree

    parser = etree.XMLParser(
        resolve_entities=False,
        no_network=True,
        huge_tree=False,
        load_dtd=False,
        dtd_validation=False,
        remove_comments=True,
        remove_pis=True,
    )
    try:
        root = etree.fromstring(data, parser)
    except etree.XMLSyntaxError as exc:
        line = f" (line {exc.lineno})" if getattr(exc, "lineno", None) else ""
        raise InputError(
            f"{path}: not well-formed XML{line}: {exc.msg}; is it truncated?"
        ) from None
    if root is None or root.tag != f"{{{WS}}}worksheet":
        raise InputError(
            f"{path}: not a Mathcad 11-15 XML worksheet (the root element is "
            f"{local_tag(root.tag) if root is not None else 'missing'}, expected worksheet in "
            f"the namespace {WS})"
        )
    if root.getroottree().docinfo.internalDTD is not None:
        raise InputError(f"{path}: a document type declaration is not allowed in a worksheet")
    count = sum(1 for _ in root.iter())
    if count > MAX_ELEMENTS:
        raise LimitError(f"{path}: {count} XML elements (limit {MAX_ELEMENTS})")
    from .structure import refuse_xinclude

    refuse_xinclude(root, path)
    return _worksheet(root, path)


#: A document type or entity declaration, refused before any XML parser sees the file.
DECLARES_DTD = re.compile(rb"<!\s*(DOCTYPE|ENTITY)", re.IGNORECASE)


def _screen(data: bytes, path: Path) -> None:
    if data[:4] == b"PK\x03\x04" or data[:4] == b"PK\x05\x06":
        raise InputError(
            f"{path}: a zip archive (a Mathcad Prime .mcdx or a renamed archive), not a Mathcad "
            "11-15 XML worksheet; it is not unpacked"
        )
    head = data[:4096].lstrip(b"\xef\xbb\xbf \t\r\n")
    if not head.startswith(b"<"):
        raise InputError(f"{path}: not a Mathcad XML worksheet (it does not start with '<')")
    if DECLARES_DTD.search(data):
        raise InputError(
            f"{path}: declares a DTD or entities (<!DOCTYPE/<!ENTITY); Mathcad worksheets have "
            "none, and such a file is refused unread (entity expansion is never done)"
        )


def local_tag(tag) -> str:
    """An element's or attribute's name without its ``{namespace}``."""
    tag = str(tag)
    return tag.rsplit("}", 1)[-1]


def tag_namespace(tag) -> str:
    """The namespace of a ``{namespace}name`` tag ('' for none)."""
    tag = str(tag)
    return tag[1:].split("}", 1)[0] if tag.startswith("{") else ""


def _node(el) -> MNode:
    if local_tag(el.tag) == "provenance":  # an expression pasted from another worksheet
        inner = [c for c in el if isinstance(c.tag, str) and tag_namespace(c.tag) == ML]
        if inner:
            return _node(inner[-1])
    children = [_node(c) for c in el if isinstance(c.tag, str)]
    return MNode(
        local_tag(el.tag),
        {local_tag(k): v for k, v in el.attrib.items()},
        (el.text or ""),
        children,
        el.sourceline,
    )


def _text_of(el) -> str:
    """The text of a text region: paragraphs joined by newlines, subscripts inline."""
    paras = []
    for p in el.iter(f"{{{WS}}}p"):
        paras.append(re.sub(r"\s+", " ", "".join(_own_text(p))).strip())
    if not paras:
        paras = [re.sub(r"\s+", " ", "".join(_own_text(el))).strip()]
    return "\n".join(x for x in paras if x)


def _own_text(el):
    """The text of an element, without the math regions placed inside a paragraph."""
    if el.text:
        yield el.text
    for child in el:
        if isinstance(child.tag, str) and local_tag(child.tag) != "region":
            yield from _own_text(child)
        if child.tail:
            yield child.tail


def _worksheet(root, path: Path) -> Worksheet:
    ws = Worksheet(path)
    gen = root.find(f"{{{WS}}}metadata/{{{WS}}}generator")
    ws.generator = (gen.text or "").strip() if gen is not None else ""
    origin = root.find(f".//{{{WS}}}builtInVariables")
    if origin is not None and origin.get("array-origin"):
        try:
            ws.origin = int(float(origin.get("array-origin")))
        except ValueError:
            raise InputError(f"{path}: array-origin {origin.get('array-origin')!r}") from None
    regions = root.find(f"{{{WS}}}regions")
    if regions is None:
        raise InputError(f"{path}: a Mathcad worksheet without <regions>")
    _collect(regions, 0.0, 0.0, ws.regions)
    binary = root.find(f"{{{WS}}}binaryContent")
    items = {
        item.get("item-id"): item.text or ""
        for item in (binary if binary is not None else ())
        if isinstance(item.tag, str) and item.get("item-id")
    }
    for region in ws.regions:  # a plot's definition is a binary item (decoded when translated)
        if region.kind == "plot" and region.plot is not None:
            region.binary = items.get(region.plot.attrs.get("item-idref", ""), "")
        if region.kind == "component":
            region.binary = items.get(region.component.get("item-idref", ""), "")
    ws.regions.sort(key=Region.order)  # Mathcad's order: top down, left to right
    return ws


def dy_of(el, top: float) -> float:
    """Where the regions inside an area start: the area region's top."""
    return top + _float(el.get("top"))


def _collect(parent, top: float, left: float, out: list[Region], areas: tuple = ()) -> None:
    """Regions in order; those inside a collapsible area are placed relative to it, and
    read with it (``areas``: where the areas around them are)."""
    for el in parent.iterchildren(f"{{{WS}}}region"):
        region = _region(el, top, left)
        region.areas = areas
        out.append(region)
        text = el.find(f"{{{WS}}}text")
        if text is not None:  # math regions placed inside a paragraph of text
            for p in text.iter(f"{{{WS}}}p"):
                _collect(p, top, left, out, areas)
        area = el.find(f"{{{WS}}}area")
        if area is not None:
            inner = (*areas, (region.top, region.left))
            _collect(area, dy_of(el, top), left + _float(el.get("left")), out, inner)


def _float(text, default=0.0) -> float:
    try:
        return float(text)
    except (TypeError, ValueError):
        return default


def _region(el, dy: float = 0.0, dx: float = 0.0) -> Region:
    rid = el.get("region-id", "?")
    top = dy + _float(el.get("align-y", el.get("top")))
    left = dx + _float(el.get("left"))
    base = dict(id=rid, line=el.sourceline, top=top, left=left)
    kids = [c for c in el if isinstance(c.tag, str)]
    for c in kids:
        tag = local_tag(c.tag)
        if tag == "text":
            return Region(kind="text", text=_text_of(c), **base)
        if tag == "math":
            body = [x for x in c if isinstance(x.tag, str) and tag_namespace(x.tag) == ML]
            while body and local_tag(body[0].tag) == "provenance":  # pasted from another file
                body = [x for x in body[0] if isinstance(x.tag, str) and tag_namespace(x.tag) == ML]
            math = _node(body[-1]) if body else None
            return Region(kind="math", math=math, disabled=c.get("disable-calc") == "true", **base)
        if tag == "plot":
            return Region(kind="plot", plot=_node(c), **base)
        if tag == "reference":
            link = el.find(f"{{{WS}}}link")
            origin = next((x for x in c if local_tag(x.tag) == "originRef"), None)
            href = (link.get("href") if link is not None else None) or (
                origin.get("href", "") if origin is not None else ""
            )
            return Region(kind="reference", href=href, **base)
        if tag == "picture":
            return Region(kind="picture", **base)
        if tag == "component":  # a data table, spreadsheet...: the names it defines
            outputs = next((x for x in c if local_tag(x.tag) == "outputs"), None)
            names = [
                _node(x)
                for x in (outputs if outputs is not None else ())
                if local_tag(x.tag) == "id"
            ]
            attrs = {k: v for k, v in c.attrib.items() if isinstance(k, str)}
            return Region(kind="component", outputs=names, component=attrs, **base)
    tag = local_tag(kids[0].tag) if kids else "empty"
    return Region(kind=tag if tag in ("area",) else "other", text=tag, **base)
