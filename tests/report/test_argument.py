"""The assurance argument: GSN structure, status propagation, exports."""
from __future__ import annotations

import copy
import dataclasses
import json
import shutil
from typing import Any

import pytest
import yaml

from _typed_rows import complete, typed_report, ungrouped_report
from rclverify.records.summary_rows import Meta
from rclverify.report.argument.build import build_argument
from rclverify.report.argument.export import argument_view, to_dot, to_gsn_yaml, to_json_text, write_argument
from rclverify.report.argument.model import Argument, ArgumentError, Element, propagate
from rclverify.report import render
from rclverify.report.diagram import Rendering

NO_DOT = Rendering(None, "no graphviz in this test")


def _build(rep: dict[str, Any]) -> Argument:
    """The argument of the report a test wrote in part (:func:`_report`), completed and decoded."""
    return build_argument(typed_report(rep))


def _ev(ob: str, status: str, kind: str = "proof", backend: str = "hoare") -> dict[str, Any]:
    return {"obligation": ob, "backend": backend, "kind": kind, "status": status, "tool": "z3", "tool_version": "4",
            "started": "2026-01-01T00:00:00Z", "duration_s": 0.1, "explanation": f"{ob} is {status}",
            "counterexample": None, "artifacts": [], "log_excerpt": ""}


def _ob(oid: str, node: str, k: int, backend: str = "hoare", status: str = "discharged") -> dict[str, Any]:
    return {"id": oid, "node": node, "guarantee": k, "backend": backend, "kind": "proof", "instance": "",
            "statement": "s", "source": "c.rcl:1:1", "artifact": "", "status": status}


def _report() -> dict[str, Any]:
    """Sensor (2 guarantees) feeds Planner (1 guarantee, one side condition);
    every piece of evidence is discharged except where a test changes it."""
    g = lambda k, text: {"index": k, "text": text, "source": f"c.rcl:{k}:3", "status": "discharged", "obligations": []}
    return {
        "meta": complete(Meta, {"tool": "rclverify", "version": "0", "workspace": "mini", "plan": "contracts/plan.yaml",
                                "contracts": ["contracts/c.rcl"], "z3_version": "4", "strict_ok": True}),
        "summary": {"status": "discharged", "counts": {}, "headline": "", "problems": []},
        "system": {"nodes": [], "connections": [], "environment_inputs": [], "loops": []},
        "requirements": [
            {"id": "REQ1", "text": "Report radiation.", "status": "discharged",
             "support": [{"node": "Sensor", "guarantee": 1, "text": "a", "source": "c.rcl:1:3", "status": "discharged", "obligations": []},
                         {"node": "Planner", "guarantee": 1, "text": "b", "source": "c.rcl:1:3", "status": "discharged", "obligations": []}]},
            {"id": "REQ2", "text": "Second.", "status": "discharged",
             "support": [{"node": "Sensor", "guarantee": 2, "text": "c", "source": "c.rcl:2:3", "status": "discharged", "obligations": []}]},
        ],
        "nodes": [{"name": "Sensor", "source": "c.rcl:1:1", "status": "discharged", "guarantees": [g(1, "a"), g(2, "c")],
                   "inputs": [], "outputs": [], "assumptions": [], "latex": ""},
                  {"name": "Planner", "source": "c.rcl:9:1", "status": "discharged", "guarantees": [g(1, "b")],
                   "inputs": [], "outputs": [], "assumptions": [], "latex": ""}],
        "side_conditions": [{"id": "Planner.sc1", "node": "Planner", "rule": "R1", "conjunct": "in.x > 0",
                             "source": "c.rcl:10:3", "status": "discharged", "smt2": "artifacts/calculus/Planner.sc1.smt2",
                             "explanation": "proved", "model": None, "hypotheses": [], "duration_s": 0.0,
                             "verdict": "discharged", "variant": "", "links": [], "context": None}],
        "derived_properties": [{"node": "Planner", "rules": ["R1"], "instances": [], "environment_assumptions": [],
                                "property": "p", "status": "discharged", "loop_assumption": None,
                                "derivation": "derived", "evidence_status": "discharged", "evidence_note": ""}],
        "findings": [{"id": "Sensor.assumption-satisfiable", "node": "Sensor", "check": "assumption-satisfiable",
                      "guarantee": None, "status": "ok", "message": "ok", "explanation": "", "smt2": "",
                      "model": None, "core": None, "duration_s": 0.0, "instances": None}],
        "obligations": [_ob("Sensor.g1.hoare", "Sensor", 1), _ob("Sensor.g2.review", "Sensor", 2, "review"),
                        _ob("Planner.g0.dafny", "Planner", 0, "dafny")],
        "evidence": [_ev("Sensor.g1.hoare", "discharged"), _ev("Sensor.g2.review", "discharged", "review", "review"),
                     _ev("Planner.g0.dafny", "discharged")],
        "environment_assumptions": [{"node": "Sensor", "source": "c.rcl:2:5", "text": "0 <= in.r"}],
        "pending": [], "lint": [],
    }


