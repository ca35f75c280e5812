"""The pipeline's monitors backend (``traces:`` of a plan entry, ``doit verify``) judges a managed node's
recorded run through the lifecycle gate the live run asks (backends/monitors/lifecycle.py; docs/monitors.md,
"Lifecycle nodes in the pipeline"): requests heard outside the guarantees' scope are no questions, outputs
outside ``active`` are red, a transition deadline stated in RCL is judged.  Each with its control: the same
run, the contract not naming its transition topic (a plain node), judged as before."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from rclverify.backends.base import NodeTarget
from rclverify.backends.monitors.backend import MonitorsBackend
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check

TRANSITION = ",\n          lifecycle_msgs/TransitionEvent battery/transition_event"
RCL = f"""\
node Battery {{
  inputs( request : REAL )
  outputs( level : REAL )
  topics( std_msgs/Float64 request matches(in.request), std_msgs/Float64 level matches(out.level){TRANSITION} )
  assume( in.request >= 0 )
  guarantee( out.level >= in.request ) while active
  ready within 50 ms of activate
}}
"""
PLAIN = RCL.replace(TRANSITION, "").replace(" while active", "").replace("  ready within 50 ms of activate\n", "")
#: configured at 1 s, activating at 2.0 s, active at 2.08 s, deactivated at 3 s: (time, start, goal)
LIFE = [(1.0, 1, 10), (1.0, 10, 2), (2.0, 2, 13), (2.08, 13, 3), (3.0, 3, 14), (3.0, 14, 2)]


def _run(tmp: Path, answer_inactive: bool) -> str:
    """A log: a request every 0.25 s from 0.5 s (9 at 1.0 s, while inactive; 1 otherwise), each answered
    20 ms later with 5 (only while active unless ``answer_inactive``)."""
    rows: list[tuple[float, str, dict[str, Any]]] = [
        (t, "battery/transition_event", {"timestamp": int(t * 1e9), "start_state.id": s, "goal_state.id": g})
        for t, s, g in LIFE]
    for k in range(12):
        t = 0.5 + 0.25 * k
        rows.append((t, "request", {"data": 9.0 if k == 2 else 1.0}))
        if answer_inactive or 2.1 <= t + 0.02 <= 3.0:
            rows.append((t + 0.02, "level", {"data": 5.0}))
    name = f"run_{int(answer_inactive)}.jsonl"
    (tmp / name).write_text("".join(json.dumps({"topic": topic, "time": round(t, 6), **f}) + "\n"
                                    for t, topic, f in sorted(rows, key=lambda r: r[0])), encoding="utf-8")
    return name


def _evidence(tmp: Path, rcl: str, trace: str) -> Any:
    (tmp / "contracts").mkdir(exist_ok=True)
    (tmp / "contracts/b.rcl").write_text(rcl, encoding="utf-8")
    (tmp / "contracts/plan.yaml").write_text("contracts: [contracts/b.rcl]\n", encoding="utf-8")
    checked = check([parse_text(rcl, "contracts/b.rcl")])
    t = NodeTarget(root=tmp, checked=checked, node=checked.nodes["Battery"],
                   config={"backend": "monitors", "horizon": 1.0, "traces": [trace]},
                   contract_files=("contracts/b.rcl",), plan_file="contracts/plan.yaml",
                   artifacts=tmp / "artifacts" / "monitors" / "Battery")
    (ob,) = MonitorsBackend().export(t)
    return MonitorsBackend().run(ob, t)


def test_a_managed_nodes_run_is_judged_in_its_scope_and_states(tmp_path: Path) -> None:
    quiet = _evidence(tmp_path, RCL.replace("50 ms", "100 ms"), _run(tmp_path, answer_inactive=False))
    life = quiet.details["lifecycle"]
    [node] = life["nodes"]
    # the request of 9 at 1.0 s came while inactive: no question; every request asked while active is answered
    assert quiet.status == "discharged", quiet.explanation
    assert life["not_questions"] == {"request": 9} and node["violations"] == [] and node["scope"] == ["active"]
    assert [(d["status"], d["stated"]) for d in node["deadlines"]] == [("met", "contracts/b.rcl:8:3")]
    counts = quiet.details["monitoring"]["counts"]
    assert (counts["satisfied"], counts["superseded"], counts["open"]) == (3, 0, 0), counts
    # control: the plain contract judges the same run as any node's: every request is a question, the eight
    # heard while the node was not active go unanswered (superseded), the last one too (open)
    plain = _evidence(tmp_path, PLAIN, _run(tmp_path, answer_inactive=False))
    counts = plain.details["monitoring"]["counts"]
    assert plain.status == "inconclusive" and "lifecycle" not in plain.details, plain.explanation
    assert (counts["satisfied"], counts["superseded"], counts["open"]) == (3, 8, 1), counts


def test_outputs_outside_active_and_a_missed_deadline_fail_the_node(tmp_path: Path) -> None:
    ev = _evidence(tmp_path, RCL, _run(tmp_path, answer_inactive=True))
    [node] = ev.details["lifecycle"]["nodes"]
    assert ev.status == "failed"
    assert ev.explanation.startswith("7 output(s) published outside active (lifecycle); the first: /battery "
                                     "published on /level while unconfigured"), ev.explanation
    assert "1 transition deadline(s) missed (lifecycle)" in ev.explanation  # 80 ms over the stated 50 ms
    assert [d["status"] for d in node["deadlines"]] == ["missed"]
    assert [v["time"] for v in node["violations"]][:2] == [0.52, 0.77]


def test_the_transition_topic_counts_as_heard(tmp_path: Path) -> None:
    ev = _evidence(tmp_path, RCL.replace("50 ms", "100 ms"), _run(tmp_path, answer_inactive=False))
    assert ev.details["not_judged"] == [], ev.details["not_judged"]
    # control: a run without its transition events says the topic was not heard (and the node never active)
    trace = _run(tmp_path, answer_inactive=False)
    lines = [ln for ln in (tmp_path / trace).read_text().splitlines() if "transition_event" not in ln]
    (tmp_path / "bare.jsonl").write_text("\n".join(lines) + "\n", encoding="utf-8")
    bare = _evidence(tmp_path, RCL.replace("50 ms", "100 ms"), "bare.jsonl")
    assert [i["name"] for i in bare.details["not_judged"]] == ["/battery/transition_event"]
    assert bare.status == "failed" and "while unconfigured" in bare.explanation
