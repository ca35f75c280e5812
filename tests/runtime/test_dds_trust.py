"""What a live run cannot vouch for keeps its evidence from ``discharged``
(runtime/dds/trust.py, issue 47)."""
from __future__ import annotations

from rclverify.runtime.dds.trust import VERDICT_KEY, downgrade, reasons_for


def _nodes() -> list[dict]:
    return [{"node": "Limiter", "status": "discharged", "explanation": "all good"},
            {"node": "Ranger", "status": "discharged", "explanation": "all good"},
            {"node": "Base", "status": "failed", "explanation": "a violation"}]


TOPICS = {"Limiter": ["limit", "speed"], "Ranger": ["range"], "Base": ["estop"]}


def test_a_writer_beside_the_gate_concerns_the_nodes_of_that_topic_only() -> None:
    nodes = _nodes()
    downgrade(nodes, TOPICS, {"speed": ["node /rogue"]}, {})
    assert [n["status"] for n in nodes] == ["inconclusive", "discharged", "failed"]
    assert "node /rogue also wrote on the guarded topic /speed" in nodes[0]["explanation"]


def test_a_foreign_verdict_writer_concerns_every_node_and_a_failure_stays_failed() -> None:
    nodes = _nodes()
    downgrade(nodes, TOPICS, {VERDICT_KEY: ["participant 1234"]}, {})
    assert [n["status"] for n in nodes] == ["inconclusive", "inconclusive", "failed"]
    assert all("trust" in n for n in nodes)


def test_a_reader_made_again_may_have_missed_a_question() -> None:
    assert reasons_for(["range"], {}, {"range": 2, "speed": 0})[0].startswith("the reader of /range was made again 2")
    assert reasons_for(["limit"], {}, {"range": 2}) == []
    nodes = _nodes()
    downgrade(nodes, TOPICS, {}, {"range": 1})
    assert [n["status"] for n in nodes] == ["discharged", "inconclusive", "failed"]
