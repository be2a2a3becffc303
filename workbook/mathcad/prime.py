"""Reading a Mathcad Prime worksheet (.mcdx) safely into the regions the translator reads.

An .mcdx is a zip (Open Packaging Conventions): ``mathcad/worksheet.xml`` holds the regions
(math in the namespace math50, close to Mathcad 15's math30), ``mathcad/result.xml`` the
results Prime stored (``resultRef`` of a math region -> ``resultData``), text regions live in
XAML parts, ORIGIN in ``mathcad/settings/calculation.xml``. The file is untrusted: its size,
its number of members and each member's unpacked size are bounded before anything is unpacked,
member names are never used as paths, and the XML is read as the .xmcd reader reads it (no
DTD, no entities, no network).

Prime stores a result in the unit it displays: a number in the unit typed after ``=`` (times a
scale factor such as ``10^3`` or ``10^-34 kg*m^2/s``, times the residual unit it stores where
the chosen unit does not cancel every dimension), else in SI base units as Mathcad 15 does. The
reader rewrites each as Mathcad 15's form: a number times a unit.
"""

from __future__ import annotations

import io
import re
import zipfile
from pathlib import Path

from ..errors import InputError, LimitError
from .reader import (
    MAX_FILE_BYTES,
    UNITS,
    MNode,
    Region,
    Worksheet,
    local_tag,
    read_bounded,
    tag_namespace,
)
from .units import FORMULA_UNITS

WS50 = "http://schemas.mathsoft.com/worksheet50"
ML50 = "http://schemas.mathsoft.com/math50"
RESULTS = "http://schemas.mathsoft.com/result10"
XAML = "http://schemas.microsoft.com/winfx/2006/xaml/presentation"

MAX_MEMBERS = 5_000  # parts of one package
MAX_MEMBER_BYTES = 64_000_000  # one part, unpacked
MAX_TOTAL_BYTES = 256_000_000  # all parts read, unpacked
MAX_TEXT_BYTES = 1_000_000  # one text region's XAML package and its document
MAX_ELEMENTS = 2_000_000

#: Prime's keywords that Mathcad 15 wrote as operators.
_KEYWORDS = {"find": "Find", "maximize": "Maximize", "minimize": "Minimize"}


class _Package:
    """The members of the zip, each read at most once and within the limits."""

    def __init__(self, data: bytes, path: Path) -> None:
        self.path = path
        self.read_total = 0
        try:
            self.zip = zipfile.ZipFile(io.BytesIO(data))
            infos = self.zip.infolist()
        except (zipfile.BadZipFile, ValueError, EOFError, OSError) as exc:
            raise InputError(f"{path}: not a Mathcad Prime worksheet (not a zip: {exc})") from None
        if len(infos) > MAX_MEMBERS:
            raise LimitError(f"{path}: {len(infos):,} parts in the package (limit {MAX_MEMBERS:,})")
        self.infos = {i.filename.lstrip("/"): i for i in infos}

    def has(self, name: str) -> bool:
        return name.lstrip("/") in self.infos

    def read(self, name: str, limit: int = MAX_MEMBER_BYTES) -> bytes:
        info = self.infos.get(name.lstrip("/"))
        if info is None:
            raise InputError(f"{self.path}: the package has no part {name}")
        if info.file_size > limit:
            raise LimitError(
                f"{self.path}: the part {info.filename} unpacks to {info.file_size:,} bytes "
                f"(limit {limit:,})"
            )
        try:
            with self.zip.open(info) as f:
                data = f.read(limit + 1)
        except (zipfile.BadZipFile, ValueError, EOFError, OSError, RuntimeError) as exc:
            raise InputError(
                f"{self.path}: the part {info.filename} cannot be read: {exc}"
            ) from None
        if len(data) > limit:
            raise LimitError(f"{self.path}: the part {info.filename} is larger than it declares")
        self.read_total += len(data)
        if self.read_total > MAX_TOTAL_BYTES:
            raise LimitError(
                f"{self.path}: its parts unpack to more than {MAX_TOTAL_BYTES:,} bytes"
            )
        return data


def read(path: str | Path) -> Worksheet:
    """Read a .mcdx file into regions; a bad or hostile file is an InputError (exit 2)."""
    path = Path(path)
    return parse_bytes(read_bounded(path, "the Mathcad Prime worksheet", MAX_FILE_BYTES), path)


