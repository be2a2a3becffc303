"""The HTTP server of ``workbook serve``: pages, the script, server-sent events and the
form's requests, on 127.0.0.1 only, each request carrying the random token of the URL.

Every worksheet the server reads or writes is a ``.toml`` file directly inside the served
folder (its path resolved, links followed, must stay there); the workbook it writes goes
beside it (for an installed template: ``reports/NAME.xlsx`` in the current folder), the PDF of
the report in the folder ``reports`` of the served folder.
"""

from __future__ import annotations

import hmac
import json
import queue
import secrets
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from urllib.parse import parse_qs, unquote, urlsplit

from ..errors import InputError, WorkbookError
from . import page
from .collector import freeze_loaded, no_collection
from .incremental import LiveSheet, stopped_by
from .watch import Watcher

HOST = "127.0.0.1"
SCRIPT = Path(__file__).with_name("live.js")
MAX_BODY = 100_000  # bytes of a form request
KEEPALIVE_SECONDS = 10.0


class Site:
    """What one server serves: a folder's worksheets (or one of them), their live state,
    the pages listening to each, and the watcher of their files."""

    def __init__(
        self,
        folder: Path,
        *,
        single: Path | None = None,
        out: Path | None = None,
        writable: bool = True,
        token: str | None = None,
        incremental: bool = True,
    ):
        self.folder = Path(folder).resolve()
        self.single = single.resolve() if single else None
        self.out = out  # where workbooks go (None: beside the worksheet)
        self.writable = writable  # may the inputs be written back into the file?
        self.token = token or secrets.token_urlsafe(24)
        self.incremental = incremental  # False: every edit computed in full (the baseline)
        self.sheets: dict[str, LiveSheet] = {}
        self.listeners: dict[str, list[queue.Queue]] = {}
        self.lock = threading.Lock()  # the sheets: held while a first load computes
        self.streams = threading.Lock()  # the listeners: held only to change the lists
        self.stopping = threading.Event()
        self.watcher = Watcher(self.file_changed)

    # -- worksheets ---------------------------------------------------------------------
    def files(self) -> list[str]:
        """The worksheets served: ``.toml`` files directly inside the folder."""
        if self.single is not None:
            return [self.single.name]
        return sorted(p.name for p in self.folder.glob("*.toml") if p.is_file() and self.inside(p))

    def inside(self, path: Path) -> bool:
        try:
            return path.resolve().parent == self.folder
        except OSError:
            return False

    def live(self, name: str) -> LiveSheet:
        """The live sheet of file ``name`` (loaded on first use); an unknown name, or one
        outside the folder, is refused."""
        if name not in self.files():
            raise LookupError(name)
        with self.lock:
            live = self.sheets.get(name)
            if live is None:
                live = LiveSheet(self.folder / name, incremental=self.incremental)
                with live.lock:
                    live.refresh()
                self.sheets[name] = live
                self.watcher.watch(live.path)
        return live

    def file_changed(self, path: Path) -> None:
        """The watcher saw ``path`` change: compute again and push the page to its listeners."""
        live = self.sheets.get(path.name)
        if live is None:
            return
        with no_collection():  # the collector resumes once the page has the numbers
            with live.lock:
                update = live.refresh()
            if update is not None:
                self.push(live)
        if update is not None:
            self.draw(live)

    def draw(self, live: LiveSheet) -> None:
        """Draw the charts an update left as they were, and push the page again."""
        with live.lock:
            update = live.draw_charts()
        if update is not None:
            self.push(live)

    def set_inputs(self, live: LiveSheet, changes: dict[str, str]) -> str | None:
        """Compute again with inputs from the form; the error (a refused value), if any."""
        with no_collection(), live.lock:
            update = live.set_inputs(changes)
            if update.html is not None or (update.error is not None and live.error is update.error):
                self.push(live)  # a value refused at its field leaves the page as it is
        if update.html is not None:
            threading.Thread(target=self.draw, args=(live,), daemon=True).start()
        return page.error_text(update.error)

    def state(self, live: LiveSheet, form: bool = True) -> dict:
        return {
            "version": live.version,
            "html": live.html if live.error is None else None,
            "error": page.error_text(live.error),
            "form": page.inputs_form(live.sheet) if form else None,
            "charts_pending": live.pending,
            # the definitions of the last good page the error stops (marked there)
            "stopped": stopped_by(live.sheet.spec if live.sheet else None, live.error),
        }

    def push(self, live: LiveSheet) -> None:
        data = self.state(live)
        with self.streams:
            queues = list(self.listeners.get(live.path.name, []))
        for q in queues:
            q.put(data)

    def listen(self, name: str) -> queue.Queue:
        q: queue.Queue = queue.Queue()
        with self.streams:
            self.listeners.setdefault(name, []).append(q)
        return q

    def unlisten(self, name: str, q: queue.Queue) -> None:
        with self.streams:
            if q in self.listeners.get(name, []):
                self.listeners[name].remove(q)

    # -- writing --------------------------------------------------------------------------
    def write_xlsx(self, live: LiveSheet) -> Path:
        """The workbook of the page's sheet (its inputs as the form has them)."""
        from ..compute.computed import compute
        from ..outputs.xlsx import write_workbook

        with live.lock:
            sheet = live.sheet
        if sheet is None:
            raise InputError(f"{live.path.name} has no good load to write")
        target = (self.out or live.path.parent) / f"{live.name}.xlsx"
        if self.out is not None:
            target.parent.mkdir(parents=True, exist_ok=True)
        sets = " ".join(f'--set {n}="{v}"' for n, v in live.overrides.items())
        command = f"workbook run {live.path.name} {sets}".strip()
        write_workbook(compute(sheet, excel=True, command=command), target)
        return target

    def write_pdf(self, live: LiveSheet) -> list[Path]:
        """The report of the page's sheet (its inputs as the form has them) printed by
        Chromium (``workbook report --pdf``): ``reports/NAME.pdf`` and its HTML, in a folder
        ``reports`` of the served folder (for an installed template: of the current one)."""
        from ..outputs.report import write_report

        with live.lock:
            computed, overrides = live.computed, dict(live.overrides)
        if computed is None:
            raise InputError(f"{live.path.name} has no good load to print")
        folder = self.out or self.folder / "reports"
        if self.out is None and (folder.is_symlink() or folder.resolve().parent != self.folder):
            raise InputError(f"{folder} leads outside the served folder; nothing is written")
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise InputError(f"cannot make {folder}: {exc.strerror or exc}") from None
        sets = " ".join(f'--set {n}="{v}"' for n, v in overrides.items())
        command = f"workbook report {live.path.name} --pdf {sets}".strip()
        return write_report(computed, folder / f"{live.name}.html", pdf=True, command=command)

    def save_inputs(self, live: LiveSheet) -> str:
        from .writeback import save_inputs

        if not self.writable:
            raise InputError(
                f"{live.path.name} is an installed template and is not changed; copy it "
                "(or `workbook new NAME`) and serve the copy"
            )
        with live.lock:
            changes = dict(live.overrides)
        if not changes:
            return "no input was changed on the page"
        save_inputs(live.path, changes)
        return f"wrote {', '.join(changes)} into {live.path.name}"

    def start(self) -> None:
        freeze_loaded()
        self.watcher.start()

    def stop(self) -> None:
        """End the event streams (a first load computing a sheet is not waited for)."""
        self.stopping.set()
        self.watcher.stop()
        with self.streams:
            for qs in self.listeners.values():
                for q in qs:
                    q.put(None)


