"""`rclverify lsp` on hostile text (issue 52): the RCL corpus the command
line is hardened against (deep nesting, bad bytes, a file over the size
limit, half-typed text at every prefix of a contract) never crashes the
server nor keeps it from answering past its time limit; a request about a
file outside the workspace is refused.  One server for the module."""
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

from _lsp_ws import wait_diagnostics

REPO = Path(__file__).resolve().parents[2]
ENV = {**os.environ, "PYTHONPATH": str(REPO / "src") + os.pathsep + os.environ.get("PYTHONPATH", "")}
pytestmark = pytest.mark.asyncio(loop_scope="module")

#: What the server may take for one check before it says so (server.TIME_LIMIT) plus slack for a shared machine.
LIMIT = 5.0 + 3.0

CONTRACT = """context {
  Mode : {idle, busy} ;
  vmax : REAL [m/s] = 2.0 [m/s] ;
}

node Driver {
  inputs( goal : REAL [m], mode : Mode )
  outputs( speed : REAL [m/s] )
  topics( geometry_msgs/Twist cmd_vel matches(out.speed) )
  assume( in.mode in {idle, busy} )
  guarantee( in.mode == idle -> out.speed == 0 [m/s] )
  guarantee( forall(k in NATURAL | k <= 3 -> 0 [m/s] <= out.speed and out.speed <= vmax) )
}
"""


