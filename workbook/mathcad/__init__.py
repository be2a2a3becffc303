"""``workbook import``: a Mathcad 11-15 (.xmcd) or Mathcad Prime (.mcdx) worksheet as a
worksheet of the language.

:func:`import_file` reads the file safely (:mod:`.reader`, :mod:`.prime`: each format its
reader, one translator of Mathcad's math for both), follows its reference regions,
translates the regions in order (:mod:`.translate`), types the translation once in memory
with the engine's typer (:mod:`.engine`), and writes ``NAME.toml`` with the printed values
(Mathcad's stored results) beside it (:mod:`.writer`). A region the engine refuses is listed
untranslated with the engine's reason, and so is everything that uses it: the written
worksheet always loads.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError, WorkbookError
from .reader import Region, Worksheet, read

MAX_REFERENCE_DEPTH = 8
MAX_REFERENCED_FILES = 100  # files read for references, a file included twice counted twice


@dataclass
class ImportSummary:
    path: Path
    definitions: int
    results: int
    untranslated: int
    files: list[Path]

    def line(self) -> str:
        return (
            f"wrote {self.path}: {self.definitions} definitions, {self.results} results of "
            f"Mathcad as printed values, {self.untranslated} regions not translated"
        )


def sheet_name(path: Path) -> str:
    """The worksheet's name from the file name: letters, digits, '-', '_'."""
    from .names import identifier

    raw = path.stem
    name = "".join(c if (c.isascii() and (c.isalnum() or c in "-_.")) else " " for c in raw)
    if name.split() != raw.split() or not name.strip():
        name = identifier(raw).replace("_", "-")
    name = "-".join(name.split()).strip("-.") or "mathcad"
    return name[:80]


def regions_with_references(
    ws: Worksheet, depth: int = 0, seen: frozenset = frozenset(), reads: list | None = None
) -> list[Region]:
    """The regions in order, a reference region replaced by the referenced file's regions
    (resolved relative to the file; it must stay inside the file's folder). A cycle is a file
    among the ones that include it (``seen``); two files that include the same third (a
    diamond) are not one. At most MAX_REFERENCED_FILES files are read in all."""
    seen = seen | {ws.path.resolve()}
    reads = [0] if reads is None else reads
    out: list[Region] = []
    for region in ws.regions:
        if region.kind != "reference":
            out.append(region)
            continue
        target = _reference_path(ws.path, region.href)
        if target.resolve() in seen:
            raise InputError(f"{ws.path}: region {region.id} references itself in a cycle")
        if depth >= MAX_REFERENCE_DEPTH:
            raise InputError(f"{ws.path}: references nested more than {MAX_REFERENCE_DEPTH} deep")
        reads[0] += 1
        if reads[0] > MAX_REFERENCED_FILES:
            raise InputError(
                f"{ws.path}: references include more than {MAX_REFERENCED_FILES} files in all"
            )
        out += regions_with_references(read(target), depth + 1, seen, reads)
    return out


def _reference_path(path: Path, href: str) -> Path:
    folder = path.parent.resolve()
    text = href.replace("\\", "/")
    if text.startswith("file:///"):
        text = text[len("file:///") :]
    candidate = Path(text)
    if candidate.is_absolute() or (len(text) > 1 and text[1] == ":"):
        candidate = Path(text.rsplit("/", 1)[-1])  # an absolute path of the author's disk
    target = (folder / candidate).resolve()
    if folder not in target.parents and target != folder:
        raise InputError(
            f"{path}: a reference region points outside the worksheet's folder ({href!r})"
        )
    if not target.is_file():
        raise InputError(
            f"{path}: the referenced worksheet {href!r} is not found beside it ({target.name})"
        )
    return target


def import_file(src: str | Path, out_dir: str | Path = ".", *, force: bool = False):
    """Translate ``src`` and write ``out_dir/NAME.toml`` and its printed values."""
    from . import engine, writer
    from .translate import Translator
    from .translation import Skipped

    src = Path(src)
    if src.suffix.lower() == ".mcdx":
        from . import prime

        ws = prime.read(src)
        regions = ws.regions  # a reference region of Prime is listed, not followed
    else:
        ws = read(src)
        regions = regions_with_references(ws)
    from .structure import check_regions

    check_regions(src, regions)
    name = sheet_name(src)
    out_dir = Path(out_dir)
    translator = Translator(engine.AtImport)
    tr = translator.run(ws, regions)
    doc, rendered = writer.document(tr, name, src)
    listed = {id(r) for r in tr.results if r.misfit}  # listed by the writer already
    refused = engine.refusals(doc.data, rendered, out_dir, tr.results)
    misfits = [r for r in tr.results if r.misfit and id(r) not in listed]
    for res in misfits:
        tr.skipped.append(Skipped(res.region, f"the result of {res.name}", res.misfit))
    if refused:
        engine.leave_out(tr, refused, _descriptions(translator, regions))
    if refused or misfits:
        doc, rendered = writer.document(tr, name, src)
    rendered.toml = doc.text()
    if refused:  # what is left loads as it is: anything else is a bug of the import
        _loads(rendered, out_dir)
    files = writer.write(rendered, out_dir, force=force)
    return ImportSummary(
        files[0],
        rendered.definitions,
        sum(len(r.rows) for r in tr.results),
        len({s.region for s in tr.skipped}),
        files,
    )


def _descriptions(translator, regions: list[Region]) -> dict[str, str]:
    """Region id -> what it is, as the list of untranslated regions names it, in the order
    the translator reads the regions (global definitions first)."""
    out = {}
    first = [r for r in regions if r.math is not None and r.math.tag == "globalDefine"]
    for r in first + [r for r in regions if r not in first]:
        out[r.id] = translator.describe(r.math) if r.math is not None else f"a {r.kind}"
    return out


def _loads(rendered, out_dir: Path) -> None:
    """Load the written worksheet's text once; an error is the import's own (exit 3)."""
    import workbook

    try:
        workbook.loads(rendered.toml, rendered.name, out_dir)
    except WorkbookError as err:
        raise RuntimeError(
            f"the translated worksheet does not load after leaving out what the engine "
            f"refused: {err}"
        ) from None
