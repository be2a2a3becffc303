"""A hostile or broken .xmcd file is a clear error (exit 2), in bounded time and memory."""

from __future__ import annotations

import io
import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
import tomllib
from helpers.mathcad_xml import define, evaluate, ident, import_sheet, real, worksheet
from helpers.paths import ROOT

from workbook.cli import main

HEAD = (
    '<?xml version="1.0" encoding="UTF-8"?>\n'
    '<worksheet xmlns="http://schemas.mathsoft.com/worksheet30" '
    'xmlns:ml="http://schemas.mathsoft.com/math30"><regions>'
)

LAUGHS = (
    '<?xml version="1.0"?>\n<!DOCTYPE lolz [<!ENTITY lol "lol">'
    + "".join(f'<!ENTITY lol{i} "{("&lol" + str(i - 1) + ";") * 10}">' for i in range(1, 10))
    + ']>\n<worksheet xmlns="http://schemas.mathsoft.com/worksheet30">&lol9;</worksheet>'
).replace("&lol0;", "&lol;")

EXTERNAL = (
    '<?xml version="1.0"?>\n<!DOCTYPE w [<!ENTITY x SYSTEM "file:///etc/passwd">]>\n'
    '<worksheet xmlns="http://schemas.mathsoft.com/worksheet30"><regions>&x;</regions>'
    "</worksheet>"
)


def _zip_bomb() -> bytes:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("worksheet.xml", b"0" * 20_000_000)  # 20 MB of zeros, ~20 kB packed
    return buf.getvalue()


CASES = {
    "billion-laughs": (LAUGHS.encode(), "DTD or entities"),
    "external-entity": (EXTERNAL.encode(), "DTD or entities"),
    "truncated": ((HEAD + '<region region-id="1"><math><ml:define>').encode(), "not well-formed"),
    "zip-bomb": (_zip_bomb(), "zip archive"),
    "not-mathcad": (b'<?xml version="1.0"?><html><body>hi</body></html>', "not a Mathcad"),
    "binary": (bytes(range(256)) * 10, "not a Mathcad"),
    "empty": (b"", "not a Mathcad"),
}