@pytest.fixture(scope="module")
def ws(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("hostile") / "ws"
    (root / "contracts").mkdir(parents=True)
    (root / "contracts" / "a.rcl").write_text(CONTRACT, encoding="utf-8")
    (root / "contracts" / "bad.rcl").write_bytes(CONTRACT.encode() + b"\n// \xff\xfe broken\n")
    (root / "contracts" / "plan.yaml").write_text(
        "name: hostile\ncontracts: [contracts/a.rcl, contracts/bad.rcl]\nrequirements: []\nconnections: []\n"
        "environment: {}\nnodes: {}\n", encoding="utf-8")
    outside = root.parent / "outside"
    outside.mkdir()
    (outside / "o.rcl").write_text(CONTRACT, encoding="utf-8")
    (root / "contracts" / "link.rcl").symlink_to(outside / "o.rcl")
    return root


@pytest_lsp.fixture(scope="module", config=ClientServerConfig(
    server_command=[sys.executable, "-m", "rclverify.cli.commands", "lsp"], server_env=ENV))
async def client(lsp_client: LanguageClient, ws: Path):
    await lsp_client.initialize_session(lsp.InitializeParams(capabilities=lsp.ClientCapabilities(), root_uri=ws.as_uri()))
    yield
    await lsp_client.shutdown_session()


def open_doc(client: LanguageClient, u: str, text: str) -> None:
    client.text_document_did_open(lsp.DidOpenTextDocumentParams(lsp.TextDocumentItem(u, "rcl", 1, text)))


def change(client: LanguageClient, u: str, version: int, text: str) -> None:
    client.text_document_did_change(lsp.DidChangeTextDocumentParams(
        text_document=lsp.VersionedTextDocumentIdentifier(uri=u, version=version),
        content_changes=[lsp.TextDocumentContentChangeWholeDocument(text=text)]))


async def wait_for(client: LanguageClient, u: str, want, timeout: float = LIMIT) -> list[lsp.Diagnostic]:
    return await wait_diagnostics(client, u, want, timeout)


async def answers(client: LanguageClient, u: str) -> float:
    """Seconds the server takes to answer a hover on ``u`` (it must answer)."""
    t = time.monotonic()
    await asyncio.wait_for(client.text_document_hover_async(lsp.HoverParams(lsp.TextDocumentIdentifier(u),
                                                                            lsp.Position(0, 0))), LIMIT)
    return time.monotonic() - t


async def test_bad_bytes_on_disk_are_one_located_error(client: LanguageClient, ws: Path) -> None:
    u = (ws / "contracts" / "a.rcl").as_uri()
    open_doc(client, u, CONTRACT)
    got = await wait_for(client, (ws / "contracts" / "bad.rcl").as_uri(), lambda ds: bool(ds))
    from rclverify.lang.errors import RclError
    from rclverify.lang.source import read_text
    with pytest.raises(RclError) as exc:  # what `rclverify check` says of the file
        read_text(ws / "contracts" / "bad.rcl", "contracts/bad.rcl")
    (d,) = exc.value.diagnostics
    assert [(x.code, x.range.start.line + 1, x.range.start.character + 1, x.message) for x in got] == [
        ("E-encoding", d.loc.line, d.loc.col, d.message)]
    assert "invalid UTF-8 (byte 0xff" in d.message and d.loc.line > 1


async def test_deep_nesting_and_strange_characters(client: LanguageClient, ws: Path) -> None:
    u = (ws / "contracts" / "a.rcl").as_uri()
    deep = CONTRACT.replace("guarantee( in.mode == idle", "guarantee( " + "not (" * 3000 + "TRUE" + ")" * 3000 + " and in.mode == idle")
    change(client, u, 2, deep)
    got = await wait_for(client, u, lambda ds: any(d.code == "E-depth" for d in ds))
    assert got[0].message == "too deeply nested (limit 200)"
    weird = CONTRACT.replace("Driver", "Dr\u00efver\U0001f916\udcff\x00\ufeff")
    change(client, u, 3, weird)
    got = await wait_for(client, u, lambda ds: any(d.code == "E-syntax" for d in ds))
    (syn,) = [d for d in got if d.code == "E-syntax"]
    assert syn.range.start.line == 5 and syn.range.start.character == 7  # after "node Dr\u00efver": the robot, 2 UTF-16 units
    assert await answers(client, u) < 1.0


async def test_over_the_size_limit_and_the_server_still_answers(client: LanguageClient, ws: Path) -> None:
    from rclverify.tools.lsp.diagnostics import MAX_CHARS
    u = (ws / "contracts" / "a.rcl").as_uri()
    huge = CONTRACT + "// padding\n" * (MAX_CHARS // 11 + 1)
    change(client, u, 4, huge)
    got = await wait_for(client, u, lambda ds: any(d.code == "E-lsp-size" for d in ds))
    assert "run `rclverify check contracts/a.rcl`" in got[0].message
    big = CONTRACT + "".join(CONTRACT.split("node Driver")[1].replace("{", f"node D{k} {{", 1) for k in range(400))
    change(client, u, 5, big)  # 400 nodes: checked in a worker thread while the server answers
    assert await answers(client, u) < 1.0
    await wait_for(client, u, lambda ds: not any(d.code == "E-lsp-size" for d in ds))


async def test_every_prefix_of_a_contract(client: LanguageClient, ws: Path) -> None:
    """Half-typed text: the checker on every prefix (in this process) gives located diagnostics and no
    exception; the server, sent every prefix in a burst, answers at once and ends on the full text."""
    from rclverify.tools.lsp.diagnostics import analyse, lsp_range
    from rclverify.tools.lsp.workspace import LspWorkspace
    lw = LspWorkspace(ws)
    for k in range(len(CONTRACT) + 1):
        a = analyse(lw, "contracts/a.rcl", {"contracts/a.rcl": CONTRACT[:k]})
        lines = CONTRACT[:k].split("\n")
        for d in a.diagnostics.get("contracts/a.rcl", []):
            r = lsp_range(d.loc, lines)
            assert 0 <= r.start.line < max(len(lines), 1), (k, d)
    u = (ws / "contracts" / "a.rcl").as_uri()
    for k in range(0, len(CONTRACT) + 1, 7):
        change(client, u, 100 + k, CONTRACT[:k])
    change(client, u, 10_000, CONTRACT + "\n")
    assert await answers(client, u) < 1.0
    got = await wait_for(client, u, lambda ds: not any(d.code in ("E-syntax", "E-lsp-size", "E-depth") for d in ds))
    assert not [d for d in got if d.severity == lsp.DiagnosticSeverity.Error and d.source == "rclverify"]


async def test_outside_the_workspace_is_refused(client: LanguageClient, ws: Path) -> None:
    from pygls.exceptions import JsonRpcException
    outside = ws.parent / "outside" / "o.rcl"
    for u in (outside.as_uri(), (ws / "contracts" / "link.rcl").as_uri(),
              (ws / "contracts" / ".." / ".." / "outside" / "o.rcl").as_uri().replace("%2E", "."), "untitled:Untitled-1"):
        with pytest.raises(JsonRpcException, match="refused"):
            await client.text_document_definition_async(lsp.DefinitionParams(lsp.TextDocumentIdentifier(u),
                                                                              lsp.Position(5, 6)))
    open_doc(client, outside.as_uri(), CONTRACT.replace("2.0", "oops"))
    assert await answers(client, (ws / "contracts" / "a.rcl").as_uri()) < 1.0
    assert outside.as_uri() not in client.diagnostics
