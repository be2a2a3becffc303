"""Property-based test: generated expressions never let anything but the engine's errors escape.

Each generated expression is parsed, typed (units) and, if it is accepted, evaluated on an
array of arguments, exactly as a worksheet definition would be. Any outcome is allowed except
an exception that is not a :class:`workbook.WorkbookError` (a crash, a traceback for a user).

The budget is fixed (``FUZZ_EXAMPLES``, 12,000 by default, >= 10^4 as the issue asks) and the
run is deterministic (``derandomize``), so CI sees the same expressions every time.
"""

from __future__ import annotations

import os
import warnings

import numpy as np
import pytest
from helpers.sheets import fuzz_settings
from hypothesis import given
from hypothesis import strategies as st

from workbook import WorkbookError
from workbook.engine.sheet import Sheet
from workbook.language import expr as ex
from workbook.language.template import load_spec
from workbook.numerics.registry import REGISTRY

EXAMPLES = int(os.environ.get("FUZZ_EXAMPLES", "12000"))
PER_TEST = EXAMPLES // 2

TEMPLATE = """
[inputs]
R1 = "20 mm"
omega = "104.6 1/s"
law = { value = "stepped", options = ["stepped", "harmonic"] }
n = "3"
Tc = "20 degC"

[arguments]
phi = { unit = "deg" }
t = { unit = "s" }
x = { unit = "" }
Ta = { unit = "degC" }

[definitions]
"h(phi)" = "R1*sin(phi)"
"g(x)" = ["x if x < 1", "2 - x otherwise"]
k = "omega*R1"
"""

NAMES = ["R1", "omega", "law", "n", "phi", "t", "x", "k", "pi", "h", "g", "sin", "nope", "__x"]
NAMES += ["Tc", "Ta"]  # an absolute temperature, as an input and as a bound variable
FUNCS = sorted(REGISTRY) + ["h", "g", "k", "R1", "log", "nope", "eval", "open"]
ATOMS = ["0", "1", "2.5", "1e308", "1e-320", "-3", "0.0", "1e999", "10", '"stepped"', '"x"']
ATOMS += ["20 degC", "5 delta_degC", "300 K", "2 mm"]
OPS = ["+", "-", "*", "/", "^", "**", "<", "<=", ">", ">=", "==", "!=", " and ", " or ", "%", "//"]
JUNK = ["(", ")", ",", ".", "[", "]", ":", "lambda", " if ", " else ", "'", "__", "@", "\\", "\n"]


@pytest.fixture(scope="module")
def sheet(load_text):
    return load_text(TEMPLATE, name="fuzz")


def expressions():
    """Well-formed trees of the language, with wrong units, arities and names mixed in."""
    leaf = st.sampled_from(NAMES + ATOMS)

    def extend(inner):
        return st.one_of(
            st.tuples(inner, st.sampled_from(OPS), inner).map(lambda t: f"({t[0]}{t[1]}{t[2]})"),
            st.tuples(st.sampled_from(["-", "+", "not "]), inner).map(lambda t: t[0] + t[1]),
            st.tuples(st.sampled_from(FUNCS), st.lists(inner, max_size=3)).map(
                lambda t: f"{t[0]}({', '.join(t[1])})"
            ),
            st.tuples(
                inner, st.sampled_from(["<", "<="]), inner, st.sampled_from(["<", "<="]), inner
            ).map(lambda t: f"{t[0]} {t[1]} {t[2]} {t[3]} {t[4]}"),
        )

    return st.recursive(leaf, extend, max_leaves=12)


def garbage():
    """Token soup: broken syntax, Python constructs the language refuses, odd characters."""
    token = st.sampled_from(NAMES + ATOMS + OPS + JUNK + FUNCS)
    return st.one_of(
        st.lists(token, max_size=12).map("".join),
        st.text(max_size=30),
    )


def check(sheet: Sheet, text: str) -> None:
    scope = {
        "phi": sheet.spec.arguments["phi"].binding_unit,
        "x": sheet.typer.dimensionless,
        "Ta": sheet.spec.arguments["Ta"].binding_unit,
    }
    values = {
        "phi": np.array([0.0, 30.0, 90.0, 180.0]),
        "x": np.array([-1.0, 0.0, 0.5, 2.0]),
        "Ta": np.array([-40.0, 0.0, 20.0, 100.0]),
    }
    try:
        node = ex.parse(text, what="fuzz")
        typed = sheet.typer.expression(node, scope, "fuzz")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            sheet.evaluator.compile(typed)(values)
        ex.to_text(node)
    except WorkbookError as err:
        assert str(err)  # a message exists
    except Exception as exc:  # noqa: BLE001 - the property: anything but a WorkbookError fails
        pytest.fail(f"{type(exc).__name__} escaped for {text!r}: {exc}")