def parse_bytes(data: bytes, path: Path) -> Worksheet:
    if data[:4] != b"PK\x03\x04":
        raise InputError(f"{path}: not a Mathcad Prime worksheet (.mcdx is a zip package)")
    package = _Package(data, path)
    if not package.has("mathcad/worksheet.xml"):
        raise InputError(f"{path}: not a Mathcad Prime worksheet (no mathcad/worksheet.xml)")
    root = _xml(package.read("mathcad/worksheet.xml"), path, "mathcad/worksheet.xml")
    if root.tag != f"{{{WS50}}}worksheet":
        raise InputError(
            f"{path}: not a Mathcad Prime worksheet (the root element of mathcad/worksheet.xml "
            f"is {local_tag(root.tag)}, expected worksheet in the namespace {WS50})"
        )
    results: dict[str, object] = {}
    if package.has("mathcad/result.xml"):
        rroot = _xml(package.read("mathcad/result.xml"), path, "mathcad/result.xml")
        for data_el in rroot:
            if isinstance(data_el.tag, str) and local_tag(data_el.tag) == "resultData":
                results[data_el.get("result-id", "")] = data_el
    ws = Worksheet(path)
    ws.generator = "Mathcad Prime"
    if package.has("mathcad/settings/calculation.xml"):
        calc = _xml(package.read("mathcad/settings/calculation.xml"), path, "calculation.xml")
        for el in calc.iter():
            if isinstance(el.tag, str) and local_tag(el.tag) == "builtInVariables":
                origin = el.get("array-origin", "0")
                if not re.fullmatch(r"-?[0-9]{1,6}", origin.strip()):
                    raise InputError(f"{path}: array-origin {origin[:40]!r} is not a whole number")
                ws.origin = int(origin)
    texts = _text_parts(package)
    regions = root.find(f"{{{WS50}}}regions")
    if regions is None:
        raise InputError(f"{path}: a Mathcad Prime worksheet without <regions>")
    reader = _Regions(results, texts, package)
    reader.collect(regions, ws.regions)
    return ws


def _xml(data: bytes, path: Path, part: str):
    from lxml import etree

    from .reader import DECLARES_DTD

    if DECLARES_DTD.search(data):
        raise InputError(f"{path}: the part {part} declares a DTD or entities; refused unread")
    parser = etree.XMLParser(
        resolve_entities=False,
        no_network=True,
        huge_tree=False,
        load_dtd=False,
        remove_comments=True,
        remove_pis=True,
    )
    try:
        root = etree.fromstring(data, parser)
    except etree.XMLSyntaxError as exc:
        raise InputError(f"{path}: the part {part} is not well-formed XML: {exc.msg}") from None
    if root is None:
        raise InputError(f"{path}: the part {part} is empty")
    count = sum(1 for _ in root.iter())
    if count > MAX_ELEMENTS:
        raise LimitError(f"{path}: {count:,} XML elements in {part} (limit {MAX_ELEMENTS:,})")
    from .structure import refuse_xinclude

    refuse_xinclude(root, path, part)
    return root


def _text_parts(package: _Package) -> dict[str, str]:
    """Relationship id -> part name, from mathcad/_rels/worksheet.xml.rels."""
    rels = "mathcad/_rels/worksheet.xml.rels"
    if not package.has(rels):
        return {}
    root = _xml(package.read(rels), package.path, rels)
    return {
        el.get("Id", ""): el.get("Target", "")
        for el in root.iter()
        if isinstance(el.tag, str) and local_tag(el.tag) == "Relationship"
    }


