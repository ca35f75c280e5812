"""`rclverify lsp` end to end (issue 52, docs/editor.md): a real LSP client
(pytest-lsp) over stdio against the server in its own process, on the case
study's contracts after a real run of the pipeline's stages.

One server for the module (started once); the tests run in order and the
document's text is set by each test that edits it."""
from __future__ import annotations

import asyncio
import os
import sys
import time
from pathlib import Path

import pytest
import pytest_lsp
from lsprotocol import types as lsp
from pytest_lsp import ClientServerConfig, LanguageClient

from _lsp_ws import REPO, RCL, make_workspace, run_pipeline

pytestmark = pytest.mark.asyncio(loop_scope="module")

ENV = {**os.environ, "PYTHONPATH": str(REPO / "src") + os.pathsep + os.environ.get("PYTHONPATH", "")}


@pytest.fixture(scope="module")
def ws(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = make_workspace(tmp_path_factory.mktemp("lsp") / "rover")
    run_pipeline(root)
    return root


@pytest_lsp.fixture(scope="module", config=ClientServerConfig(
    server_command=[sys.executable, "-m", "rclverify.cli", "lsp"], server_env=ENV))
async def client(lsp_client: LanguageClient, ws: Path):
    await lsp_client.initialize_session(lsp.InitializeParams(
        capabilities=lsp.ClientCapabilities(), root_uri=ws.as_uri(),
        workspace_folders=[lsp.WorkspaceFolder(uri=ws.as_uri(), name="rover")]))
    yield
    await lsp_client.shutdown_session()


def uri(ws: Path, rel: str = RCL) -> str:
    return (ws / rel).as_uri()


async def diagnostics(client: LanguageClient, u: str, want, timeout: float = 10.0) -> list[lsp.Diagnostic]:
    """The diagnostics of ``u`` once ``want(diagnostics)`` holds (waits for publications)."""
    end = time.monotonic() + timeout
    while True:
        got = list(client.diagnostics.get(u, []))
        if want(got):
            return got
        left = end - time.monotonic()
        assert left > 0, f"no diagnostics as wanted within {timeout} s; last: {[(d.code, d.message) for d in got]}"
        try:
            await asyncio.wait_for(client.wait_for_notification(lsp.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS), left)
        except asyncio.TimeoutError:
            pass


def change(client: LanguageClient, u: str, version: int, text: str) -> None:
    client.text_document_did_change(lsp.DidChangeTextDocumentParams(
        text_document=lsp.VersionedTextDocumentIdentifier(uri=u, version=version),
        content_changes=[lsp.TextDocumentContentChangeWholeDocument(text=text)]))


async def test_open_shows_the_last_runs_findings(client: LanguageClient, ws: Path) -> None:
    """Opened as saved: the last run's findings in the file, with the SARIF rule ids and the repair attached."""
    text = (ws / RCL).read_text(encoding="utf-8")
    client.text_document_did_open(lsp.DidOpenTextDocumentParams(lsp.TextDocumentItem(uri(ws), "rcl", 1, text)))
    got = await diagnostics(client, uri(ws), lambda ds: any(d.code == "RCL-HEALTH-VACUOUS" for d in ds))
    vac = sorted(d.range.start.line + 1 for d in got if d.code == "RCL-HEALTH-VACUOUS")
    assert vac == [64, 69]  # guarantees 1 and 2 of the Agent, as the SARIF log places them
    assert {d.code for d in got} >= {"RCL-HEALTH-UNREALIZABLE", "RCL-LINT-UNUSED-BOUND", "W-unused-bound"}
    assert all(not d.message.startswith("stale") for d in got)
