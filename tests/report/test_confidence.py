"""Evidence strength and the confidence calculus (issue 50; docs/confidence.md)."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import networkx as nx
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from _report_schema import check_report
from _typed_rows import complete
from rclverify.records.evidence_rows import EvidenceRow
from rclverify.records.side_condition_rows import SideConditionRow
from rclverify.report.argument.confidence import Premise, claim, cones, derived_claims, requirement_claim
from rclverify.report.argument.strength import BACKEND_KIND, KINDS, evidence_strength, one_sided_bound
from rclverify.cli.commands import main
from rclverify.model.plan.entries import BACKEND_NAMES

IDENTITY = "var x : REAL;\nvar y : REAL;\n\ny := x\n"
EVIDENCE = """nodes:
  Sensor:
    evidence:
      - {backend: hoare, program: backends/hoare/id.imp, binding: {in.reading: x, out.sensor_value: y}}
  Controller:
    evidence:
      - {backend: hoare, program: backends/hoare/id.imp, binding: {in.sensor_value: x, out.controller_value: y}}
  Actuator:
    evidence:
      - {backend: hoare, program: backends/hoare/id.imp, binding: {in.controller_value: x, out.actuator_value: y}}
"""


def test_every_backend_has_a_strength() -> None:
    assert set(BACKEND_NAMES) == set(BACKEND_KIND)
    assert set(BACKEND_KIND.values()) <= set(KINDS)
    for b in BACKEND_NAMES:  # any status but discharged gives no confidence
        assert evidence_strength(EvidenceRow.of(complete(EvidenceRow, {"backend": b, "status": "failed"}))).doubt == 1.0
        s = evidence_strength(EvidenceRow.of(complete(EvidenceRow, {"backend": b, "status": "discharged",
                                                               "figures": [["count", "60"]]})))
        assert s.kind == BACKEND_KIND[b] and 0 < s.doubt < 1


def test_the_experiment_bound_is_clopper_pearson_with_no_failure() -> None:
    # 0.95 = 1 - (1 - p)^n at p = the bound: n trials all passing
    for n in (1, 10, 47, 300):
        p = one_sided_bound(n)
        assert abs((1 - p) ** n - 0.05) < 1e-12
    s = evidence_strength(EvidenceRow.of(complete(EvidenceRow, {"backend": "experiment", "status": "discharged",
                                                                "figures": [["count", "10"]]})))
    assert s.doubt == pytest.approx(one_sided_bound(10)) and "10 trials" in str(s.detail)


# -- the oracle: random argument graphs with loops against a direct reading of the rules ----------------

@st.composite
def graphs(draw):
    n = draw(st.integers(1, 5))
    nodes = [f"N{i}" for i in range(n)]
    edges = draw(st.lists(st.tuples(st.sampled_from(nodes), st.sampled_from(nodes)), max_size=8))
    own = {v: [Premise(f"{v} p{j}", draw(st.sampled_from(KINDS)),
                       draw(st.sampled_from([0.0, 1e-4, 1e-3, 0.01, 0.05, 0.2, 0.5, 1.0])))
               for j in range(draw(st.integers(0, 3)))] for v in nodes}
    return nodes, edges, own


@settings(max_examples=200, deadline=None)
@given(graphs())
def test_confidence_equals_a_direct_evaluation_of_the_rules(g) -> None:
    nodes, edges, own = g
    producers = {v: [a for a, b in edges if b == v] for v in nodes}
    dg = nx.DiGraph()
    dg.add_nodes_from(nodes)
    dg.add_edges_from(edges)
    got = derived_claims(own, producers)
    assert cones(producers) == {v: frozenset(nx.ancestors(dg, v) | {v}) for v in nodes}
    for v in nodes:
        # C4 read directly: every premise of every node that reaches v (v included), each once; C2: the sum, at most 1
        premises = {p.label: p.doubt for u in nx.ancestors(dg, v) | {v} for p in own[u]}
        doubt = min(1.0, sum(premises.values()))
        assert got[v].doubt == pytest.approx(doubt, abs=1e-9)
        assert got[v].confidence == pytest.approx(1 - doubt, abs=1e-9)
        if premises:
            assert got[v].limits.doubt == max(premises.values())
    proof = Premise("proof", "proof", 1e-4)
    assert requirement_claim(False, proof, own[nodes[0]]).confidence == 0.0
    assert requirement_claim(True, proof, own[nodes[0]]) == claim([proof, *own[nodes[0]]])


@settings(max_examples=200, deadline=None)
@given(graphs(), st.booleans(), st.lists(st.floats(0.0, 0.3), min_size=15, max_size=15))
def test_derived_claims_equal_claim_over_each_cone_exactly(g, shared, doubts) -> None:
    """The per-node fast path (labels all distinct) and the reference (a label shared: every premise
    through claim()) give the claim of claim() over the sorted cone, float for float (issue 67)."""
    nodes, edges, own = g
    it = iter(doubts)  # any doubts, not only the strength table's round ones
    own = {v: [Premise(p.label, p.kind, next(it)) for p in ps] for v, ps in own.items()}
    if shared:  # a label in two places sends derived_claims down the reference path
        own = {v: [Premise(f"p{j}", p.kind, p.doubt) for j, p in enumerate(ps)] for v, ps in own.items()}
    producers = {v: [a for a, b in edges if b == v] for v in nodes}
    cone = cones(producers)
    want = {v: claim(p for m in sorted(cone[v]) for p in own.get(m, ())) for v in nodes}
    assert derived_claims(own, producers) == want
    assert derived_claims(own, producers, vector_from=0) == want  # the bit masks over numpy arrays


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 40), st.data())
def test_the_bit_mask_path_equals_claim_over_each_cone_on_larger_graphs(n: int, data: st.DataObject) -> None:
    """Issue 67: the cones as bit masks over numpy arrays (derived_claims from VECTOR_FROM nodes) give
    claim() over the sorted cone on graphs of up to 40 nodes whose names do not sort as their numbers,
    with loops, joins, premises-free nodes and producers that have no premises entry at all."""
    nodes = [f"N{i}" for i in range(n)]
    extra = ["X", "A0"]  # producers that appear only as producers
    edges = data.draw(st.lists(st.tuples(st.sampled_from(nodes + extra), st.sampled_from(nodes)), max_size=3 * n))
    doubts = st.floats(0.0, 0.2, allow_nan=False)
    own = {v: [Premise(f"{v} p{j}", "tested", data.draw(doubts)) for j in range(data.draw(st.integers(0, 3)))]
           for v in nodes}
    producers = {v: [a for a, b in edges if b == v] for v in nodes}
    cone = cones(producers)
    want = {v: claim(p for m in sorted(cone[v]) for p in own.get(m, ())) for v in nodes}
    assert derived_claims(own, producers, vector_from=0) == want
    assert derived_claims(own, producers, vector_from=10 ** 9) == want


# -- on a verified workspace --------------------------------------------------------------------------

@pytest.fixture(scope="module")
def ws(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("confidence") / "ws"
    assert main(["init", str(root)]) == 0
    (root / "backends/hoare").mkdir(parents=True)
    (root / "backends/hoare/id.imp").write_text(IDENTITY)
    plan = root / "contracts/plan.yaml"
    text = plan.read_text()
    plan.write_text(text.replace("nodes:\n  Sensor: {}\n  Controller: {}\n  Actuator: {}\n", EVIDENCE)
                    .replace("    text: The output of Actuator stays within 0..100.\n",
                             "    text: The output of Actuator stays within 0..100.\n    strength: proof\n"))
    assert main(["verify", "-w", str(root)]) == 0
    return root


def test_strength_and_confidence_in_every_format(ws: Path) -> None:
    r = json.loads((ws / "reports/assurance.json").read_text())
    assert r["evidence"] and all(e["strength"]["kind"] == "proof" and e["status"] == "discharged" for e in r["evidence"])
    assert all(sc["strength"] == {"kind": "proof", "detail": "Z3 and cvc5", "solvers": 2, "doubt": 1e-4}
               for sc in r["side_conditions"])
    req = {q["id"]: q for q in r["requirements"]}
    assert req["REQ1"]["verdict"] == "met" and 0.99 < req["REQ1"]["confidence"] < 1
    assert req["REQ1"]["limited_by"]["sentence"].startswith("REQ1 rests on a proof for Actuator guarantee 1")
    assert req["REQ1"]["strength_shortfall"] == []
    check_report(r, "required strength")  # the keys a required strength adds are in the published schema
    assert r["summary"]["confidence"] == min(q["confidence"] for q in r["requirements"])
    sarif = json.loads((ws / "reports/assurance.sarif").read_text())
    assert sarif and "strength" in (ws / "reports/assurance.junit.xml").read_text()
    assert "rests on a proof for Actuator guarantee 1" in (ws / "reports/assurance.html").read_text()
    assert "confidence" in (ws / "reports/argument.gsn.yaml").read_text()


def test_every_requirement_goal_has_an_assurance_claim_point_gsn2x_accepts(ws: Path) -> None:
    import yaml

    from test_argument import _claim_points_obey_v09
    data = yaml.safe_load((ws / "reports/argument.gsn.yaml").read_text())
    points = _claim_points_obey_v09(data)
    r = json.loads((ws / "reports/assurance.json").read_text())
    for q in r["requirements"]:
        assert (f"G-{q['id']}", f"ACP-{q['id']}") in points
    req1 = data["G-REQ1"]
    assert req1["acp"] == {"ACP-REQ1": ["S-REQ1"]}
    conf = next(q["confidence"] for q in r["requirements"] if q["id"] == "REQ1")
    assert f"[ACP-REQ1: confidence {conf:.4g} by rule C5; REQ1 rests on a proof for Actuator guarantee 1" in req1["text"]
    # the strategy's link to the premise that limits REQ1 (the calculus names it)
    assert data["S-REQ1"]["acp"] == {"ACP-REQ1.limit": ["G-Actuator.g1"]}
    assert all((f"G-{n}", f"ACP-{n}") in points for n in ("Sensor", "Controller", "Actuator"))


def test_a_required_strength_the_evidence_lacks_fails_strict(ws: Path, tmp_path: Path) -> None:
    root = tmp_path / "ws"
    shutil.copytree(ws, root)
    plan = root / "contracts/plan.yaml"
    # Actuator's only evidence goes: REQ1 (strength: proof) now rests on nothing discharged
    plan.write_text(plan.read_text().replace(
        "  Actuator:\n    evidence:\n      - {backend: hoare, program: backends/hoare/id.imp, binding: "
        "{in.controller_value: x, out.actuator_value: y}}\n", "  Actuator: {}\n"))
    assert main(["verify", "-w", str(root), "--strict"]) == 1
    r = json.loads((root / "reports/assurance.json").read_text())
    req = next(q for q in r["requirements"] if q["id"] == "REQ1")
    assert req["confidence"] == 0.0 and req["strength_shortfall"] == ["Actuator guarantee 1 (nothing discharged)"]
    check_report(r, "strength short")
    assert any(p.startswith("Requirement REQ1 requires proof evidence") for p in r["summary"]["problems"])


def test_hoare_conditions_are_decided_by_both_solvers(ws: Path, tmp_path: Path) -> None:
    from rclverify.stages.crosscheck.stage import stage_crosscheck
    r = json.loads((ws / "reports/assurance.json").read_text())
    hoare = [e for e in r["evidence"] if e["backend"] == "hoare"]
    assert hoare and all(e["solvers"]["agreement"] == "two solvers" for e in hoare)
    assert all(e["strength"]["detail"] == "Z3 and cvc5 on the verification conditions" for e in hoare)
    root = tmp_path / "ws"
    shutil.copytree(ws, root)
    # a Hoare condition Z3 is recorded to have proved is in fact satisfiable: the evidence is not discharged
    (root / "artifacts/hoare/Sensor/g2.id.c1.smt2").write_text(
        "(push 1)\n(declare-fun x () Real)\n(assert (< x 0.0))\n(check-sat)\n(pop 1)\n")
    stage_crosscheck(root, ["Sensor", "Controller", "Actuator"])
    assert main(["report", "-w", str(root)]) in (0, 1)
    r = json.loads((root / "reports/assurance.json").read_text())
    ev = next(e for e in r["evidence"] if e["obligation"] == "Sensor.g2.hoare.id.c1")
    assert ev["status"] == "inconclusive" and ev["solvers"]["agreement"] == "disagree"
    assert ev["explanation"].startswith("Not discharged: Z3 answered unsat, cvc5 sat")
    assert next(q for q in r["requirements"] if q["id"] == "REQ2")["verdict"] != "met"


def test_a_side_condition_read_from_cone_summaries_is_not_two_solvers() -> None:
    """cvc5 decides only the last query of a side condition discharged from its producers' cone summaries
    (calculus/summary.py): each summary was proved implied by its cone by Z3 alone, so the proof is not
    one two solvers agreed on (its doubt must not be the two-solver one)."""
    from rclverify.report.argument.strength import DOUBT, side_condition_strength
    sc = {"status": "discharged", "solvers": {"agreement": "two solvers"}, "context": {"summaries": ["Planner"]}}
    s = side_condition_strength(SideConditionRow.of(complete(SideConditionRow, sc)))
    assert s.solvers == 1 and s.doubt == DOUBT["proof"] and "summaries" in str(s.detail), s
    sc["context"] = {"summaries": []}
    assert side_condition_strength(SideConditionRow.of(complete(SideConditionRow, sc))).doubt == DOUBT["proof2"]


def test_the_observed_detail_counts_judged_messages_not_questions() -> None:
    """The monitors count satisfied and violated per judged message (an output, or a question its inputs
    alone decide; docs/semantics.md): a node without inputs has no question, yet its 5 outputs read
    "5 questions answered"."""
    row = {"backend": "monitors", "status": "discharged", "monitoring": {"counts": {"satisfied": 5}, "events_read": 5}}
    d = str(evidence_strength(EvidenceRow.of(complete(EvidenceRow, row))).detail)
    assert d.startswith("5 verdicts on messages (satisfied or violated)") and "question" not in d, d
