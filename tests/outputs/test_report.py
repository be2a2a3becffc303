"""``workbook report``: the formulas as MathML, every number the engine's, the document
self-contained, written atomically (Chromium's part is in test_report_chromium.py)."""

from __future__ import annotations

import html
import math
import re

import numpy as np
import pytest
from helpers import report_parse as rp
from helpers.sheets import SINE_TABLE, write_template

import workbook
from workbook.cli import main
from workbook.compute.computed import compute
from workbook.language import expr as ex
from workbook.language import units as un
from workbook.outputs.report import render
from workbook.outputs.report.mathml import MathML, name_box

# -- the printer ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    "name, markup",
    [
        ("R3", "<msub><mi>R</mi><mrow><mn>3</mn></mrow></msub>"),
        ("phi", "<mi>\u03c6</mi>"),
        ("Theta", "<mi>\u0398</mi>"),
        ("deg", "<mi>deg</mi>"),
        ("h_max", "<msub><mi>h</mi><mrow><mi>max</mi></mrow></msub>"),
        (
            "phi1_max",
            "<msub><mi>\u03c6</mi><mrow><mn>1</mn><mo separator='true'>,</mo><mi>max</mi>"
            "</mrow></msub>",
        ),
        ("delta_sigma", "<msub><mi>\u03b4</mi><mrow><mi>\u03c3</mi></mrow></msub>"),
    ],
)
def test_names_are_written_by_hand(name, markup):
    assert name_box(name).xml == markup


def _shown(text: str) -> str:
    doc = rp.parse(f"<div><math>{MathML().box(ex.parse(text)).xml}</math></div>")
    return rp.formula_text(doc.xpath("//math")[0])


@pytest.mark.parametrize(
    "text",
    [
        "(R1 + R3)/(R3 - Rp)",
        "a - (b - c)",
        "a - (-b)",
        "(a + b)^2",
        "1 if F0(omega) > 0*G otherwise 0",
        "x^(3/2)",
        "-2*a*omega^2*cos((Theta - phi)*deg)",
        "1/k*sqrt(1 - k^2*sin(phi*deg)^2)",
        "(1 - k^2*sin(phi*deg)^2)^(3/2)",
        "abs(Sp(x) + delta_sigma*e)/tan(alpha_max) - S(x)",
        "2^3^2",
        "(2^3)^2",
        "-x^2",
        "(-x)^2",
        "a/(b/c)",
        "(a/b)/c",
        "a*(b*c)",
        "0 <= phi <= 22 and not x > 1",
        "log10(x) + ln(y) + exp(-z) + atan2(y, x)",
        "sum(R*sin(k*x)/k, k, 1, 3) + 2*sum(I^2 + 1, I, 1, n)",
        "floor(x/2) - ceil(-x) + abs(a - b)*sqrt(c)",
        "integral(x^2 + 1, x, 0, a) + maximum(sin(x), x, 0, 3)*argmin(x^2 - x, x, -1, 1)",
        "diff(x^3, x) - diff(x^3, x, 2) + product(I + 1, I, 1, n)",
    ],
)
def test_the_formula_shown_is_the_formula_written(text):
    """MathML read back as text parses to the same tree (same precedence, same names)."""
    back = _shown(text)
    assert ex.to_text(ex.parse(back)) == ex.to_text(ex.parse(text)), back


def test_every_builtin_is_written_as_its_registry_entry_says():
    from workbook.numerics.registry import REGISTRY

    for name, entry in REGISTRY.items():
        a = entry.arity
        n = a if isinstance(a, int) else (a[0] if isinstance(a, tuple) else 2)
        if entry.binds is not None and n <= max(entry.binds) and isinstance(a, tuple):
            n = a[1]  # the binding form: sum(EXPR, I, A, B) beside sum(v)
        args = ["x", "y", "z", "w"][:n]
        if entry.binds is not None:
            args[entry.binds[1]] = "I"
        text = f"{name}({', '.join(args)})"
        box = MathML().box(ex.parse(text))
        if entry.mathml:
            assert box.xml.startswith(f"<mrow data-call='{name}'>"), name
        assert ex.to_text(ex.parse(_shown(text))) == ex.to_text(ex.parse(text)), name


def test_fractions_roots_powers_and_braces():
    box = MathML().box(ex.parse("(R1 + R3)/(R3 - Rp)"))
    assert box.xml.startswith("<mfrac>")
    assert "<msqrt>" in MathML().box(ex.parse("sqrt(x)")).xml
    assert "<msup><mi>sin</mi>" in MathML().box(ex.parse("sin(x)^2")).xml  # sin²(x)
    sheet = workbook.load("concave-cam")
    h = sheet.spec.definitions["h"]
    brace = MathML().pieces(h.branches).xml
    assert "<mo stretchy='true'>{</mo><mtable>" in brace and brace.count("<mtr>") == 3


