"""The language server (pygls): documents loaded as they are opened and changed, their
diagnostics published twice (the load's at once, then with the values' when they are
computed), and the
answers of :mod:`.features`."""

from __future__ import annotations

import asyncio
from pathlib import Path

from lsprotocol import types as lsp
from pygls.lsp.server import LanguageServer
from pygls.uris import to_fs_path

from ..version import __version__
from . import document, features


class WorkbookServer(LanguageServer):
    """A LanguageServer that keeps the last load of every open worksheet."""

    def __init__(self):
        super().__init__("workbook", __version__)
        self.documents: dict[str, document.Document] = {}
        self.versions: dict[str, int] = {}

    def analyse(self, uri: str) -> document.Document:
        old = self.documents.get(uri)
        if old is not None:
            old.stale = True  # its values, if still being computed, stop
        text = self.workspace.get_text_document(uri).source
        path = Path(to_fs_path(uri) or "sheet.toml")
        doc = document.load(text, path)
        self.documents[uri] = doc
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


async def _changed(ls: WorkbookServer, uri: str, version: int | None) -> None:
    ls.versions[uri] = version or 0
    doc = ls.analyse(uri)
    ls.publish(uri, doc.problems, version)
    if doc.sheet is None:
        return
    loop = asyncio.get_running_loop()
    more = await loop.run_in_executor(None, document.compute_values, doc)
    if ls.versions.get(uri) == (version or 0) and ls.documents.get(uri) is doc:
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
