"""A checked repair of the code as the editor's quick fix (issue 111; tools/lsp/actions.py, docs/editor.md):
a real LSP client (pytest-lsp) over stdio against ``rclverify lsp`` in its own process, on a workspace the
pipeline verified: ``Gate``'s property test fails at ``nodes/gate.py:5`` (``x < 3`` where the contract
says ``x <= 3``), and the Python file, opened in the editor, shows that finding (no RCL check of Python)
with the repairs the diagnosis checked by running the property tests again as quick fixes.  The control:
once the file is saved after the run the finding is stale and no repair is offered."""
from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest
import pytest_lsp
from lsprotocol import types as lsp
from pytest_lsp import ClientServerConfig, LanguageClient

from _lsp_ws import REPO, wait_diagnostics

pytestmark = [pytest.mark.asyncio(loop_scope="module"), pytest.mark.live]

ENV = {**os.environ, "PYTHONPATH": str(REPO / "src") + os.pathsep + os.environ.get("PYTHONPATH", "")}
RCL = """\
node Gate {
  inputs( x : INTEGER )
  outputs( ok : BOOL )
  assume( 0 <= in.x and in.x <= 10 )
  guarantee( in.x <= 3 -> out.ok )
  guarantee( in.x >= 4 -> not out.ok )
}
"""
GATE = '"""The gate (a seeded slip: < for <=)."""\n\n\ndef gate(x):\n    return {"ok": x < 3}\n'
PLAN = """contracts: [contracts/robot.rcl]
nodes:
  Gate:
    evidence:
      - {backend: property_tests, implementation: "nodes/gate.py:gate", max_examples: 60}
"""
PY = "nodes/gate.py"


@pytest.fixture(scope="module")
def ws(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from rclverify.cli.commands import main
    root = tmp_path_factory.mktemp("lsp_code_repair") / "ws"
    (root / "contracts").mkdir(parents=True)
    (root / "nodes").mkdir()
    (root / "contracts/robot.rcl").write_text(RCL, encoding="utf-8")
    (root / "contracts/plan.yaml").write_text(PLAN, encoding="utf-8")
    (root / PY).write_text(GATE, encoding="utf-8")
    main(["verify", "-w", str(root)])
    return root


@pytest_lsp.fixture(scope="module", config=ClientServerConfig(
    server_command=[sys.executable, "-m", "rclverify.cli.commands", "lsp"], server_env=ENV))
async def client(lsp_client: LanguageClient, ws: Path):
    await lsp_client.initialize_session(lsp.InitializeParams(
        capabilities=lsp.ClientCapabilities(), root_uri=ws.as_uri(),
        workspace_folders=[lsp.WorkspaceFolder(uri=ws.as_uri(), name="gate")]))
    yield
    await lsp_client.shutdown_session()


def _applied(text: str, edit: lsp.TextEdit) -> str:
    lines = text.split("\n")
    r = edit.range
    assert r.start.line == r.end.line
    line = lines[r.start.line]
    lines[r.start.line] = line[:r.start.character] + edit.new_text + line[r.end.character:]
    return "\n".join(lines)


async def test_the_property_tests_repair_is_a_quick_fix_in_the_python_file(client: LanguageClient, ws: Path) -> None:
    u = (ws / PY).as_uri()
    client.text_document_did_open(lsp.DidOpenTextDocumentParams(lsp.TextDocumentItem(u, "python", 1, GATE)))
    got = await wait_diagnostics(client, u, lambda ds: any(d.code == "RCL-OBL-FAILED" for d in ds), 20.0)
    # the Python is not checked as RCL: the last run's finding is all there is
    assert [d.source for d in got] == ["rclverify (last run)"], [(d.source, d.message[:60]) for d in got]
    [failed] = got
    assert failed.range.start.line == 4 and not failed.message.startswith("stale")
    actions = await client.text_document_code_action_async(lsp.CodeActionParams(
        lsp.TextDocumentIdentifier(u), failed.range, lsp.CodeActionContext(diagnostics=[failed])))
    assert actions and all(a.kind == lsp.CodeActionKind.QuickFix for a in actions)
    [fix] = [a for a in actions if a.edit and a.edit.changes[u][0].new_text == "<="]
    assert "\u2014 the property tests show: every guarantee of Gate (2) held again" in fix.title
    assert "not shown: that the edit is right for the robot" in fix.title
    assert fix.diagnostics and fix.diagnostics[0].code == "RCL-OBL-FAILED"
    [edit] = fix.edit.changes[u]
    assert _applied(GATE, edit) == GATE.replace("x < 3", "x <= 3")
    # no RCL keywords offered in Python
    done = await client.text_document_completion_async(lsp.CompletionParams(
        lsp.TextDocumentIdentifier(u), lsp.Position(4, 4)))
    assert done is not None and not done.items


async def test_control_saved_after_the_run_no_repair_is_offered(client: LanguageClient, ws: Path) -> None:
    u = (ws / PY).as_uri()
    fixed = GATE.replace("x < 3", "x <= 3")
    client.text_document_did_change(lsp.DidChangeTextDocumentParams(
        text_document=lsp.VersionedTextDocumentIdentifier(uri=u, version=2),
        content_changes=[lsp.TextDocumentContentChangeWholeDocument(text=fixed)]))
    (ws / PY).write_text(fixed, encoding="utf-8")
    sarif = ws / "reports/assurance.sarif"
    stamp = sarif.stat().st_mtime + 2
    os.utime(ws / PY, (stamp, stamp))  # saved after the run wrote its log, whatever the clock's resolution
    client.text_document_did_save(lsp.DidSaveTextDocumentParams(lsp.TextDocumentIdentifier(u)))
    got = await wait_diagnostics(client, u, lambda ds: bool(ds) and all(d.message.startswith("stale") for d in ds),
                                 20.0)
    actions = await client.text_document_code_action_async(lsp.CodeActionParams(
        lsp.TextDocumentIdentifier(u), got[0].range, lsp.CodeActionContext(diagnostics=got)))
    assert not actions