def _canon(node) -> str:
    """Worksheet text with x_0 and x0 alike (both are x with subscript 0)."""
    return re.sub(r"_([0-9])", r"\1", ex.to_text(node))


@pytest.mark.slow
def test_every_template_formula_reads_back(concave):
    """Every formula of every installed template, as displayed, parses back to itself."""
    for name in workbook.list_templates():
        sheet = concave if name == "concave-cam" else workbook.load(name)
        for d in sheet.spec.definitions.values():
            if d.body is None and d.branches is None:
                continue  # a program or a state of an ODE: not one formula
            bodies = [d.body] if d.body is not None else [b.value for b in d.branches]
            bodies += [b.condition for b in d.branches or () if b.condition is not None]
            for node in bodies:
                back = _shown(ex.to_text(node))
                assert _canon(ex.parse(back)) == _canon(node), (name, d.name, back)


# -- the numbers ---------------------------------------------------------------------------


def _same(shown: float, engine: float, digits: int = 6) -> bool:
    return shown == float(f"{engine:.{digits}g}")


@pytest.fixture(scope="module")
def concave_report(concave) -> str:
    return render(compute(concave))


def check_numbers(sheet, text: str | None = None) -> int:
    """Compare every number of the report of ``sheet`` with the engine; returns how many."""
    doc = rp.parse(text or render(compute(sheet)))
    count = 0
    # inputs
    for row in doc.xpath("//table[@class='inputs']/tbody/tr"):
        name = row.get("data-name")
        v = sheet.values[name]
        cell = row.xpath("td")[1].text_content()
        if isinstance(v, str):
            assert cell == f"\u201c{v}\u201d"
        else:
            assert rp.number(cell) == float(f"{v.magnitude:.12g}"), name
        count += 1
    # every value put into a formula: the input, or the definition's result, with its unit
    for el in doc.xpath("//mrow[@class='value'][@data-name]"):
        name = el.get("data-name")
        value, unit = rp.value_and_unit(el)
        if name in sheet.spec.inputs:
            q, spec = sheet.values[name], sheet.spec.inputs[name]
            want = float(q.magnitude)
            assert un.unit(unit) == (un.unit("") if spec.label else q.units), (name, unit)
        else:
            d = sheet.spec.definitions[name]
            q = sheet.evaluate(name)
            q = q.to(d.unit) if d.unit is not None else q
            want = float(q.magnitude)
            assert un.unit(unit) == un.unit(un.pretty(q.units)), (name, unit)
        assert _same(value, want), (name, value, want)
        count += 1
    # every scalar definition: its result and unit, or its error
    shown = {el.get("data-name"): el for el in doc.xpath("//mrow[@class='result']")}
    texts = {el.get("data-name"): el for el in doc.xpath("//mrow[@class='result-text']")}
    arrays = {el.get("data-name"): el for el in doc.xpath("//mrow[@class='result-matrix']")}
    for name, d in sheet.spec.definitions.items():
        if d.is_function:
            continue
        try:
            q = sheet.evaluate(name)
        except workbook.WorkbookError:
            div = doc.get_element_by_id(f"def-{name}")
            assert "not computed" in div.text_content(), name
            continue
        if isinstance(q, str):  # a text: shown in quotes
            assert texts[name].text_content() == f"\u201c{q}\u201d", name
            count += 1
            continue
        if np.ndim(q.magnitude):  # a vector or matrix: every element, by rows
            want = q.to(d.unit) if d.unit is not None else q
            cells = [rp.number(td.text_content()) for td in arrays[name].xpath(".//mtd")]
            assert len(cells) == want.magnitude.size, name
            for got, engine in zip(cells, np.asarray(want.magnitude, dtype=float).ravel()):
                assert _same(got, float(engine)), (name, got, engine)
            count += len(cells)
            continue
        value, unit = rp.value_and_unit(shown[name])
        want = q.to(d.unit) if d.unit is not None else q
        assert un.unit(unit) == un.unit(un.pretty(want.units)), (name, unit, want.units)
        assert _same(value, float(want.magnitude)), (name, value, want)
        count += 1
    # tables: each shown cell against the engine's column
    for t in sheet.spec.tables:
        div = doc.get_element_by_id(f"table-{t.name}")
        if t.computed:  # a block's table or a family over an input's values
            df = sheet.table(t.name)
            columns = [df[c].to_numpy() for c in df.columns]
            units = [None] * len(columns)
        else:
            data = sheet.table_data(t.name)
            columns = [c.values for c in data.columns]
            units = [un.pretty(c.unit) for c in data.columns]
        count += _check_table(div, columns, units, t.name)
    # checks: the computed column against the engine at the printed argument
    report = sheet.check()
    rows = doc.xpath("//table[contains(@class, 'checks')]/tbody/tr")
    assert len(rows) == len(report.rows)
    for tr, r in zip(rows, report.rows):
        cell = tr.xpath("td[contains(@class, 'computed')]")[0].text_content()
        if r.computed is None:
            assert cell == "not computed"
            continue
        kw = {r.argument: r.at} if r.at is not None and r.argument else {}
        engine = sheet.evaluate(r.name, **kw).to(un.unit(r.unit)).magnitude
        assert _same(rp.number(cell), float(engine)), (r.name, r.at, cell)
        count += 1
    return count


