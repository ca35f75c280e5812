"""One contract run as several nodes under namespaces (issue 110; model/instances.py, docs/plan.md
"Instances"): the plan's ``instances`` key read and refused where it is wrong, each instance a node of
its own with its names resolved as rcl resolves them, linked within its robot; the calculus, the
monitors and the NoDL matching see each instance as its own node, each with a control."""
from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors.config import load_mapping
from rclverify.calculus.compose import compose_node
from rclverify.lang.errors import RclError
from rclverify.model.instances import fleet_system, instantiate, namespaces_of
from rclverify.model.nodl.match import match_instances
from rclverify.model.plan.errors import PlanError
from rclverify.model.plan.instances import instance_name, snake
from rclverify.model.system.model import build
from rclverify.runtime.live import LiveRun
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
QOS = "  qos:\n    history: KEEP_LAST\n    depth: 10\n    reliability: RELIABLE\n    durability: VOLATILE\n"
ODOM = f"nodl_version: 2\npublishers:\n- name: odom\n  type: std_msgs/msg/Float64\n{QOS}"
RELAY = (f"nodl_version: 2\nsubscriptions:\n- name: odom\n  type: std_msgs/msg/Float64\n{QOS}"
         f"publishers:\n- name: ~/cmd\n  type: std_msgs/msg/Float64\n{QOS}")
FLEET = "instances:\n  OdomSource: [/r1, /r2]\n  Relay: {node: relay, namespaces: [/r1, /r2/]}\n"


def _ws(tmp: Path, instances: str = FLEET, sub: str = "") -> Workspace:
    tmp = tmp / sub if sub else tmp
    (tmp / "contracts").mkdir(parents=True, exist_ok=True)
    (tmp / "contracts/fleet.rcl").write_text(RCL, encoding="utf-8")
    (tmp / "contracts/plan.yaml").write_text("contracts: [contracts/fleet.rcl]\n" + instances, encoding="utf-8")
    return Workspace(tmp, "contracts/plan.yaml")


def test_the_plan_names_each_instance_and_its_ros_node(tmp_path: Path) -> None:
    ws = _ws(tmp_path)
    insts = ws.plan.node_instances
    assert [(i.name, i.fqn) for c in ("OdomSource", "Relay") for i in insts[c]] == [
        ("OdomSource_r1", "/r1/odom_source"), ("OdomSource_r2", "/r2/odom_source"),
        ("Relay_r1", "/r1/relay"), ("Relay_r2", "/r2/relay")]
    assert ws.checked.nodes.keys() == {"OdomSource", "Relay"}  # the contracts stay types: proofs are about them
    assert snake("OdomSource") == "odom_source" and instance_name("Relay", "/fleet/r1") == "Relay_fleet_r1"
    assert instance_name("Relay", "/") == "Relay"
    assert _ws(tmp_path, "", "none").plan.node_instances == {}  # control: no instances, none


@pytest.mark.parametrize("text, needle, words", [
    ("instances:\n  Relay: [/r1, /2x]\n", "/2x", "namespace '/2x': no token of a namespace starts with a digit"),
    ("instances:\n  Relay: [/r1, /r1]\n", "/r1]", "namespace /r1 is given twice"),
    ("instances:\n  Relay: {node: 9relay, namespaces: [/r1]}\n", "9relay", "node name '9relay'"),
])
def test_a_wrong_instance_is_one_located_error(tmp_path: Path, text: str, needle: str, words: str) -> None:
    plan = "contracts: [contracts/fleet.rcl]\n" + text
    with pytest.raises(PlanError) as exc:
        _ws(tmp_path, text).plan
    [d] = exc.value.diagnostics
    line = next(i for i, t in enumerate(plan.splitlines(), 1) if needle in t)
    assert (d.loc.line, d.loc.col) == (line, plan.splitlines()[line - 1].rindex(needle) + 1), d
    assert words in d.message and d.code == "E-instances", d.message


