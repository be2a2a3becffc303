"""The shape of a worksheet's math trees, checked before they are translated.

A Mathcad file is untrusted: an element of another kind where Mathcad writes a definition's
two sides, an operator without its operands, or an ``xi:include`` (XML that would pull in
another file) is a file Mathcad did not write. Such a file is refused with the file, the line
and the region (exit 2), never translated by guessing the missing part.
"""

from __future__ import annotations

from pathlib import Path

from ..errors import InputError

#: XML Inclusions: no Mathcad worksheet includes other XML
XINCLUDE = ("http://www.w3.org/2001/XInclude", "http://www.w3.org/2003/XInclude")

#: tag -> (fewest, most) children (None: any number) of Mathcad's containers
CHILDREN: dict[str, tuple[int, int | None]] = {
    "define": (2, 2),
    "globalDefine": (2, 2),
    "eval": (1, None),
    "function": (2, 2),
    "boundVars": (1, None),
    "parens": (1, 1),
    "ifThen": (2, 2),
    "otherwise": (1, 1),
    "for": (3, 3),
    "while": (2, 2),
    "localDefine": (2, 2),
    "range": (2, 3),
    "apply": (2, None),
    "lambda": (2, 2),
    "sequence": (1, None),
}

#: operators of two operands: ``apply`` holds the operator and both
BINARY = frozenset(
    "plus minus mult div pow equal lessThan greaterThan lessOrEqual greaterOrEqual notEqual "
    "and or indexer matcol".split()
)


def refuse_xinclude(root, path: Path, part: str = "") -> None:
    """Refuse a parsed XML tree with an XInclude element (never expanded)."""
    for el in root.iter():
        tag = el.tag if isinstance(el.tag, str) else ""
        if tag.startswith("{") and tag[1:].split("}", 1)[0] in XINCLUDE:
            where = f" of {part}" if part else ""
            raise InputError(
                f"{path}: line {el.sourceline}{where}: an XInclude element "
                f"(<{tag.rsplit('}', 1)[-1]}>): a Mathcad worksheet includes no other XML, "
                "and the file is refused (the inclusion is never followed)"
            )


def check_regions(path: Path, regions) -> None:
    """Refuse the file if a math region's tree is not shaped as Mathcad writes it."""
    for region in regions:
        if region.math is not None:
            _check(region.math, path, region.id)


def _check(node, path: Path, region: str) -> None:
    stack = [node]
    while stack:
        n = stack.pop()
        bounds = CHILDREN.get(n.tag)
        count = len(n.children)
        bad = bounds is not None and (
            count < bounds[0] or (bounds[1] is not None and count > bounds[1])
        )
        if n.tag == "apply" and n.children and n.children[0].tag in BINARY:
            bad = bad or count != 3
            what = f"<apply> of <{n.children[0].tag}> with {count - 1} operands, not 2"
        else:
            what = f"<{n.tag}> with {count} elements inside"
        if bad:
            raise InputError(
                f"{path}: line {n.line}, region {region}: {what}; Mathcad writes no such "
                "expression (an element of another kind, or one missing), and the file is "
                "refused rather than translated by guessing"
            )
        stack.extend(n.children)
