"""Tests of the assurance report renderers (HTML, Markdown, JSON, DOT/SVG)."""
from __future__ import annotations

import copy
import json
import re
import shutil
from html.parser import HTMLParser
from pathlib import Path
from typing import Any

import msgspec
import pytest

from _typed_rows import complete, ungrouped_report
from rclverify.records.summary_rows import Meta, SystemView
from rclverify.report import diagram, render


def _check(formal: str, source: str) -> dict[str, Any]:
    """A requirement's check record as the report carries it (report/requirement_rows.py): every field the
    report keeps, the formal statement proved from the premises it is traced to."""
    from rclverify.report.requirement_rows import _CHECK_FIELDS
    return {**{k: None for k in _CHECK_FIELDS}, "origin": "plan", "source": source, "formal": formal,
            "assuming": [], "used": [], "consistency": "consistent", "vacuity": "not vacuous",
            "declarations": []}


def _report() -> dict[str, Any]:
    """A small report in the shape the pipeline produces: two nodes in a loop,
    an environment input, one failed evidence (with a hostile explanation),
    one pending, one refuted side condition and one health problem; the parts
    it leaves out completed empty, its problems grouped by the renderers."""
    return ungrouped_report({
        "meta": complete(Meta, {
            "tool": "rclverify", "version": "0.1.0", "workspace": "mini",
            "plan": "contracts/plan.yaml", "contracts": ["contracts/mini.rcl"],
            "z3_version": "4.12.2", "strict_ok": False,
        }),
        "summary": {
            "status": "failed",
            "counts": {"discharged": 1, "failed": 1, "pending": 1},
            "headline": "1 of 3 obligations discharged; 1 failed.",
            "problems": ["Sensor guarantee 1 fails its Hoare proof."],
        },
        "system": {
            "nodes": [{"name": "Sensor", "status": "failed"}, {"name": "Agent", "status": "pending"}],
            "connections": [
                {"from_node": "Sensor", "from_var": "status", "to_node": "Agent", "to_var": "status", "via": "name"},
                {"from_node": "Agent", "from_var": "command", "to_node": "Sensor", "to_var": "cmd", "via": "plan"},
            ],
            "environment_inputs": [{"node": "Sensor", "var": "r", "type": "REAL"}],
            "loops": [["Agent", "Sensor"]],
        },
        "requirements": [
            {"id": "REQ1", "text": "Report high radiation as red.", "verdict": "proved, evidence outstanding",
             "status": "failed", "note": "proved from the guarantees it is traced to; their evidence is failed",
             "check": _check("in.r >= 250 -> out.command == stop", "contracts/plan.yaml:5:11"),
             "support": [
                 {"node": "Sensor", "guarantee": 1, "text": "in.r >= 250 -> out.status == red",
                  "source": "contracts/mini.rcl:12:3", "status": "failed",
                  "obligations": ["Sensor.g1.hoare"]},
                 {"node": "Agent", "guarantee": 1, "text": "in.status == red -> out.command == stop",
                  "source": "contracts/mini.rcl:20:3", "status": "pending",
                  "obligations": ["Agent.g1.ajpf"]},
             ]},
            {"id": "REQ2", "text": "Move when | safe & sound.", "verdict": "met", "status": "discharged",
             "note": "proved from consistent premises whose evidence is all discharged",
             "check": _check("in.status == green -> out.command == go", "contracts/plan.yaml:9:11"),
             "support": [
                 {"node": "Agent", "guarantee": 2, "text": "forall(k in NATURAL | in.status == green -> out.command == go)",
                  "source": "contracts/mini.rcl:21:3", "status": "discharged",
                  "obligations": ["Agent.g2.dafny"]},
             ]},
        ],
        "nodes": [
            {"name": "Sensor", "source": "contracts/mini.rcl:8:1", "status": "failed",
             "inputs": [{"name": "r", "type": "REAL", "producer": None},
                        {"name": "cmd", "type": "Cmd", "producer": "Agent.command"}],
             "outputs": [{"name": "status", "type": "RadStat", "consumers": ["Agent.status"]}],
             "assumptions": [{"text": "in.r >= 0", "source": "contracts/mini.rcl:11:3", "environment": True}],
             "guarantees": [{"index": 1, "text": "in.r >= 250 -> out.status == red",
                             "source": "contracts/mini.rcl:12:3", "status": "failed",
                             "obligations": ["Sensor.g1.hoare"]}],
             "latex": "\\textbf{Sensor}: $r \\geq 250 \\Rightarrow status = red$"},
            {"name": "Agent", "source": "contracts/mini.rcl:16:1", "status": "pending",
             "inputs": [{"name": "status", "type": "RadStat", "producer": "Sensor.status"}],
             "outputs": [{"name": "command", "type": "Cmd", "consumers": ["Sensor.cmd"]}],
             "assumptions": [{"text": "in.status in {red, orange, green}",
                              "source": "contracts/mini.rcl:19:3", "environment": False}],
             "guarantees": [
                 {"index": 1, "text": "in.status == red -> out.command == stop",
                  "source": "contracts/mini.rcl:20:3", "status": "pending", "obligations": ["Agent.g1.ajpf"]},
                 {"index": 2, "text": "in.status == green -> out.command == go",
                  "source": "contracts/mini.rcl:21:3", "status": "discharged", "obligations": ["Agent.g2.dafny"]},
             ],
             "latex": "\\textbf{Agent}"},
        ],
        "side_conditions": [
            {"id": "Agent.sc1", "node": "Agent", "rule": "R1", "conjunct": "in.status in {red, orange, green}",
             "source": "contracts/mini.rcl:19:3", "hypotheses": ["in.r >= 250 -> out.status == red"],
             "status": "discharged", "model": None, "smt2": "artifacts/calculus/Agent.sc1.smt2",
             "duration_s": 0.012, "explanation": "", "verdict": "discharged", "variant": "", "links": [],
             "context": None},
            {"id": "Sensor.sc1", "node": "Sensor", "rule": "R4", "conjunct": "in.cmd != halt",
             "source": "contracts/mini.rcl:11:9", "hypotheses": ["in.status == red -> out.command == stop"],
             "status": "failed", "model": {"Agent.out.command": "halt"},
             "smt2": "artifacts/calculus/Sensor.sc1.smt2", "duration_s": 0.02,
             "explanation": "The producer's guarantee allows halt.", "verdict": "failed", "variant": "",
             "links": [], "context": None},
        ],
        "derived_properties": [
            {"node": "Agent", "rules": ["R1", "R4"],
             "instances": [{"rule": "R1", "premises": ["A_S => <> G_S", "A_A => <> G_A"],
                            "conclusion": "A_S => <> G_A"}],
             "environment_assumptions": ["in.r >= 0"],
             "property": "in.r >= 0 => <> (in.status == red -> out.command == stop)",
             "status": "failed", "derivation": "not derived", "evidence_status": "discharged", "evidence_note": "",
             "loop_assumption": "Every node on the loop Agent -> Sensor terminates for each input."},
        ],
        "findings": [
            {"id": "Agent.health.g2", "node": "Agent", "check": "vacuity", "guarantee": 2,
             "status": "problem", "message": "Guarantee 2 can never fire.", "explanation": "Its premise is unsatisfiable.",
             "model": None, "core": ["in.status == green", "in.status != green"]},
            {"id": "Sensor.health.assume", "node": "Sensor", "check": "assumption satisfiable", "guarantee": None,
             "status": "ok", "message": "The assumption is satisfiable.", "explanation": "",
             "model": {"Sensor.in.r": "0.0"}, "core": None},
        ],
        "obligations": [
            {"id": "Agent.g1.ajpf", "node": "Agent", "guarantee": 1, "backend": "ajpf", "kind": "model checking",
             "instance": "", "statement": "[] (red -> <> stop)", "source": "contracts/mini.rcl:20:3",
             "artifact": "artifacts/ajpf/Agent.g1.psl", "status": "pending"},
            {"id": "Agent.g2.dafny", "node": "Agent", "guarantee": 2, "backend": "dafny", "kind": "proof",
             "instance": "", "statement": "ensures status == green ==> command == go",
             "source": "contracts/mini.rcl:21:3", "artifact": "artifacts/dafny/Agent.dfy", "status": "discharged"},
            {"id": "Sensor.g1.hoare", "node": "Sensor", "guarantee": 1, "backend": "hoare", "kind": "proof",
             "instance": "", "statement": "{r >= 250} P {status == red}", "source": "contracts/mini.rcl:12:3",
             "artifact": "artifacts/hoare/Sensor.g1.smt2", "status": "failed"},
        ],
        "evidence": [
            {"obligation": "Agent.g1.ajpf", "backend": "ajpf", "kind": "model checking", "status": "pending",
             "tool": "ajpf", "tool_version": "unknown", "started": "2024-05-01T10:00:00Z", "duration_s": 0.0,
             "explanation": "", "counterexample": None, "artifacts": ["artifacts/ajpf/Agent.g1.psl"],
             "log_excerpt": ""},
            {"obligation": "Agent.g2.dafny", "backend": "dafny", "kind": "proof", "status": "discharged",
             "tool": "dafny", "tool_version": "2.3.0", "started": "2024-05-01T10:00:01Z", "duration_s": 6.5,
             "explanation": "Dafny verified the refinement.", "counterexample": None,
             "artifacts": ["artifacts/dafny/Agent.dfy"], "log_excerpt": "Dafny program verifier finished with 2 verified, 0 errors"},
            {"obligation": "Sensor.g1.hoare", "backend": "hoare", "kind": "proof", "status": "failed",
             "tool": "z3", "tool_version": "4.12.2", "started": "2024-05-01T10:00:02Z", "duration_s": 0.03,
             "explanation": "Postcondition fails <script>alert(1)</script> at r = 250.",
             "counterexample": {"r": "250.0"}, "artifacts": ["artifacts/hoare/Sensor.g1.smt2"],
             "log_excerpt": "sat\n(model (define-fun r () Real 250.0))"},
        ],
        "environment_assumptions": [{"node": "Sensor", "text": "in.r >= 0", "source": "contracts/mini.rcl:11:3"}],
        "pending": [{"obligation": "Agent.g1.ajpf", "backend": "ajpf",
                     "reason": "AJPF is not installed; run: ajpf-run artifacts/ajpf/Agent.g1.jpf"}],
        "lint": [{"severity": "warning", "location": "contracts/mini.rcl:20:3",
                  "message": "'->' mixed with 'and' without parentheses.", "code": "W-implication-precedence"}],
    })