def _check_table(div, columns, units, name) -> int:
    count = 0
    assert div.xpath(".//table"), (name, div.text_content()[:300])
    for table in div.xpath(".//table"):
        turned = "turned" in (table.get("class") or "")
        if turned:
            for tr in table.xpath(".//tr[@data-col]"):
                j = int(tr.get("data-col"))
                cells = [td.text_content() for td in tr.xpath("td")]
                count += _compare_cells(cells, list(range(len(cells))), columns[j], name)
                count += _compare_unit(tr.xpath("th")[0], units[j], name)
            continue
        heads = table.xpath(".//th[@data-col]")
        cols = [int(th.get("data-col")) for th in heads]
        for th, j in zip(heads, cols):
            count += _compare_unit(th, units[j], name)
        n = len(columns[0])
        body = table.xpath("tbody/tr")
        indices = list(range(n))
        if any("skipped" in (tr.get("class") or "") for tr in body):
            k = len(body) // 2
            indices = list(range(k)) + list(range(n - k, n))
            body = [tr for tr in body if "skipped" not in (tr.get("class") or "")]
        assert len(body) == len(indices), name
        for pos, j in enumerate(cols):
            cells = [tr.xpath("td")[pos].text_content() for tr in body]
            count += _compare_cells(cells, indices, columns[j], name)
    return count


def _compare_unit(th, unit, name) -> int:
    if unit is None:
        return 0
    maths = th.xpath(".//span[@class='unit']//math")
    shown = rp.to_text(maths[0]).replace("^", "**") if maths else ""
    assert un.unit(shown) == un.unit(unit), (name, shown, unit)
    return 1


def _compare_cells(cells, indices, values, name) -> int:
    for text, k in zip(cells, indices):
        v = values[k]
        if isinstance(v, (float, np.floating)) and not math.isnan(v):
            assert _same(rp.number(text), float(v)), (name, k, text, v)
        elif isinstance(v, (int, np.integer)) and not isinstance(v, (bool, np.bool_)):
            assert rp.number(text) == v
    return len(cells)


@pytest.mark.slow
def test_every_number_is_the_engines(concave, concave_report):
    assert check_numbers(concave, concave_report) > 300


@pytest.mark.slow
@pytest.mark.parametrize("name", [n for n in workbook.list_templates() if n != "concave-cam"])
def test_every_number_is_the_engines_in_every_template(name):
    assert check_numbers(workbook.load(name)) > 10


def test_substituted_values_are_the_inputs(concave_report):
    doc = rp.parse(concave_report)
    eq = doc.get_element_by_id("def-k")
    maths = eq.xpath(".//math")
    assert rp.formula_text(maths[0]) == "k==((R1+R3)/(R3-Rp))"
    subst = rp.formula_text(maths[1]).replace(" ", "")
    assert subst == "==((20mm+50mm)/(50mm-10mm))"


# -- the document --------------------------------------------------------------------------


def test_the_document_is_self_contained(concave, concave_report):
    text = concave_report
    lower = text.lower()
    for banned in ("<script", "<link", "@import", "src=", "url(http", "<iframe", "<img"):
        assert banned not in lower, banned
    assert text.count("<svg") == len(concave.spec.charts)
    assert "workbook report concave-cam" in text  # the command that regenerates it
    assert "hand-checks" in text and "--part hand-checks" in text  # what was left out


