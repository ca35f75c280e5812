"""`rclverify lsp` under random and invalid requests (issue 63, row 11).

The server is driven over stdio by a real LSP client (pytest-lsp), one
server for the module:

* the three findings of the hostile round, each a test that failed before
  the fix: a position past the end (up to a line no ``uinteger`` holds) is
  answered; a NUL in a document URI is answered with one sentence and no
  traceback; formatting a file with bare-CR line ends gives edits that,
  applied as LSP applies them, give the formatted text with CR line ends;
* a bounded fuzz run (fixed seed, :data:`REQUESTS` requests): hover,
  definition, references, completion, formatting and code actions at
  random positions (in range, past the end of the line, past the end of the
  document), in documents with random line ends (``\\n``, ``\\r\\n``, ``\\r``,
  mixed, a byte-order mark, characters outside the BMP before a clause),
  on random URIs (inside, outside, a NUL, other schemes).  Every request is
  answered within :data:`BOUND` seconds; no error is an internal one, none
  holds a traceback or a path of the server's code; every formatting
  result, applied with :func:`apply_edits` (LSP's rules, written here),
  keeps the document's line ends, re-parses to the same contract, and
  formatting it again gives no edit.
"""
from __future__ import annotations

import asyncio
import os
import random
import re
import sys
import time
from pathlib import Path
from typing import Any

import pytest
import pytest_lsp
from lsprotocol import types as lsp
from pygls.exceptions import JsonRpcException
from pytest_lsp import ClientServerConfig, LanguageClient

REPO = Path(__file__).resolve().parents[2]
ENV = {**os.environ, "PYTHONPATH": str(REPO / "src") + os.pathsep + os.environ.get("PYTHONPATH", "")}
pytestmark = pytest.mark.asyncio(loop_scope="module")

#: Seconds one request may take to be answered (the handlers answer in milliseconds; slack for 2 shared cores).
BOUND = 5.0
#: Random requests of the fuzz run, and its seed.
REQUESTS = 400
SEED = int(os.environ.get("RCL_LSP_FUZZ_SEED", "6311"))

#: Not in the form `rclverify fmt` prints (two clauses to format), comments between clauses kept,
#: a character outside the BMP (two UTF-16 units) before the second clause on its line.
CONTRACT = """// header \U0001f916 of the file
context { Mode : {idle, busy} ;
  vmax : REAL [m/s] = 2.0 [m/s] ; }
/* \U0001f916 */ node Driver { inputs( goal : REAL [m], mode : Mode ) outputs( speed : REAL [m/s] )
  topics( geometry_msgs/Twist cmd_vel matches(out.speed) )
  assume( in.mode in {idle, busy} )
  guarantee( in.mode == idle -> out.speed == 0 [m/s] ) }

node Brake {
  inputs( speed : REAL [m/s] )
  outputs( stop : BOOL )
  guarantee( out.stop -> in.speed <= vmax )
}
"""
PLAN = ("name: fuzz\ncontracts: [contracts/a.rcl]\nrequirements: []\nconnections: []\n"
        "environment: {}\nnodes: {}\n")
#: The end-of-line sequences of LSP 3.17 ("Text Documents").
EOLS = ("\n", "\r\n", "\r")
_BREAK = re.compile(r"\r\n|\r|\n")
#: What an error message may not hold: a traceback, a file of the server's code.
_LEAK = re.compile(r"Traceback|File \"|\.py\b|site-packages|rclverify/tools/lsp/")


# -- LSP's rules, written here (not the server's code) ----------------------------------------------

def offset(text: str, pos: lsp.Position) -> int:
    """The string offset of an LSP position in ``text`` (LSP 3.17 "Position": lines end at ``\\r\\n``,
    ``\\r`` or ``\\n``; ``character`` counts UTF-16 units; a character past the line's end means the
    line's end; a line past the last means the end of the text)."""
    starts, ends = [0], []
    for m in _BREAK.finditer(text):
        ends.append(m.start())
        starts.append(m.end())
    ends.append(len(text))
    if pos.line >= len(starts):
        return len(text)
    k, units = starts[pos.line], 0
    while k < ends[pos.line] and units < pos.character:
        units += 2 if ord(text[k]) > 0xFFFF else 1
        k += 1
    return k


