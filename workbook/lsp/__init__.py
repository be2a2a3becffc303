"""``workbook lsp``: a Language Server Protocol server over stdin and stdout, for editors:
diagnostics, hover, completion, go to definition and the outline of a worksheet
(:mod:`.document` loads a text, :mod:`.features` answers, :mod:`.server` speaks pygls)."""

from __future__ import annotations

__all__ = ["main"]


def main() -> int:
    """Serve on stdin and stdout until the editor ends the session; returns 0."""
    import warnings

    warnings.simplefilter("ignore", RuntimeWarning)
    from .server import server

    server.start_io()
    return 0