class Handler(BaseHTTPRequestHandler):
    """One request: the token checked first (403 without it), then the route."""

    server_version = "workbook-serve"
    site: Site  # set on the subclass made by make_server
    protocol_version = "HTTP/1.1"

    def log_message(self, format, *args):  # noqa: A002 - the base class's name
        pass  # quiet: the terminal shows the URL and errors only

    def _query(self) -> tuple[str, dict[str, str]]:
        parts = urlsplit(self.path)
        query = {k: v[0] for k, v in parse_qs(parts.query).items()}
        return unquote(parts.path), query

    def _allowed(self, query: dict[str, str]) -> bool:
        given = query.get("token", "")
        return hmac.compare_digest(given.encode(), self.site.token.encode())

    def _send(self, status: int, body: bytes, ctype: str, extra: dict | None = None) -> None:
        self.send_response(status)
        self.send_header("Content-Type", ctype)
        self.send_header("Content-Length", str(len(body)))
        self.send_header("Content-Security-Policy", page.CSP)
        self.send_header("X-Content-Type-Options", "nosniff")
        self.send_header("Referrer-Policy", "no-referrer")
        self.send_header("Cache-Control", "no-store")
        for k, v in (extra or {}).items():
            self.send_header(k, v)
        self.end_headers()
        self.wfile.write(body)

    def _text(self, status: int, text: str) -> None:
        self._send(status, text.encode(), "text/plain; charset=utf-8")

    def _json(self, data: dict, status: int = 200) -> None:
        self._send(status, json.dumps(data).encode(), "application/json")

    def _sheet(self, query) -> LiveSheet | None:
        name = query.get("sheet") or (self.site.files() or [""])[0]
        try:
            return self.site.live(name)
        except LookupError:
            self._text(404, f"no worksheet {name} in the served folder")
            return None

    def do_GET(self) -> None:  # noqa: N802 - the base class's name
        path, query = self._query()
        if not self._allowed(query):
            self._text(403, "forbidden: open the URL workbook serve printed (with its token)")
            return
        if path == "/static/live.js":
            self._send(200, SCRIPT.read_bytes(), "text/javascript; charset=utf-8")
        elif path == "/":
            if self.site.single is None:
                html = page.folder_page(self.site.folder, self.site.files(), self.site.token)
                self._send(200, html.encode(), "text/html; charset=utf-8")
            else:
                self._page(self.site.single.name)
        elif path.startswith("/sheet/"):
            self._page(path[len("/sheet/") :])
        elif path == "/events":
            live = self._sheet(query)
            if live is not None:
                self._events(live)
        else:
            self._text(404, "not found")

    def _page(self, name: str) -> None:
        try:
            live = self.site.live(name)
        except LookupError:
            self._text(404, f"no worksheet {name} in the served folder")
            return
        html = page.sheet_page(live, self.site.token)
        self._send(200, html.encode(), "text/html; charset=utf-8")

    def _events(self, live: LiveSheet) -> None:
        self.send_response(200)
        self.send_header("Content-Type", "text/event-stream")
        self.send_header("Cache-Control", "no-store")
        self.send_header("X-Content-Type-Options", "nosniff")
        self.end_headers()
        self.close_connection = True
        q = self.site.listen(live.path.name)
        try:
            q.put(self.site.state(live))
            while not self.site.stopping.is_set():
                try:
                    data = q.get(timeout=KEEPALIVE_SECONDS)
                except queue.Empty:
                    self.wfile.write(b": keep-alive\n\n")
                    self.wfile.flush()
                    continue
                if data is None:
                    break
                self.wfile.write(f"event: update\ndata: {json.dumps(data)}\n\n".encode())
                self.wfile.flush()
        except (BrokenPipeError, ConnectionResetError, OSError):
            pass
        finally:
            self.site.unlisten(live.path.name, q)

    def do_POST(self) -> None:  # noqa: N802 - the base class's name
        path, query = self._query()
        if not self._allowed(query):
            self._text(403, "forbidden")
            return
        if self.headers.get("Content-Type", "").split(";")[0].strip() != "application/json":
            self._text(415, "send application/json")
            return
        size = int(self.headers.get("Content-Length") or 0)
        if size > MAX_BODY:
            self._text(413, "request too large")
            return
        try:
            data = json.loads(self.rfile.read(size) or b"{}")
        except ValueError:
            self._text(400, "not JSON")
            return
        live = self._sheet(query)
        if live is None:
            return
        try:
            if path == "/input":
                if not isinstance(data, dict) or not all(
                    isinstance(k, str) and isinstance(v, str) for k, v in data.items()
                ):
                    self._json({"error": "send {NAME: VALUE} with texts"}, 400)
                    return
                self._json({"error": self.site.set_inputs(live, data)})
            elif path == "/write-xlsx":
                self._json({"message": f"wrote {self.site.write_xlsx(live)}"})
            elif path == "/write-pdf":
                written = self.site.write_pdf(live)
                self._json({"message": "wrote " + ", ".join(map(str, written))})
            elif path == "/save-inputs":
                self._json({"message": self.site.save_inputs(live)})
            else:
                self._text(404, "not found")
        except WorkbookError as err:
            self._json({"error": str(err)})


def make_server(site: Site, port: int = 0) -> ThreadingHTTPServer:
    """An HTTP server of ``site`` on 127.0.0.1 (``port`` 0: any free port)."""
    handler = type("SiteHandler", (Handler,), {"site": site})
    server = ThreadingHTTPServer((HOST, port), handler)
    server.daemon_threads = True
    server.block_on_close = False  # a page listening to events does not hold up a stop
    return server


def url_of(server: ThreadingHTTPServer, site: Site) -> str:
    host, port = server.server_address[:2]
    return f"http://{host}:{port}/?token={site.token}"
