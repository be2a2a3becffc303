"""``workbook lsp``: a Language Server Protocol server over stdin and stdout, for editors:
diagnostics, hover, completion, go to definition and the outline of a worksheet
(:mod:`.document` loads a text, :mod:`.features` answers, :mod:`.server` speaks pygls)."""

from __future__ import annotations

__all__ = ["main"]


def main() -> int:
    """Serve on stdin and stdout until the editor ends the session; returns 0."""
    import warnings

    warnings.simplefilter("ignore", RuntimeWarning)
    from ..engine.sheet import Sheet  # noqa: F401 - imported before the freeze
    from ..language import units
    from ..serve.collector import freeze_loaded
    from .server import server

    units.registry()
    freeze_loaded()
    server.start_io()
    return 0
