"""The corpus table of docs/excel-import.md: each Excel workbook imported, then checked.

For every .xlsm/.xlsx/.xls of the folders (default ../shared/excel-vba and
../shared/corpus-more/excel-vba-a beside the repository), with the VBA of an add-in of the same
folder whose name starts like the workbook's (aero-toolkit-test.xlsm takes aero-toolkit.xlam),
runs ``workbook import`` and then ``workbook check --json`` as the user would (each in its own
process, with a time limit) and counts the formula cells whose cached value Excel stored (read
here with openpyxl, independently of the importer): reproduced, wrong (computed, outside the
tolerance), not computable (an error when computed, or not translated, with its reason).

    python scripts/excel_import_table.py [FOLDER ...] [--json] [--timeout SECONDS]
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SHARED = ROOT.parent / "shared"
FOLDERS = [SHARED / "excel-vba", SHARED / "corpus-more" / "excel-vba-a"]
SUFFIXES = (".xlsm", ".xlsx", ".xls")
sys.path.insert(0, str(ROOT))


def addins(book: Path) -> list[Path]:
    """Add-ins of the folder whose name starts as the workbook's does (before its last '-')."""
    stem = book.stem.rsplit("-", 1)[0].lower()
    return sorted(p for p in book.parent.glob("*.xla*") if p.stem.lower().startswith(stem))


def cached_formula_cells(book: Path) -> int:
    """Formula cells (each cell of a multi-cell array formula) whose cached value is a number,
    a text or TRUE/FALSE (not empty, not an error value), counted with openpyxl."""
    if book.suffix.lower() == ".xls":  # the file's FORMULA records (the importer's reader)
        from workbook.excelimport.xls import cached_values

        return sum(
            1
            for _, values in cached_values(book)
            for v in values.values()
            if v is not None and not (isinstance(v, str) and (not v.strip() or _is_error(v)))
        )
    import warnings

    import openpyxl

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        formulas = openpyxl.load_workbook(book, data_only=False, keep_links=False)
        values = openpyxl.load_workbook(book, data_only=True, keep_links=False)
    count = 0
    for ws in formulas.worksheets:
        wv = values[ws.title]
        cells = set()
        for row in ws.iter_rows():
            for c in row:
                text = c.value
                if isinstance(text, str) and text.startswith("="):
                    cells.add((c.row, c.column))
                elif hasattr(text, "ref") and hasattr(text, "text"):  # an array formula
                    for part_row in ws[str(text.ref)] if ":" in str(text.ref) else [[c]]:
                        cells.update((p.row, p.column) for p in part_row)
        for r, col in cells:
            v = wv.cell(r, col).value
            if v is None or (isinstance(v, str) and (not v.strip() or _is_error(v))):
                continue
            count += 1
    return count


def _is_error(text: str) -> bool:
    return text.startswith("#") and text.upper().rstrip("!?") in (
        "#DIV/0", "#N/A", "#NAME", "#NULL", "#NUM", "#REF", "#VALUE", "#GETTING_DATA",
    )  # fmt: skip


def _run(args: list[str], timeout: float) -> tuple[int, str, str, float]:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    start = time.monotonic()
    try:
        done = subprocess.run(
            [sys.executable, "-m", "workbook.cli", *args],
            capture_output=True,
            text=True,
            timeout=timeout,
            env=env,
            cwd=ROOT,
        )
    except subprocess.TimeoutExpired:
        return -1, "", f"timed out after {timeout:.0f} s", time.monotonic() - start
    return done.returncode, done.stdout, done.stderr, time.monotonic() - start