def _status(arg: Argument, eid: str) -> str | None:
    return arg.elements[eid].status



def _rendered() -> dict[str, Any]:
    """:func:`_report` as the report writes it for its renderers: each requirement with its verdict, note
    and check record (records/requirement_rows.py), here informal (no formal statement: traced only)."""
    from rclverify.report.requirement_rows import _CHECK_FIELDS
    rep = _report()
    check = {**{k: None for k in _CHECK_FIELDS}, "origin": "plan", "source": "contracts/plan.yaml:3:5",
             "declarations": []}  # an informal requirement's record: nothing checked
    rep["requirements"] = [{**rq, "verdict": "informal", "note": "no formal statement: traced only",
                            "check": check} for rq in rep["requirements"]]
    return ungrouped_report(rep)  # the parts it leaves out completed empty, its problems grouped by the renderers

def test_structure_has_the_gsn_elements_of_the_method() -> None:
    arg = _build(_report())
    els = arg.elements
    top = els[arg.top]
    assert arg.top == "G-system" and "REQ1, REQ2" in top.text and top.in_context_of == ("C-plan",)
    assert {"G-REQ1", "G-REQ2", "S-REQ1", "G-Sensor", "G-Planner", "G-Sensor.g1", "G-Sensor.g2", "G-Planner.g1",
            "G-sc.Planner.sc1", "Sn-sc.Planner.sc1", "A-persist", "J-calculus", "A-env.Sensor.1"} <= set(els)
    assert "composition calculus" in els["S-REQ1"].text
    assert els["S-REQ1"].supported_by == ("G-Sensor.g1", "G-Planner.g1", "G-sc.Planner.sc1")
    assert "A-persist" in els["S-REQ1"].in_context_of and "J-calculus" in els["S-REQ1"].in_context_of
    # the whole-contract obligation (guarantee 0) supports every guarantee of its node
    assert "Sn-ev.Planner.g0.dafny" in els["G-Planner.g1"].supported_by
    # node-level health findings support every guarantee of the node
    assert "Sn-health.Sensor.assumption-satisfiable" in els["G-Sensor.g2"].supported_by
    assert all(e.status == "discharged" for e in els.values() if e.type in ("goal", "strategy", "solution"))
    assert all(e.status is None for e in els.values() if e.type in ("context", "assumption", "justification"))


def test_one_failed_solution_fails_every_goal_above_it() -> None:
    rep = _report()
    rep["evidence"][0]["status"] = "failed"  # Sensor.g1.hoare
    arg = _build(rep)
    for eid in ("Sn-ev.Sensor.g1.hoare", "G-Sensor.g1", "S-REQ1", "G-REQ1", "S-requirements", "G-Sensor",
                "S-contracts", "G-system"):
        assert _status(arg, eid) == "failed", eid
    # what it does not support is unaffected
    for eid in ("G-Sensor.g2", "G-REQ2", "G-Planner", "G-Planner.g1"):
        assert _status(arg, eid) == "discharged", eid


def test_a_loop_assumption_is_an_explicit_gsn_assumption() -> None:
    rep = _report()
    rep["derived_properties"][0]["loop_assumption"] = "Rule R4 ... every node in the loop terminates"
    arg = _build(rep)
    loops = [e for e in arg.elements.values() if e.id.startswith("A-loop")]
    assert len(loops) == 1 and "terminates" in loops[0].text
    assert loops[0].id in arg.elements["S-REQ1"].in_context_of and loops[0].id in arg.elements["S-contracts"].in_context_of