def _section(text: str, start: str, end: str) -> str:
    i = text.index(start)
    return text[i:text.index(end, i + len(start))]


NO_DOT = diagram.Rendering(None, diagram.INSTALL_HINT)


def test_html_autoescapes_report_text() -> None:
    html = render.render_html(_report(), rendering=NO_DOT)
    assert "<script>" not in html
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in html
    # The requirement text with '&' and '|' is escaped, not dropped.
    assert "Move when | safe &amp; sound." in html


def test_html_sections_in_order_and_anchors_resolve() -> None:
    html = render.render_html(_report(), rendering=NO_DOT)
    order = ["id=\"attention\"", "id=\"system\"", "id=\"traceability\"", "id=\"calculus\"",
             "id=\"health\"", "id=\"evidence\"", "id=\"pending\"", "id=\"environment\"",
             "id=\"lint\"", "id=\"appendix\""]
    positions = [html.index(s) for s in order]
    assert positions == sorted(positions)
    ids = set(re.findall(r'\sid="([^"]+)"', html))
    targets = set(re.findall(r'href="#([^"]+)"', html))
    assert targets, "no internal links"
    assert targets <= ids, f"dangling links: {sorted(targets - ids)}"
    # Requirement rows link to node, guarantee and evidence sections.
    trace = _section(html, 'id="traceability"', "</section>")
    for frag in ("#node-Sensor", "#g-Sensor-1", "#ob-Sensor.g1.hoare", "#ev-Sensor.g1.hoare"):
        assert f'href="{frag}"' in trace
    assert 'rowspan="2"' in trace