FUZZ = fuzz_settings(PER_TEST)


@pytest.mark.slow
@FUZZ
@given(text=expressions())
def test_generated_expressions(sheet, text):
    check(sheet, text)


@pytest.mark.slow
@FUZZ
@given(text=garbage())
def test_generated_garbage(sheet, text):
    check(sheet, text)


def test_budget_is_at_least_ten_thousand():
    assert PER_TEST * 2 >= 10_000


# -- quantity and unit text; template value types --------------------------------------------
# Every text a user types as a value or unit goes through one reader (workbook.language.quantity);
# every table of a template through checked fields. Generated texts and TOML values must give a
# quantity or a WorkbookError, quickly: never another exception, never a long computation.

QUANTITY_TOKENS = [
    "0",
    "45",
    "45.5",
    "-3",
    "+2",
    ".5",
    "1e3",
    "1e999",
    "nan",
    "inf",
    "9",
    "2000",
    ",",
    ";",
    " ",
    "  ",
    "mm",
    "MPa",
    "m",
    "s",
    "kg",
    "N",
    "deg",
    "rad",
    "1/s",
    "°",
    "%",
    "percent",
    "µm",
    "Ω",
    "furlongz",
    "*",
    "/",
    "^",
    "**",
    "(",
    ")",
    "[",
    "]",
    "{",
    "}",
    "-",
    "+",
    "e",
    "9**9**9",
    "2**2000",
    "__import__",
    "'",
    '"',
    "\\",
    "\n",
    "\t",
    "x" * 50,
]
SLOW_EXAMPLES = int(os.environ.get("FUZZ_SLOW_EXAMPLES", "10000"))
FAST_EXAMPLES = int(os.environ.get("FUZZ_FAST_EXAMPLES", "50"))
CASE_SECONDS = 10.0


def quantity_texts():
    token = st.sampled_from(QUANTITY_TOKENS)
    return st.one_of(
        st.lists(token, max_size=10).map("".join),
        st.tuples(st.floats(allow_nan=True), st.lists(token, max_size=5).map("".join)).map(
            lambda t: f"{t[0]!r} {t[1]}"
        ),
        st.text(max_size=40),
        st.integers(min_value=0, max_value=400).map(lambda n: "1" + "0" * n + " mm"),
    )


def check_quantity(text: str) -> None:
    import time

    from workbook.language import units as un

    start = time.monotonic()
    for read in (lambda: un.quantity(text, what="q"), lambda: un.unit(text, what="u")):
        try:
            q = read()
            assert q is not None
        except WorkbookError as err:
            assert str(err)
        except Exception as exc:  # noqa: BLE001 - the property: anything but a WorkbookError fails
            pytest.fail(f"{type(exc).__name__} escaped for {text!r}: {exc}")
    assert time.monotonic() - start < CASE_SECONDS, text


def toml_values():
    """TOML values of every type: texts (quantities and junk), numbers, booleans, dates,
    arrays and tables."""
    scalar = st.one_of(
        quantity_texts(),
        st.sampled_from(['"20 mm"', '"a"', '"R*2"', '"phi := 0 .. 10"', '"="', '"=1+1"']).map(
            lambda s: s[1:-1]
        ),
        st.integers(min_value=-(2**63), max_value=2**63 - 1),
        st.floats(allow_nan=True, allow_infinity=True),
        st.booleans(),
        st.dates(),
    )
    return st.recursive(
        scalar,
        lambda inner: st.one_of(
            st.lists(inner, max_size=3),
            st.dictionaries(st.sampled_from(KEYS), inner, max_size=3),
        ),
        max_leaves=6,
    )


KEYS = [
    "value",
    "unit",
    "note",
    "options",
    "min",
    "max",
    "positive",
    "label",
    "plain",
    "expr",
    "pieces",
    "name",
    "title",
    "range",
    "columns",
    "sheet",
    "block",
    "part",
    "x",
    "y",
    "series",
    "file",
    "tolerance",
    "rel_tolerance",
    "role",
    "misprints",
    "at",
    "postive",
    "unti",
    "colums",
    "about",
    "outputs",
    "units",
    "line",
    "axis",
    "marker",
    "log_x",
    "equal_axes",
]


def toml_literal(value) -> str:
    import datetime
    import json
    import math

    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return (
            "nan"
            if math.isnan(value)
            else ("inf" if value > 0 else "-inf")
            if math.isinf(value)
            else repr(value)
        )
    if isinstance(value, datetime.date):
        return value.isoformat()
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, list):
        return "[" + ", ".join(toml_literal(v) for v in value) + "]"
    return "{ " + ", ".join(f"{k} = {toml_literal(v)}" for k, v in value.items()) + " }"