def test_missing_evidence_is_an_undeveloped_goal_counted_as_pending_or_unverified() -> None:
    rep = _report()
    del rep["evidence"][1]  # Sensor.g2.review has no record
    rep["obligations"] = [o for o in rep["obligations"] if o["id"] != "Planner.g0.dafny"]
    del rep["evidence"][-1]  # Planner guarantee 1: no obligation at all
    arg = _build(rep)
    ob = arg.elements["G-ob.Sensor.g2.review"]
    assert ob.undeveloped and ob.status == "pending" and not ob.supported_by
    # no obligation at all for the guarantee: unverified, as the report has it (report/unverified.py)
    none = arg.elements["G-Planner.g1.evidence"]
    assert none.undeveloped and none.status == "unverified"
    # REQ2 rests on Sensor guarantee 2 (its record missing: pending), REQ1 on Planner guarantee 1
    assert _status(arg, "G-REQ2") == "pending" and _status(arg, "G-REQ1") == "unverified"
    assert _status(arg, "G-system") == "unverified"


def test_any_evidence_kind_is_a_solution_with_its_own_status() -> None:
    rep = _report()
    rep["obligations"].append(_ob("Sensor.g1.experiment.e0", "Sensor", 1, "experiment"))
    rep["evidence"].append(_ev("Sensor.g1.experiment.e0", "inconclusive", "experiment", "experiment"))
    arg = _build(rep)
    sn = arg.elements["Sn-ev.Sensor.g1.experiment.e0"]
    assert sn.type == "solution" and sn.status == "inconclusive" and sn.text.startswith("experiment evidence")
    assert sn.url == "artifacts/evidence/Sensor.g1.experiment.e0.json"
    assert _status(arg, "G-REQ1") == "inconclusive" and _status(arg, "G-REQ2") == "discharged"


def test_propagation_takes_the_worst_child_and_rejects_malformed_structures() -> None:
    els = {e.id: e for e in [
        Element("G1", "goal", "top", supported_by=("S1",), in_context_of=("C1",)),
        Element("S1", "strategy", "s", supported_by=("G2", "G3", "Sn1")),
        Element("G2", "goal", "no evidence", undeveloped=True),
        Element("G3", "goal", "stale", supported_by=("Sn2",)),
        Element("Sn1", "solution", "ok", status="discharged"),
        Element("Sn2", "solution", "old", status="stale"),
        Element("C1", "context", "c"),
    ]}
    arg = propagate(Argument("G1", els))
    assert [arg.status(i) for i in ("G1", "S1", "G2", "G3", "C1")] == ["stale", "stale", "pending", "stale", None]
    # only the status changes: every other field (all of them, also ones added later) is kept
    assert all(arg.elements[i] == dataclasses.replace(e, status=arg.status(i)) for i, e in els.items())
    with pytest.raises(ArgumentError, match="cycle"):
        propagate(Argument("G1", {**els, "G3": Element("G3", "goal", "x", supported_by=("G1",))}))
    with pytest.raises(ArgumentError, match="cannot link"):
        propagate(Argument("G1", {**els, "G3": Element("G3", "goal", "x", supported_by=("C1",))}))
    with pytest.raises(ArgumentError, match="must start with"):
        propagate(Argument("G1", {**els, "Sn3": Element("Sn3", "strategy", "x")}))
    with pytest.raises(ArgumentError, match="not an evidence status"):
        propagate(Argument("G1", {**els, "Sn1": Element("Sn1", "solution", "x", status="proved")}))


def test_json_round_trips_and_is_deterministic() -> None:
    arg = _build(_report())
    text = to_json_text(arg)
    assert Argument.from_json(json.loads(text)) == arg
    assert to_json_text(_build(copy.deepcopy(_report()))) == text
    from rclverify.records.store import dumps
    from rclverify.report.fragments import FragmentCache
    assert text == dumps(arg.to_json())
    cache = FragmentCache()
    assert to_json_text(arg, cache) == text and cache.misses > 0  # rendered piece by piece
    misses = cache.misses
    assert to_json_text(_build(copy.deepcopy(_report())), cache) == text and cache.misses == misses  # all kept