class _Regions:
    def __init__(self, results: dict, texts: dict[str, str], package: _Package) -> None:
        self.results = results
        self.texts = texts
        self.package = package
        self.order = 0

    def _base(self, el, suffix: str = "") -> dict:
        self.order += 1
        return dict(
            id=el.get("region-id", "?") + suffix,
            line=el.sourceline,
            top=float(self.order),
            left=0.0,
        )

    def collect(self, regions_el, out: list[Region]) -> None:
        """Regions in the file's order (Prime writes them in reading order)."""
        for el in regions_el:
            if not isinstance(el.tag, str) or local_tag(el.tag) != "region":
                continue
            kids = [c for c in el if isinstance(c.tag, str)]
            if not kids:
                continue
            content = kids[0]
            tag = local_tag(content.tag)
            if tag == "math":
                out.append(self.math(el, content))
            elif tag == "text":
                out.append(Region(kind="text", text=self.text(content), **self._base(el)))
                inner = content.find(f"{{{WS50}}}regions")
                if inner is not None:  # math regions inside the text compute where it stands
                    self.collect(inner, out)
            elif tag == "solveblock":
                self.solve_block(el, content, out)
            elif tag == "Area":
                inner = content.find(f"{{{WS50}}}regions")
                if inner is not None:
                    self.collect(inner, out)
            elif tag == "spec-table":
                maths = [c for c in content.iter(f"{{{WS50}}}math")]
                for k, m in enumerate(maths):
                    out.append(self.math(el, m, f".{k + 1}"))
            elif tag == "pageBreak":
                continue
            else:
                what = {
                    "plot": "a plot",
                    "picture": "a picture",
                    "chartComponent": "a chart component",
                    "oleObject": "an embedded object",
                    "reference": "a reference to another worksheet",
                }.get(tag, f"Mathcad Prime's <{tag}>")
                region = Region(kind="listed", text=what, **self._base(el))
                region.href = "not translated from Mathcad Prime yet"
                out.append(region)

    def solve_block(self, el, content, out: list[Region]) -> None:
        """Guess values, then Given, the constraints and the solver, as Mathcad 15 had them."""
        inner = content.find(f"{{{WS50}}}regions")
        if inner is None:
            return
        parts: dict[str, list[Region]] = {"guess-value": [], "constraint": [], "solver": []}
        for r in inner:
            if not isinstance(r.tag, str) or local_tag(r.tag) != "region":
                continue
            kind = r.get("solve-block-category", "constraint")
            collected: list[Region] = []
            self.collect([r], collected)
            parts.setdefault(kind, []).extend(collected)
        given = Region(kind="math", math=MNode("id", {}, "Given", []), **self._base(el, ".given"))
        given.guesses = [r.math for r in parts["guess-value"] if r.math is not None]
        out += parts["guess-value"] + [given] + parts["constraint"] + parts["solver"]

    def text(self, content) -> str:
        """A text region's paragraphs (its XAML package, a zip of its own, read bounded)."""
        target = self.texts.get(content.get("item-idref", ""), "")
        if not target or not self.package.has(target):
            return ""
        try:
            inner = _Package(self.package.read(target, MAX_TEXT_BYTES), self.package.path)
            name = next((n for n in inner.infos if n.lower().endswith(".xaml")), None)
            if name is None:
                return ""
            root = _xml(inner.read(name, MAX_TEXT_BYTES), self.package.path, target)
        except InputError:
            return ""  # a text the reader cannot read is left out (it defines nothing)
        paragraphs = []
        for p in root.iter(f"{{{XAML}}}Paragraph"):
            words = "".join(t for t in p.itertext())
            if words.strip():
                paragraphs.append(" ".join(words.split()))
        return "\n".join(paragraphs)

    def math(self, el, content, suffix: str = "") -> Region:
        base = self._base(el, suffix)
        body = [c for c in content if isinstance(c.tag, str) and tag_namespace(c.tag) == ML50]
        if not body:
            return Region(kind="math", math=None, **base)
        node = _node(body[-1])
        stored = self.results.get(content.get("resultRef", ""))
        evaluation = _first(node, "eval")
        if evaluation is not None:
            _attach_result(evaluation, stored)
        disabled = content.get("disable-calc") == "true" or el.get("disable-calc") == "true"
        return Region(kind="math", math=node, disabled=disabled, **base)


def _first(node: MNode, tag: str) -> MNode | None:
    if node.tag == tag:
        return node
    if node.tag == "define":
        return next((c for c in node.children if c.tag == tag), None)
    return None


