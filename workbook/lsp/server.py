"""The language server (pygls): documents loaded as they are opened and changed (of changes
that come faster than :data:`DEBOUNCE`, the last; each load typing again only what the change
reaches), their diagnostics published twice (the load's at once, then with the values' once
the text has not changed for :data:`QUIET`), and the answers of :mod:`.features`."""

from __future__ import annotations

import asyncio
from pathlib import Path

from lsprotocol import types as lsp
from pygls.lsp.server import LanguageServer
from pygls.uris import to_fs_path

from ..serve.collector import no_collection
from ..version import __version__
from . import document, features


class WorkbookServer(LanguageServer):
    """A LanguageServer that keeps the last load of every open worksheet (and the last good
    one, whose typing the next load takes over)."""

    def __init__(self):
        super().__init__("workbook", __version__)
        self.documents: dict[str, document.Document] = {}
        self.good: dict[str, document.Document] = {}
        self.versions: dict[str, int] = {}

    def analyse(self, uri: str, text: str | None = None) -> document.Document:
        """Load the document's ``text`` (None: the workspace's), typed, not computed."""
        old = self.documents.get(uri)
        if old is not None:
            old.stale = True  # its values, if still being computed, stop
        if text is None:
            text = self.workspace.get_text_document(uri).source
        path = Path(to_fs_path(uri) or "sheet.toml")
        with no_collection():  # the collector resumes after the load
            doc = document.load(text, path, self.good.get(uri))
        self.documents[uri] = doc
        if doc.sheet is not None:
            self.good[uri] = doc
        return doc

    def doc(self, uri: str) -> document.Document:
        return self.documents.get(uri) or self.analyse(uri)

    def publish(self, uri: str, problems, version: int | None) -> None:
        self.text_document_publish_diagnostics(
            lsp.PublishDiagnosticsParams(
                uri=uri, diagnostics=features.diagnostics(problems), version=version
            )
        )


server = WorkbookServer()

#: Seconds a change waits for the next one: of rapid changes, only the last is checked.
DEBOUNCE = 0.02
#: Seconds without a change before the values are computed (their errors follow the load's
#: diagnostics): while a person types, keystrokes apart by less do not start them.
QUIET = 0.5


def _latest(ls: WorkbookServer, uri: str, version: int) -> bool:
    return ls.versions.get(uri) == version


async def _changed(ls: WorkbookServer, uri: str, version: int | None) -> None:
    version = version or 0
    ls.versions[uri] = version
    current = ls.documents.get(uri)
    if current is not None:
        current.stale = True  # the values of the last text, if being computed, stop now
    await asyncio.sleep(DEBOUNCE)
    if not _latest(ls, uri, version):
        return  # a newer change came: its diagnostics are the ones wanted
    # loaded here, between two messages (tens of ms): a thread of its own would wait for the
    # interpreter all the same, and a busy machine's scheduler once more
    doc = ls.analyse(uri)
    ls.publish(uri, doc.problems, version)
    loop = asyncio.get_running_loop()
    if doc.sheet is None:
        return
    await asyncio.sleep(QUIET)
    if not _latest(ls, uri, version) or ls.documents.get(uri) is not doc:
        return
    more = await loop.run_in_executor(None, document.values_apart, doc)
    if more is not None and _latest(ls, uri, version) and ls.documents.get(uri) is doc:
        ls.publish(uri, doc.problems + more, version)  # again, even when nothing was added


@server.feature(lsp.TEXT_DOCUMENT_DID_OPEN)
async def did_open(ls: WorkbookServer, params: lsp.DidOpenTextDocumentParams) -> None:
    await _changed(ls, params.text_document.uri, params.text_document.version)


@server.feature(lsp.TEXT_DOCUMENT_DID_CHANGE)
async def did_change(ls: WorkbookServer, params: lsp.DidChangeTextDocumentParams) -> None:
    await _changed(ls, params.text_document.uri, params.text_document.version)


@server.feature(lsp.TEXT_DOCUMENT_DID_CLOSE)
def did_close(ls: WorkbookServer, params: lsp.DidCloseTextDocumentParams) -> None:
    ls.documents.pop(params.text_document.uri, None)
    ls.good.pop(params.text_document.uri, None)
    ls.versions.pop(params.text_document.uri, None)
    ls.publish(params.text_document.uri, [], None)


@server.feature(lsp.TEXT_DOCUMENT_HOVER)
def hover(ls: WorkbookServer, params: lsp.HoverParams) -> lsp.Hover | None:
    doc = ls.doc(params.text_document.uri)
    return features.hover(doc, params.position.line, params.position.character)


@server.feature(
    lsp.TEXT_DOCUMENT_COMPLETION, lsp.CompletionOptions(trigger_characters=["[", "(", " ", '"'])
)
def completion(ls: WorkbookServer, params: lsp.CompletionParams) -> lsp.CompletionList:
    doc = ls.doc(params.text_document.uri)
    items = features.completion(doc, params.position.line, params.position.character)
    return lsp.CompletionList(is_incomplete=False, items=items)


@server.feature(lsp.TEXT_DOCUMENT_DEFINITION)
def definition(ls: WorkbookServer, params: lsp.DefinitionParams) -> lsp.Location | None:
    uri = params.text_document.uri
    return features.definition(ls.doc(uri), uri, params.position.line, params.position.character)


@server.feature(lsp.TEXT_DOCUMENT_DOCUMENT_SYMBOL)
def symbols(ls: WorkbookServer, params: lsp.DocumentSymbolParams) -> list[lsp.DocumentSymbol]:
    return features.outline(ls.doc(params.text_document.uri))