class _TagBalance(HTMLParser):
    VOID = {"br", "meta", "link", "img", "hr", "input", "path", "polygon", "ellipse", "polyline", "col", "wbr"}

    def __init__(self) -> None:
        super().__init__()
        self.stack: list[str] = []
        self.errors: list[str] = []

    def handle_starttag(self, tag: str, attrs: Any) -> None:
        if tag not in self.VOID:
            self.stack.append(tag)

    def handle_endtag(self, tag: str) -> None:
        if tag in self.VOID:
            return
        if self.stack and self.stack[-1] == tag:
            self.stack.pop()
        else:
            self.errors.append(f"</{tag}> at {self.getpos()} inside {self.stack[-3:]}")


@pytest.mark.parametrize("with_svg", [False, True])
def test_html_tags_balance(with_svg: bool) -> None:
    if with_svg and shutil.which("dot") is None:
        pytest.skip("graphviz `dot` not installed")
    html = render.render_html(_report(), rendering=None if with_svg else NO_DOT)
    parser = _TagBalance()
    parser.feed(html)
    assert parser.errors == [] and parser.stack == []


def test_failed_evidence_is_first_in_attention() -> None:
    html = render.render_html(_report(), rendering=NO_DOT)
    attention = _section(html, 'id="attention"', "</section>")
    assert "Sensor.g1.hoare" in attention
    assert "Sensor guarantee 1 fails its Hoare proof." in attention
    # Refuted side condition and health problem are problems too; pending is outstanding.
    problems = _section(attention, "Problems (", "</table>")
    assert "Sensor.sc1" in problems and "Agent.health.g2" in problems
    assert problems.index("Sensor.g1.hoare") < problems.index("Agent.health.g2")
    assert "Agent.g1.ajpf" not in problems
    outstanding = _section(attention, "Outstanding (", "</table>")
    assert "Agent.g1.ajpf" in outstanding and "AJPF is not installed" in outstanding
    # A healthy finding is not flagged.
    assert "Sensor.health.assume" not in attention

    md = render.render_markdown(_report())
    md_attention = _section(md, "## What needs attention", "## System model")
    assert "Sensor.g1.hoare" in md_attention and "**failed**" in md_attention


