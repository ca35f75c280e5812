"""`rclverify lsp` end to end (issue 52, docs/editor.md): a real LSP client
(pytest-lsp) over stdio against the server in its own process, on the case
study's contracts after a real run of the pipeline's stages.

One server for the module (started once); the tests run in order and the
document's text is set by each test that edits it."""
from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest
import pytest_lsp
from lsprotocol import types as lsp
from pytest_lsp import ClientServerConfig, LanguageClient

from _lsp_ws import REPO, RCL, make_workspace, run_pipeline, wait_diagnostics

pytestmark = pytest.mark.asyncio(loop_scope="module")

ENV = {**os.environ, "PYTHONPATH": str(REPO / "src") + os.pathsep + os.environ.get("PYTHONPATH", "")}


@pytest.fixture(scope="module")
def ws(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = make_workspace(tmp_path_factory.mktemp("lsp") / "rover")
    run_pipeline(root)
    return root


@pytest_lsp.fixture(scope="module", config=ClientServerConfig(
    server_command=[sys.executable, "-m", "rclverify.cli.commands", "lsp"], server_env=ENV))
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
    return await wait_diagnostics(client, u, want, timeout)


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


def pos(text: str, needle: str, nth: int = 0, offset: int = 0) -> lsp.Position:
    """The position of the ``nth`` occurrence of ``needle`` in ``text`` (plus ``offset`` characters)."""
    k = -1
    for _ in range(nth + 1):
        k = text.index(needle, k + 1)
    k += offset
    line = text.count("\n", 0, k)
    return lsp.Position(line, k - (text.rfind("\n", 0, k) + 1))


async def test_a_typed_error_is_located_and_the_findings_go_stale(client: LanguageClient, ws: Path) -> None:
    saved = (ws / RCL).read_text(encoding="utf-8")
    bad = saved.replace("assume( in.radiationStatus in {red, orange, green} )",
                        "assume( in.radiationStatu in {red, orange, green} )")
    change(client, uri(ws), 2, bad)
    got = await diagnostics(client, uri(ws), lambda ds: any(d.source == "rclverify" and d.severity == 1 for d in ds))
    (err,) = [d for d in got if d.source == "rclverify" and d.severity == 1]
    at = pos(bad, "in.radiationStatu in")
    assert (err.range.start.line, err.range.start.character) == (at.line, at.character)
    assert err.range.end.line == at.line and err.range.end.character > at.character
    # the command line's message for the same text
    from rclverify.lang.parser import parse_text
    from rclverify.lang.typecheck import check
    from rclverify.lang.errors import RclError
    with pytest.raises(RclError) as exc:
        check([parse_text(bad, RCL)])
    assert (err.message, err.code) == (exc.value.diagnostics[0].message, exc.value.diagnostics[0].code)
    last = [d for d in got if d.source == "rclverify (last run)"]
    assert last and all(d.message.startswith("stale (the text changed after the last run): ") for d in last)
    half = saved.replace("in.wayP(x', y') == i and in.inspected(i) == TRUE", "in.wayP(x', y') == i and in.inspected(i) ==", 1)
    change(client, uri(ws), 3, half)
    got = await diagnostics(client, uri(ws), lambda ds: any(d.code == "E-syntax" for d in ds))
    with pytest.raises(RclError) as exc:
        parse_text(half, RCL)
    (syn,) = exc.value.diagnostics
    assert [(d.range.start.line + 1, d.range.start.character + 1, d.message) for d in got if d.code == "E-syntax"] == [
        (syn.loc.line, syn.loc.col, syn.message)]
    change(client, uri(ws), 4, saved)
    got = await diagnostics(client, uri(ws), lambda ds: ds and not any(d.severity == 1 and d.source == "rclverify" for d in ds)
                            and not any(d.message.startswith("stale") for d in ds))


async def test_hover_on_node_variable_guarantee_and_requirement(client: LanguageClient, ws: Path) -> None:
    text = (ws / RCL).read_text(encoding="utf-8")
    h = await client.text_document_hover_async(lsp.HoverParams(lsp.TextDocumentIdentifier(uri(ws)),
                                                               pos(text, "node Agent", offset=6)))
    assert "**node Agent** — last run: `failed`" in h.contents.value
    assert "outputs( command : CommandSet )" in h.contents.value and "reads from: " in h.contents.value
    h = await client.text_document_hover_async(lsp.HoverParams(lsp.TextDocumentIdentifier(uri(ws)),
                                                               pos(text, "in.at(x', y')", offset=4)))
    v = h.contents.value
    assert "**in.at** of Agent: `AtType`" in v and "topic `at` of `gazebo_radiation_plugin/Snapshot`" in v
    assert "produced by: Navigation.out.at" in v
    h = await client.text_document_hover_async(lsp.HoverParams(lsp.TextDocumentIdentifier(uri(ws)),
                                                               pos(text, "guarantee(", nth=2)))
    v = h.contents.value
    assert "**guarantee 1 of Agent**" in v and "`Agent.g1.non-vacuous`: `problem`" in v
    plan = (ws / "contracts/plan.yaml").read_text(encoding="utf-8")
    h = await client.text_document_hover_async(lsp.HoverParams(
        lsp.TextDocumentIdentifier(uri(ws, "contracts/plan.yaml")), pos(plan, "id: REQ3", offset=5)))
    v = h.contents.value
    assert v.startswith("**requirement REQ3** — last run: proved") and "premises its proof used:" in v
    assert "- Agent guarantee 3: `forall(x', y' in REAL" in v


async def test_definition_and_references(client: LanguageClient, ws: Path) -> None:
    text = (ws / RCL).read_text(encoding="utf-8")
    doc = lsp.TextDocumentIdentifier(uri(ws))
    # a consumer's input -> the producer's output
    got = await client.text_document_definition_async(lsp.DefinitionParams(doc, pos(text, "in.at(x', y')", offset=3)))
    at = pos(text, "at : AtType")  # Navigation's output
    assert [(g.uri, g.range.start.line, g.range.start.character) for g in got] == [(uri(ws), at.line, at.character)]
    # a context type -> its declaration
    got = await client.text_document_definition_async(lsp.DefinitionParams(doc, pos(text, "wayP : WayP", offset=8)))
    assert [g.range.start.line for g in got] == [pos(text, "WayP : REAL").line]
    # the output's references: its declaration, its topic, and the consumer's uses of in.at
    refs = await client.text_document_references_async(lsp.ReferenceParams(
        text_document=doc, position=pos(text, "at : AtType"), context=lsp.ReferenceContext(include_declaration=True)))
    lines = sorted(r.range.start.line + 1 for r in refs)
    uses = {pos(text, "in.at(x', y') == TRUE", nth=k).line + 1 for k in (0, 1)}  # the Agent's guarantees 1 and 2
    assert lines[0] == at.line + 1 and uses <= set(lines) and pos(text, "matches(in.at)").line + 1 in lines
    assert pos(text, "matches(out.at)").line + 1 in lines  # Navigation's topic
    # a plan entry -> the node
    plan = (ws / "contracts/plan.yaml").read_text(encoding="utf-8")
    got = await client.text_document_definition_async(lsp.DefinitionParams(
        lsp.TextDocumentIdentifier(uri(ws, "contracts/plan.yaml")), pos(plan, "Agent:", offset=1)))
    assert [g.range.start.line for g in got] == [pos(text, "node Agent").line]


async def test_completion(client: LanguageClient, ws: Path) -> None:
    text = (ws / RCL).read_text(encoding="utf-8")
    doc = lsp.TextDocumentIdentifier(uri(ws))
    got = await client.text_document_completion_async(lsp.CompletionParams(doc, pos(text, "in.wayP(x', y') == i", offset=3)))
    assert {i.label for i in got.items} == {"wayP", "at", "radiationStatus", "inspected"}
    got = await client.text_document_completion_async(lsp.CompletionParams(doc, pos(text, "assume( TRUE )", offset=8)))
    labels = {i.label for i in got.items}
    assert {"forall", "exists_unique", "RadStat", "move", "red", "Agent", "out.position"} <= labels
    got = await client.text_document_completion_async(lsp.CompletionParams(
        doc, pos(text, "gazebo_radiation_plugin/Snapshot position", offset=33)))
    assert {"command", "posx", "posy", "id", "level", "value"} == {i.label for i in got.items}


async def test_quick_fix_guards_guarantee_3(client: LanguageClient, ws: Path) -> None:
    """The repair the report proposes for the Agent's guarantee 3, applied from the vacuity finding on
    guarantee 1; saved, the finding is stale; after the next run it is gone."""
    text = (ws / RCL).read_text(encoding="utf-8")
    got = await diagnostics(client, uri(ws), lambda ds: any(d.code == "RCL-HEALTH-VACUOUS" and not
                                                            d.message.startswith("stale") for d in ds))
    vac = [d for d in got if d.code == "RCL-HEALTH-VACUOUS" and d.range.start.line == 63]
    actions = await client.text_document_code_action_async(lsp.CodeActionParams(
        lsp.TextDocumentIdentifier(uri(ws)), vac[0].range, lsp.CodeActionContext(diagnostics=vac)))
    (fix,) = [a for a in actions if a.title.startswith("Guard guarantee 3 of Agent with `i + 1 <= 12`")]
    assert fix.kind == lsp.CodeActionKind.QuickFix and " \u2014 Z3 shows: " in fix.title and "not shown: " in fix.title
    (edit,) = fix.edit.changes[uri(ws)]
    lines = text.split("\n")
    line = lines[edit.range.start.line]
    lines[edit.range.start.line] = line[:edit.range.start.character] + edit.new_text + line[edit.range.end.character:]
    guarded = "\n".join(lines)
    assert ("    i + 1 <= 12 and (in.radiationStatus in {red, orange} or not exists(x, y in REAL | in.wayP(x, y) == i + 1))\n"
            "    -> exists(x'', y'' in REAL | in.wayP(x'', y'') == 0 and out.command == move(x'', y''))) )") in guarded
    change(client, uri(ws), 5, guarded)
    (ws / RCL).write_text(guarded, encoding="utf-8")
    client.text_document_did_save(lsp.DidSaveTextDocumentParams(lsp.TextDocumentIdentifier(uri(ws))))
    got = await diagnostics(client, uri(ws), lambda ds: any(d.code == "RCL-HEALTH-VACUOUS" for d in ds)
                            and all(d.message.startswith("stale") for d in ds if d.source == "rclverify (last run)"))
    assert not [d for d in got if d.source == "rclverify" and d.severity == 1]
    run_pipeline(ws, ("Agent",))  # the next run (the Agent's health again, the report)
    got = await diagnostics(client, uri(ws), lambda ds: any(d.code == "RCL-HEALTH-UNREALIZABLE" and not
                                                            d.message.startswith("stale") for d in ds))
    assert not [d for d in got if d.code == "RCL-HEALTH-VACUOUS"]


async def test_formatting_keeps_comments_between_clauses(client: LanguageClient, ws: Path) -> None:
    text = (ws / RCL).read_text(encoding="utf-8")
    edits = await client.text_document_formatting_async(lsp.DocumentFormattingParams(
        lsp.TextDocumentIdentifier(uri(ws)), lsp.FormattingOptions(tab_size=2, insert_spaces=True)))
    assert edits, "the case study is not in rclverify fmt's form"
    lines = text.split("\n")
    for e in sorted(edits, key=lambda e: (e.range.start.line, e.range.start.character), reverse=True):
        a, b = e.range.start, e.range.end
        head = "\n".join(lines[:a.line] + [lines[a.line][:a.character]])
        tail = "\n".join([lines[b.line][b.character:]] + lines[b.line + 1:])
        lines = (head + e.new_text + tail).split("\n")
    out = "\n".join(lines)
    assert out.count("//") == text.count("//")
    from rclverify.lang.parser import parse_text
    from rclverify.lang.printer import to_rcl
    assert to_rcl(parse_text(out)) == to_rcl(parse_text(text))
    assert "  CommandSet : {move(REAL, REAL), inspect(NATURAL)} ;" in out


async def test_outside_the_workspace_is_refused(client: LanguageClient, ws: Path, tmp_path: Path) -> None:
    other = tmp_path / "elsewhere.rcl"
    other.write_text("context { T : REAL ; }\n", encoding="utf-8")
    from pygls.exceptions import JsonRpcException
    with pytest.raises(JsonRpcException, match="outside the workspace"):
        await client.text_document_hover_async(lsp.HoverParams(lsp.TextDocumentIdentifier(other.as_uri()),
                                                               lsp.Position(0, 11)))