def apply_edits(text: str, edits: list[lsp.TextEdit]) -> str:
    """``text`` with ``edits`` applied as LSP applies them: every range is of
    the original text, ranges do not overlap, so they are applied from the last."""
    spans = sorted(((offset(text, e.range.start), offset(text, e.range.end), e.new_text) for e in edits), reverse=True)
    for (s, e, _), (s2, e2, _) in zip(spans[1:], spans):
        assert e <= s2, f"overlapping edits {s}-{e} and {s2}-{e2}"
    for s, e, new in spans:
        assert s <= e
        text = text[:s] + new + text[e:]
    return text


def with_eols(text: str, rng: random.Random, kind: str) -> str:
    """``text`` (``\\n`` line ends) with the line ends of ``kind``: one of :data:`EOLS`, or ``mixed``."""
    if kind != "mixed":
        return text.replace("\n", kind)
    return "".join(line + (rng.choice(EOLS) if k < text.count("\n") else "")
                   for k, line in enumerate(text.split("\n")))


def normalize(text: str) -> str:
    return _BREAK.sub("\n", text)


def printed(text: str) -> str:
    """The contract of ``text`` as `rclverify fmt` prints it (what a formatting may not change)."""
    from rclverify.lang.parser import parse_text
    from rclverify.lang.printer import to_rcl
    return to_rcl(parse_text(normalize(text).lstrip("\ufeff"), "a.rcl"))


# -- the server ------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def ws(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("fuzz") / "w s\u00e9"  # a URI with escapes (%20, %C3%A9)
    (root / "contracts").mkdir(parents=True)
    (root / "contracts" / "a.rcl").write_text(CONTRACT, encoding="utf-8")
    (root / "contracts" / "b.rcl").write_text(CONTRACT.replace("Driver", "Other").replace("Brake", "Halt"), encoding="utf-8")
    (root / "contracts" / "plan.yaml").write_text(PLAN, encoding="utf-8")
    (root.parent / "outside.rcl").write_text(CONTRACT, encoding="utf-8")
    return root


@pytest_lsp.fixture(scope="module", config=ClientServerConfig(
    server_command=[sys.executable, "-m", "rclverify.cli.commands", "lsp"], server_env=ENV))
async def client(lsp_client: LanguageClient, ws: Path):
    await lsp_client.initialize_session(lsp.InitializeParams(capabilities=lsp.ClientCapabilities(), root_uri=ws.as_uri()))
    yield
    await lsp_client.shutdown_session()


def open_doc(client: LanguageClient, u: str, text: str, version: int = 1) -> None:
    client.text_document_did_open(lsp.DidOpenTextDocumentParams(lsp.TextDocumentItem(u, "rcl", version, text)))


def change(client: LanguageClient, u: str, version: int, text: str) -> None:
    client.text_document_did_change(lsp.DidChangeTextDocumentParams(
        text_document=lsp.VersionedTextDocumentIdentifier(uri=u, version=version),
        content_changes=[lsp.TextDocumentContentChangeWholeDocument(text=text)]))


async def answer(coro: Any) -> tuple[Any, JsonRpcException | None]:
    """``(result, None)`` or ``(None, error)`` of a request; fails when it is not answered within :data:`BOUND`."""
    try:
        return await asyncio.wait_for(coro, BOUND), None
    except JsonRpcException as exc:
        return None, exc
    except asyncio.TimeoutError:
        raise AssertionError(f"not answered within {BOUND} s") from None


def one_sentence(exc: JsonRpcException) -> None:
    """The error is one line with no traceback and no file of the server's code, and not an internal error."""
    assert exc.code != -32603, exc.message
    assert exc.message and "\n" not in exc.message and not _LEAK.search(exc.message), exc.message
    assert exc.data is None, exc.data


def beyond(line: int, character: int) -> lsp.Position:
    """A position the client's types would refuse (a line no ``uinteger`` holds), built past their check."""
    pos = lsp.Position(0, 0)
    object.__setattr__(pos, "line", line)
    object.__setattr__(pos, "character", character)
    return pos


async def formatting(client: LanguageClient, u: str) -> list[lsp.TextEdit]:
    got, err = await answer(client.text_document_formatting_async(lsp.DocumentFormattingParams(
        lsp.TextDocumentIdentifier(u), lsp.FormattingOptions(tab_size=2, insert_spaces=True))))
    assert err is None, err
    return list(got or [])


# -- the hostile round's findings ------------------------------------------------------------------

