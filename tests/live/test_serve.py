"""`workbook serve` without a browser: the HTTP server in this process, spoken to with urllib
(pages, the token, the policy, server-sent events, the form's requests, the files it writes),
and the incremental compute checked against a full one."""

from __future__ import annotations

import json
import math
import re
import shutil
import subprocess
import threading
import time
import urllib.error
import urllib.request
from pathlib import Path

import pytest
from helpers.paths import ROOT

from workbook.serve.incremental import LiveSheet
from workbook.serve.server import Site, make_server

SHEET = """[sheet]
title = "Live test"

[inputs]
R = { value = "2 mm", note = "radius <script>alert(1)</script>", positive = true }
L = { value = "30 mm", max = "100 mm" }
law = { value = "linear", options = ["linear", "cubic"] }

[definitions]
A = { expr = "pi*R^2", note = "area" }
V = { expr = "A*L", unit = "mm^3" }
r1 = { expr = "root(x^2 - R^2, x, 0 mm, 10 mm)", unit = "mm" }
n = "1 if law == 'linear' otherwise 3"

[arguments]
x = { unit = "mm" }
"""


class Served:
    """A server of one folder, on a free port, in a thread of this process."""

    def __init__(self, folder: Path, **options):
        self.site = Site(folder, **options)
        self.httpd = make_server(self.site, 0)
        self.base = f"http://127.0.0.1:{self.httpd.server_address[1]}"
        self.site.start()
        self.thread = threading.Thread(
            target=self.httpd.serve_forever, kwargs={"poll_interval": 0.05}, daemon=True
        )
        self.thread.start()

    def url(self, path: str, token: str | None = None, **query) -> str:
        query["token"] = self.site.token if token is None else token
        q = "&".join(f"{k}={urllib.request.quote(v)}" for k, v in query.items())
        return f"{self.base}{path}?{q}"

    def get(self, path: str, token: str | None = None, **query):
        return urllib.request.urlopen(self.url(path, token, **query), timeout=30)

    def post(self, path: str, data: dict, **query) -> dict:
        req = urllib.request.Request(
            self.url(path, **query),
            data=json.dumps(data).encode(),
            headers={"Content-Type": "application/json"},
            method="POST",
        )
        with urllib.request.urlopen(req, timeout=240) as r:
            return json.loads(r.read())

    def close(self) -> None:
        if not self.site.stopping.is_set():
            self.site.stop()
            self.httpd.shutdown()
            self.httpd.server_close()


class Events:
    """The server-sent events of one sheet, read in a thread."""

    def __init__(self, served: Served, sheet: str):
        self.stream = served.get("/events", sheet=sheet)
        assert self.stream.headers["Content-Type"] == "text/event-stream"
        self.items: list = []
        self.cond = threading.Condition()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        event = {}
        try:
            for raw in self.stream:
                line = raw.decode().rstrip("\n")
                if line.startswith("data: "):
                    event = json.loads(line[len("data: ") :])
                elif not line and event:
                    with self.cond:
                        self.items.append(event)
                        self.cond.notify_all()
                    event = {}
        except (OSError, ValueError):
            pass

    def next(self, after: int = 0, timeout: float = 60.0) -> dict:
        """The first event with a version above ``after``."""
        end = time.monotonic() + timeout
        with self.cond:
            while True:
                for e in self.items:
                    if e["version"] > after:
                        return e
                left = end - time.monotonic()
                assert left > 0, "no event"
                self.cond.wait(left)

    def close(self, served: Served) -> None:
        """Stop the server's side first: closing the response while the reader waits in it
        would wait for the next keep-alive."""
        served.close()
        self.stream.close()


@pytest.fixture
def served(tmp_path):
    (tmp_path / "live.toml").write_text(SHEET, encoding="utf-8")
    s = Served(tmp_path)
    yield s
    s.close()


def _value(html: str, name: str) -> float:
    """The result of scalar definition ``name`` as the report shows it (6 significant
    digits): the first number of its ``result`` element."""
    m = re.search(r"class='result' data-name='" + name + r"'>(.*?)</math>", html, re.S)
    assert m, name
    return number(re.findall(r"<mn>([^<]+)</mn>", m.group(1)))


def number(mns: list[str]) -> float:
    """A number of the report's MathML: a mantissa, and ``×10`` and an exponent after it."""
    text = mns[0].replace("\u2212", "-")
    if len(mns) >= 3 and mns[1] == "10":
        return float(text.rstrip("\u00d7")) * 10 ** float(mns[2].replace("\u2212", "-"))
    return float(text)