def _node(el) -> MNode:
    """A math50 element as the translator reads Mathcad 15's: names with their subscripts,
    ``scale`` as a product, Prime's keywords as Mathcad 15's operators."""
    tag = local_tag(el.tag)
    attrs = {local_tag(k): v for k, v in el.attrib.items()}
    if tag == "id":
        text, subscript = _name(el)
        if subscript:
            attrs["subscript"] = subscript
        if attrs.get("labels") == "KEYWORD" and text.strip().lower() in _KEYWORDS:
            return MNode(_KEYWORDS[text.strip().lower()], attrs, "", [], el.sourceline)
        if attrs.get("labels") == "CONSTANT":
            return _constant(text, subscript, attrs, el.sourceline)
        return MNode("id", attrs, text, [], el.sourceline)
    children = [
        _node(c) for c in el if isinstance(c.tag, str) and tag_namespace(c.tag) in (ML50, UNITS, "")
    ]
    children = [c for c in children if c.tag != "display"]
    if tag == "scale":
        tag = "mult"
    if tag == "unitOverride" and all(c.tag == "placeholder" for c in children):
        return MNode("noOverride", {}, "", [], el.sourceline)
    node = MNode(tag, attrs, el.text or "", children, el.sourceline)
    if tag == "eval":
        node.children = [c for c in children if c.tag != "noOverride"]
    if tag == "apply" and children:
        return _apply(node)
    if tag == "if":
        chain = _if_chain(node)
        if chain is not node:
            return chain
        statements = _if_statements(node)
        if statements is None:
            return node
        return statements[0] if len(statements) == 1 else MNode("program", {}, "", statements)
    if tag == "ComboBoxControl":
        return _combo_box(node)
    if tag == "program":
        node.children = [
            s for c in children for s in (_if_statements(c) if c.tag == "if" else None) or [c]
        ]
    return node


def _combo_box(node: MNode) -> MNode:
    """A combo box input control: the value of the row selected when the file was saved
    (``SelectedRow`` counts from 0), when its rows have no scale factors; else as it is
    (listed as not translated)."""
    values = next((c for c in node.children if c.tag == "ComboBoxValues"), None)
    scales = next((c for c in node.children if c.tag == "ComboBoxScaleFactors"), None)
    row = node.attrs.get("SelectedRow", "")
    if values is None or not re.fullmatch(r"[0-9]{1,6}", row.strip()):
        return node
    if scales is not None and any(c.tag != "placeholder" for c in scales.children):
        return node
    k, cells = int(row), values.children
    cols = node.attrs.get("cols", "1").strip()
    if not re.fullmatch(r"[0-9]{1,4}", cols) or int(cols) < 1:
        return node
    n = int(cols)  # the values are stored row by row; a row of several is a column vector
    if (k + 1) * n > len(cells):
        return node
    if n == 1:
        return cells[k]
    return MNode("matrix", {"rows": str(n), "cols": "1"}, "", cells[k * n : (k + 1) * n])


def _if_statements(node: MNode) -> list[MNode] | None:
    """Prime's if / else if / else with blocks as Mathcad 15's statements: ``if`` then
    ``otherwise`` holding the rest of the chain (None: not of that form)."""
    parts = [node] + [c for c in node.children if c.tag == "elseif"]
    other = next((c for c in node.children if c.tag == "else"), None)

    def block(holder: MNode | None) -> MNode | None:
        if holder is None or not holder.children:
            return None
        kids = holder.children
        return kids[0] if len(kids) == 1 else MNode("program", {}, "", kids)

    pairs = []
    for part in parts:
        test = next((c for c in part.children if c.tag == "test"), None)
        then = block(next((c for c in part.children if c.tag == "then"), None))
        if test is None or len(test.children) != 1 or then is None:
            return None
        pairs.append((test.children[0], then))
    tail: list[MNode] = []
    if other is not None:
        rest = block(other)
        if rest is None:
            return None
        tail = [MNode("otherwise", {}, "", [rest])]
    for cond, then in reversed(pairs[1:]):
        inner = [MNode("ifThen", {}, "", [cond, then])] + tail
        tail = [MNode("otherwise", {}, "", [MNode("program", {}, "", inner)])]
    cond, then = pairs[0]
    return [MNode("ifThen", {}, "", [cond, then])] + tail


#: Prime's built-in constants (labelled CONSTANT) -> pint's name of the same constant.
_CONSTANTS = {
    ("c", ""): "speed_of_light",
    ("g", ""): "standard_gravity",
    ("h", ""): "planck_constant",
    ("ℏ", ""): "hbar",
    ("k", ""): "boltzmann_constant",
    ("e", "c"): "elementary_charge",
    ("m", "u"): "atomic_mass_constant",
    ("N", "A"): "avogadro_constant",
    ("R", ""): "molar_gas_constant",
    ("R", "∞"): "rydberg_constant",
    ("α", ""): "fine_structure_constant",
    ("ε", "0"): "vacuum_permittivity",
    ("μ", "0"): "vacuum_permeability",
    ("σ", ""): "stefan_boltzmann_constant",
    ("Φ", "0"): "magnetic_flux_quantum",
}
_BASE_UNITS = {"[length]": "m", "[mass]": "kg", "[time]": "s", "[current]": "A",
               "[temperature]": "K", "[substance]": "mol", "[luminosity]": "cd"}  # fmt: skip