SLOTS = [  # where a generated value goes in an otherwise good template
    ("inputs", "R1"),
    ("inputs", "law"),
    ("arguments", "phi"),
    ("definitions", "k"),
    ("definitions", '"h(phi)"'),
    ("sheet", "title"),
    ("sheet", "about"),
    ("sweep", "outputs"),
    ("parts", "extra"),
]
ARRAY_SLOTS = ["tables", "charts", "printed"]


def templates():
    slot = st.tuples(st.sampled_from(SLOTS), toml_values())
    item = st.tuples(
        st.sampled_from(ARRAY_SLOTS),
        st.dictionaries(st.sampled_from(KEYS), toml_values(), max_size=5),
    )
    return st.tuples(st.lists(slot, max_size=3), st.lists(item, max_size=2))


BASE = {
    "inputs": {"R1": '"20 mm"', "law": '{ value = "a", options = ["a", "b"] }'},
    "arguments": {"phi": '{ unit = "deg" }'},
    "definitions": {"k": '"2*R1"', '"h(phi)"': '"R1*sin(phi)"'},
}


def template_text(slots, items) -> str:
    sections = {name: dict(body) for name, body in BASE.items()}
    for (section, key), value in slots:
        sections.setdefault(section, {})[key] = toml_literal(value)
    lines = []
    for name, body in sections.items():
        lines.append(f"[{name}]")
        lines += [f"{k} = {v}" for k, v in body.items()]
    for section, table in items:
        lines.append(f"[[{section}]]")
        lines += [f"{k} = {toml_literal(v)}" for k, v in table.items()]
    return "\n".join(lines) + "\n"


def check_template(folder, slots, items) -> None:
    import time

    from workbook.language.template import load_spec as load

    text = template_text(slots, items)
    path = folder / "fuzz.toml"
    path.write_text(text, encoding="utf-8")
    start = time.monotonic()
    try:
        sheet = Sheet(load(path))
        sheet.evaluate("k")
        for t in sheet.spec.tables:
            sheet.table(t.name) if not t.block else None
    except WorkbookError as err:
        assert str(err)
    except Exception as exc:  # noqa: BLE001 - the property: anything but a WorkbookError fails
        pytest.fail(f"{type(exc).__name__} escaped for\n{text}\n{exc}")
    assert time.monotonic() - start < CASE_SECONDS, text


@pytest.mark.slow
@fuzz_settings(FAST_EXAMPLES)
@given(text=quantity_texts())
def test_quantity_text(text):
    check_quantity(text)


@pytest.mark.slow
@fuzz_settings(FAST_EXAMPLES)
@given(case=templates())
def test_template_values(fuzz_folder, case):
    check_template(fuzz_folder, *case)


@pytest.mark.slow
@fuzz_settings(SLOW_EXAMPLES)
@given(text=quantity_texts())
def test_quantity_text_many(text):
    check_quantity(text)


@pytest.mark.slow
@fuzz_settings(SLOW_EXAMPLES)
@given(case=templates())
def test_template_values_many(fuzz_folder, case):
    check_template(fuzz_folder, *case)


@pytest.fixture(scope="module")
def fuzz_folder(tmp_path_factory):
    return tmp_path_factory.mktemp("fuzz-templates")


def test_slow_budget_is_at_least_ten_thousand_each():
    assert SLOW_EXAMPLES >= 10_000


# -- hostile payloads: labels that look like references, CSV cells, names, arrays ---------------

LABEL_PIECES = [
    "=",
    "+",
    "-",
    "@",
    "!",
    "'",
    "A1",
    "$B$2",
    "Sheet1!A1",
    "Inputs!B2",
    "'\\\\evil.example\\s\\[x.xlsx]S'!A1",
    "[x.xlsx]",
    "http://x.example/a",
    "cmd|' /C calc'!A0",
    '=DDE("cmd";"/C calc";"x")',
    "HYPERLINK(",
    ")",
    "\t",
    "\r",
    "\n",
    "\x7f",
    "\x01",
    " ",
    "\u00a0",
    "\uff1d",
    "phi",
    "mm",
    "\u03c6",
]


def labels():
    """Texts made of reference, formula and control-character pieces, and random text."""
    pieces = st.lists(st.sampled_from(LABEL_PIECES), min_size=1, max_size=6).map("".join)
    return st.one_of(pieces, st.text(min_size=1, max_size=30))