def test_all_clear_report_says_nothing_needs_attention() -> None:
    rep = _report()
    rep["summary"].update(status="discharged", problems=[], counts={"discharged": 1})
    rep["requirements"] = []
    rep["pending"] = []
    for key in ("evidence", "obligations", "side_conditions", "derived_properties", "findings"):
        rep[key] = [x for x in rep[key] if render.rank(x["status"]) == 0]
    attention = _section(render.render_html(rep, rendering=NO_DOT), 'id="attention"', "</section>")
    assert "Nothing needs attention" in attention and "Problems (" not in attention


def test_markdown_traceability_table_and_escaping() -> None:
    md = render.render_markdown(_report())
    trace = _section(md, "## Requirements traceability", "## Calculus")
    lines = [ln for ln in trace.splitlines() if ln.startswith("|")]
    assert lines[0] == "| Requirement | Node | Guarantee | Obligations | Evidence |"
    assert lines[1].count("---") == 5
    rows = lines[2:]
    assert len(rows) == 3  # REQ1 has two supporting guarantees, REQ2 one
    assert "REQ1" in rows[0] and "Sensor.g1.hoare" in rows[0] and "#ev-Sensor.g1.hoare" in rows[0]
    assert "REQ1" not in rows[1] and "Agent.g1.ajpf" in rows[1]
    # Every row keeps the five columns: user '|' is escaped, never a cell break.
    for row in rows:
        assert len(re.findall(r"(?<!\\)\|", row)) == 6, row
    assert "safe \\& sound" in rows[2]
    assert "`forall(k in NATURAL \\| in.status == green -> out.command == go)`" in rows[2]
    assert "<script>" not in md


def test_markdown_shows_counterexamples_and_loop_assumption() -> None:
    md = render.render_markdown(_report())
    assert "`r` = `250.0`" in md
    assert "`Agent.out.command` = `halt`" in md
    assert "R4 extra assumption:" in md and "terminates for each input" in md
    assert "```latex\n\\textbf{Sensor}" in md


def test_json_is_deterministic_and_round_trips(tmp_path: Path) -> None:
    rep = _report()
    text = render.render_json(rep)
    assert json.loads(text) == rep
    shuffled = {k: rep[k] for k in reversed(list(rep))}
    assert render.render_json(shuffled) == text
    assert text.startswith('{\n  "acknowledgements": [],\n  "deadlines": [],\n  "derived_properties"')  # keys sorted


def test_missing_key_is_reported() -> None:
    rep = _report()
    del rep["lint"]
    with pytest.raises(ValueError, match="lint"):
        render.render_json(rep)
    rep = _report()
    del rep["evidence"][0]["started"]  # a row that is no EvidenceRow (records/evidence_rows.py) is refused, named
    with pytest.raises(msgspec.ValidationError, match="started"):
        render.render_html(rep, rendering=NO_DOT)


def test_dot_has_every_node_and_connection() -> None:
    rep = _report()
    dot = diagram.system_dot(rep["system"])
    assert dot.startswith("// system model, generated by rclverify\ndigraph system {")
    for n in rep["system"]["nodes"]:
        assert re.search(rf'^\s*"{n["name"]}" \[label="{n["name"]}\\n{n["status"]}"', dot, re.M)
    assert re.search(r'"Sensor" -> "Agent" \[label="status"', dot)
    assert re.search(r'"Agent" -> "Sensor" \[label="command -> cmd"', dot)
    assert '"env:Sensor.r" [label="env: r"' in dot
    assert '"env:Sensor.r" -> "Sensor"' in dot
    # Both connections lie on the loop and are drawn bold.
    assert dot.count("penwidth=2.2") == 2
    # Deterministic regardless of input order.
    rev = copy.deepcopy(rep["system"])
    for key in ("nodes", "connections", "environment_inputs"):
        rev[key].reverse()
    assert diagram.system_dot(rev) == dot