async def test_a_position_past_the_end_is_answered(client: LanguageClient, ws: Path) -> None:
    u = (ws / "contracts" / "a.rcl").as_uri()
    open_doc(client, u, CONTRACT)
    lines = CONTRACT.count("\n") + 1
    for line, char in ((lines + 5, 0), (2, 10_000), (2**31 - 1, 2**31 - 1)):
        got, err = await answer(client.text_document_hover_async(lsp.HoverParams(lsp.TextDocumentIdentifier(u),
                                                                                 lsp.Position(line, char))))
        assert err is None, err
    doc, far = lsp.TextDocumentIdentifier(u), beyond(2**31, 0)
    for method, coro in (("textDocument/hover", client.text_document_hover_async(lsp.HoverParams(doc, far))),
                         ("textDocument/definition", client.text_document_definition_async(lsp.DefinitionParams(doc, far))),
                         ("textDocument/completion", client.text_document_completion_async(lsp.CompletionParams(doc, far)))):
        # a line past what LSP's uinteger holds (2^31 - 1): an invalid position, answered -32602
        got, err = await answer(coro)
        assert err is not None and err.code == -32602, (method, got)
        assert err.message.startswith(f"{method}: invalid params (position") and "\n" not in err.message
    got, err = await answer(client.text_document_hover_async(lsp.HoverParams(lsp.TextDocumentIdentifier(u),
                                                                             lsp.Position(8, 6))))
    assert err is None  # still serving


async def test_a_nul_in_a_uri_is_answered_without_a_traceback(client: LanguageClient, ws: Path) -> None:
    base = (ws / "contracts" / "a.rcl").as_uri()
    for u in (base + "\x00x", base.replace("a.rcl", "%00a.rcl"), base + "\ud800"):
        got, err = await answer(client.text_document_hover_async(lsp.HoverParams(lsp.TextDocumentIdentifier(u),
                                                                                 lsp.Position(1, 2))))
        assert err is not None and err.code == -32602, got
        one_sentence(err)
        assert "refused: not a valid file name" in err.message and "\x00" not in err.message
    open_doc(client, base + "\x00x", CONTRACT)  # a notification: ignored with a log message
    got, err = await answer(client.text_document_hover_async(lsp.HoverParams(lsp.TextDocumentIdentifier(base),
                                                                             lsp.Position(1, 2))))
    assert err is None
    assert not [m for m in client.messages if m.type == lsp.MessageType.Error], client.messages


#: The contract, and the contract without its first line's `//` comment (which, read with `\n` line ends only,
#: hides a bare-CR file whole: the file then is not formatted; without it, the edits were computed on one long line).
TEXTS = {"comment": CONTRACT, "no-comment": CONTRACT.split("\n", 1)[1]}


@pytest.mark.parametrize("eol", EOLS, ids=["lf", "crlf", "cr"])
@pytest.mark.parametrize("which", TEXTS)
async def test_formatting_keeps_the_documents_line_ends(client: LanguageClient, ws: Path, eol: str, which: str) -> None:
    u, lf = (ws / "contracts" / "b.rcl").as_uri(), TEXTS[which]
    text = lf.replace("\n", eol)
    open_doc(client, u, text)
    edits = await formatting(client, u)
    assert edits
    got = apply_edits(text, edits)
    want = apply_edits(lf, await formatting_lf(client, ws, lf))  # the same text with \n line ends, formatted
    assert got == want.replace("\n", eol)
    assert printed(got) == printed(lf)
    change(client, u, 2, got)
    assert await formatting(client, u) == []
    client.text_document_did_close(lsp.DidCloseTextDocumentParams(lsp.TextDocumentIdentifier(u)))


async def formatting_lf(client: LanguageClient, ws: Path, text: str) -> list[lsp.TextEdit]:
    u = (ws / "contracts" / "lf.rcl").as_uri()
    open_doc(client, u, text)
    try:
        return await formatting(client, u)
    finally:
        client.text_document_did_close(lsp.DidCloseTextDocumentParams(lsp.TextDocumentIdentifier(u)))