@pytest.mark.slow
@fuzz_settings(FAST_EXAMPLES // 2)  # a workbook each: about 0.1 s
@given(texts=st.lists(labels(), min_size=4, max_size=4))
def test_chart_labels_are_never_references(tmp_path_factory, texts):
    """A title, axis title or series name is shown as written: the chart refers to nothing but
    its data and the text cells that hold labels xlsxwriter would read as a reference."""
    import re
    import zipfile

    import openpyxl
    import xlsxwriter

    from workbook.compute import style
    from workbook.compute.excelsheets import chart_label

    texts = [t.replace("\x00", "") or "x" for t in texts]  # no cell or XML holds NUL
    path = tmp_path_factory.mktemp("labels") / "c.xlsx"
    wb = xlsxwriter.Workbook(str(path), {"strings_to_formulas": False, "strings_to_urls": False})
    data, charts = wb.add_worksheet("Data"), wb.add_worksheet("Charts")
    for i in range(3):
        data.write_number(i, 0, i)
        data.write_number(i, 1, i * i)
    row, shown = 0, []
    for text in texts:
        label, row = chart_label(charts, "Charts", text, row)
        shown.append(label)
    c = style.scatter_chart(wb)
    c.add_series(
        {"name": shown[0], "categories": ["Data", 0, 0, 2, 0], "values": ["Data", 0, 1, 2, 1]}
    )
    c.set_title({"name": shown[1]})
    c.set_x_axis(style.axis(shown[2]))
    c.set_y_axis(style.axis(shown[3]))
    style.place_chart(charts, 0, c)
    wb.close()
    with zipfile.ZipFile(path) as z:
        assert not [n for n in z.namelist() if "externalLink" in n]
        xml = z.read("xl/charts/chart1.xml").decode()
    refs = re.findall(r"<c:f>([^<]*)</c:f>", xml)
    assert all(r.startswith(("Charts!$P$", "Data!$A$", "Data!$B$")) for r in refs), refs
    cells = openpyxl.load_workbook(path)["Charts"]
    for text, label in zip(texts, shown):
        if isinstance(label, list):  # a text cell the chart refers to: exactly the label
            cell = cells.cell(row=label[1] + 1, column=label[2] + 1)
            shown_text = re.sub(  # the OOXML escape of a control character, as Excel reads it
                r"_x([0-9A-Fa-f]{4})_", lambda m: chr(int(m.group(1), 16)), cell.value
            )
            assert cell.data_type == "s" and shown_text == text
        else:  # given as it is: xlsxwriter takes it as literal text
            assert not text.startswith("=") and "!" not in text


@pytest.mark.slow
@fuzz_settings(FAST_EXAMPLES)
@given(cells=st.lists(labels(), min_size=1, max_size=8), dtype=st.sampled_from([object, "str"]))
def test_csv_cells_never_run_and_never_forge_rows(tmp_path_factory, cells, dtype):
    """Every text cell reads back as written or behind one apostrophe (never starting with a
    formula character a spreadsheet runs), one row per row written."""
    import csv

    import pandas as pd

    from workbook.outputs.atomic import write_csv

    cells = [c.replace("\x00", "") for c in cells]
    path = tmp_path_factory.mktemp("csv") / "t.csv"
    write_csv(pd.DataFrame({"text": pd.Series(cells, dtype=dtype), "n": range(len(cells))}), path)
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    assert len(rows) == len(cells) + 1
    for k, (written, (back, n)) in enumerate(zip(cells, rows[1:])):
        assert back in (written, "'" + written) and n == str(k)
        first = back.lstrip(" \t\r\n\u00a0\u3000")[:1]
        assert back[:1] in ("'", "") or (
            first not in set("=+-@\uff1d\uff0b\uff0d\uff20") and back[:1] not in set("\t\r\n")
        ), repr(back)


NAME_CHARS = st.sampled_from(
    list("abcXYZ_019") + ["\t", "\n", "\r", "\x7f", "\x01", "\u200b", "\u03c6", " ", ".", "-"]
)


@fuzz_settings(FAST_EXAMPLES)
@given(name=st.lists(NAME_CHARS, min_size=1, max_size=8).map("".join))
def test_names_with_control_characters(fuzz_folder, name):
    """A name with control characters, spaces or invisible characters in [inputs] or
    [definitions] is refused with the engine's error, or is a valid name that computes."""
    import json

    key = json.dumps(name)  # a TOML basic string (DEL written as an escape)
    key = key.replace("\x7f", "\\u007f")
    for text in (
        f'[inputs]\n{key} = "2 mm"\n[definitions]\nd = "1"\n',
        f'[inputs]\nR = "2 mm"\n[definitions]\n{key} = "2*R"\n',
    ):
        path = fuzz_folder / "names.toml"
        path.write_text(text, encoding="utf-8")
        try:
            sheet = Sheet(load_spec(path))
            sheet.evaluate(name)
        except WorkbookError:
            continue
        assert ex.is_identifier(name), repr(name)
