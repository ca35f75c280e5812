"""`rclverify lsp` answers what it cannot serve in one line (issue 63, row 11): the guard around
every handler, a malformed root URI, requests after ``shutdown`` and a notification pygls cannot
read (over raw JSON-RPC, a short-lived server of its own).  The random requests are in
tests/tools/test_lsp_fuzz.py."""
from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Any

import pytest
from lsprotocol import types as lsp
from pygls.exceptions import JsonRpcException

REPO = Path(__file__).resolve().parents[2]
ENV = {**os.environ, "PYTHONPATH": str(REPO / "src") + os.pathsep + os.environ.get("PYTHONPATH", "")}
#: Seconds the short-lived server may take for the whole exchange.
BOUND = 10.0


def test_an_unexpected_exception_is_one_line() -> None:
    """The guard around every handler (in this process: no request makes the real server fail on purpose)."""
    from rclverify.tools.lsp.rpc import guarded

    @guarded("textDocument/hover")
    def broken(ls: Any, params: Any) -> None:
        raise KeyError("a\nb")

    with pytest.raises(JsonRpcException) as exc:
        broken(None, None)
    assert exc.value.code == -32603 and exc.value.data is None
    assert exc.value.message == "textDocument/hover: internal error of the language server (KeyError: 'a\\nb'); it goes on serving"


def test_a_malformed_root_uri_leaves_the_working_directory_the_root() -> None:
    from rclverify.tools.lsp.server import _root_of
    for bad in ("file://[::1/ws", "file:///srv/a%00b", "file:///srv/a\x00b"):
        assert _root_of(lsp.InitializeParams(capabilities=lsp.ClientCapabilities(), root_uri=bad)) is None, bad
    assert _root_of(lsp.InitializeParams(capabilities=lsp.ClientCapabilities(), root_uri="file:///srv/w%20s")) == Path("/srv/w s")

def test_requests_after_shutdown_are_answered(tmp_path: Path) -> None:
    """Over raw JSON-RPC (its own short-lived server): a notification pygls cannot read is logged in one line,
    and a request after ``shutdown`` is answered -32600 (LSP 3.17 "Shutdown Request"), not dropped."""
    import json
    import subprocess

    from _procs import stop
    proc = subprocess.Popen([sys.executable, "-m", "rclverify.cli.commands", "lsp", "-w", str(tmp_path)], env=ENV,
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
    try:
        def send(msg: dict[str, Any]) -> None:
            body = json.dumps(msg).encode()
            proc.stdin.write(b"Content-Length: %d\r\n\r\n" % len(body) + body)  # type: ignore[union-attr]
            proc.stdin.flush()  # type: ignore[union-attr]

        send({"jsonrpc": "2.0", "id": 1, "method": "initialize", "params": {"capabilities": {}}})
        send({"jsonrpc": "2.0", "method": "textDocument/didOpen", "params": {"textDocument": {"uri": 5}}})
        send({"jsonrpc": "2.0", "id": 2, "method": "shutdown"})
        send({"jsonrpc": "2.0", "id": 3, "method": "textDocument/hover",
              "params": {"textDocument": {"uri": (tmp_path / "a.rcl").as_uri()}, "position": {"line": 0, "character": 0}}})
        send({"jsonrpc": "2.0", "method": "exit"})
        out, err = proc.communicate(timeout=BOUND)
    finally:
        stop(proc)
    msgs = [json.loads(part.split(b"\r\n\r\n", 1)[1]) for part in out.split(b"Content-Length: ")[1:]]
    by_id = {m.get("id"): m for m in msgs if "id" in m}
    assert set(by_id) == {1, 2, 3}, msgs
    assert by_id[3]["error"] == {"code": -32600, "message": "textDocument/hover: the server is shutting down "
                                                             "(it received `shutdown`)"}
    logs = [m["params"]["message"] for m in msgs if m.get("method") == "window/logMessage"]
    assert logs == ["the server could not handle a message (JsonRpcInvalidParams: Invalid Params)"], msgs
    assert b"Traceback" not in err and all(len(line) <= 400 for line in err.splitlines()), err.decode()