def test_token_policy_and_escaping(served):
    for token in ("", "wrong"):
        with pytest.raises(urllib.error.HTTPError) as err:
            served.get("/", token=token)
        assert err.value.code == 403
    with pytest.raises(urllib.error.HTTPError) as err:
        urllib.request.urlopen(served.base + "/sheet/live.toml", timeout=10)
    assert err.value.code == 403
    with served.get("/") as r:  # a folder: its list
        listing = r.read().decode()
    assert "/sheet/live.toml?token=" in listing
    with served.get("/sheet/live.toml") as r:
        csp = r.headers["Content-Security-Policy"]
        page = r.read().decode()
    script_src = next(p for p in csp.split(";") if p.strip().startswith("script-src"))
    assert script_src.split() == ["script-src", "'self'"]
    assert "default-src 'none'" in csp
    scripts = re.findall(r"<script[^>]*>", page)
    assert scripts == [f"<script src='/static/live.js?token={served.site.token}' defer>"]
    assert "<script>alert" not in page and "&lt;script&gt;alert(1)&lt;/script&gt;" in page
    assert served.site.token not in page.split("<main", 1)[1]  # the token is not in the report
    with served.get("/static/live.js") as r:
        assert r.headers["Content-Type"].startswith("text/javascript")
        assert "EventSource" in r.read().decode()


def test_only_files_of_the_folder(served, tmp_path):
    outside = tmp_path.parent / f"{tmp_path.name}-outside.toml"
    outside.write_text(SHEET, encoding="utf-8")
    (tmp_path / "link.toml").symlink_to(outside)
    try:
        for path, query in (
            (f"/sheet/../{outside.name}", {}),
            ("/sheet/link.toml", {}),
            ("/events", {"sheet": f"../{outside.name}"}),
            ("/sheet/nothing.toml", {}),
        ):
            with pytest.raises(urllib.error.HTTPError) as err:
                served.get(path, **query)
            assert err.value.code == 404, path
        with served.get("/") as r:
            assert "link.toml" not in r.read().decode()
    finally:
        outside.unlink()


def test_file_edit_error_and_form_through_events(served, tmp_path):
    path = tmp_path / "live.toml"
    events = Events(served, "live.toml")
    try:
        first = events.next()
        assert first["error"] is None
        assert _value(first["html"], "V") == pytest.approx(math.pi * 4 * 30, rel=1e-5)
        assert "name='R'" in first["form"] and "<select name='law'>" in first["form"]
        # an edit of a formula in the file: the page gets the new number
        path.write_text(SHEET.replace('expr = "A*L"', 'expr = "2*A*L"'), encoding="utf-8")
        second = events.next(first["version"])
        assert _value(second["html"], "V") == pytest.approx(2 * math.pi * 4 * 30, rel=1e-5)
        # an edit that breaks the sheet: the error at its line and definition, no new page
        broken = SHEET.replace('expr = "A*L"', 'expr = "A*L + R"')
        path.write_text(broken, encoding="utf-8")
        third = events.next(second["version"])
        line = broken.splitlines().index(next(s for s in broken.splitlines() if "A*L + R" in s))
        assert third["html"] is None
        assert f"live.toml:{line + 1}, in 'V': unit error" in third["error"]
        assert third["stopped"] == ["V"]  # marked on the last good page
        assert served.site.live("live.toml").html == second["html"]  # the last good one stays
        path.write_text(SHEET, encoding="utf-8")
        fourth = events.next(third["version"])
        assert fourth["error"] is None
        # an input from the form: computed again, the file untouched
        before = path.read_text(encoding="utf-8")
        assert served.post("/input", {"R": "3 mm"}, sheet="live.toml") == {"error": None}
        fifth = events.next(fourth["version"])
        assert _value(fifth["html"], "A") == pytest.approx(math.pi * 9, rel=1e-5)
        assert _value(fifth["html"], "r1") == pytest.approx(3.0, rel=1e-6)
        assert "value='3'" in fifth["form"]
        refused = served.post("/input", {"L": "200 mm"}, sheet="live.toml")["error"]
        assert "live.toml:6, in 'L': input error" in refused and "100 mm" in refused
        refused = served.post("/input", {"R": "3 kg"}, sheet="live.toml")["error"]
        assert "[mass]" in refused
        served.post("/input", {"law": "cubic"}, sheet="live.toml")
        assert _value(served.site.live("live.toml").html, "n") == 3
        assert path.read_text(encoding="utf-8") == before
    finally:
        events.close(served)


