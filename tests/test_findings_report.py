"""Report summaries and the loop view (report/build.py, system/model.py)."""
from __future__ import annotations

from rclverify.report.build import _evidence_of_cone, _headline
from rclverify.system.model import Link, SystemModel


def test_headline_has_no_empty_fragments():
    h = _headline([], {}, [], [])
    assert h == "no obligations; no side conditions; no contract health problem."
    assert ": ;" not in h and "0 obligations" not in h
    rows = [{"status": "pending"}]
    h = _headline(rows, {"pending": 1}, [{"status": "discharged"}], [{"status": "problem"}])
    assert h == "1 obligation: 1 pending; 1/1 side conditions discharged; 1 contract health problem."


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


def test_cycles_follow_existing_connections_only():
    # A -> B -> C -> A and A -> C: one SCC, two elementary cycles; no B -> A edge
    links = (Link("A", "x", "B", "x", "name"), Link("B", "y", "C", "y", "name"),
             Link("C", "z", "A", "z", "name"), Link("A", "w", "C", "w", "name"))
    m = SystemModel(("A", "B", "C"), links, (), (("A", "B", "C"),))
    assert m.cycles() == [["A", "C"], ["A", "B", "C"]]
    view = m.view({})
    assert view["loops"] == m.cycles() and view["loop_components"] == [["A", "B", "C"]]
