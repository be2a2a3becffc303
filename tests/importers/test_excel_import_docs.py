"""The VBA examples of docs/excel-import.md: each program is the one the import writes, and
each expectation holds when the engine computes it."""

from __future__ import annotations

import re

import pytest
import tomli_w
from helpers.paths import ROOT

import workbook
from workbook.excelimport.book import translate_vba

DOC = ROOT / "docs" / "excel-import.md"
_EXAMPLE = re.compile(
    r"```vba\n(?P<vba>.*?)\n```\n\nbecomes `\"(?P<sig>[^\"]+)\" = \{ program = \.\.\. \}` with the "
    r"program\n\n```text\n(?P<program>.*?)\n```\n\n(?P<expects>(?:<!-- expect: .*? -->\n)+)",
    re.S,
)


def examples():
    found = list(_EXAMPLE.finditer(DOC.read_text(encoding="utf-8")))
    assert len(found) >= 10
    return [pytest.param(m, id=m.group("sig").split("(")[0]) for m in found]


@pytest.mark.parametrize("example", examples())
def test_doc_example(example, sheet_from):
    (info,) = translate_vba(example.group("vba")).values()
    assert info.problem is None
    assert f"{info.final}({', '.join(info.params)})" == example.group("sig")
    assert info.program == example.group("program")
    expects = re.findall(r"<!-- expect: (.*?) -->", example.group("expects"))
    definitions = {example.group("sig"): {"program": info.program + "\n"}}
    checks = []
    for k, line in enumerate(expects):
        if line.startswith("error: "):
            definitions[f"probe_{k}"] = {"expr": line[len("error: ") :]}
            checks.append((f"probe_{k}", None))
        else:
            call, value = line.rsplit(" = ", 1)
            definitions[f"probe_{k}"] = {"expr": call}
            checks.append((f"probe_{k}", float(value)))
    doc = {
        "arguments": {p: {"unit": ""} for p in info.params},
        "definitions": definitions,
    }
    sheet = sheet_from(tomli_w.dumps(doc, multiline_strings=True), name="example")
    for name, value in checks:
        if value is None:
            with pytest.raises(workbook.WorkbookError):
                sheet.evaluate(name)
        else:
            got = float(sheet.evaluate(name).magnitude)
            assert got == pytest.approx(value, rel=1e-10, abs=1e-12), (name, got)