def test_dot_quotes_hostile_names() -> None:
    system = {"nodes": [{"name": 'A"] ; x -> y [label="', "status": "discharged"}],
              "connections": [], "environment_inputs": [], "loops": [], "loop_components": []}
    dot = diagram.system_dot(system)
    assert '"A\\"] ; x -> y [label=\\""' in dot
    assert "\n  x -> y" not in dot


@pytest.mark.skipif(shutil.which("dot") is None, reason="graphviz `dot` not installed")
def test_dot_to_svg_and_inline_html() -> None:
    rep = _report()
    svg = diagram.dot_to_svg(diagram.system_dot(rep["system"]))
    assert svg is not None and svg.startswith("<svg ")
    assert "<?xml" not in svg and "<!DOCTYPE" not in svg
    assert svg.rstrip().endswith("</svg>")
    assert ">Sensor</text>" in svg and ">env: r</text>" in svg
    html = render.render_html(rep)
    system = _section(html, 'id="system"', "</section>")
    assert "<svg " in system and "install graphviz" not in system


def test_without_dot_report_embeds_source(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(diagram.shutil, "which", lambda name: None)
    assert diagram.dot_to_svg("digraph { a -> b }") is None
    html = render.render_html(_report())
    system = _section(html, 'id="system"', "</section>")
    assert "install graphviz for the diagram" in system
    assert "<svg" not in system
    assert "digraph system {" in system and "&#34;Sensor&#34; -&gt; &#34;Agent&#34;" in system


def test_a_system_too_large_to_draw_is_not_laid_out(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Issue 67: above diagram.MAX_SYSTEM_LAYOUT_ELEMENTS (nodes, connections, environment inputs) the
    report runs no `dot` (whose time grows faster than the size: minutes, or its 30 s timeout, at a few
    thousand nodes, and whether the diagram appeared then depended on the machine's speed); it says
    why and how to draw it, inlines no source in the HTML, and the Markdown keeps the source."""
    rep = _report()
    system = SystemView.of(rep["system"])
    n = diagram.system_elements(system)
    assert diagram.system_layout(system, "digraph { this is not dot").note  # at the limit: dot runs
    monkeypatch.setattr(diagram, "MAX_SYSTEM_LAYOUT_ELEMENTS", n - 1)
    def render_dot(dot: str, *a: Any, **k: Any) -> diagram.Rendering:
        assert "digraph system {" not in dot, "dot must not run on the system"
        return NO_DOT  # the argument's diagram
    monkeypatch.setattr(diagram, "render_dot", render_dot)
    for html in (render.render_html(rep), render.render_html(rep, rendering=NO_DOT),
                 (render.render_files(rep, tmp_path, ["assurance.html"])[0]).read_text(encoding="utf-8")):
        system = _section(html, 'id="system"', "</section>")
        assert f"No diagram: the system has {len(rep['system']['nodes'])} nodes" in system, system[:2000]
        assert "<svg" not in system and "<pre>" not in system and "doit graph" in system
    md = render.render_markdown(rep)
    assert "too large for the HTML report to draw" in md and "digraph system {" in md


@pytest.mark.skipif(shutil.which("dot") is None, reason="graphviz `dot` not installed")
def test_dot_error_is_explained() -> None:
    result = diagram.render_dot("digraph { this is not dot")
    assert result.svg is None and "failed" in result.note


def test_render_all_writes_three_files(tmp_path: Path) -> None:
    out = tmp_path / "reports"
    paths = render.render_all(_report(), out)
    assert [p.name for p in paths] == ["assurance.html", "assurance.md", "assurance.json"]
    assert all(p.is_file() and p.stat().st_size > 0 for p in paths)
    assert json.loads(paths[2].read_text(encoding="utf-8")) == _report()
    html = paths[0].read_text(encoding="utf-8")
    assert html.startswith("<!-- assurance report of mini from contracts/plan.yaml")
    assert 'href="../artifacts/calculus/Sensor.sc1.smt2"' in html
    assert "<link" not in html and "<script" not in html and "http://" not in html.replace(
        'xmlns="http://www.w3.org/2000/svg"', "").replace('xmlns:xlink="http://www.w3.org/1999/xlink"', "")
    # Same report, same bytes.
    before = [p.read_bytes() for p in paths]
    render.render_all(_report(), out)
    assert [p.read_bytes() for p in paths] == before
    assert sorted(x.name for x in out.iterdir()) == ["assurance.html", "assurance.json", "assurance.md"]


def test_artifact_links_cannot_become_urls() -> None:
    rep = _report()
    rep["obligations"][0]["artifact"] = "javascript:alert(1)"
    html = render.render_html(rep, link_prefix="", rendering=NO_DOT)
    assert 'href="javascript:' not in html
    assert 'href="javascript%3Aalert%281%29"' in html


def test_huge_model_values_are_clipped_in_html_and_markdown_but_kept_in_json() -> None:
    from rclverify.report.render import CLIP_CHARS, clip
    value = "ite(" * 5000
    shown = clip(value)
    assert shown.startswith(value[:CLIP_CHARS]) and len(shown) < CLIP_CHARS + 80
    assert f"{len(value) - CLIP_CHARS} more characters in the JSON report" in shown
    assert clip("short") == "short"


def test_identical_outstanding_items_are_one_group() -> None:
    """39 AJPF instances pending for one reason are one row (issue: diagnosis and report); a
    different reason, status or backend is a row of its own."""
    from rclverify.report.render import group_items

    def item(ref: str, msg: str, status: str = "pending", where: str = "ajpf (model checking)") -> dict:
        return {"status": status, "kind": "evidence", "ref": ref, "anchor": ref, "where": where, "message": msg,
                "formula": ""}
    items = [item(f"Agent.g1.ajpf.p{k}_i{k}", f"AJPF is not installed; run instance {k} with MCAPL") for k in range(39)]
    items += [item("Localisation.g1.review.e0", "the review names no reviewed file", where="review (review)"),
              item("X.g1.ajpf.p1_i1", "AJPF is not installed; run instance 1 with MCAPL", status="stale")]
    groups = group_items(items)
    assert [len(g["items"]) for g in groups] == [39, 1, 1]
    assert groups[0]["message"] == "AJPF is not installed; run instance 0 with MCAPL"
    assert [it["ref"] for it in groups[0]["items"]] == [f"Agent.g1.ajpf.p{k}_i{k}" for k in range(39)]


def test_dashboard_cells_are_the_worst_status_of_each_technique_and_link_to_it() -> None:
    rep = _report()
    v = render.view(rep)
    dash = v["dashboard"]
    assert dash["columns"][:3] == ["health", "side conditions", "hoare"]
    cells = {row["node"]: dict(zip(dash["columns"], row["cells"])) for row in dash["rows"]}
    assert [row["node"] for row in dash["rows"]] == ["Sensor", "Agent"]
    assert cells["Sensor"]["hoare"]["status"] == "failed" and cells["Sensor"]["hoare"]["anchor"] == "ev-Sensor.g1.hoare"
    assert cells["Sensor"]["side conditions"]["status"] == "failed"
    assert cells["Sensor"]["dafny"] is None
    assert cells["Agent"]["health"] == {"status": "failed", "worst": 1, "total": 1, "counts": [("failed", 1)],
                                        "anchor": "finding-Agent.health.g2"}
    assert cells["Agent"]["ajpf"]["status"] == "pending" and cells["Agent"]["dafny"]["status"] == "discharged"
    # a healthy finding counts as discharged; a worse item of the same kind wins
    assert cells["Sensor"]["health"]["status"] == "discharged"
    rep["evidence"].append({**rep["evidence"][1], "obligation": "Agent.g2.dafny", "status": "stale"})
    rep["obligations"][1]["status"] = "stale"
    cells = dict(zip(render.view(rep)["dashboard"]["columns"], render.view(rep)["dashboard"]["rows"][1]["cells"]))
    assert cells["dafny"]["status"] == "stale" and cells["dafny"]["anchor"] == "ev-Agent.g2.dafny"
    html = render.render_html(rep, rendering=NO_DOT)
    dashboard = _section(html, 'id="dashboard"', "</section>")
    assert 'href="#ev-Sensor.g1.hoare"' in dashboard and "REQ1" in dashboard
    # the first screen leads with what to fix (issue 48), then the dashboard, then the diagram
    assert html.index('id="attention"') < html.index('id="dashboard"') < html.index('id="system"')
    md = render.render_markdown(rep)
    assert "## Dashboard" in md and "(#ev-Sensor.g1.hoare)" in md


def _grouping_report() -> dict[str, Any]:
    """The case study's pattern in small: guarantee 3 of Agent makes 1 and 2
    vacuous (with different facts in their cores), a property test fails on
    guarantee 1, a requirement is vacuous through guarantee 2, two Hoare
    triples fail on the same program constants; a lone refinement problem."""
    rep = _report()
    rep["nodes"][1]["guarantees"].append({"index": 3, "text": "out.command == go", "source": "contracts/mini.rcl:22:3",
                                          "status": "failed", "obligations": []})
    fact = {"what": "environment fact 1 (contracts/plan.yaml:9:10) `in.n <= 12`", "source": "contracts/plan.yaml:9:10"}
    fact2 = {"what": "environment fact 2 (contracts/plan.yaml:10:10)", "source": "contracts/plan.yaml:10:10"}
    g3 = {"what": "guarantee 3 (contracts/mini.rcl:22:3) at i=13", "source": "contracts/mini.rcl:22:3"}
    prog = [{"what": "backends/hoare/s.imp line 15", "source": "backends/hoare/s.imp:15"},
            {"what": "backends/hoare/s.imp line 18", "source": "backends/hoare/s.imp:18"}]

    def d(id: str, kind: str, node: str, k: Any, culprits: list[dict[str, str]], repairs: Any = ()) -> dict[str, Any]:
        return {"id": id, "kind": kind, "node": node, "status": "failed", "sentence": f"{id} is wrong. More.",
                "culprits": culprits, "counterexample": [], "repairs": list(repairs), "guarantee": k, "related": []}
    said = {"proves": "the problem no longer follows from the edited text", "not_shown": "that the change is safe"}
    guard = {"kind": "guard", "checked_by": "z3", "summary": "Guard guarantee 3.", "checks": [], "cost": [],
             "diff": "--- a\n+++ b\n", "file": "contracts/mini.rcl", **said,
             "edit": {"file": "contracts/mini.rcl", "line": 22, "col": 5, "end_line": 22, "end_col": 5,
                      "inserted": "x > 0 -> ", "deleted": ""}}
    const = {"kind": "constant", "checked_by": "z3", "summary": "10 -> 120.", "checks": [], "cost": [],
             "diff": "--- p\n+++ p\n", "file": "backends/hoare/s.imp", **said,
             "edit": {"file": "backends/hoare/s.imp", "line": 3, "col": 9, "end_line": 3, "end_col": 11,
                      "inserted": "120", "deleted": "10"}}
    rep["diagnoses"] = [
        d("Agent.g1.non-vacuous", "vacuity", "Agent", 1, [fact, g3, fact2], [guard]),
        d("Agent.g2.non-vacuous", "vacuity", "Agent", 2, [fact, g3], [guard]),
        d("Agent.replacement-refines", "refinement", "Agent", None, []),
        d("Agent.g1.property_tests.e2", "property-test", "Agent", 1,
          [{"what": "guarantee 1 of Agent (contracts/mini.rcl:20:3)", "source": "contracts/mini.rcl:20:3"}]),
        d("Sensor.g1.hoare.c2", "hoare", "Sensor", 1,
          [*prog, {"what": "conjunct of guarantee 1 of Sensor", "source": "contracts/mini.rcl:12:11"}], [const]),
        d("Sensor.g1.hoare.c3", "hoare", "Sensor", 1,
          [*prog, {"what": "conjunct of guarantee 1 of Sensor", "source": "contracts/mini.rcl:13:5"}], [const]),
    ]
    rep["requirements"][0].update(verdict="proved vacuously", note="its premise never holds", check={
        "formal": "in.r >= 250 -> out.command == stop", "source": "contracts/plan.yaml:5:11", "assuming": [],
        "used": [], "traced_not_needed": [], "inconsistent_core": None, "counterexample": None,
        "failed_to_prevent": None,
        "vacuity_core": [{"label": "Agent guarantee 2", "source": "contracts/mini.rcl:21:14", "text": "x"},
                         {"label": "Sensor guarantee 1", "source": "contracts/mini.rcl:12:14", "text": "y"}]})
    return rep


def test_problems_with_the_same_culprit_are_one_row() -> None:
    from rclverify.report.problems import group_problems
    rep = _grouping_report()
    rep["diagnoses"][1]["sentence"] = "G3 excludes it. More to read."
    groups = [g.to_json() for g in group_problems(rep, render.problem_items(rep), render.anchor)]
    by_key = {tuple(g["key"]): g for g in groups}
    agent = by_key[("guarantee:Agent:3",)]
    assert [m["id"] for m in agent["members"]] == ["Agent.g1.non-vacuous", "Agent.g2.non-vacuous",
                                                   "Agent.g1.property_tests.e2", "REQ1"]
    assert agent["culprits"] == [{"id": "guarantee:Agent:3", "what": "guarantee 3 of Agent",
                                  "source": "contracts/mini.rcl:22:3", "file": "contracts/mini.rcl",
                                  "anchor": "g-Agent-3"}]
    assert agent["repairs"] == [{"diagnosis": "Agent.g1.non-vacuous", "index": 0}]  # the same diff once
    assert agent["sentence"] == "G3 excludes it."  # the shortest first sentence of the row's diagnoses
    hoare = by_key[("line:backends/hoare/s.imp:15", "line:backends/hoare/s.imp:18")]
    assert [m["id"] for m in hoare["members"]] == ["Sensor.g1.hoare.c2", "Sensor.g1.hoare.c3"]
    assert hoare["culprits"][0]["anchor"] == "" and hoare["culprits"][0]["file"] == "backends/hoare/s.imp"
    assert [m["id"] for m in by_key[("problem:Agent.replacement-refines",)]["members"]] == ["Agent.replacement-refines"]
    # attention items without a diagnosis: the refuted side condition of Sensor's assumption, the health problem
    # of the fixture (its own guarantee), the failed Hoare evidence is covered by its diagnosis... each once
    ids = [m["id"] for g in groups for m in g["members"]]
    assert len(ids) == len(set(ids))
    assert {"Sensor.sc1", "Agent.health.g2", "Sensor.g1.hoare"} <= set(ids)
    # Agent's derived property is not derived because Sensor.sc1 (upstream of it, on the loop) is refuted
    sc_row = next(g for g in groups if any(m["id"] == "Sensor.sc1" for m in g["members"]))
    assert [m["id"] for m in sc_row["members"]] == ["Sensor.sc1", "Agent.derived"]  # named fully, never "Agent"
    # the JSON report carries the grouping as it is rendered
    html = render.render_html({**rep, "problems": groups}, rendering=NO_DOT)
    assert html == render.render_html(rep, rendering=NO_DOT)
    attention = _section(html, 'id="attention"', "</section>")
    assert attention.count('<tr id="problem-') == len(groups)
    assert 'id="diagnosis-Agent-g2-non-vacuous"' in attention and "10 -&gt; 120." in attention
    md = _section(render.render_markdown(rep), "## What needs attention", "## System model")
    assert "| 4: [`Agent.g1.non-vacuous`](#finding-Agent.g1.non-vacuous)" in md


def test_long_formulas_are_folded_and_broken_at_connectives() -> None:
    short = "in.r >= 250 -> out.status == red"
    assert render.formula_html(short) == f"<code>{short.replace('>', '&gt;')}</code>"
    long = ("forall(i in NATURAL | in.a(i) == TRUE and in.b(i) == FALSE or not exists(x in REAL | in.w(x) == i + 1) "
            "-> exists(y in REAL | in.w(y) == 0 and out.c == move(y)))")
    html = render.formula_html(long, limit=60)
    assert html.startswith('<details class="formula"><summary><code>forall(i in NATURAL')
    lines = render.formula_lines(long).split("\n")
    assert lines[0] == "forall(i in NATURAL |" and lines[1] == "  in.a(i) == TRUE"
    assert "  -> exists(y in REAL |" in lines and "    and out.c == move(y)))" in lines
    assert " ".join(x.strip() for x in lines) == long
    assert render.breakable("a/b_c.d") == "a/<wbr>b_<wbr>c.<wbr>d"


def test_the_diagram_marks_the_culprit_and_the_failing_edge() -> None:
    """Issue 48: the system diagram blames the culprit, not only its red victims."""
    from rclverify.report.diagram import system_dot
    system = {"nodes": [{"name": "Gnss", "status": "discharged"}, {"name": "Loc", "status": "failed"},
                        {"name": "Plan", "status": "failed"}],
              "connections": [{"from_node": "Gnss", "from_var": "h", "to_node": "Loc", "to_var": "h", "via": ""},
                              {"from_node": "Loc", "from_var": "p", "to_node": "Plan", "to_var": "p", "via": ""}],
              "environment_inputs": [], "loops": [], "loop_components": []}
    dot = system_dot(system, culprits={"Gnss"}, failing={("Gnss", "Loc")})
    lines = dot.splitlines()
    gnss = next(l for l in lines if l.strip().startswith('"Gnss" ['))
    assert 'class="culprit"' in gnss and "culprit" in gnss.split("label=")[1]
    assert not any('class="culprit"' in l for l in lines if l.strip().startswith(('"Loc" [', '"Plan" [')))
    edge = next(l for l in lines if '"Gnss" -> "Loc"' in l)
    assert 'class="failing"' in edge and 'class="failing"' not in next(l for l in lines if '"Loc" -> "Plan"' in l)
    assert system_dot(system) == system_dot(system, culprits=(), failing=())  # nothing marked by default
