"""`workbook lsp` tested through the protocol: a client written here speaks JSON-RPC over the
real server process's stdin and stdout (Content-Length framing, as editors do), opens and
edits worksheets, and reads the diagnostics, hover texts, completion items, definitions and
outline that come back."""

from __future__ import annotations

import json
import os
import queue
import re
import subprocess
import sys
import threading
from pathlib import Path

import pytest
from helpers.paths import ROOT, TESTS

CORPUS = TESTS / "bad_inputs"
TIMEOUT = 60.0


class Client:
    """A minimal LSP client of a subprocess: requests, notifications, and what it sends."""

    def __init__(self, cwd: Path):
        env = dict(os.environ, PYTHONPATH=str(ROOT))
        self.proc = subprocess.Popen(
            [
                sys.executable,
                "-c",
                "import sys; from workbook.cli import main; sys.exit(main())",
                "lsp",
            ],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            cwd=cwd,
            env=env,
        )
        self.next_id = 0
        self.replies: dict[int, queue.Queue] = {}
        self.notes: queue.Queue = queue.Queue()
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self) -> None:
        out = self.proc.stdout
        while True:
            headers = {}
            while True:
                line = out.readline()
                if not line:
                    return
                line = line.decode("ascii").strip()
                if not line:
                    break
                key, _, value = line.partition(":")
                headers[key.lower()] = value.strip()
            body = json.loads(out.read(int(headers["content-length"])))
            if "id" in body and "method" not in body:
                self.replies.setdefault(body["id"], queue.Queue()).put(body)
            elif "method" in body and "id" in body:  # a request of the server's: answered
                self._send({"jsonrpc": "2.0", "id": body["id"], "result": None})
            else:
                self.notes.put(body)

    def _send(self, message: dict) -> None:
        data = json.dumps(message).encode()
        self.proc.stdin.write(b"Content-Length: %d\r\n\r\n" % len(data) + data)
        self.proc.stdin.flush()

    def request(self, method: str, params) -> object:
        self.next_id += 1
        rid = self.next_id
        self.replies.setdefault(rid, queue.Queue())
        self._send({"jsonrpc": "2.0", "id": rid, "method": method, "params": params})
        reply = self.replies[rid].get(timeout=TIMEOUT)
        assert "error" not in reply, reply
        return reply["result"]

    def notify(self, method: str, params) -> None:
        self._send({"jsonrpc": "2.0", "method": method, "params": params})

    def diagnostics(self, uri: str, version: int | None = None) -> list[dict]:
        """The next diagnostics published for ``uri`` (of ``version``, when given)."""
        while True:
            note = self.notes.get(timeout=TIMEOUT)
            if note["method"] != "textDocument/publishDiagnostics":
                continue
            p = note["params"]
            if p["uri"] == uri and (version is None or p.get("version") == version):
                return p["diagnostics"]

    def start(self, root: Path) -> dict:
        caps = self.request(
            "initialize",
            {"processId": os.getpid(), "rootUri": root.as_uri(), "capabilities": {}},
        )
        self.notify("initialized", {})
        return caps

    def open(self, path: Path, text: str | None = None, version: int = 1) -> str:
        uri = path.resolve().as_uri()
        text = path.read_text(encoding="utf-8") if text is None else text
        self.notify(
            "textDocument/didOpen",
            {"textDocument": {"uri": uri, "languageId": "toml", "version": version, "text": text}},
        )
        return uri

    def change(self, uri: str, text: str, version: int) -> None:
        self.notify(
            "textDocument/didChange",
            {
                "textDocument": {"uri": uri, "version": version},
                "contentChanges": [{"text": text}],
            },
        )

    def at(self, method: str, uri: str, line: int, character: int):
        return self.request(
            method,
            {"textDocument": {"uri": uri}, "position": {"line": line, "character": character}},
        )

    def stop(self) -> int:
        try:
            self.request("shutdown", None)
            self.notify("exit", None)
            return self.proc.wait(timeout=20)
        finally:
            if self.proc.poll() is None:
                self.proc.kill()
            self.proc.stdin.close()
            self.proc.stdout.close()
            self.proc.stderr.close()


