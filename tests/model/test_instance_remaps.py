"""Remap rules per instance in the plan (issue 110): ``instances: {R2: {type: Relay, namespace: /r2,
remap: {odom: /r1/odom}}}`` gives one node its own rules, applied as rcl applies them
(model/plan/instances.py, model/names.py ``resolve``); each with its control."""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.model.instances import fleet_system
from rclverify.model.plan.errors import PlanError
from rclverify.stages.workspace import Workspace

RCL = """\
node OdomSource {
  inputs( wheel : REAL )
  outputs( odom : REAL )
  topics( std_msgs/Float64 wheel matches(in.wheel), std_msgs/Float64 odom matches(out.odom) )
  assume( in.wheel >= 0 )
  guarantee( out.odom >= 0 )
}

node Relay {
  inputs( odom : REAL, limit : REAL )
  outputs( cmd : REAL )
  topics( std_msgs/Float64 odom matches(in.odom), std_msgs/Float64 relay/cmd matches(out.cmd),
          std_msgs/Float64 /fleet/limit matches(in.limit) )
  assume( in.odom >= 0 )
  guarantee( out.cmd == in.odom )
}
"""
SOURCES = "  OdomSource: [/r1, /r2]\n"


def _ws(tmp: Path, instances: str) -> Workspace:
    (tmp / "contracts").mkdir(parents=True, exist_ok=True)
    (tmp / "contracts/fleet.rcl").write_text(RCL, encoding="utf-8")
    (tmp / "contracts/plan.yaml").write_text("contracts: [contracts/fleet.rcl]\ninstances:\n" + instances,
                                             encoding="utf-8")
    return Workspace(tmp, "contracts/plan.yaml")


def test_an_instance_by_name_with_its_remaps(tmp_path: Path) -> None:
    """``R2`` reads ``/r1/odom`` by its remap rule (relative ``odom`` expands to ``/r2/odom``, which the
    rule's ``odom`` also expands to) and writes ``relay/cmd`` remapped to an absolute name; ``R1``, with
    no rule, keeps its namespace's names (the control)."""
    ws = _ws(tmp_path, SOURCES + "  R1: {type: Relay, namespace: /r1}\n"
                       "  R2: {type: Relay, namespace: /r2, node: relay, remap: {odom: /r1/odom, relay/cmd: /cmd_all}}\n")
    [r1, r2] = ws.plan.node_instances["Relay"]
    assert (r1.name, r1.fqn, r1.remaps) == ("R1", "/r1/relay", ())
    assert (r2.name, r2.fqn, [(r.source, r.target) for r in r2.remaps]) == (
        "R2", "/r2/relay", [("odom", "/r1/odom"), ("relay/cmd", "/cmd_all")])
    inst, model = fleet_system(ws.checked, ws.plan.node_instances)
    assert [t.field for t in inst.nodes["R2"].node.topics] == ["/r1/odom", "/cmd_all", "/fleet/limit"]
    assert [t.field for t in inst.nodes["R1"].node.topics] == ["/r1/odom", "/r1/relay/cmd", "/fleet/limit"]
    # both relays now read /r1's odometry: R2 is fed by the other robot's source, by its topic
    assert {(l.from_node, l.to_node) for l in model.links} == {("OdomSource_r1", "R1"), ("OdomSource_r1", "R2")}


def test_a_rule_matches_as_rcl_matches_it(tmp_path: Path) -> None:
    """A rule applies when its ``from`` expands to the name's expansion: ``/r2/odom`` (absolute) matches
    the relative ``odom`` in ``/r2``; ``/odom`` does not (control)."""
    ws = _ws(tmp_path, "  R2: {type: Relay, namespace: /r2, remap: {/r2/odom: odom_filtered}}\n")
    assert ws.plan.node_instances["Relay"][0].remaps[0].source == "/r2/odom"
    inst, _ = fleet_system(ws.checked, ws.plan.node_instances)
    assert inst.nodes["R2"].node.topics[0].field == "/r2/odom_filtered"
    other = _ws(tmp_path / "other", "  R2: {type: Relay, namespace: /r2, remap: {/odom: odom_filtered}}\n")
    inst, _ = fleet_system(other.checked, other.plan.node_instances)
    assert inst.nodes["R2"].node.topics[0].field == "/r2/odom"


@pytest.mark.parametrize("text, needle, words", [
    ("  R2: {type: Relay, namespace: /r2, remap: {odom: 9bad}}\n", "odom", "remap rule 'odom:=9bad': name '9bad'"),
    ("  R2: {type: Relay, namespace: /r2, remap: {__ns: /r3}}\n", "__ns", "renames the node; write node: or namespace:"),
    ("  R-2: {type: Relay, namespace: /r2}\n", "R-2", "its name is a node of the system, an identifier"),
    ("  R2: {type: Relay, namespace: /2x}\n", "/2x", "namespace '/2x'"),
])
def test_a_wrong_named_instance_is_one_located_error(tmp_path: Path, text: str, needle: str, words: str) -> None:
    plan = "contracts: [contracts/fleet.rcl]\ninstances:\n" + text
    with pytest.raises(PlanError) as exc:
        _ws(tmp_path, text).plan
    [d] = exc.value.diagnostics
    line = next(i for i, t in enumerate(plan.splitlines(), 1) if needle in t)
    assert d.loc.line == line and words in d.message and d.code == "E-instances", (d, d.loc)


def test_a_named_instance_of_no_contract_is_refused(tmp_path: Path) -> None:
    with pytest.raises(PlanError, match="no node named 'Relai'"):
        _ws(tmp_path, "  R2: {type: Relai, namespace: /r2}\n").checked