async def test_a_quick_fix_inserts_the_documents_line_end(client: LanguageClient, ws: Path) -> None:
    """A repair of the last run whose text spans two lines, offered in a CRLF file: its edit inserts CRLF.
    The SARIF log is written here in the form the report writes (the fix by rclverify.diagnosis.edits.sarif_fix,
    the run's own producer of it): a run of the pipeline offers no repair of two lines to test with."""
    import json

    from rclverify.records.repair_rows import EditRow
    from rclverify.records.sarif import sarif_fix
    rel = "contracts/c.rcl"
    lf = CONTRACT.replace("Driver", "Third").replace("Brake", "Stop")
    text = lf.replace("\n", "\r\n")
    (ws / rel).write_bytes(text.encode("utf-8"))
    line = lf.split("\n").index("  guarantee( out.stop -> in.speed <= vmax )") + 1
    fix = sarif_fix("Split guarantee 1 of Stop. Z3 shows: nothing; not shown: anything.", EditRow(
        file=rel, line=line, col=3, end_line=line, end_col=44,
        inserted="guarantee( out.stop -> in.speed <= vmax )\n  guarantee( in.speed >= 0 [m/s] )",
        deleted="guarantee( out.stop -> in.speed <= vmax )"))
    result = {"ruleId": "RCL-TEST", "level": "warning", "message": {"text": "a finding"}, "fixes": [fix],
              "locations": [{"physicalLocation": {"artifactLocation": {"uri": rel},
                                                  "region": {"startLine": line, "startColumn": 3}}}]}
    sarif = ws / "reports" / "assurance.sarif"
    sarif.parent.mkdir(exist_ok=True)
    sarif.write_text(json.dumps({"version": "2.1.0", "runs": [{"results": [result]}]}), encoding="utf-8")
    stamp = (ws / rel).stat().st_mtime + 1
    os.utime(sarif, (stamp, stamp))  # the run wrote its log after the file was saved: the finding is fresh
    u = (ws / rel).as_uri()
    open_doc(client, u, text)
    got, err = await answer(client.text_document_code_action_async(lsp.CodeActionParams(
        lsp.TextDocumentIdentifier(u), lsp.Range(lsp.Position(line - 1, 0), lsp.Position(line - 1, 5)),
        lsp.CodeActionContext(diagnostics=[]))))
    assert err is None and got, (err, got)
    (edit,) = got[0].edit.changes[u]
    assert "\r\n" in edit.new_text and "\n" not in edit.new_text.replace("\r\n", "")
    fixed = apply_edits(text, [edit])
    assert set(_BREAK.findall(fixed)) == {"\r\n"}
    assert normalize(fixed) == lf.replace("  guarantee( out.stop -> in.speed <= vmax )",
                                          "  guarantee( out.stop -> in.speed <= vmax )\n  guarantee( in.speed >= 0 [m/s] )")
    client.text_document_did_close(lsp.DidCloseTextDocumentParams(lsp.TextDocumentIdentifier(u)))