_NUMBERS = {("∞", ""): 1e307, ("γ", ""): 0.57721566490153286}  # Prime's ∞ is 10^307


def _constant(text: str, subscript: str, attrs: dict, line) -> MNode:
    """A built-in constant of Prime as a number times SI base units (π and e stay names the
    translator knows; a constant it does not know stays a name, not defined)."""
    key = (text.strip(), subscript)
    if key in _NUMBERS:
        return MNode("real", {}, repr(_NUMBERS[key]), [], line)
    if key not in _CONSTANTS:
        named = dict(attrs, subscript=subscript) if subscript else attrs
        return MNode("id", named, text, [], line)
    from ..language import units as un

    q = un.registry().Quantity(1, _CONSTANTS[key]).to_base_units()
    node = MNode("real", {}, repr(float(q.magnitude)), [], line)
    for dim, power in q.dimensionality.items():
        unit = MNode("id", {"labels": "UNIT"}, _BASE_UNITS[dim], [], line)
        if power != 1:
            exponent = MNode("real", {}, repr(float(power)), [], line)
            unit = MNode("apply", {}, "", [MNode("pow", {}, "", []), unit, exponent], line)
        node = MNode("apply", {}, "", [MNode("mult", {}, "", []), node, unit], line)
    return MNode("parens", {}, "", [node], line)


def _branch_value(node: MNode | None) -> MNode | None:
    """The expression of a then/else branch that holds one expression, else None."""
    while node is not None and node.tag in ("then", "else", "program") and len(node.children) == 1:
        node = node.children[0]
    if node is None or node.tag in ("then", "else", "program", "localDefine", "return"):
        return None
    return node


def _if_chain(node: MNode) -> MNode:
    """Prime's if / else if / else of single expressions as Mathcad 15's nested if(c, a, b)
    (the first true condition decides); any other if stays as it is (not translated)."""
    tests, values, other = [], [], None
    parts = [node] + []
    test = next((c for c in node.children if c.tag == "test"), None)
    then = next((c for c in node.children if c.tag == "then"), None)
    for child in node.children:
        if child.tag == "elseif":
            parts.append(child)
        elif child.tag == "else":
            other = _branch_value(child)
            if other is None:
                return node
    if test is None or then is None or other is None:
        return node
    for part in parts:
        test = next((c for c in part.children if c.tag == "test"), None)
        value = _branch_value(next((c for c in part.children if c.tag == "then"), None))
        if test is None or value is None or len(test.children) != 1:
            return node
        tests.append(test.children[0])
        values.append(value)
    tree = other
    for cond, value in zip(reversed(tests), reversed(values)):
        tree = MNode("apply", {}, "", [MNode("id", {}, "if", []), cond, value, tree], node.line)
    return tree


def _apply(node: MNode) -> MNode:
    """Prime's forms of operators Mathcad 15 wrote otherwise."""
    op, args = node.children[0].tag, node.children[1:]
    lower = next((a for a in args if a.tag == "lowerBound"), None)
    upper = next((a for a in args if a.tag == "upperBound"), None)
    if lower is not None and upper is not None and len(lower.children) == len(upper.children) == 1:
        bounds = MNode("bounds", {}, "", [lower.children[0], upper.children[0]])
        rest = [a for a in args if a is not lower and a is not upper]
        return MNode("apply", node.attrs, "", [node.children[0], *rest, bounds], node.line)
    if op == "mult" and len(args) == 2 and args[1].tag == "placeholder":
        return args[0]  # a value with an empty unit placeholder (scale)
    if op == "nthRoot" and len(args) == 2 and args[0].tag == "placeholder":
        return MNode("apply", {}, "", [MNode("sqrt", {}, "", []), args[1]], node.line)
    if op == "percent" and len(args) == 1:  # 9% is 0.09
        hundred = MNode("real", {}, "100", [])
        return MNode("apply", {}, "", [MNode("div", {}, "", []), args[0], hundred], node.line)
    if op == "determinant" and len(args) == 1:  # |M|, as Mathcad 15 wrote it
        return MNode("apply", {}, "", [MNode("absval", {}, "", []), args[0]], node.line)
    return node


