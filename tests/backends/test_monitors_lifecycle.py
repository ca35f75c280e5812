"""The pipeline's monitors backend (``traces:`` of a plan entry, ``doit verify``) judges a managed node's
recorded run through the lifecycle gate the live run asks (backends/monitors/lifecycle.py; docs/monitors.md,
"Lifecycle nodes in the pipeline"): requests heard outside the guarantees' scope are no questions, outputs
outside ``active`` are red, a transition deadline stated in RCL is judged.  Each with its control: the same
run, the contract not naming its transition topic (a plain node), judged as before."""
from __future__ import annotations

import dataclasses
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


def _fleet_log(tmp: Path) -> str:
    """One run of two robots: /r1's battery as in :func:`_run` (answering only while active), /r2's the
    same but answering while inactive too, every name under the robot's namespace."""
    rows: list[str] = []
    for ns, answer_inactive in (("/r1", False), ("/r2", True)):
        for ln in (tmp / _run(tmp, answer_inactive)).read_text().splitlines():
            row = json.loads(ln)
            row["topic"] = f"{ns}/{row['topic']}"
            rows.append(json.dumps(row))
    (tmp / "fleet.jsonl").write_text("\n".join(sorted(rows, key=lambda r: json.loads(r)["time"])) + "\n",
                                     encoding="utf-8")
    return "fleet.jsonl"


def test_a_fleets_run_is_judged_per_instance(tmp_path: Path) -> None:
    """``instances: {Battery: [/r1, /r2]}``: each trace is one obligation per instance, judged on that
    instance's names and lifecycle states; the control is the same run judged for the contract as written
    (its root-namespace names): nothing of it is heard."""
    from rclverify.model.plan.instances import Instance
    trace = _fleet_log(tmp_path)
    rcl = RCL.replace("50 ms", "100 ms")
    (tmp_path / "contracts").mkdir(exist_ok=True)
    (tmp_path / "contracts/b.rcl").write_text(rcl, encoding="utf-8")
    checked = check([parse_text(rcl, "contracts/b.rcl")])
    fleet = tuple(Instance("Battery", ns, "battery", f"Battery_{ns[1:]}") for ns in ("/r1", "/r2"))
    t = NodeTarget(root=tmp_path, checked=checked, node=checked.nodes["Battery"],
                   config={"backend": "monitors", "horizon": 1.0, "traces": [trace]},
                   contract_files=("contracts/b.rcl",), plan_file="contracts/plan.yaml",
                   artifacts=tmp_path / "artifacts" / "monitors" / "Battery", instances=fleet)
    obs = MonitorsBackend().export(t)
    assert [o.id for o in obs] == ["Battery.g0.monitors.fleet_jsonl_Battery_r1", "Battery.g0.monitors.fleet_jsonl_Battery_r2"]
    assert "the contract of Battery as /r1/battery (instance Battery_r1)" in obs[0].statement
    ev = {o.data["instance"]["name"]: MonitorsBackend().run(o, t) for o in obs}
    assert ev["Battery_r1"].status == "discharged", ev["Battery_r1"].explanation
    [r1] = ev["Battery_r1"].details["lifecycle"]["nodes"]
    assert (r1["ros_node"], r1["transitions"], r1["violations"]) == ("/r1/battery", 6, [])
    assert ev["Battery_r1"].details["lifecycle"]["not_questions"] == {"r1/request": 9}
    assert ev["Battery_r2"].status == "failed"
    assert ev["Battery_r2"].explanation.startswith("7 output(s) published outside active (lifecycle); the first: "
                                                   "/r2/battery published on /r2/level while unconfigured")
    # control: no instances, the contract's own names: the fleet's run holds none of them
    plain = dataclasses.replace(t, instances=())
    (ob,) = MonitorsBackend().export(plain)
    bare = MonitorsBackend().run(ob, plain)
    assert bare.status != "discharged" and {i["name"] for i in bare.details["not_judged"]} >= {"/request", "/level"}
