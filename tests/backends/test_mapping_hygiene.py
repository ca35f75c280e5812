"""Mapping hygiene (issue 64): two variables on one topic read distinct
fields or get a located error; the generated mapping names each variable's
field or says which it omits and why; an ambiguous node name in the plan's
ros.nodes is answered with the candidates."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
import yaml

from rclverify.cli.commands import main
from rclverify.traces.mapping import RuleError, load_rules, rule_for

REACH = """node Reach {
  inputs( x : REAL, y : REAL )
  outputs( ok : BOOL )
  topics( geometry_msgs/Point target matches(in.x),
          geometry_msgs/Point target matches(in.y),
          std_msgs/Bool ok matches(out.ok) )
  assume( in.x < in.y )
  guarantee( out.ok <=> in.x < in.y )
}
"""
PLAN = """name: reach
contracts: [contracts/reach.rcl]
nodes:
  Reach:
    evidence:
      - {backend: monitors, traces: [runs/run.jsonl]}
"""
RUN = [{"topic": "target", "time": 1.0, "x": 1.0, "y": 2.0, "z": 0.0}, {"topic": "ok", "time": 1.1, "data": True},
       {"topic": "target", "time": 2.0, "x": 3.0, "y": 4.5, "z": 0.0}, {"topic": "ok", "time": 2.1, "data": True}]
PER_VAR = "topics:\n  target: {fields: {x: [x], y: [y]}}\n  ok: {fields: [data]}\n"


@pytest.fixture()
def reach(tmp_path: Path) -> Path:
    ws = tmp_path / "reach"
    for d in ("contracts", "runs", "backends/monitors"):
        (ws / d).mkdir(parents=True)
    (ws / "contracts" / "reach.rcl").write_text(REACH, encoding="utf-8")
    (ws / "contracts" / "plan.yaml").write_text(PLAN, encoding="utf-8")
    (ws / "runs" / "run.jsonl").write_text("".join(json.dumps(x) + "\n" for x in RUN), encoding="utf-8")
    return ws


def _run(*args: str) -> tuple[int, str]:
    """``rclverify ARGS`` in a process of its own: its messages as a user sees them."""
    import subprocess
    import sys
    p = subprocess.run([sys.executable, "-m", "rclverify.cli.commands", *args], capture_output=True, text=True, timeout=300)
    return p.returncode, p.stdout + p.stderr


def test_two_variables_on_one_topic_without_their_fields_is_a_located_error(reach):
    rc, out = _run("verify", "-w", str(reach))
    assert rc != 0  # the check task fails: no evidence is made
    assert "contracts/reach.rcl:5:11: error: Reach maps in.x and in.y to topic target: both would read its first " \
           "REAL field, so in.y would silently hold in.x's value" in out
    assert "Traceback" not in out
    # a list of fields for the topic does not separate them either, nor in the monitor command
    (reach / "backends" / "monitors" / "mapping.yaml").write_text(
        "topics:\n  target: {fields: [x, y]}\n", encoding="utf-8")
    rc, out = _run("monitor", "-w", str(reach), str(reach / "runs" / "run.jsonl"))
    assert rc != 0 and "both would read field 'x'" in out


def test_each_variable_reads_its_own_field(reach, capsys):
    (reach / "backends" / "monitors" / "mapping.yaml").write_text(PER_VAR, encoding="utf-8")
    assert main(["monitor", "-w", str(reach), "--json", str(reach / "runs" / "run.jsonl")]) == 0
    [row] = json.loads(capsys.readouterr().out)
    # y is read from y: the assumption x < y holds at both messages and both answers are judged
    assert row["assumption"]["violations"] == 0 and row["counts"]["satisfied"] == 2


def test_per_variable_rules_are_read_and_checked():
    rules = load_rules(yaml.safe_load(PER_VAR)["topics"])
    assert rule_for(rules, "target", "in.y").fields == ("y",) and rule_for(rules, "/target", "out.x").fields == ("x",)
    assert rule_for(rules, "ok", "out.ok").fields == ("data",) and rules["target"].fields == ()
    with pytest.raises(RuleError) as e:
        load_rules({"target": {"fields": {"x": "x"}}})
    assert e.value.path == ("topics", "target", "fields", "x")


def test_the_generated_mapping_names_each_field_or_says_why_not(reach, capsys):
    (reach / "backends" / "monitors" / "mapping.yaml").write_text(PER_VAR, encoding="utf-8")
    assert main(["generate", "ros2", "-w", str(reach), "-o", str(reach / "gen")]) == 0
    got = yaml.safe_load((reach / "gen" / "rclverify_mapping.yaml").read_text(encoding="utf-8"))
    assert got["topics"]["target"] == {"fields": {"x": ["x"], "y": ["y"]}}  # never one list for two variables
    # a standard message of several fields that no rule narrows: the field of the variable's name,
    # else omitted with the reason (never the first field of the type, which may be another quantity)
    (reach / "backends" / "monitors" / "mapping.yaml").unlink()
    one = REACH.replace("          geometry_msgs/Point target matches(in.y),\n", "").replace(
        "std_msgs/Bool ok", "geometry_msgs/Point dy matches(in.y), std_msgs/Bool ok")
    (reach / "contracts" / "reach.rcl").write_text(one.replace("in.y", "in.gap").replace("y : REAL", "gap : REAL"),
                                                   encoding="utf-8")
    assert main(["generate", "ros2", "-w", str(reach), "-o", str(reach / "gen")]) == 0
    text = (reach / "gen" / "rclverify_mapping.yaml").read_text(encoding="utf-8")
    topics = yaml.safe_load(text)["topics"]
    assert topics["target"] == {"fields": ["x"]} and "dy" not in topics
    assert "#   dy (Reach.in.gap): geometry_msgs/Point has several fields and no mapping rule names the one" in text


def test_an_ambiguous_node_name_is_answered_with_the_candidates(tmp_path):
    ws = tmp_path / "rig"
    shutil.copytree(Path(__file__).parent.parent / "data" / "ros_corpus" / "loose", ws)
    (ws / "contracts").mkdir()
    (ws / "contracts" / "rig.rcl").write_text(
        "node RigJogger {\n  inputs( x : REAL )\n  outputs( y : REAL )\n  guarantee( out.y == in.x )\n}\n")
    for extra in ("  nodes: {RigJogger: /rig_jogger}\n", ""):
        (ws / "contracts" / "plan.yaml").write_text(
            "name: rig\ncontracts: [contracts/rig.rcl]\nros:\n  workspaces: [src]\n" + extra)
        assert main(["ros", "check", "-w", str(ws), "--json", str(ws / "f.json")]) == 1
        [f] = [f for f in json.loads((ws / "f.json").read_text())["findings"] if f["code"] == "ROS-NODE-NOT-IN-GRAPH"]
        assert f["message"].startswith("contract node RigJogger is ambiguous")
        assert "/rig_jogger@bench_tools.jog_linear.py (bench_tools/jog_linear.py, " \
               "src/bench_tools/scripts/jog_linear.py:10)" in f["message"]
        assert "/rig_jogger@bench_tools.jog_spin.py" in f["message"] and "does not have" not in f["message"]
        assert (f["ros"]["file"], f["ros"]["line"]) == ("src/bench_tools/scripts/jog_linear.py", 10)