async def test_formatting_a_text_over_the_size_limit_is_refused_at_once(client: LanguageClient, ws: Path) -> None:
    from rclverify.tools.lsp.diagnostics import MAX_CHARS
    u = (ws / "contracts" / "b.rcl").as_uri()
    open_doc(client, u, CONTRACT + "// padding\r\n" * (MAX_CHARS // 12 + 1))
    t = time.monotonic()
    got, err = await answer(client.text_document_formatting_async(lsp.DocumentFormattingParams(
        lsp.TextDocumentIdentifier(u), lsp.FormattingOptions(tab_size=2, insert_spaces=True))))
    assert err is not None and err.code == -32803 and "run `rclverify fmt contracts/b.rcl`" in err.message, (got, err)
    one_sentence(err)
    assert time.monotonic() - t < 2.0
    client.text_document_did_close(lsp.DidCloseTextDocumentParams(lsp.TextDocumentIdentifier(u)))


async def test_every_position_of_a_cr_document(client: LanguageClient, ws: Path) -> None:
    """Hover, completion, definition and references at every position of the contract with bare-CR line
    ends (and one past each line's end): every one answered, none an error; what hover finds on a name
    is what it finds at the same place of the `\\n` document."""
    u = (ws / "contracts" / "a.rcl").as_uri()
    lf = CONTRACT
    change(client, u, 50, lf.replace("\n", "\r"))
    from _lsp_ws import wait_diagnostics
    await wait_diagnostics(client, u, lambda ds: not any(d.code == "E-syntax" for d in ds), BOUND)
    doc, positions = lsp.TextDocumentIdentifier(u), []
    for k, line in enumerate(lf.split("\n")):
        positions += [lsp.Position(k, c) for c in range(len(line.encode("utf-16-le")) // 2 + 2)]
    requests = []
    for p in positions:
        requests += [client.text_document_hover_async(lsp.HoverParams(doc, p)),
                     client.text_document_completion_async(lsp.CompletionParams(doc, p)),
                     client.text_document_definition_async(lsp.DefinitionParams(doc, p)),
                     client.text_document_references_async(lsp.ReferenceParams(
                         context=lsp.ReferenceContext(include_declaration=True), text_document=doc, position=p))]
    got = await asyncio.wait_for(asyncio.gather(*requests, return_exceptions=True), BOUND * 4)
    errors = [(positions[k // 4], g) for k, g in enumerate(got) if isinstance(g, BaseException)]
    assert not errors, errors[:3]
    hovers = {(p.line, p.character): got[4 * k] for k, p in enumerate(positions)}
    assert hovers[(8, 6)] is not None and "node Brake" in hovers[(8, 6)].contents.value  # `Brake` on line 9
    assert hovers[(4, 10)] is None  # inside `topics(`: nothing to say
    units = got[4 * positions.index(lsp.Position(2, 16)) + 1]  # after `REAL [m` on line 3: the unit symbols
    assert "m" in {i.label for i in units.items} and all(i.kind == lsp.CompletionItemKind.Unit for i in units.items)
    change(client, u, 51, lf)


async def test_every_position_of_the_plan(client: LanguageClient, ws: Path) -> None:
    """The plan open in the editor with names of every form (`in.x` alone, `Node.in.x`, `Node.out.y`, a node):
    hover, definition and references at every position answered, none an error (a bare `in.x` raised)."""
    u = (ws / "contracts" / "plan.yaml").as_uri()
    text = PLAN + "notes: [in.speed, Driver.in.goal, Driver.out.speed, Brake, in.x.y, Brake.in]\r\n"
    open_doc(client, u, text)
    doc, requests = lsp.TextDocumentIdentifier(u), []
    positions = [lsp.Position(k, c) for k, line in enumerate(_BREAK.split(text)) for c in range(len(line) + 2)]
    for p in positions:
        requests += [client.text_document_hover_async(lsp.HoverParams(doc, p)),
                     client.text_document_definition_async(lsp.DefinitionParams(doc, p)),
                     client.text_document_references_async(lsp.ReferenceParams(
                         context=lsp.ReferenceContext(include_declaration=True), text_document=doc, position=p))]
    got = await asyncio.wait_for(asyncio.gather(*requests, return_exceptions=True), BOUND * 4)
    errors = [(positions[k // 3], g) for k, g in enumerate(got) if isinstance(g, BaseException)]
    assert not errors, errors[:3]
    line = len(_BREAK.split(PLAN)) - 1
    driver = got[3 * positions.index(lsp.Position(line, text.split("\n")[line].index("Driver.in.goal") + 1))]
    assert driver is not None and driver.contents.value.startswith("**in.goal** of Driver")
    client.text_document_did_close(lsp.DidCloseTextDocumentParams(doc))


# -- the fuzz run ------------------------------------------------------------------------------------

def _document(rng: random.Random) -> str:
    text = CONTRACT
    if rng.random() < 0.3:  # more to format: spaces collapsed, a clause on one line
        text = text.replace("\n  ", " ", rng.randint(1, 6))
    if rng.random() < 0.2:
        text = "\ufeff" + text
    text = with_eols(text, rng, rng.choice([*EOLS, "mixed"]))
    for _ in range(rng.choice([0, 0, 0, 1, 3])):  # hostile edits: a slice cut, or a strange character put in
        k = rng.randrange(len(text) + 1)
        if rng.random() < 0.5:
            text = text[:k] + text[k + rng.randint(1, 12):]
        else:
            text = text[:k] + rng.choice(["\x00", "\u2028", "\x0c", "\r", "\n", "{", "}", "\U0001f916", "\ufeff", "//"]) + text[k:]
    return text


def _uris(ws: Path) -> list[tuple[str, str]]:
    a = (ws / "contracts" / "a.rcl").as_uri()
    return [("doc", a), ("doc", a), ("doc", a), ("doc", a), ("disk", (ws / "contracts" / "b.rcl").as_uri()),
            ("plan", (ws / "contracts" / "plan.yaml").as_uri()), ("missing", (ws / "contracts" / "none.rcl").as_uri()),
            ("dir", (ws / "contracts").as_uri()), ("outside", (ws.parent / "outside.rcl").as_uri()),
            ("refused", a + "\x00"), ("refused", a.replace("a.rcl", "%00")), ("refused", "untitled:Untitled-1"),
            ("refused", "http://example.invalid/a.rcl"), ("refused", "file:///../../etc/passwd"), ("refused", "\x00"),
            ("refused", "file://[::1/a.rcl")]


def _position(rng: random.Random, text: str) -> lsp.Position:
    lines = _BREAK.split(text)
    r = rng.random()
    if r < 0.7:
        line = rng.randrange(len(lines))
        n = len(lines[line].encode("utf-16-le")) // 2
        return lsp.Position(line, rng.randint(0, n + (3 if rng.random() < 0.2 else 0)))
    if r < 0.85:
        return lsp.Position(len(lines) + rng.randint(0, 50), rng.randint(0, 5))
    return lsp.Position(rng.randint(0, 2**31 - 1), rng.randint(0, 2**31 - 1))


async def _one(client: LanguageClient, rng: random.Random, kind: str, u: str, text: str) -> Any:
    method = rng.choice(["hover", "definition", "references", "completion", "formatting", "codeAction"])
    doc = lsp.TextDocumentIdentifier(u)
    pos = _position(rng, text)
    if method == "hover":
        coro = client.text_document_hover_async(lsp.HoverParams(doc, pos))
    elif method == "definition":
        coro = client.text_document_definition_async(lsp.DefinitionParams(doc, pos))
    elif method == "references":
        coro = client.text_document_references_async(lsp.ReferenceParams(
            context=lsp.ReferenceContext(include_declaration=rng.random() < 0.5), text_document=doc, position=pos))
    elif method == "completion":
        coro = client.text_document_completion_async(lsp.CompletionParams(doc, pos))
    elif method == "formatting":
        coro = client.text_document_formatting_async(lsp.DocumentFormattingParams(
            doc, lsp.FormattingOptions(tab_size=2, insert_spaces=True)))
    else:
        end = _position(rng, text)
        start, end = sorted([pos, end], key=lambda p: (p.line, p.character))
        coro = client.text_document_code_action_async(lsp.CodeActionParams(doc, lsp.Range(start, end),
                                                                           lsp.CodeActionContext(diagnostics=[])))
    got, err = await answer(coro)
    if kind == "refused":
        assert err is not None and err.code == -32602, (method, u, got)
    if err is not None:
        one_sentence(err)
        assert err.code in (-32602, -32803), (method, u, err.message)  # refused, or a text that does not parse
        assert kind in ("refused", "outside", "plan") or method == "formatting", (method, kind, err.message)
    return method, got


async def test_random_requests_are_answered_and_formatting_round_trips(client: LanguageClient, ws: Path) -> None:
    rng = random.Random(SEED)
    a = (ws / "contracts" / "a.rcl").as_uri()
    text, version = _document(rng), 100
    open_doc(client, a, text, version)
    uris, formatted, t0 = _uris(ws), 0, time.monotonic()
    for _ in range(REQUESTS):
        if rng.random() < 0.15:
            text, version = _document(rng), version + 1
            change(client, a, version, text)
        kind, u = rng.choice(uris)
        if rng.random() < 0.05 and kind != "doc":  # a notification about any URI: ignored or checked, never fatal
            open_doc(client, u, _document(rng))
        shown = {"doc": text, "disk": CONTRACT, "plan": PLAN}.get(kind, CONTRACT)
        method, got = await _one(client, rng, kind, u, shown)
        if method == "formatting" and kind == "doc" and got is not None:
            result = apply_edits(text, list(got))
            eols = set(_BREAK.findall(text))
            assert set(_BREAK.findall(result)) <= (eols or {"\n"}), (text, got)  # only the document's line ends
            if len(eols) == 1:
                assert result == _BREAK.sub(eols.pop(), result)
            assert printed(result) == printed(text)
            from rclverify.tools.lsp.actions import format_edits  # the \n text's formatting: no line end lost or added
            lf = normalize(text)
            assert normalize(result) == apply_edits(lf, format_edits("a.rcl", lf))
            assert result.startswith("\ufeff") == text.startswith("\ufeff")
            version += 1
            change(client, a, version, result)
            assert await formatting(client, a) == [], repr(result)
            text = result
            formatted += 1
    took = time.monotonic() - t0
    assert formatted >= 3, formatted  # the round trip was checked, not skipped
    assert took < REQUESTS * BOUND
    got, err = await answer(client.text_document_hover_async(lsp.HoverParams(lsp.TextDocumentIdentifier(a),
                                                                             lsp.Position(0, 0))))
    assert err is None  # the server still serves
    assert not client.messages, client.messages  # no pop-up: what a notification could not do is in the log
    assert not [m for m in client.log_messages if _LEAK.search(m.message)], client.log_messages