SHEET = """[inputs]
R = { value = "2 mm", note = "radius", positive = true }
L = "30 mm"

[arguments]
x = { unit = "mm" }

[definitions]
A = { expr = "pi*R^2", note = "area" }
V = "A*L"
"f(x)" = { expr = "x*R", unit = "mm^2" }
r1 = "root(x^2 - R^2, x, 0 mm, 10 mm)"

[[tables]]
name = "tab"
range = "x := 0, 1 .. 3"
columns = ["f(x)"]
"""


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    folder = tmp_path_factory.mktemp("lsp")
    c = Client(folder)
    caps = c.start(folder)
    c.folder = folder
    c.capabilities = caps["capabilities"]
    yield c
    assert c.stop() == 0


def _line_of(text: str, start: str) -> int:
    return next(i for i, line in enumerate(text.splitlines()) if line.startswith(start))


@pytest.mark.slow
def test_capabilities(client):
    caps = client.capabilities
    for key in (
        "hoverProvider",
        "completionProvider",
        "definitionProvider",
        "documentSymbolProvider",
        "textDocumentSync",
    ):
        assert caps.get(key), key


def test_diagnostics_of_a_good_sheet_then_an_unknown_name_then_a_unit_error(client):
    path = client.folder / "good.toml"
    path.write_text(SHEET, encoding="utf-8")
    uri = client.open(path, version=1)
    assert client.diagnostics(uri, 1) == []
    bad = SHEET.replace('V = "A*L"', 'V = "A*Lx"')
    client.change(uri, bad, 2)
    (d,) = client.diagnostics(uri, 2)
    row = _line_of(bad, "V =")
    assert d["range"]["start"] == {"line": row, "character": bad.splitlines()[row].index("Lx")}
    assert d["range"]["end"]["character"] - d["range"]["start"]["character"] == 2
    assert d["code"] == "template error"
    assert "unknown name 'Lx'" in d["message"] and "L" in d["message"].split("did you mean")[1]
    units = SHEET.replace('V = "A*L"', 'V = "A + L"')
    client.change(uri, units, 3)
    (d,) = client.diagnostics(uri, 3)
    row = _line_of(units, "V =")
    line = units.splitlines()[row]
    assert d["code"] == "unit error" and d["range"]["start"]["line"] == row
    shown = line[d["range"]["start"]["character"] : d["range"]["end"]["character"]]
    assert shown == "A + L"  # the formula's text, without its quotes
    client.change(uri, SHEET, 4)
    assert client.diagnostics(uri, 4) == []


def test_toml_syntax_error_at_its_column(client):
    text = '[inputs]\nR = "2 mm\n'
    path = client.folder / "syntax.toml"
    path.write_text(text, encoding="utf-8")
    uri = client.open(path, version=1)
    (d,) = client.diagnostics(uri, 1)
    assert d["range"]["start"]["line"] == 1 and d["code"] == "template error"
    assert "TOML syntax" in d["message"]


def test_domain_error_of_a_value_is_published_after_the_load(client):
    text = '[inputs]\nR = "2 mm"\n\n[definitions]\nA = "sqrt(R - 3 mm)*sqrt(R)"\n'
    path = client.folder / "domain.toml"
    path.write_text(text, encoding="utf-8")
    uri = client.open(path, version=1)
    assert client.diagnostics(uri, 1) == []  # the load is good
    (d,) = client.diagnostics(uri, 1)  # then the values
    assert d["code"] == "domain error" and d["range"]["start"]["line"] == 4


