"""A hostile or broken .xmcd file is a clear error (exit 2), in bounded time and memory."""

from __future__ import annotations

import io
import time
import zipfile

import pytest

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


@pytest.mark.parametrize("case", sorted(CASES))
def test_hostile_file_is_refused(case, tmp_path, capsys):
    data, message = CASES[case]
    src = tmp_path / f"{case}.xmcd"
    src.write_bytes(data)
    start = time.perf_counter()
    status = main(["import", str(src), "--out", str(tmp_path / "out")])
    elapsed = time.perf_counter() - start
    err = capsys.readouterr().err
    assert status == 2, err
    assert message in err and src.name in err
    assert elapsed < 5
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


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
