"""Expected verdicts stated in the plan (report/expected.py)."""
from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

from _typed_rows import typed_report
from rclverify.lang.ast import Loc
from rclverify.report.expected import expected_rows


def _plan(expected):
    entry = SimpleNamespace(node="Agent", index=0, backend="ajpf", config={"backend": "ajpf", "expected": expected},
                            loc=Loc("contracts/plan.yaml", 70, 9))
    return SimpleNamespace(evidence={"Agent": (entry,)}, locs={})


OBS = typed_report({"obligations": [
    {"id": "Agent.g3.ajpf.p28_i12", "node": "Agent", "backend": "ajpf", "guarantee": 3, "instance": "i=12",
     "status": "discharged"},
    {"id": "Agent.g3.ajpf.p27_i0", "node": "Agent", "backend": "ajpf", "guarantee": 3, "instance": "i=0",
     "status": "pending"},
    {"id": "Agent.g2.ajpf.p14_i0", "node": "Agent", "backend": "ajpf", "guarantee": 2, "instance": "i=0",
     "status": "failed"},
]}).obligations


def test_a_decided_verdict_other_than_the_expected_one_is_a_mismatch():
    rows = expected_rows(_plan([{"guarantee": 3, "instance": "i=12", "verdict": "failed", "reason": "known false"}]),
                         OBS)
    assert [(r.obligation, r.outcome) for r in rows] == [("Agent.g3.ajpf.p28_i12", "MISMATCH")]
    assert rows[0].reason == "known false" and rows[0].source == "contracts/plan.yaml:70:9"


def test_expected_undecided_unmatched_and_malformed():
    rows = expected_rows(_plan([{"guarantee": 2, "verdict": "failed"}, {"guarantee": 3, "verdict": "failed"},
                                {"guarantee": 9, "verdict": "failed"}, {"verdict": "maybe"}]), OBS)
    outcomes = [(r.obligation, r.outcome) for r in rows]
    assert ("Agent.g2.ajpf.p14_i0", "as expected") in outcomes
    assert ("Agent.g3.ajpf.p27_i0", "not yet decided") in outcomes
    assert (None, "no obligation matches") in outcomes
    assert any(o.startswith("invalid expectation") for _, o in outcomes)
