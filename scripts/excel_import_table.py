"""The corpus table of docs/excel-import.md: each Excel workbook imported, then checked.

For every .xlsm/.xlsx/.xls in the folder (default ../shared/excel-vba beside the repository),
with the VBA of an add-in of the folder whose name starts like the workbook's
(aero-toolkit-test.xlsm takes aero-toolkit.xlam), imports the workbook and counts, among the
cells whose formula calls a VBA function and whose cached value is a number: reproduced
(the engine's value within the printed values' tolerance), wrong (computed, outside it),
not computable (an error when computed) and not translated (listed in the worksheet).

    python scripts/excel_import_table.py [FOLDER] [--json]
"""

from __future__ import annotations

import json
import re
import sys
import tempfile
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


def addins(book: Path) -> list[Path]:
    """Add-ins of the folder whose name starts as the workbook's does (before its last '-')."""
    stem = book.stem.rsplit("-", 1)[0].lower()
    return sorted(p for p in book.parent.glob("*.xla*") if p.stem.lower().startswith(stem))


def udf_cells(tr) -> dict[str, float]:
    """{cell: cached number} of the formula cells that call a VBA Function (not Private, in a
    standard module, not named like an Excel function)."""
    from openpyxl.utils.formulas import FORMULAE

    names = [
        info.proc.name
        for info in tr.functions.values()
        if not info.proc.private and info.proc.name.upper() not in FORMULAE
    ]
    if not names:
        return {}
    call = re.compile(r"(?<![\w.])(?:\w+\.)?(" + "|".join(map(re.escape, names)) + r")\s*\(", re.I)
    out = {}
    for cells in tr.book.sheets.values():
        for cell in cells.values():
            if cell.formula is None or isinstance(cell.value, bool):
                continue
            if isinstance(cell.value, (int, float)) and call.search(
                re.sub(r"(\[\d+\]|'[^']*')!", "", cell.formula)
            ):
                out[cell.ref] = float(cell.value)
    return out


def measure(book: Path) -> dict:
    """Import one workbook and count its VBA-calling cells by verdict."""
    from workbook.errors import WorkbookError
    from workbook.excelimport.book import translate_book
    from workbook.excelimport.writer import write

    row: dict = {"workbook": book.name, "vba": [p.name for p in addins(book)]}
    try:
        tr = translate_book(book, addins(book))
        with tempfile.TemporaryDirectory() as tmp:
            result = write(tr, Path(tmp), force=True)
            row["exit"] = 0
            verdicts = _verdicts(result)
    except WorkbookError as err:
        row.update(exit=2, error=str(err))
        return row
    cells = udf_cells(tr)
    counts: Counter = Counter()
    for ref in cells:
        if ref not in result.cells:
            counts["not translated"] += 1
        else:
            counts[verdicts.get(result.cells[ref], "not translated")] += 1
    functions = [i for i in tr.functions.values()]
    row.update(
        functions=len(functions),
        translated=sum(1 for i in functions if not i.problem),
        cells=len(cells),
        reproduced=counts["pass"],
        wrong=counts["FAIL"],
        not_computable=counts["error"],
        not_translated=counts["not translated"],
        listed=_reasons(result.not_translated),
    )
    return row


def _verdicts(result) -> dict:
    """{(name, at): verdict} of the worksheet's check."""
    import workbook

    sheet = workbook.load(str(result.toml))
    report = sheet.check()
    return {(r.name, r.at): r.verdict for r in report.rows}


def _reasons(listed) -> dict[str, int]:
    """The kinds of what is listed, counted."""
    kinds: Counter = Counter()
    for what, why in listed:
        low = f"{what}: {why}".lower()
        for key, label in (
            ("solver", "Solver"),
            ("declares a dll", "Declare"),
            ("a sub", "Subs"),
            ("event procedure", "events"),
            ("on error", "On Error"),
            ("volatile", "volatile"),
            ("external link", "external links"),
            ("engine refuses", "refused at load"),
            ("not mapped", "Excel functions not mapped"),
            ("formulas translated", "beyond the cap"),
        ):
            if key in low:
                kinds[label] += 1
                break
        else:
            kinds["other"] += 1
    return dict(kinds.most_common())


def table(rows: list[dict]) -> str:
    lines = [
        "| workbook | exit | VBA functions translated | cells calling VBA (cached numbers) "
        "| reproduced | wrong | not computable | not translated | listed |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |",
    ]
    total: Counter = Counter()
    for r in rows:
        if r["exit"]:
            lines.append(f"| {r['workbook']} | {r['exit']} | | | | | | | {r['error']} |")
            continue
        name = r["workbook"] + (f" (+ {', '.join(r['vba'])})" if r["vba"] else "")
        listed = ", ".join(f"{k} {v}" for k, v in r["listed"].items())
        lines.append(
            f"| {name} | 0 | {r['translated']} of {r['functions']} | {r['cells']:,} "
            f"| {r['reproduced']:,} | {r['wrong']} | {r['not_computable']:,} "
            f"| {r['not_translated']:,} | {listed} |"
        )
        if not r["workbook"].startswith("refprop"):
            for k in ("cells", "reproduced", "wrong", "not_computable", "not_translated"):
                total[k] += r[k]
    share = total["reproduced"] / total["cells"] if total["cells"] else 0.0
    lines.append(
        f"| all but refprop.xls | | | {total['cells']:,} | {total['reproduced']:,} "
        f"({share:.1%}) | {total['wrong']} | {total['not_computable']:,} "
        f"| {total['not_translated']:,} | |"
    )
    return "\n".join(lines)


def main(argv: list[str]) -> int:
    args = [a for a in argv if not a.startswith("--")]
    folder = Path(args[0]) if args else ROOT.parent / "shared" / "excel-vba"
    books = sorted(p for p in folder.iterdir() if p.suffix.lower() in (".xlsm", ".xlsx", ".xls"))
    rows = []
    for book in books:
        rows.append(measure(book))
        print(f"{book.name}: {rows[-1]}", file=sys.stderr, flush=True)
    if "--json" in argv:
        print(json.dumps(rows, indent=1))
    else:
        print(table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