def test_errors_are_shown_not_blank(tmp_path):
    path = write_template(
        tmp_path,
        """
[inputs]
x = { value = "-1", note = "a <b> note" }

[arguments]
t = { unit = "" }

[definitions]
r = "sqrt(x)"
"f(t)" = "sqrt(t)"

[[tables]]
name = "bad"
range = "t := -2 .. 2"
columns = { f = "" }
""",
    )
    text = render(compute(workbook.load(path)))
    assert "a &lt;b&gt; note" in text
    doc = rp.parse(text)
    assert "not computed" in doc.get_element_by_id("def-r").text_content()
    assert "not a finite number" in doc.get_element_by_id("table-bad").text_content()


def test_long_tables_show_their_ends(sheet_from):
    sheet = sheet_from(SINE_TABLE.replace("0, 10 .. 90", "0, 0.05 .. 90"))
    doc = rp.parse(render(compute(sheet)))
    rows = doc.get_element_by_id("table-t").xpath(".//tbody/tr")
    assert len(rows) == 21 and "1,781 rows not shown" in rows[10].text_content()
    assert rp.number(rows[-1].xpath("td")[0].text_content()) == 90
    full = rp.parse(render(compute(sheet), full_tables=True))
    assert len(full.get_element_by_id("table-t").xpath(".//tbody/tr")) == 1801


@pytest.mark.slow
def test_the_notebook_shows_the_same_rendering(concave, concave_report):
    page = concave_report
    shown = concave._repr_html_()
    body = page[page.index("<header>") : page.index("</main>")].strip()
    assert body in shown and "<script" not in shown


# -- command line and API ------------------------------------------------------------------


@pytest.mark.slow
def test_cli_writes_the_report(tmp_path, capsys):
    path = write_template(tmp_path, SINE_TABLE)
    out = tmp_path / "r.html"
    assert main(["report", str(path), "--out", str(out), "--set", "R=20 mm"]) == 0
    text = html.unescape(out.read_text(encoding="utf-8"))
    assert f'workbook report {path} --set R="20 mm"' in text
    assert main(["report", str(path), "--out", str(out)]) == 0  # its own file: overwritten
    other = tmp_path / "notes.html"
    other.write_text("<p>mine</p>")
    assert main(["report", str(path), "--out", str(other)]) == 2
    assert "use --force" in capsys.readouterr().err and other.read_text() == "<p>mine</p>"
    assert main(["report", str(path), "--out", str(other), "--force"]) == 0


@pytest.mark.slow
def test_pdf_without_chromium_is_a_clear_error(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("WORKBOOK_CHROMIUM", str(tmp_path / "no-such-chromium"))
    path = write_template(tmp_path, SINE_TABLE)
    out = tmp_path / "r.html"
    assert main(["report", str(path), "--out", str(out), "--pdf"]) == 2
    assert "apt-get install chromium" in capsys.readouterr().err
    assert not out.exists() and not out.with_suffix(".pdf").exists()


def test_a_failed_write_keeps_the_old_file(sheet_from, tmp_path, monkeypatch):
    sheet = sheet_from(SINE_TABLE)
    out = sheet.report(tmp_path / "r.html")
    before = out.read_text(encoding="utf-8")

    def boom(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr("workbook.outputs.report.render", boom)
    with pytest.raises(KeyboardInterrupt):
        sheet.with_inputs(R="30 mm").report(out)
    assert out.read_text(encoding="utf-8") == before
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


@pytest.mark.slow
def test_charts_leave_pyplot_alone_and_run_does_not_draw(tmp_path):
    """Reports draw with a bare matplotlib Figure (a notebook's backend is left alone);
    ``workbook run`` imports neither the report nor matplotlib."""
    import subprocess
    import sys

    code = (
        "import sys, workbook\n"
        "from workbook.cli import main\n"
        f"main(['run', 'concave-cam', '--out', {str(tmp_path / 'c.xlsx')!r}])\n"
        "print(sorted(m for m in ('matplotlib', 'workbook.outputs.report') if m in sys.modules))\n"
        "from workbook.compute.computed import compute\n"
        "from workbook.outputs.report import render\n"
        "assert render(compute(workbook.load('concave-cam'))).count('<svg') == 2\n"
        "print('matplotlib.pyplot' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.splitlines()[-2:] == ["[]", "False"], out.stdout


def test_functions_point_to_their_tables_and_charts(concave_report):
    doc = rp.parse(concave_report)
    note = doc.get_element_by_id("def-h").xpath(".//p[@class='note']")[0].text_content()
    assert "in mm" in note and "values in table curves, chart fig4" in note
    brace = doc.get_element_by_id("def-h").xpath(".//mtable")[0]
    assert len(brace.xpath("mtr")) == 3