def test_an_instance_of_no_contract_is_refused_where_it_is_written(tmp_path: Path) -> None:
    with pytest.raises(PlanError) as exc:
        _ws(tmp_path, "instances:\n  Relai: [/r1]\n").checked
    [d] = exc.value.diagnostics
    assert d.loc.line == 3 and "no node named 'Relai'" in d.message, d


def test_a_name_too_long_in_its_namespace_is_refused_at_the_instance(tmp_path: Path) -> None:
    """rmw's 247 characters hold for the resolved name: a namespace that makes one longer is refused where
    the plan gives it (control: the same tokens, shorter, load)."""
    deep = "/" + "/".join(["n" * 60] * 4)
    text = f"instances:\n  Relay: [/r1, {deep}]\n"
    with pytest.raises(PlanError) as exc:
        _ws(tmp_path, text).checked
    [d] = exc.value.diagnostics
    assert d.loc.line == 3 and "has at most 247 characters" in d.message and "Relay in " + deep in d.message, d
    assert _ws(tmp_path, text.replace("n" * 60, "n" * 40), "short").checked


def test_each_instance_is_a_node_with_its_names_resolved_and_fed_within_its_robot(tmp_path: Path) -> None:
    ws = _ws(tmp_path)
    inst, model = fleet_system(ws.checked, ws.plan.node_instances)
    assert list(inst.nodes) == ["OdomSource_r1", "OdomSource_r2", "Relay_r1", "Relay_r2"]
    assert [t.field for t in inst.nodes["Relay_r2"].node.topics] == ["/r2/odom", "/r2/relay/cmd", "/fleet/limit"]
    assert {(l.from_node, l.to_node, l.via) for l in model.links} == {
        ("OdomSource_r1", "Relay_r1", "instance"), ("OdomSource_r2", "Relay_r2", "instance")}
    # control: the same instances without their links are fed by name by either robot: refused as ambiguous
    with pytest.raises(RclError, match="input 'odom' of Relay_r1 could be fed by OdomSource_r1, OdomSource_r2"):
        build(instantiate(ws.checked, ws.plan.node_instances))


def test_the_calculus_discharges_each_instance_from_its_own_robot(tmp_path: Path) -> None:
    ws = _ws(tmp_path)
    inst, model = fleet_system(ws.checked, ws.plan.node_instances)
    for robot in ("r1", "r2"):
        [sc] = compose_node(inst, model, f"Relay_{robot}").side_conditions
        other = "r2" if robot == "r1" else "r1"
        assert sc.status == "discharged" and model.producers(f"Relay_{robot}") == [f"OdomSource_{robot}"], sc
        assert any(f"OdomSource_{robot}" in l for l in sc.links) and not any(other in l for l in sc.links), sc.links
    # control: with OdomSource in /r1 only, /r2's relay has no producer: its assumption is the environment's
    ws1 = _ws(tmp_path, "instances:\n  OdomSource: [/r1]\n  Relay: [/r1, /r2]\n", "one")
    inst1, model1 = fleet_system(ws1.checked, ws1.plan.node_instances)
    assert not compose_node(inst1, model1, "Relay_r2").side_conditions
    assert ("Relay_r2", "odom", "REAL") in model1.env_inputs and model1.producers("Relay_r1") == ["OdomSource_r1"]
    assert model1.producers("Relay_r2") == [] and ("Relay_r1", "limit", "REAL") in model1.env_inputs


def _monitored(tmp: Path, r2_cmd: float) -> dict[str, str]:
    ws = _ws(tmp, FLEET, str(r2_cmd))
    tmp = ws.root
    inst = instantiate(ws.checked, ws.plan.node_instances)
    cfg = load_mapping(tmp, None, 1.0)
    live = LiveRun(inst, list(inst.nodes.values()), cfg.rules, cfg.horizon, tmp / "live.jsonl", reorder_window=0.0)
    for t, topic, v in [(0.9, "fleet/limit", 3.0), (1.0, "r1/odom", 1.0), (1.0, "r2/odom", 2.0), (1.02, "r1/relay/cmd", 1.0),
                        (1.03, "r2/relay/cmd", r2_cmd)]:
        live.tick(t)
        live.push(topic, {"data": v}, t)
    live.tick(3.0)
    return {n["node"]: n["status"] for n in live.stop()["nodes"]}