def test_gsn2x_yaml_has_the_documented_shape() -> None:
    rep = _report()
    del rep["evidence"][1]
    arg = _build(rep)
    text = to_gsn_yaml(arg, "mini")
    assert text.startswith("# mini, generated by rclverify")
    data = yaml.safe_load(text)
    assert list(data) == list(arg.elements)
    prefix = {"goal": "G", "strategy": "S", "solution": "Sn", "context": "C", "assumption": "A", "justification": "J"}
    for eid, body in data.items():
        e = arg.elements[eid]
        assert eid.startswith(prefix[e.type]) and isinstance(body["text"], str)
        assert set(body) <= {"text", "supportedBy", "inContextOf", "undeveloped", "url", "acp"}
        for x in body.get("supportedBy", []):
            assert data[x] is not None and arg.elements[x].type in ("goal", "strategy", "solution")
        for x in body.get("inContextOf", []):
            assert arg.elements[x].type in ("context", "assumption", "justification")
    assert data["G-ob.Sensor.g2.review"]["undeveloped"] is True
    assert data["Sn-ev.Sensor.g1.hoare"]["url"] == "../artifacts/evidence/Sensor.g1.hoare.json"
    assert data["G-system"]["text"].endswith("[pending]")


def test_hostile_text_cannot_break_the_yaml_or_the_dot() -> None:
    rep = _report()
    rep["requirements"][0]["text"] = 'x"\n  supportedBy: [G-evil]\n}; "a" -> "b'
    arg = _build(rep)
    data = yaml.safe_load(to_gsn_yaml(arg))
    assert "G-evil" not in data and data["G-REQ1"]["text"].startswith('REQ1: x"')
    dot = to_dot(arg)
    assert '"G-REQ1" [label="G-REQ1\\nREQ1: x\\"' in dot


@pytest.mark.skipif(shutil.which("dot") is None, reason="graphviz not installed")
def test_the_html_report_embeds_the_argument_diagram(tmp_path: Any) -> None:
    html = render.render_html(_rendered())
    section = html[html.index('<section id="argument">'):]
    section = section[:section.index("</section>")]
    assert "<svg" in section and "G-system" in section and 'href="#argument"' in html
    paths = write_argument(typed_report(_report()), tmp_path)
    assert [p.name for p in paths] == ["argument.json", "argument.gsn.yaml", "argument.dot", "argument.svg"]
    before = [p.read_bytes() for p in paths]
    write_argument(typed_report(_report()), tmp_path)
    assert [p.read_bytes() for p in paths] == before


def test_without_graphviz_the_report_shows_the_dot_source() -> None:
    view = argument_view(typed_report(_report()), NO_DOT)
    assert view["svg"] is None and view["dot"].startswith("// assurance argument of mini")
    html = render.render_html(_rendered(), rendering=NO_DOT)
    assert "The argument's Graphviz source" in html and "no graphviz in this test" in html
    md = render.render_markdown(_rendered())
    assert "## Assurance argument (GSN)" in md and "`G-REQ1`" in md


@pytest.mark.skipif(shutil.which("dot") is None, reason="graphviz not installed")
def test_a_long_element_text_is_clipped_in_the_tooltip_so_dot_accepts_it(tmp_path: Any) -> None:
    # a 1000-node plan's context element names every contract file: Graphviz rejects
    # a quoted string over 16,384 characters, and the argument diagram was lost
    rep = _report()
    rep["meta"]["contracts"] = [f"contracts/n{k}.rcl" for k in range(2000)]
    arg = _build(rep)
    assert max(len(e.text) for e in arg.elements.values()) > 16_384
    assert all(len(line) < 16_384 for line in to_dot(arg).splitlines())
    assert "argument.svg" in [p.name for p in write_argument(typed_report(rep), tmp_path)]


