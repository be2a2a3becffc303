"""``workbook serve``: a worksheet's report as a live local page, computed again as the file
or the page's inputs change (:mod:`.server`, :mod:`.incremental`, :mod:`.watch`,
:mod:`.page`, :mod:`.writeback`)."""

from __future__ import annotations

import sys
from pathlib import Path

from ..errors import InputError

__all__ = ["site_for", "serve"]


def site_for(target: str | None):
    """The :class:`.server.Site` of a template name, a ``.toml`` file or a folder (None: the
    current folder)."""
    from .server import Site

    if target is None:
        return Site(Path.cwd())
    path = Path(target)
    if path.is_dir():
        return Site(path)
    if target.endswith(".toml") or "/" in target or "\\" in target:
        if not path.is_file():
            raise InputError(f"no worksheet file {target}")
        if path.suffix.lower() != ".toml":
            raise InputError(f"{target}: serve a .toml worksheet or a folder of them")
        return Site(path.resolve().parent, single=path)
    from .. import template_path

    found = template_path(target)  # an installed template: read there, written nowhere there
    return Site(found.parent, single=found, out=Path.cwd() / "reports", writable=False)


def serve(target: str | None, port: int = 0, open_browser: bool = True) -> int:
    """Serve until Ctrl-C; returns the exit status (0)."""
    from .server import make_server, url_of

    site = site_for(target)
    try:
        server = make_server(site, port)
    except OSError as exc:
        raise InputError(f"cannot listen on 127.0.0.1:{port}: {exc.strerror or exc}") from None
    url = url_of(server, site)
    print(f"workbook serve: {url}", flush=True)
    print("  (Ctrl-C stops it)", flush=True)
    site.start()
    if site.single is not None:
        live = site.live(site.single.name)
        if live.error is not None:
            print(f"workbook: {live.error}", file=sys.stderr, flush=True)
    if open_browser:
        import webbrowser

        webbrowser.open(url)
    try:
        server.serve_forever(poll_interval=0.2)
    except KeyboardInterrupt:
        print("workbook serve: stopped", file=sys.stderr)
    finally:
        site.stop()
        server.server_close()
    return 0
