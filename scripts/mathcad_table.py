"""The table of docs/mathcad.md: each Mathcad worksheet imported, then checked.

For every .xmcd or .mcdx file under each folder (default: the Mathcad 15 and Prime folders of
../shared beside the repository, corpus-more's included; a file that is only referenced by
another one is skipped), runs ``workbook import`` and ``workbook check --json`` and prints a
Markdown table per folder: both exit codes, results Mathcad stored, reproduced, failed, not
computable, and the most common reasons for those not reproduced (from the untranslated list
of the worksheet), then one summary row per folder.

    python scripts/mathcad_table.py [FOLDER ...]
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
import tempfile
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def referenced(folder: Path) -> set[Path]:
    out = set()
    for path in folder.rglob("*.xmcd"):
        text = path.read_text(encoding="utf-8", errors="replace")
        for href in re.findall(r'<link href="([^"]+)"', text):
            out.add((path.parent / href).resolve())
    return out


def run(args: list[str]) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "workbook.cli", *args], capture_output=True, text=True
    )


def reasons(toml: Path, failures: list[dict]) -> Counter:
    """Why each result is not reproduced: the untranslated region's reason, else the error."""
    text = toml.read_text(encoding="utf-8")
    why = dict(re.findall(r"^#   region (\S+): (.*)$", text, re.M))
    # a definition left out, by its Mathcad name (its value may be shown in another region)
    by_name = dict(re.findall(r"^#   region \S+: (\S+) := \.\.\.: (.*)$", text, re.M))
    region_of: dict[str, str] = {}
    shown: dict[str, str] = {}  # region -> the Mathcad name it shows
    for csv in toml.parent.glob(f"{toml.stem}.mathcad*.csv"):
        region = None
        for line in csv.read_text(encoding="utf-8").splitlines():
            m = re.match(r"# region (\S+): (\S+)$", line) or re.match(r"# region (\S+):", line)
            if m:
                region = m.group(1)
                if m.lastindex == 2:
                    shown[region] = m.group(2)
            elif region and line and not line.startswith("#"):
                region_of.setdefault(line.split(",")[0], region)
    counts: Counter = Counter()
    for f in failures:
        region = region_of.get(f["name"])
        if region not in why and shown.get(region) in by_name:
            reason = by_name[shown[region]]
        elif region in why:
            reason = why[region].split(": ", 1)[-1]
        elif "error" in f:
            reason = "error: " + f["error"].split(": ", 2)[-1]
        else:
            reason = f"computed {f['ours']!r}, Mathcad {f['printed']!r}"
        counts[_short(reason)] += 1
    return counts


def evaluations(toml: Path, failures: list[dict]) -> tuple[int, int]:
    """(evaluations whose every stored value is reproduced, evaluations): one `=` of Mathcad
    is one evaluation, whether it shows a number or a column of 11."""
    bad = {(f["name"], f["at"]) for f in failures}
    regions: dict[str, bool] = {}
    for csv in toml.parent.glob(f"{toml.stem}.mathcad*.csv"):
        region = None
        for line in csv.read_text(encoding="utf-8").splitlines():
            m = re.match(r"# region (\S+):", line)
            if m:
                region = m.group(1)
                regions.setdefault(region, True)
            elif region and line and not line.startswith(("#", "name,")):
                cells = line.split(",")
                at = float(cells[1]) if cells[1] else None
                if (cells[0], at) in bad:
                    regions[region] = False
    return sum(regions.values()), len(regions)


def _short(reason: str) -> str:
    reason = re.sub(r"uses \S+, which is not translated: ", "uses an untranslated name: ", reason)
    reason = re.sub(r"piece '.*?': ", "", reason)
    reason = re.sub(r" (for|at) [^ ]+ = [^ :;]+", "", reason)  # one reason for every argument
    return reason[:150]


FOLDERS = (
    "mathcad",
    "mathcad-prime",
    "corpus-more/mathcad15-a",
    "corpus-more/mathcad15-b",
    "corpus-more/prime-a",
)


def table(folder: Path, tmp: str) -> tuple[list[str], Counter]:
    """The rows of one folder's table and its sums."""
    skip = referenced(folder)
    rows = []
    sums: Counter = Counter()
    for path in sorted([*folder.rglob("*.xmcd"), *folder.rglob("*.mcdx")]):
        if path.resolve() in skip:
            continue
        name = path.relative_to(folder).as_posix()
        sums.update(files=1)
        imp = run(["import", str(path), "--out", tmp, "--force"])
        if imp.returncode != 0:
            sums.update(errors=1)
            msg = imp.stderr.strip().splitlines()[-1:] or [""]
            rows.append(f"| {name} | {imp.returncode} | | import failed: {msg[0][:120]} |||||")
            continue
        toml = Path(tmp) / (path.stem + ".toml")
        chk = run(["check", str(toml), "--json"])
        if chk.returncode not in (0, 1):
            sums.update(errors=1)
            msg = chk.stderr.strip().splitlines()[-1:] or [""]
            rows.append(f"| {name} | 0 | {chk.returncode} | check failed: {msg[0][:120]} |||||")
            continue
        res = json.loads(chk.stdout)
        n, ok = res["printed"], res["reproduced"]
        pct = f"{100 * ok / n:.0f} %" if n else "-"
        why = "; ".join(f"{c} × {r}" for r, c in reasons(toml, res["failures"]).most_common(6))
        good, total = evaluations(toml, res["failures"])
        sums.update(
            good=good, total=total, n=n, ok=ok, failed=res["failed"], nc=res["not_computable"]
        )
        rows.append(
            f"| {name} | 0 | {chk.returncode} | {good} of {total} | {n} | {ok} | "
            f"{res['failed']} | {res['not_computable']} | {pct} | {why or '-'} |"
        )
    return rows, sums


def main() -> int:
    shared = ROOT.parent / "shared"
    folders = [Path(a) for a in sys.argv[1:]] or [shared / f for f in FOLDERS]
    header = (
        "| file | import exit | check exit | evaluations reproduced | values stored | "
        "reproduced | failed | not computable | share of values | why not (most common) |\n"
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |"
    )
    summary = []
    with tempfile.TemporaryDirectory() as tmp:
        for folder in folders:
            if not folder.is_dir():
                continue
            rows, sums = table(folder, tmp)
            pct = f"{100 * sums['ok'] / sums['n']:.1f} %" if sums["n"] else "-"
            print(f"\n### {folder.name}\n\n{header}")
            print("\n".join(rows))
            line = (
                f"{sums['good']} of {sums['total']} | {sums['n']} | {sums['ok']} | "
                f"{sums['failed']} | {sums['nc']} | {pct}"
            )
            print(f"| all | | | {line} | |")
            summary.append(f"| {folder.name} | {sums['files']} | {sums['errors']} | {line} |")
    print(
        "\n| folder | files | import or check errors | evaluations reproduced | values stored "
        "| reproduced | failed | not computable | share of values |\n"
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
    )
    print("\n".join(summary))
    return 0


if __name__ == "__main__":
    sys.exit(main())