def test_a_defect_of_one_instance_is_red_at_that_instance_only(tmp_path: Path) -> None:
    # /r2's relay answers 2.0 with 1.0, the other robot's odometry (a namespace slip): red there only
    assert _monitored(tmp_path, 1.0) == {"OdomSource_r1": "discharged", "OdomSource_r2": "discharged",
                                                 "Relay_r1": "discharged", "Relay_r2": "failed"}
    assert set(_monitored(tmp_path, 2.0).values()) == {"discharged"}  # control: each relays its own


def _dump(r2_odom: str) -> dict[str, Any]:
    """The fleet as rclpy's graph reader sends it (tests/ros/test_names_fleet.py's shape)."""
    f64 = "std_msgs/msg/Float64"
    nodes: list[dict[str, Any]] = []
    ends: dict[str, dict[str, list[dict[str, Any]]]] = {}
    for i, ns in enumerate(("/r1", "/r2")):
        odom, sub, cmd = f"{ns}/odom", (r2_odom if ns == "/r2" else f"{ns}/odom"), f"{ns}/relay/cmd"
        nodes += [{"name": "odom_source", "ns": ns, "pubs": [[odom, [f64]]], "subs": [], "servers": [], "clients": []},
                  {"name": "relay", "ns": ns, "pubs": [[cmd, [f64]]], "subs": [[sub, [f64]]], "servers": [],
                   "clients": []}]
        for k, (topic, side, node) in enumerate(((odom, "pubs", "odom_source"), (sub, "subs", "relay"),
                                                 (cmd, "pubs", "relay"))):
            ends.setdefault(topic, {"pubs": [], "subs": []})[side].append(
                {"gid": f"{10 * i + k:032x}", "node": node, "ns": ns, "type": f64, "hash": "", "reliable": True,
                 "durability": "volatile"})
    return {"what": "graph_all", "rmw": "rmw_fastrtps_cpp", "nodes": nodes, "endpoints": ends}


def test_the_nodl_documents_are_matched_per_instance_and_find_a_wire_to_the_other_robot(tmp_path: Path) -> None:
    from rclverify.model.nodl.check import document_files, read_all, shown
    from rclverify.model.nodl.document import Resolver
    from rclverify.ros.ground.diff_nodl import nodes_of
    from rclverify.ros.ground.nodl_code import check_code
    from rclverify.ros.live.diff_dds import graph_of
    from rclverify.runtime.rclpy_source.graph import RclpyDiscovery
    ws = _ws(tmp_path)
    folder = tmp_path / "nodl"
    folder.mkdir()
    (folder / "OdomSource.nodl.yaml").write_text(ODOM, encoding="utf-8")
    (folder / "Relay.nodl.yaml").write_text(RELAY, encoding="utf-8")
    documents = nodes_of(read_all(document_files(folder), Resolver([], shown(tmp_path))))
    spaces = namespaces_of(ws.plan.node_instances)
    assert spaces == {"OdomSource": ["/r1", "/r2"], "Relay": ["/r1", "/r2"]}

    def found(r2_odom: str) -> list[str]:
        disc = RclpyDiscovery(_dump(r2_odom))
        running = graph_of(disc, "rclpy")  # type: ignore[arg-type]
        assert all(i.running for i in match_instances(documents, running.nodes, spaces))
        return [f.message for f in check_code(documents, running.nodes, side="live", namespaces=spaces)[1]]
    assert found("/r2/odom") == []  # control: each relay reads its own robot's odometry
    wrong = found("/r1/odom")
    assert wrong and all("/r2/relay" in m for m in wrong) and any("/r1/odom" in m for m in wrong), wrong