def test_buttons_write_the_workbook_and_the_inputs(served, tmp_path):
    import openpyxl

    path = tmp_path / "live.toml"
    served.get("/sheet/live.toml").close()
    served.post("/input", {"R": "2.5 mm", "law": "cubic"}, sheet="live.toml")
    reply = served.post("/write-xlsx", {}, sheet="live.toml")
    assert reply["message"] == f"wrote {tmp_path / 'live.xlsx'}"
    book = openpyxl.load_workbook(tmp_path / "live.xlsx", data_only=True)
    cells = [c.value for row in book["Inputs"].iter_rows() for c in row]
    assert 2.5 in cells
    reply = served.post("/save-inputs", {}, sheet="live.toml")
    assert reply == {"message": "wrote R, law into live.toml"}
    text = path.read_text(encoding="utf-8")
    old, new = SHEET.splitlines(), text.splitlines()
    changed = [(a, b) for a, b in zip(old, new) if a != b]
    assert len(old) == len(new) and len(changed) == 2
    assert 'R = { value = "2.5 mm", note' in changed[0][1]
    assert 'law = { value = "cubic"' in changed[1][1]
    assert not [p.name for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary


def test_incremental_reuses_what_an_edit_does_not_reach(tmp_path):
    path = tmp_path / "live.toml"
    path.write_text(SHEET, encoding="utf-8")
    live = LiveSheet(path)
    assert live.refresh().error is None
    edited = SHEET.replace('expr = "A*L"', 'expr = "3*A*L"')
    typed_before = dict(live.sheet.typer.scalars)
    update = live.rebuild(edited, {})
    assert update.error is None and update.recomputed == {"V"}
    # the typing of what the edit does not reach is taken over, the edited one is new
    assert live.sheet.typer.scalars["A"] is typed_before["A"]
    assert live.sheet.typer.scalars["V"] is not typed_before["V"]
    assert live.pieces[("definition", "A")] in update.html
    assert {("value", "A"), ("value", "r1")} <= set(live.sheet.reused)
    assert ("value", "V") not in live.sheet.reused
    update = live.set_inputs({"R": "4 mm"})
    assert {"R", "A", "V", "r1"} <= update.recomputed and "n" not in update.recomputed
    assert set(live.sheet.reused) & {("value", "A"), ("value", "V"), ("value", "r1")} == set()
    full = LiveSheet(path, incremental=False)
    full.rebuild(edited, {"R": "4 mm"})
    for name in ("A", "V", "r1", "n"):
        a, b = live.computed.scalars[name].value, full.computed.scalars[name].value
        assert a.to(b.units).magnitude == pytest.approx(b.magnitude, rel=1e-12), name


def _templates() -> list[str]:
    import workbook

    return list(workbook.list_templates())


@pytest.mark.slow
@pytest.mark.parametrize("name", _templates())
def test_incremental_equals_full_on_every_template(name, tmp_path):
    """An edited formula and an edited input, computed incrementally and in full: the same
    scalars, tables and the same report."""
    import workbook

    src = workbook.list_templates()[name]
    for f in src.parent.glob(name + ".*"):
        shutil.copy(f, tmp_path / f.name)
    path = tmp_path / src.name
    text = path.read_text(encoding="utf-8")
    live = LiveSheet(path)
    assert live.refresh().error is None
    d = next(d for d in reversed(live.sheet.spec.definitions.values()) if d.body is not None)
    line = text.splitlines()[d.line - 1]
    assert d.text in line, name
    edited_line = line.replace(d.text, f"({d.text})*1.5", 1) if not d.params else line
    edited = text.replace(line, edited_line, 1)
    i = next(i for i in live.sheet.spec.inputs.values() if not i.options)
    value = live.sheet.values[i.name]
    new_value = f"{float(value.magnitude) * 1.01!r} {value.units:~}".strip()
    live.rebuild(edited, {})
    live.draw_charts()
    live.set_inputs({i.name: new_value})
    live.draw_charts()
    full = LiveSheet(path, incremental=False)
    full.rebuild(edited, {i.name: new_value})
    assert (live.error, full.error) == (None, None)
    for n, s in full.computed.scalars.items():
        mine = live.computed.scalars[n]
        assert (mine.error is None) == (s.error is None), n
        if s.error is None and not isinstance(s.value, str):
            a = mine.value.to(s.value.units).magnitude
            assert a == pytest.approx(s.value.magnitude, rel=1e-9, abs=1e-12), n
    assert _untimed(live.html) == _untimed(full.html)


def _untimed(html: str) -> str:
    """The report without the rows that say how long a solver ran (measured each time)."""
    return re.sub(r"<tr[^>]*>(?:(?!</tr>).)*\d steps,(?:(?!</tr>).)*</tr>", "", html, flags=re.S)


@pytest.mark.slow
def test_a_newcomers_sheet(tmp_path):
    from workbook.scaffold import write_starter

    path = write_starter("mine", tmp_path / "mine.toml")
    live = LiveSheet(path)
    update = live.refresh()
    assert update.error is None and "class='result'" in update.html


@pytest.mark.slow
def test_an_installed_template_is_served_read_only(tmp_path, monkeypatch):
    from workbook.errors import InputError
    from workbook.serve import site_for

    monkeypatch.chdir(tmp_path)
    site = site_for("concave-cam")
    assert site.files() == ["concave-cam.toml"] and not site.writable
    assert site.out == tmp_path / "reports"
    live = site.live("concave-cam.toml")
    site.set_inputs(live, {"R3": "45 mm"})
    with pytest.raises(InputError, match="installed template"):
        site.save_inputs(live)
    site.stop()


@pytest.mark.slow
def test_the_benchmark_runs():
    """benchmarks/bench_serve.py at one repetition (its timings are not asserted)."""
    import sys

    sys.path.insert(0, str(ROOT / "benchmarks"))
    import bench_serve

    m = bench_serve.measure("concave-cam", 1)
    assert set(m["times"]) == {
        (a, b) for a in ("incremental", "full") for b in ("formula", "input")
    }
    assert all(0 < t[0] <= t[1] for ts in m["times"].values() for t in ts)
    ((name, times),) = bench_serve.measure_lsp(["concave-cam"], 1)
    assert name == "concave-cam" and len(times) == 1 and times[0][0] > 0


@pytest.mark.parametrize("name", _templates())
def test_downstream_is_what_reads_the_change(name):
    """What an edit reaches, followed backwards from the change, is every input and
    definition whose (transitive) dependencies include it."""
    import workbook
    from workbook.language import expr as ex
    from workbook.language.uses import dependencies
    from workbook.serve.incremental import downstream

    spec = workbook.load(workbook.list_templates()[name]).full_spec
    names = [*spec.inputs, *spec.definitions]
    for changed in (names[:1], names[len(names) // 2 : len(names) // 2 + 1], names[-2:]):
        want = set(changed) | {n for n in names if dependencies(spec, ex.Name(n)) & set(changed)}
        assert downstream(spec, set(changed)) == want, changed


def test_the_pdf_is_not_written_outside_the_served_folder(served, tmp_path):
    outside = tmp_path.parent / (tmp_path.name + "-elsewhere")
    outside.mkdir()
    (tmp_path / "reports").symlink_to(outside, target_is_directory=True)
    served.get("/sheet/live.toml").close()
    reply = served.post("/write-pdf", {}, sheet="live.toml")
    assert "leads outside the served folder" in reply["error"]
    assert list(outside.iterdir()) == []


@pytest.mark.slow
@pytest.mark.skipif(not shutil.which("chromium"), reason="chromium needed")
def test_the_pdf_button_prints_the_report_with_the_forms_inputs(served, tmp_path):
    served.get("/sheet/live.toml").close()
    served.post("/input", {"R": "2.5 mm"}, sheet="live.toml")
    reply = served.post("/write-pdf", {}, sheet="live.toml")
    pdf, html = tmp_path / "reports" / "live.pdf", tmp_path / "reports" / "live.html"
    assert reply == {"message": f"wrote {html}, {pdf}"}
    assert pdf.read_bytes().startswith(b"%PDF") and pdf.stat().st_size > 1000
    assert "--set R=&quot;2.5 mm&quot;" in html.read_text(encoding="utf-8")  # its command
    assert abs(_value(html.read_text(encoding="utf-8"), "A") - math.pi * 2.5**2) < 1e-3
    if shutil.which("pdftotext"):
        text = subprocess.run(
            ["pdftotext", str(pdf), "-"], capture_output=True, text=True, check=True
        ).stdout
        assert "Live test" in text
