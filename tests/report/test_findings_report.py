"""Report summaries and the loop view (report/build.py, model/system/model.py)."""
from __future__ import annotations

import random

from _typed_rows import typed_report

from rclverify.records.records import SEVERITY, worst
from rclverify.report.cones import CONE_NAMES, ConeEvidence
from rclverify.report.summary_rows import headline as _headline
from rclverify.model.system.model import Link, SystemModel


def test_headline_has_no_empty_fragments():
    h = _headline([], {}, [], [])
    assert h == "no obligations; no side conditions; no contract health problem."
    assert ": ;" not in h and "0 obligations" not in h
    r = typed_report({"obligations": [{"status": "pending"}], "side_conditions": [{"status": "discharged"}],
                      "findings": [{"status": "problem"}]})
    h = _headline(r.obligations, {"pending": 1}, r.side_conditions, r.findings)
    assert h == "1 obligation: 1 pending; 1/1 side conditions discharged; 1 contract health problem."


def _evidence_of_cone(cone: list[str], node_evidence: dict[str, str]) -> tuple[str, str]:
    """(worst evidence status, note) of one cone, listed in system order."""
    cones = ConeEvidence(cone, node_evidence)
    return cones.summary(cones.mask(cone))[1:]


def test_evidence_note_names_the_node_contracts_a_derivation_rests_on():
    st, note = _evidence_of_cone(["A", "B", "C"], {"A": "discharged", "B": "failed", "C": "pending"})
    assert st == "failed"
    assert note == "rests on 1 failed node contract: B; 1 pending node contract: C"


def test_a_long_cone_names_ten_contracts_per_status_and_counts_the_rest():
    cone = [f"N{k}" for k in range(25)]
    st, note = _evidence_of_cone(cone, {"N3": "failed"})
    assert st == "failed"
    assert note == ("rests on 1 failed node contract: N3; 24 pending node contracts: "
                    + ", ".join(f"N{k}" for k in range(11) if k != 3) + " and 14 more")


def _note_by_grouping(cone: list[str], node_evidence: dict[str, str]) -> tuple[str, str]:
    """The rule written out plainly: group the cone's names by status, name
    the first CONE_NAMES of each status that is not discharged."""
    by: dict[str, list[str]] = {}
    for m in cone:
        by.setdefault(node_evidence.get(m, "pending"), []).append(m)
    if set(by) == {"discharged"}:
        return "discharged", "every node contract it rests on is discharged"
    parts = []
    for st in sorted(by, key=lambda x: -SEVERITY[x]):
        if st != "discharged":
            ns = by[st]
            more = f" and {len(ns) - CONE_NAMES} more" if len(ns) > CONE_NAMES else ""
            parts.append(f"{len(ns)} {st} node contract{'s' if len(ns) != 1 else ''}: {', '.join(ns[:CONE_NAMES])}{more}")
    return worst(list(by)), "rests on " + "; ".join(parts)


def test_cone_notes_of_a_whole_system_match_the_rule_on_random_cones():
    rng = random.Random(7)
    names = [f"N{k}" for k in range(60)]
    statuses = ["discharged", "failed", "pending", "stale", "inconclusive"]
    for _ in range(40):
        evidence = {n: rng.choice(statuses) for n in names if rng.random() < 0.9}  # some nodes have none
        side_conditions = {n: rng.choice(statuses) for n in names}
        cones = ConeEvidence(names, evidence, side_conditions)
        for _ in range(20):
            members = set(rng.sample(names, rng.randint(1, 60)))
            cone = [n for n in names if n in members]  # a cone lists nodes in system order (model.upstream)
            derivation = worst([side_conditions.get(m, "pending") for m in cone])
            assert cones.summary(cones.mask(cone)) == (derivation, *_note_by_grouping(cone, evidence))
    discharged = {n: "discharged" for n in names}
    everything = ConeEvidence(names, discharged, discharged)
    assert everything.summary(everything.mask(names)) == (
        "discharged", "discharged", "every node contract it rests on is discharged")
    assert ConeEvidence([], {}).summary(0) == ("discharged", "discharged", "derived; rests on no node contract")


def test_cycles_follow_existing_connections_only():
    # A -> B -> C -> A and A -> C: one SCC, two elementary cycles; no B -> A edge
    links = (Link("A", "x", "B", "x", "name"), Link("B", "y", "C", "y", "name"),
             Link("C", "z", "A", "z", "name"), Link("A", "w", "C", "w", "name"))
    m = SystemModel(("A", "B", "C"), links, (), (("A", "B", "C"),))
    assert m.cycles() == [["A", "C"], ["A", "B", "C"]]
    view = m.view({})
    assert view["loops"] == m.cycles() and view["loop_components"] == [["A", "B", "C"]]