@pytest.mark.slow
def test_hover_value_function_builtin_and_estimate(client):
    path = client.folder / "hover.toml"
    path.write_text(SHEET, encoding="utf-8")
    uri = client.open(path, version=1)
    client.diagnostics(uri, 1)
    lines = SHEET.splitlines()
    row = _line_of(SHEET, "V =")
    h = client.at("textDocument/hover", uri, row, 0)
    value = h["contents"]["value"]
    # V = pi*R^2*L = pi*4*30 mm^3, computed here independently
    import math

    number = float(re.search(r"= ([-0-9.e+]+) mm", value).group(1))
    assert number == pytest.approx(math.pi * 4 * 30, rel=1e-5)
    assert "mm^3" in value or "mm³" in value
    row = _line_of(SHEET, "A =")
    col = lines[row].index("pi")
    h = client.at("textDocument/hover", uri, row, col + 1)
    assert "pi" in h["contents"]["value"] and "3.14159" in h["contents"]["value"]
    row = _line_of(SHEET, '"f(x)"')
    h = client.at("textDocument/hover", uri, row, 2)
    assert "**f(x [mm])** -> mm^2" in h["contents"]["value"].replace("²", "^2")
    row = _line_of(SHEET, "r1 =")
    h = client.at("textDocument/hover", uri, row, lines[row].index("root") + 1)
    assert "root(EXPR, X, A, B)" in h["contents"]["value"]
    h = client.at("textDocument/hover", uri, row, 0)
    text = h["contents"]["value"]
    assert float(re.search(r"= ([-0-9.e+]+) mm", text).group(1)) == pytest.approx(2.0)
    assert "error estimate of root" in text
    row = _line_of(SHEET, "R =")
    h = client.at("textDocument/hover", uri, row, 0)
    assert (
        h["contents"]["value"].startswith("**R** = 2 mm (input)")
        and "radius" in h["contents"]["value"]
    )


def test_completion_names_builtins_units_keys_and_sections(client):
    path = client.folder / "complete.toml"
    text = SHEET + "\n[definitions2]\n"
    path.write_text(SHEET, encoding="utf-8")
    uri = client.open(path, version=1)
    client.diagnostics(uri, 1)
    lines = SHEET.splitlines()
    row = _line_of(SHEET, "V =")
    items = client.at("textDocument/completion", uri, row, lines[row].index("A*L") + 1)["items"]
    labels = {i["label"] for i in items}
    assert {"R", "L", "A", "f", "x", "sin", "root", "pi"} <= labels
    row = _line_of(SHEET, "L =")
    items = client.at("textDocument/completion", uri, row, lines[row].index("mm"))["items"]
    labels = {i["label"] for i in items}
    assert {"mm", "m", "s", "N", "kg"} <= labels and "root" not in labels
    row = _line_of(SHEET, "R =")
    col = lines[row].index("note")
    items = client.at("textDocument/completion", uri, row, col)["items"]
    assert {"value", "note", "min", "max", "options"} <= {i["label"] for i in items}
    client.change(uri, text + "[", 2)
    client.diagnostics(uri, 2)
    items = client.at("textDocument/completion", uri, len(text.splitlines()), 1)["items"]
    assert {"[inputs]", "[definitions]", "[[tables]]"} <= {i["label"] for i in items}


def test_definition_and_outline(client):
    path = client.folder / "goto.toml"
    path.write_text(SHEET, encoding="utf-8")
    uri = client.open(path, version=1)
    client.diagnostics(uri, 1)
    lines = SHEET.splitlines()
    row = _line_of(SHEET, "V =")
    loc = client.at("textDocument/definition", uri, row, lines[row].index("A*L"))
    assert loc["uri"] == uri and loc["range"]["start"]["line"] == _line_of(SHEET, "A =")
    row = _line_of(SHEET, "columns")
    loc = client.at("textDocument/definition", uri, row, lines[row].index("f("))
    assert loc["range"]["start"]["line"] == _line_of(SHEET, '"f(x)"')
    symbols = client.request("textDocument/documentSymbol", {"textDocument": {"uri": uri}})
    by_name = {s["name"]: s for s in symbols}
    assert {"[inputs]", "[arguments]", "[definitions]", "[[tables]] tab"} <= set(by_name)
    children = [c["name"] for c in by_name["[definitions]"]["children"]]
    assert children == ["A", "V", "f(x)", "r1"]
    assert by_name["[inputs]"]["children"][0]["range"]["start"]["line"] == 1