def measure(book: Path, timeout: float = 900.0, time_limit: float | None = None) -> dict:
    """Import and check one workbook in subprocesses; the counts of the check.

    ``time_limit`` is given to both commands as ``--time-limit`` (seconds of CPU): the
    default budget is a hang guard sized for the machine it was set on, and a count of the
    values reproduced should not depend on how fast the machine is.
    """
    row: dict = {"workbook": book.name, "folder": book.parent.name}
    row["vba"] = [p.name for p in addins(book)]
    limit = [] if time_limit is None else ["--time-limit", f"{time_limit:g}"]
    with tempfile.TemporaryDirectory() as tmp:
        args = ["import", str(book), "--out", tmp, "--force", *limit]
        for addin in addins(book):
            args += ["--vba", str(addin)]
        code, out, err, seconds = _run(args, timeout)
        row.update(import_exit=code, import_seconds=round(seconds, 1))
        row["cached"] = cached_formula_cells(book)
        if code != 0:
            row["error"] = (err.strip().splitlines() or [""])[-1][:300]
            return row
        toml = next(Path(tmp).glob("*.toml"))
        code, out, err, seconds = _run(["check", str(toml), "--json", *limit], timeout)
        row.update(check_exit=code, check_seconds=round(seconds, 1))
        try:
            counts = json.loads(out)
        except ValueError:
            row["error"] = (err.strip().splitlines() or [""])[-1][:300]
            return row
    row.update(
        printed=counts["printed"],
        reproduced=counts["reproduced"],
        wrong=counts["failed"],
        not_computable=counts["not_computable"],
    )
    return row


def table(rows: list[dict]) -> str:
    """The Markdown table of the measured rows, with a total line."""
    lines = [
        "| folder | workbook | import exit | check exit | formula cells with a cached value "
        "| counted by check | reproduced | wrong | not computable |",
        "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    if any("commit" in r for r in rows):  # rows measured on different commits say which
        lines = [lines[0] + " commit |", lines[1] + " --- |"]
    total = dict.fromkeys(("cached", "printed", "reproduced", "wrong", "not_computable"), 0)
    for r in rows:
        name = r["workbook"] + (f" (+ {', '.join(r['vba'])})" if r["vba"] else "")
        end = f" {r['commit']} |" if "commit" in r else ""
        total["cached"] += r.get("cached") or 0
        if "printed" not in r:
            lines.append(
                f"| {r['folder']} | {name} | {r['import_exit']} | {r.get('check_exit', '')} "
                f"| {r.get('cached') or 0:,} | | | | {r.get('error', '')[:90]} |{end}"
            )
            continue
        cached = f"{r['cached']:,}"
        lines.append(
            f"| {r['folder']} | {name} | {r['import_exit']} | {r['check_exit']} | {cached} "
            f"| {r['printed']:,} | {r['reproduced']:,} | {r['wrong']:,} "
            f"| {r['not_computable']:,} |{end}"
        )
        for key in ("printed", "reproduced", "wrong", "not_computable"):
            total[key] += r[key]
    share = total["reproduced"] / total["cached"] if total["cached"] else 0.0
    lines.append(
        f"| all | | | | {total['cached']:,} | {total['printed']:,} | {total['reproduced']:,} "
        f"({share:.1%} of the cached values) | {total['wrong']:,} | {total['not_computable']:,} |"
    )
    return "\n".join(lines)


def _books(folders: list[Path]) -> list[Path]:
    out = []
    for folder in folders:
        if not folder.is_dir():
            print(f"{folder}: not found, left out", file=sys.stderr)
            continue
        out += sorted(p for p in folder.iterdir() if p.suffix.lower() in SUFFIXES)
    return out


def _find(row: dict, folders: list[Path]) -> Path:
    return next(b for b in _books(folders) if b.name == row["workbook"])


def main(argv: list[str]) -> int:
    """Measure every workbook of the folders and print the table (or JSON)."""
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folders", nargs="*", type=Path)
    parser.add_argument("--json", action="store_true")
    parser.add_argument("--timeout", type=float, default=900.0)
    parser.add_argument("--table", type=Path, help="print the table of a --json output")
    opts = parser.parse_args(argv)
    folders, timeout = opts.folders or FOLDERS, opts.timeout
    if opts.table:  # the rows of an earlier --json run
        rows = json.loads(opts.table.read_text())
        for r in rows:
            if r.get("cached") is None:
                r["cached"] = cached_formula_cells(_find(r, folders))
    else:
        rows = []
        for book in _books(folders):
            rows.append(measure(book, timeout))
            print(json.dumps(rows[-1]), file=sys.stderr, flush=True)
    print(json.dumps(rows, indent=1) if opts.json else table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