def test_rclverify_monitor_judges_each_instance_of_the_plan(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``rclverify monitor LOG`` over a workspace whose plan has instances: each is a node of the verdicts,
    heard on its own topics; the same log judged without the instances (control) has only the contracts,
    whose relative names (``odom``) no robot publishes."""
    import json
    from rclverify.cli.commands import main
    log = tmp_path / "run.jsonl"
    rows = [(0.9, "/fleet/limit", 3.0), (1.0, "/r1/odom", 1.0), (1.0, "/r2/odom", 2.0), (1.02, "/r1/relay/cmd", 1.0),
            (1.03, "/r2/relay/cmd", 1.0)]
    log.write_text("".join(json.dumps({"topic": t, "time": at, "data": v}) + "\n" for at, t, v in rows))

    def judged(plan: str) -> dict[str, str]:
        ws = _ws(tmp_path, plan, str(len(plan)))
        code = main(["monitor", "-w", str(ws.root), "--horizon", "1", "--json", str(log)])
        out = {n["node"]: n["status"] for n in json.loads(capsys.readouterr().out)}
        assert code == (1 if "failed" in out.values() else 0), (code, out)
        return out
    fleet = judged(FLEET)
    assert fleet["Relay_r2"] == "failed" and fleet["Relay_r1"] == "discharged", fleet
    assert set(judged("")) == {"OdomSource", "Relay"}


def test_nodl_check_matches_each_document_in_the_namespaces_of_the_plan(tmp_path: Path,
                                                                         capsys: pytest.CaptureFixture[str]) -> None:
    """``nodl check -w WS --graph FILE`` (a recorded graph, no node running) with the plan's instances: the
    relay of /r2 wired to /r1/odom is a finding at /r2's relay; the fleet as documented (control) has none
    about a relay; without instances (control) the documents match no node of the fleet at all."""
    import json
    from rclverify.cli.commands import main

    def check_(plan: str, r2_odom: str) -> str:
        ws = _ws(tmp_path, plan, f"{len(plan)}{r2_odom.count('r1')}")
        (ws.root / "nodl").mkdir()
        (ws.root / "nodl/OdomSource.nodl.yaml").write_text(ODOM, encoding="utf-8")
        (ws.root / "nodl/Relay.nodl.yaml").write_text(RELAY, encoding="utf-8")
        dump = _dump(r2_odom)
        for ends in dump["endpoints"].values():
            for e in ends["pubs"] + ends["subs"]:
                e.update(deadline_ns=0, liveliness="automatic", lease_ns=0)
        graph = ws.root / "graph.json"
        graph.write_text(json.dumps({"kind": "rclverify-ros2-graph", "version": 1, "rmw": dump["rmw"],
                                     "nodes": dump["nodes"], "endpoints": dump["endpoints"]}), encoding="utf-8")
        main(["nodl", "check", "-w", str(ws.root), "--graph", str(graph)])
        cap = capsys.readouterr()
        assert "Traceback" not in cap.err, cap.err
        return cap.out + cap.err
    slip = check_(FLEET, "/r1/odom")
    assert "node /r2/relay has /r1/odom (std_msgs/msg/Float64) in subscriptions in the running node" in slip, slip
    assert "nodl/Relay.nodl.yaml:3:9: error: node /r2/relay's NoDL document declares /r2/odom" in slip, slip
    live = [ln for ln in slip.splitlines() if "[nodl-live" in ln]
    assert len(live) == 4 and all("node /r2/relay" in ln for ln in live), live  # /r1 and the sources: clean
    own = check_(FLEET, "/r2/odom")
    assert "nodl-live" not in own and "4 document(s) matched" in own, own
    alone = check_("", "/r2/odom")
    assert "the base name alone is ambiguous" in alone, alone