@pytest.mark.slow
@pytest.mark.parametrize("case", sorted(CASES))
def test_hostile_file_is_refused(case, tmp_path, capsys):
    data, message = CASES[case]
    src = tmp_path / f"{case}.xmcd"
    src.write_bytes(data)
    status = main(["import", str(src), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert status == 2, err
    assert message in err and src.name in err
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


@pytest.mark.slow
def test_reference_outside_the_folder_is_refused(tmp_path, capsys):
    inner = tmp_path / "inner"
    inner.mkdir()
    (tmp_path / "lib.xmcd").write_text(HEAD + "</regions></worksheet>", encoding="utf-8")
    src = inner / "main.xmcd"
    src.write_text(
        HEAD + '<region region-id="1" top="0" left="0"><reference/>'
        '<link href="../lib.xmcd"/></region></regions></worksheet>',
        encoding="utf-8",
    )
    assert main(["import", str(src), "--out", str(tmp_path / "out")]) == 2
    assert "outside the worksheet's folder" in capsys.readouterr().err


MATH = 'xmlns:ml="http://schemas.mathsoft.com/math30"'


# The forged worksheet's regions have ids that are text (a newline in an id), which
# helpers.mathcad_xml's builders (whole-number ids) do not write: built here.
def _math(rid: str, tag: str, body: str) -> str:
    return (
        f'<region region-id="{rid}" left="0" top="{len(rid) * 7}" align-y="0"><math>'
        f"<ml:{tag} {MATH}>{body}</ml:{tag}></math></region>"
    )


def _worksheet(*regions: str) -> str:
    return HEAD + "".join(regions) + "</regions></worksheet>"


FORGED = "&#10;[blocks]&#10;x = 1&#10;"


@pytest.mark.slow
def test_names_and_region_ids_cannot_forge_the_generated_files(tmp_path, capsys):
    """A newline in a region id or in a Mathcad name, DEL and a line separator in a name and
    in a text region: each stays inside its comment, string or CSV cell; no [blocks] section,
    no forged CSV row, and the worksheet loads and checks."""
    result = "<ml:result><ml:real>2</ml:real></ml:result>"
    src = tmp_path / "forge.xmcd"
    src.write_text(
        _worksheet(
            '<region region-id="7" left="0" top="1" align-y="1"><text><p>note&#127; here'
            "&#8232;[blocks]</p></text></region>",
            _math("1", "define", "<ml:id>a&#127;b</ml:id><ml:real>2</ml:real>"),
            _math("2" + FORGED, "eval", f"<ml:id>a&#127;b</ml:id>{result}"),
            _math("3", "eval", f"<ml:id>q{FORGED}</ml:id>{result}"),
            _math("4" + FORGED, "eval", f"<ml:id>r</ml:id>{result}"),
        ),
        encoding="utf-8",
    )
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0, capsys.readouterr().err
    text = (tmp_path / "forge.toml").read_text(encoding="utf-8")
    data = tomllib.loads(text)
    assert "blocks" not in data and not any(line.startswith("[blocks") for line in text.split("\n"))
    assert "\x7f" not in text and "\u2028" not in text
    for path in tmp_path.glob("forge*.csv"):
        rows = [ln for ln in path.read_text(encoding="utf-8").split("\n") if ln.strip()]
        assert all(ln.startswith(("#", "name,", "a_b", "result_", "q", "r")) for ln in rows), rows
        assert not any(ln.startswith(("[", "x = ")) for ln in rows)
    capsys.readouterr()
    main(["check", str(tmp_path / "forge.toml"), "--json"])
    checked = json.loads(capsys.readouterr().out)
    assert checked["printed"] == 3 and checked["reproduced"] == 1, checked


@pytest.mark.slow
@pytest.mark.parametrize(
    "name, body, reason",
    [
        (
            "M",
            '<ml:matrix rows="nan" cols="1"><ml:real>1</ml:real></ml:matrix>',
            "not a whole number",
        ),
        (
            "M",
            '<ml:matrix rows="-1" cols="-1"><ml:real>1</ml:real></ml:matrix>',
            "a matrix of -1 x -1 elements",
        ),
        (
            "i",
            "<ml:range><ml:real>0</ml:real><ml:real>1e999</ml:real></ml:range>",
            "not finite",
        ),
        (
            "i",
            "<ml:range><ml:real>0</ml:real><ml:apply><ml:pow/><ml:real>10"
            "</ml:real><ml:real>400</ml:real></ml:apply></ml:range>",
            "not values known at import",
        ),
        (
            "i",
            "<ml:range><ml:sequence><ml:real>0</ml:real><ml:real>1e-308"
            "</ml:real></ml:sequence><ml:real>10</ml:real></ml:range>",
            "more than 100,000 values",
        ),
    ],
)
def test_a_broken_size_or_range_is_listed(name, body, reason, tmp_path, capsys):
    assert reason in import_sheet(tmp_path, capsys, "broken", define(1, ident(name), body))


@pytest.mark.slow
def test_a_stored_result_that_is_not_a_number_is_listed(tmp_path, capsys):
    results = ["nan", "abc", "1e999"]
    text = import_sheet(
        tmp_path,
        capsys,
        "stored",
        define(1, ident("a"), real(2)),
        *(evaluate(k + 2, ident("a"), real(r)) for k, r in enumerate(results)),
    )
    assert "a stored number 'abc'" in text and "not finite (nan)" in text
    assert "not finite (1e999)" in text


@pytest.mark.slow
def test_out_naming_a_file_is_refused(tmp_path, capsys):
    src = tmp_path / "one.xmcd"
    src.write_text(worksheet(define(1, ident("a"), real(2))))
    existing = tmp_path / "existing.txt"
    existing.write_text("keep")
    assert main(["import", str(src), "--out", str(existing)]) == 2
    assert "is a file, not a folder" in capsys.readouterr().err
    assert existing.read_text() == "keep"


def _import_in_child(path: Path, out: Path) -> subprocess.CompletedProcess:
    code = "import sys; from workbook.cli import main; sys.exit(main(sys.argv[1:]))"
    return subprocess.run(
        [sys.executable, "-c", code, "import", str(path), "--out", str(out)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,  # a read that blocks fails the test instead of hanging it
    )


@pytest.mark.slow
@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no named pipes here")
def test_a_fifo_is_refused_unopened(tmp_path):
    fifo = tmp_path / "pipe.xmcd"
    os.mkfifo(fifo)
    done = _import_in_child(fifo, tmp_path / "out")
    assert done.returncode == 2, done.stderr
    assert "not a regular file (a named pipe)" in done.stderr


@pytest.mark.slow
@pytest.mark.skipif(not Path("/dev/zero").exists(), reason="no /dev/zero here")
def test_a_device_behind_a_link_is_refused_unread(tmp_path):
    link = tmp_path / "zero.xmcd"
    link.symlink_to("/dev/zero")
    done = _import_in_child(link, tmp_path / "out")
    assert done.returncode == 2, done.stderr
    assert "not a regular file (a character device)" in done.stderr


def test_stored_texts_that_a_spreadsheet_would_run_are_escaped_and_still_reproduced(
    tmp_path, capsys
):
    """Mathcad stores the texts "=1+1" and "-OK": the printed-values CSV holds them with a
    leading apostrophe (a spreadsheet opening the file shows them as text), and the check
    reads them back without it: both are reproduced."""
    import csv

    from helpers.mathcad_xml import check_sheet

    def text(t: str) -> str:
        return f"<ml:str>{t}</ml:str>"

    import_sheet(
        tmp_path,
        capsys,
        "texts",
        define(1, ident("s"), text("=1+1")),
        define(2, ident("t"), text("-OK")),
        evaluate(3, ident("s"), text("=1+1")),
        evaluate(4, ident("t"), text("-OK")),
    )
    with open(tmp_path / "texts.mathcad.csv", newline="", encoding="utf-8") as f:
        values = [r[2] for r in csv.reader(f) if r and not r[0].startswith("#")][1:]
    assert values == ["'=1+1", "'-OK"]
    result = check_sheet(tmp_path, capsys, "texts")
    assert (result["printed"], result["reproduced"]) == (2, 2), result["failures"]
