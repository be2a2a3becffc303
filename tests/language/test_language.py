"""Every example in docs/language.md is loaded and its `# expect:` lines are checked."""

import re

import pytest
from helpers.paths import ROOT

import workbook
from workbook.facade import Sheet
from workbook.language.template import load_spec

DOC = ROOT / "docs" / "language.md"
BLOCKS = re.findall(r"```toml\n(.*?)```", DOC.read_text(encoding="utf-8"), flags=re.S)
RUNNABLE = [b for b in BLOCKS if "# expect:" in b]
# data files the examples read (```csv NAME blocks), written beside each example
FILES = re.findall(r"```csv (\S+)\n(.*?)```", DOC.read_text(encoding="utf-8"), flags=re.S)


def test_the_reference_has_runnable_examples():
    assert len(RUNNABLE) >= 10


#: an example that says it is slow (it runs to a limit) runs with the slow tests
SLOW = "a slow test"


@pytest.mark.parametrize(
    "text",
    [pytest.param(t, marks=pytest.mark.slow) if SLOW in t else t for t in RUNNABLE],
    ids=[f"example{i}" for i in range(len(RUNNABLE))],
)
def test_example(tmp_path, text):
    path = tmp_path / "example.toml"
    path.write_text(text, encoding="utf-8")
    for name, content in FILES:
        (tmp_path / name).write_text(content, encoding="utf-8")
    expects = re.findall(r"# expect: (.*)", text)
    errors = [e[len("error: ") :] for e in expects if e.startswith("error: ")]
    sheet = None
    try:
        sheet = Sheet(load_spec(path))
    except workbook.WorkbookError as err:
        assert errors, f"unexpected error {err}"
        assert errors[0] in str(err)
        assert str(path) in str(err)
        return
    for line in expects:
        if line.startswith("error: "):
            call = line[len("error: ") :]
            name, _, args = call.partition("(")
            with pytest.raises(workbook.WorkbookError):
                sheet.evaluate(name, *[float(a) for a in args.rstrip(")").split(",") if a])
            continue
        if line.startswith("table "):
            _, name, _, _, n = line.split()
            assert len(sheet.table(name)) == int(n)
            continue
        if line.startswith("tables "):  # tables [with PART] = NAME, NAME
            lhs, _, rhs = line.partition(" = ")
            part = lhs.partition(" with ")[2] or None
            chosen = sheet.with_parts(part) if part else sheet
            assert [t.name for t in chosen.spec.tables] == rhs.split(", "), line
            continue
        if line.startswith("sweep "):  # sweep NAME at INPUT=VALUE = NUMBER UNIT
            from workbook.sweep import sweep

            lhs, _, rhs = line[len("sweep ") :].partition(" = ")
            out, _, setting = lhs.partition(" at ")
            name, _, value = setting.partition("=")
            result = sweep(sheet, {name: value + ".." + value + ":1"}, {out: None})
            number, _, unit = rhs.partition(" ")
            assert result.output_units[out] == unit, line
            digits = len(number.split(".")[1]) if "." in number else 0
            got = result.table.iloc[0][f"{out} [{unit}]" if unit else out]
            assert got == pytest.approx(float(number), abs=0.6 * 10**-digits), line
            continue
        if line.startswith("finding "):  # finding WHAT -> VERDICT
            what, _, verdict = line[len("finding ") :].rpartition(" -> ")
            found = {f.what: f.verdict for f in sheet.check().findings}
            assert found.get(what) == verdict, (line, found)
            continue
        if " shown in " in line:  # NAME shown in UNIT: the unit its value is shown in
            from workbook.language.units import pretty

            name, _, unit = line.partition(" shown in ")
            assert pretty(sheet.evaluate(name).units) == unit, line
            continue
        if line.startswith("chart "):
            _, name, _, _, n = line.split()
            assert len(next(c for c in sheet.spec.charts if c.name == name).series) == int(n)
            sheet.write_xlsx(tmp_path / "chart.xlsx")
            continue
        lhs, _, rhs = line.partition(" = ")
        name, _, args = lhs.partition("(")
        args = [float(a) for a in args.rstrip(")").split(",") if a]
        if rhs.startswith('"'):  # a text
            assert sheet.evaluate(name, *args) == rhs.strip('"'), line
            continue
        if rhs.startswith("["):  # a vector or matrix: [1, 2] (a column) or [[1, 2], [3, 4]]
            import ast

            import numpy as np

            cut = rhs.rindex("]") + 1
            want = np.array(ast.literal_eval(rhs[:cut]), dtype=float)
            want = want.reshape(-1, 1) if want.ndim == 1 else want
            unit = rhs[cut:].strip()
            q = sheet.evaluate(name, *args)
            got = q.to(unit).magnitude if unit else q.to("").magnitude
            assert got.shape == want.shape, line
            assert np.allclose(got, want, rtol=1e-9, atol=1e-9), line
            continue
        value, _, unit = rhs.partition(" ")
        q = sheet.evaluate(name, *args)
        got = q.to(unit).magnitude if unit else q.to("").magnitude
        digits = len(value.split(".")[1]) if "." in value else 0
        assert got == pytest.approx(float(value), abs=0.6 * 10**-digits), line
