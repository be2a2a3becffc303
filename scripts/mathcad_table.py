"""The table of docs/mathcad.md: each Mathcad worksheet imported, then checked.

For every .xmcd or .mcdx file under the folder (default ../shared/mathcad beside the repository; a
file that is only referenced by another one is skipped), runs ``workbook import`` and
``workbook check --json`` and prints a Markdown table: results Mathcad stored, reproduced,
failed, not computable, and the reasons for those not reproduced (from the untranslated list
of the worksheet).

    python scripts/mathcad_table.py [FOLDER]
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
    region_of: dict[str, str] = {}
    for csv in toml.parent.glob(f"{toml.stem}.mathcad*.csv"):
        region = None
        for line in csv.read_text(encoding="utf-8").splitlines():
            m = re.match(r"# region (\S+):", line)
            if m:
                region = m.group(1)
            elif region and line and not line.startswith("#"):
                region_of.setdefault(line.split(",")[0], region)
    counts: Counter = Counter()
    for f in failures:
        region = region_of.get(f["name"])
        if region in why:
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
    return reason[:150]


def main() -> int:
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT.parent / "shared" / "mathcad"
    skip = referenced(folder)
    rows = []
    sums = Counter()
    with tempfile.TemporaryDirectory() as tmp:
        for path in sorted([*folder.rglob("*.xmcd"), *folder.rglob("*.mcdx")]):
            if path.resolve() in skip:
                continue
            name = path.relative_to(folder).as_posix()
            imp = run(["import", str(path), "--out", tmp, "--force"])
            if imp.returncode != 0:
                rows.append(f"| {name} | import failed: {imp.stderr.strip()[:120]} | | | | | |")
                continue
            toml = Path(tmp) / (path.stem + ".toml")
            chk = run(["check", str(toml), "--json"])
            res = json.loads(chk.stdout)
            n, ok = res["printed"], res["reproduced"]
            pct = f"{100 * ok / n:.0f} %" if n else "-"
            why = "; ".join(f"{c} × {r}" for r, c in reasons(toml, res["failures"]).most_common())
            good, total = evaluations(toml, res["failures"])
            sums.update(
                good=good, total=total, n=n, ok=ok, failed=res["failed"], nc=res["not_computable"]
            )
            rows.append(
                f"| {name} | {good} of {total} | {n} | {ok} | {res['failed']} | "
                f"{res['not_computable']} | {pct} | {why or '-'} |"
            )
    print(
        "| file | evaluations reproduced | values stored | reproduced | failed | not computable "
        "| share of values | why not |"
    )
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | --- |")
    print("\n".join(rows))
    pct = f"{100 * sums['ok'] / sums['n']:.0f} %" if sums["n"] else "-"
    print(
        f"| all | {sums['good']} of {sums['total']} | {sums['n']} | {sums['ok']} | "
        f"{sums['failed']} | {sums['nc']} | {pct} | |"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