def test_an_argument_too_large_to_draw_is_not_laid_out(tmp_path: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    from rclverify.report.argument import export
    from rclverify.report import diagram
    n = len(_build(_rendered()).elements)
    monkeypatch.setattr(export, "MAX_LAYOUT_ELEMENTS", n - 1)
    monkeypatch.setattr(diagram, "render_dot", lambda *a, **k: pytest.fail("dot must not run"))
    view = argument_view(_rendered())
    assert view["too_large"] and view["svg"] is None and f"the argument has {n} elements" in view["note"]
    (tmp_path / "argument.svg").write_text("<svg/>")  # a diagram of an earlier, smaller argument
    names = [p.name for p in write_argument(_rendered(), tmp_path)]
    assert names == ["argument.json", "argument.gsn.yaml", "argument.dot"] and not (tmp_path / "argument.svg").exists()
    html = render.render_html(_rendered(), rendering=NO_DOT)
    section = html[html.index('<section id="argument">'):html.index("</section>", html.index('<section id="argument">'))]
    assert f"the argument has {n} elements" in section and '<a href="argument.dot">' in section
    assert "<pre>" not in section and 'href="argument.svg"' not in section
    assert "No diagram: the argument has" in render.render_markdown(_rendered())


def _claim_points_obey_v09(data: dict[str, Any]) -> list[tuple[str, str]]:
    """Every assurance claim point of a gsn2x YAML document, ``(element, ACP name)``, after checking gsn2x's V09
    on it: it references only the element itself or the element's supportedBy / inContextOf targets."""
    out = []
    for eid, body in data.items():
        for name, refs in (body.get("acp") or {}).items():
            assert refs, (eid, name)
            for x in refs:
                assert x == eid or x in body.get("supportedBy", []) or x in body.get("inContextOf", []), (eid, name, x)
            out.append((eid, name))
    return out


def test_assurance_claim_points_mark_where_confidence_is_argued() -> None:
    import msgspec
    from rclverify.report.assemble import with_confidence
    from rclverify.report.confidence_rows import confidence_part
    rep = _report()
    rep["evidence"][0]["status"] = "failed"  # counter-evidence: a defeater of Sensor guarantee 1
    rep["obligations"][0]["status"] = "failed"
    rep["nodes"][0]["guarantees"][0]["obligations"] = ["Sensor.g1.hoare"]
    rep["nodes"][0]["guarantees"][1]["obligations"] = ["Sensor.g2.review"]
    typed = typed_report(rep)  # the confidence pass reads and gives the decoded report
    rep = msgspec.to_builtins(with_confidence(typed, confidence_part(typed, [("Sensor", "Planner")])))
    data = yaml.safe_load(to_gsn_yaml(_build(rep), "mini"))
    points = dict(_claim_points_obey_v09(data))
    # each requirement goal has one (these requirements are argued by the calculus: no confidence of their own)
    assert points["G-REQ1"] == "ACP-REQ1" and points["G-REQ2"] == "ACP-REQ2"
    # a node claim: on its link to the premise that limits it, with the confidence and rule C3
    assert data["G-Sensor"]["acp"] == {"ACP-Sensor": ["G-Sensor.g1"]}
    assert "[ACP-Sensor: confidence 0 by rule C3, limited by Sensor guarantee 1" in data["G-Sensor"]["text"]
    assert "confidence 0.0001 by rule C4" not in data["G-Planner"]["text"]
    assert "its derived property (rules R1-R4): confidence 0 by rule C4" in data["G-Planner"]["text"]
    # where the defeater attaches
    assert data["G-Sensor.g1"]["acp"] == {"ACP-Sensor.g1.challenged": ["G-Sensor.g1"]}
    assert "challenged by CSn-ev.Sensor.g1.hoare (defeated): confidence 0 by rule C0" in data["G-Sensor.g1"]["text"]
    # the model rejects a claim point gsn2x's V09 would reject
    arg = _build(rep)
    bad = dict(arg.elements)
    bad["G-Sensor"] = dataclasses.replace(bad["G-Sensor"], acp=(("ACP-x", ("G-Planner.g1",)),))
    with pytest.raises(ArgumentError, match="ACP-x references 'G-Planner.g1'"):
        propagate(Argument(arg.top, bad))
    assert Argument.from_json(arg.to_json()) == arg


def test_a_requirement_with_a_check_record_is_argued_by_formal_entailment() -> None:
    """The form of a requirement's goal is read from its row: a check record (the requirements stage's)
    gives the formal entailment with Z3's proof under it; an empty one the calculus over its support."""
    rep = _report()
    rep["requirements"][0].update({"verdict": "met", "note": "proved", "check": {
        "formal": "out.x > 0", "smt2": "artifacts/requirements/REQ1.smt2",
        "used": [{"kind": "guarantee", "node": "Sensor", "index": 1, "label": "Sensor guarantee 1"}]}})
    els = _build(rep).elements
    assert "formal entailment: out.x > 0" in els["S-REQ1"].text and "(Sensor guarantee 1)" in els["S-REQ1"].text
    assert els["S-REQ1"].supported_by == ("Sn-req.REQ1", "G-Sensor.g1")
    assert els["Sn-req.REQ1"].status == "discharged" and els["Sn-req.REQ1"].url == "artifacts/requirements/REQ1.smt2"
    # the control: REQ2's row has no check record, so the calculus argues it over its support
    assert "composition calculus" in els["S-REQ2"].text and "Sn-req.REQ2" not in els


def test_argument_json_of_another_shape_is_refused_when_read_back() -> None:
    import msgspec
    data = json.loads(to_json_text(_build(_report())))
    assert Argument.from_json(data) == _build(_report())  # the control: the file as written reads back
    first = {**data["elements"][0], "colour": "red"}
    with pytest.raises(msgspec.ValidationError, match="colour"):
        Argument.from_json({**data, "elements": [first, *data["elements"][1:]]})
    with pytest.raises(msgspec.ValidationError, match="supported_by"):
        Argument.from_json({**data, "elements": [{**data["elements"][0], "supported_by": "G-x"}]})


def test_a_report_json_object_gives_the_argument_of_the_decoded_report(tmp_path: Any) -> None:
    """write_argument decodes a report's JSON object once (report/view.py decoded_parts): the files are
    those of the decoded report; a JSON object of another shape is refused, never read by key."""
    import msgspec
    typed = typed_report(_report())
    files = ("argument.json", "argument.gsn.yaml", "argument.dot")
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    write_argument(typed, tmp_path / "a", files=files)
    write_argument(typed.to_json(), tmp_path / "b", files=files)
    assert [(tmp_path / "a" / f).read_bytes() for f in files] == [(tmp_path / "b" / f).read_bytes() for f in files]
    bad = typed.to_json()
    bad["nodes"][0]["guarantees"][0]["index"] = "one"
    with pytest.raises(msgspec.ValidationError, match="index"):
        write_argument(bad, tmp_path / "b", files=files)


def test_a_check_record_is_read_through_its_record_class() -> None:
    """A requirement's check (records/requirement_check.py RequirementCheckRow): its declarations become
    goals with their evidence, its ``assuming`` formulas assumptions, a second solver that disagrees a
    defeater (one that agrees none: the control); a check of another shape is refused."""
    import msgspec
    check = {"formal": "out.x > 0", "smt2": "artifacts/requirements/REQ1.smt2", "assuming": ["in.y > 1"],
             "used": [{"kind": "guarantee", "node": "Sensor", "index": 1, "label": "Sensor guarantee 1"}],
             "declarations": [{"label": "Sensor progress", "node": "Sensor", "kind": "progress", "index": 0,
                               "text": "progress", "source": "c.rcl:3:3", "status": "pending",
                               "words": "declared, not verified"}],
             "solvers": {"agreement": "disagree", "why": "cvc5 found a model", "cvc5": None}}
    rep = _report()
    rep["requirements"][0].update({"verdict": "met", "note": "proved", "check": check})
    els = _build(rep).elements
    assert els["G-decl.Sensor_progress"].status == "pending" and "G-decl.Sensor_progress" in els["S-REQ1"].supported_by
    assert "(c.rcl:3:3): pending (declared, not verified)" in els["Sn-decl.Sensor_progress"].text
    assert "REQ1 assumes: in.y > 1" in els["A-REQ1.assuming.1"].text and "A-REQ1.assuming.1" in els["S-REQ1"].in_context_of
    assert "cvc5 found a model" in els["CSn-solvers.REQ1"].text and els["G-REQ1"].defeated
    rep["requirements"][0]["check"] = {**check, "solvers": {"agreement": "two solvers", "why": "", "cvc5": None}}
    els = _build(rep).elements
    assert "CSn-solvers.REQ1" not in els and not els["G-REQ1"].defeated
    rep["requirements"][0]["check"] = {**check, "used": [{"kind": "guarantee", "node": "Sensor", "index": "1"}]}
    with pytest.raises(msgspec.ValidationError, match="used"):
        _build(rep)