def _corpus_cases() -> list[tuple[Path, str, int]]:
    """The corpus files run as ``run FILE`` whose error names a line: (file, kind, line)."""
    out = []
    for path in sorted(CORPUS.glob("*.toml")):
        try:
            head = path.read_text(encoding="utf-8").splitlines()[:6]
        except UnicodeDecodeError:  # an editor sends text: a file that is not UTF-8 is not one
            continue
        if any(h.startswith("# args:") or h.startswith("# setup:") for h in head):
            continue
        expect = next(h for h in head if h.startswith("# expect:"))
        where = next((h for h in head if h.startswith("# where:")), None)
        if where is None or where.split()[2] == "-":
            continue
        kind = expect.split(":", 3)[2].strip()
        out.append((path, kind, int(where.split()[2])))
    return out


@pytest.mark.slow
def test_every_corpus_error_is_a_diagnostic_at_its_line(client, tmp_path):
    """Each bad input of tests/bad_inputs/ that names a line is a diagnostic of its kind at
    that line, from the load or from the values that follow it; every kind of error of
    docs/errors.md among them."""
    missed, kinds = [], set()
    for path, kind, line in _corpus_cases():
        target = tmp_path / path.name
        target.write_text(path.read_text(encoding="utf-8"), encoding="utf-8")
        for extra in CORPUS.glob(path.stem + ".*.csv"):
            (tmp_path / extra.name).write_bytes(extra.read_bytes())
        uri = client.open(target, version=1)
        found = client.diagnostics(uri, 1)
        if not any(d["range"]["start"]["line"] == line - 1 for d in found):
            found = client.diagnostics(uri, 1)  # the second publication: with the values
        hit = [d for d in found if d["range"]["start"]["line"] == line - 1 and d["code"] == kind]
        if hit:
            kinds.add(kind)
        else:
            missed.append((path.name, kind, line, found))
        client.notify("textDocument/didClose", {"textDocument": {"uri": uri}})
    assert not missed, missed
    assert {"template error", "unit error", "input error", "domain error"} <= kinds


def test_limit_exceeded_is_a_diagnostic_at_its_line(client):
    text = '[inputs]\nR = "2 mm"\n\n[definitions]\nA = "' + "(" * 250 + "R" + ")" * 250 + '"\n'
    path = client.folder / "deep.toml"
    path.write_text(text, encoding="utf-8")
    uri = client.open(path, version=1)
    (d,) = client.diagnostics(uri, 1)
    assert d["code"] == "limit exceeded" and d["range"]["start"]["line"] == 4
    assert "nested 250 deep" in d["message"]


def test_rapid_changes_are_answered_for_the_last_version(client):
    path = client.folder / "rapid.toml"
    path.write_text(SHEET, encoding="utf-8")
    uri = client.open(path, version=1)
    assert client.diagnostics(uri, 1) == []
    bad = SHEET.replace('V = "A*L"', 'V = "A*Lx"')
    client.change(uri, bad, 2)
    client.change(uri, SHEET.replace('V = "A*L"', 'V = "A + L"'), 3)
    (d,) = client.diagnostics(uri, 3)
    assert d["code"] == "unit error"  # the text of version 3, not of 2
    client.change(uri, SHEET, 4)
    while (found := client.diagnostics(uri)) != []:  # nothing of version 2 after 3's
        assert found[0]["code"] != "template error", found


def test_a_change_types_again_only_what_it_reaches(tmp_path):
    """The load of a changed text takes over the typing of what the change does not reach,
    and finds the same errors as a load from nothing."""
    from workbook.lsp.document import load

    path = tmp_path / "inc.toml"
    first = load(SHEET, path)
    assert first.problems == [] and first.sheet is not None
    edited = SHEET.replace('V = "A*L"', 'V = "3*A*L"')
    second = load(edited, path, first)
    assert second.sheet.typer.scalars["A"] is first.sheet.typer.scalars["A"]
    assert second.sheet.typer.scalars["V"] is not first.sheet.typer.scalars["V"]
    bad = SHEET.replace('V = "A*L"', 'V = "A + L"')
    assert load(bad, path, second).problems == load(bad, path).problems
    assert load(bad, path, second).problems[0].kind == "unit error"