def _name(el) -> tuple[str, str]:
    """(text, literal subscript) of an id: plain text, or XAML ``<Span>f<Subscript>ck``."""
    base: list[str] = []
    sub: list[str] = []

    def walk(e, in_sub: bool) -> None:
        here = in_sub or local_tag(e.tag) == "Subscript"
        if e.text:
            (sub if here else base).append(e.text)
        for c in e:
            if isinstance(c.tag, str):
                walk(c, here)
            if c.tail:
                (sub if here else base).append(c.tail)

    walk(el, False)
    return "".join(base).strip(), "".join(sub).strip()


def _attach_result(evaluation: MNode, stored) -> None:
    """Put Prime's stored result inside the evaluation as Mathcad 15 stores it: a number in
    the unit typed after ``=`` becomes that number times that unit (a scale factor applied)."""
    if stored is None:
        return
    result_el = next(
        (c for c in stored if isinstance(c.tag, str) and local_tag(c.tag) == "result"), None
    )
    if result_el is None or not len(result_el):
        return  # an engine error, or nothing stored: Mathcad showed no value
    value = _node(next(c for c in result_el if isinstance(c.tag, str)))
    override = evaluation.find("unitOverride")
    if override is not None and override.children:
        try:
            factor, unit = _override_quantity(override.children[0])
        except ValueError as why:
            value = MNode("unreadable", {"why": f"a result shown in {why}"}, "", [])
        else:
            value = _in_unit(value, factor, unit)
            if not unit:
                evaluation.children = [c for c in evaluation.children if c.tag != "unitOverride"]
    evaluation.children.append(MNode("result", {}, "", [value]))


def _override_quantity(node: MNode) -> tuple[float, str]:
    """(scale factor, pint unit text) of the unit typed after ``=`` (``kN/m``, ``10^3``,
    ``10^-34 kg*m^2/s``)."""
    from ..language import units as un

    text = _unit_expression(node)
    try:
        q = un.registry().Quantity(text)
    except Exception:  # noqa: BLE001 - pint's parse errors are many kinds
        raise ValueError(f"a unit pint cannot read ({text})") from None
    unit = "" if q.dimensionless and str(q.units) in ("", "dimensionless") else str(q.units)
    return float(q.magnitude), unit


def _unit_expression(node: MNode) -> str:
    if node.tag == "id":
        name = node.text.strip()
        if node.attrs.get("subscript"):
            raise ValueError(f"the unit {name}.{node.attrs['subscript']}")
        return f"({FORMULA_UNITS.get(name, name)})"
    if node.tag == "real":
        return f"({float(node.text)!r})"
    if node.tag == "parens" and node.children:
        return f"({_unit_expression(node.children[0])})"
    if node.tag == "apply" and node.children:
        op, args = node.children[0].tag, node.children[1:]
        ops = {"mult": "*", "div": "/", "pow": "**"}
        if op in ops and len(args) == 2:
            a, b = (_unit_expression(x) for x in args)
            return f"({a} {ops[op]} {b})"
        if op == "neg" and len(args) == 1:
            return f"(-{_unit_expression(args[0])})"
    raise ValueError(f"Mathcad Prime's <{node.tag}> after =")


def _in_unit(value: MNode, factor: float, unit: str) -> MNode:
    """``value`` (numbers in the chosen unit, perhaps times a residual unit) times ``factor``,
    in ``unit`` (times the residual)."""
    scaled = _scaled(value, factor)
    if not unit:
        return scaled
    inner, residual = scaled, ""
    if scaled.tag == "unitedValue":
        inner = scaled.children[0]
        mono = scaled.find("unitMonomial")
        from .trees import unit_monomial

        residual = unit_monomial(mono) if mono is not None else ""
    if inner.tag == "matrix" and any(c.tag == "unitedValue" for c in inner.children):
        return MNode("unreadable", {"why": "a matrix result with a unit per element"}, "", [])
    text = f"({unit}) * ({residual})" if residual else unit
    return MNode("unitedValue", {}, "", [inner, MNode("unitMonomial", {"text": text}, "", [])])


def _scaled(node: MNode, factor: float) -> MNode:
    if factor == 1.0:
        return node
    if node.tag == "real":
        try:
            return MNode("real", {}, repr(float(node.text) * factor), [])
        except ValueError:
            return node
    return MNode(
        node.tag, node.attrs, node.text, [_scaled(c, factor) for c in node.children], node.line
    )
