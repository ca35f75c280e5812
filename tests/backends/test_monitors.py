"""Runtime monitors: direct evaluation, offline trace checking, RML and ROSMonitoring config."""
from __future__ import annotations

import itertools
import shutil
from pathlib import Path
from typing import Any

import lark
import pytest
import yaml

from rclverify.backends.base import NodeTarget
from rclverify.backends.monitors.backend import MonitorsBackend, render_config
from rclverify.backends.monitors.check import check_trace
from rclverify.backends.monitors.config import load_mapping
from rclverify.cli.commands import main
from rclverify.semantics.evaluate import evaluate
from rclverify.lang.parser import parse_formula as parse_expr
from rclverify.lang.typecheck import load
from rclverify.traces import read_trace
from rclverify.semantics.values import FiniteFunction, Term

REPO = Path(__file__).resolve().parents[2]
RCL = "contracts/remote_inspection.rcl"
TRACES = REPO / "backends" / "monitors" / "traces"
MSG = [REPO / "backends" / "monitors" / "msg"]
RML_GRAMMAR = lark.Lark((REPO / "tests" / "data" / "rml.lark").read_text(), parser="earley")


@pytest.fixture(scope="module")
def checked() -> Any:
    return load([REPO / RCL])


@pytest.fixture(scope="module")
def cfg() -> Any:
    return load_mapping(REPO, "backends/monitors/mapping.yaml", 2.0)


def verdicts(checked: Any, cfg: Any, trace: str, node: str = "RadiationSensor") -> Any:
    _, [res] = check_trace(checked, [checked.nodes[node]], read_trace(TRACES / trace, MSG), cfg.rules, cfg.horizon)
    return res


# -- direct evaluation ---------------------------------------------------------

def ev(checked: Any, node: str, text: str, values: dict[str, Any]) -> Any:
    return evaluate(parse_expr(text), checked, checked.nodes[node], values)


def test_evaluate_radiation_sensor_guarantee(checked: Any) -> None:
    g = "forall(i in NATURAL | in.command == inspect(i) -> out.inspected(i) == TRUE and " \
        "(250 <= in.r -> out.radiationStatus == red))"
    inspected = FiniteFunction({(4,): True}, False, 1)
    base = {"in.command": Term("inspect", (4,)), "in.r": 300.0, "out.inspected": inspected}
    assert ev(checked, "RadiationSensor", g, {**base, "out.radiationStatus": "red"}) is True
    assert ev(checked, "RadiationSensor", g, {**base, "out.radiationStatus": "orange"}) is False
    assert ev(checked, "RadiationSensor", g, {**base, "in.command": Term("inspect", (5,)),
                                             "out.radiationStatus": "red"}) is False
    assert ev(checked, "RadiationSensor", g, {**base, "in.command": Term("move", (1.0, 2.0)),
                                             "out.radiationStatus": "green"}) is True


def test_evaluate_quantifiers_over_tables_match_brute_force(checked: Any) -> None:
    """exists/forall/exists_unique over REAL decided from the table agree with a brute-force
    search over a grid that contains every table key plus other points."""
    grid = [0.0, 1.0, 2.0, 3.0]
    for bits in itertools.product([False, True], repeat=3):
        table = {k: True for k, b in zip([(0.0, 1.0), (1.0, 1.0), (2.0, 3.0)], bits) if b}
        pos = FiniteFunction(table, False, 2)
        vals = {"out.position": pos}
        truths = [pos(x, y) for x in grid for y in grid]
        assert ev(checked, "Localisation", "exists(x, y in REAL | out.position(x, y))", vals) is any(truths)
        assert ev(checked, "Localisation", "exists_unique(x, y in REAL | out.position(x, y))", vals) is \
            (sum(truths) == 1)
        assert ev(checked, "Localisation", "forall(x, y in REAL | not out.position(x, y))", vals) is \
            (not any(truths))
    # a fresh point is TRUE everywhere-else: uniqueness fails, forall holds
    everywhere = FiniteFunction({}, True, 2)
    assert ev(checked, "Localisation", "exists_unique(x, y in REAL | out.position(x, y))",
              {"out.position": everywhere}) is False
    assert ev(checked, "Localisation", "forall(x, y in REAL | out.position(x, y))",
              {"out.position": everywhere}) is True


def test_evaluate_shifted_index_and_undecided(checked: Any) -> None:
    wayp = FiniteFunction({(0.0, 0.0): 0, (1.0, 1.0): 1}, None, 2)
    vals = {"in.wayP": wayp}
    assert ev(checked, "Agent", "exists(x, y in REAL | in.wayP(x, y) == 0 + 1)", vals) is True
    assert ev(checked, "Agent", "forall(i in NATURAL | i <= 0 or exists(x, y in REAL | in.wayP(x, y) == i))",
              vals) is None  # i is ordered: not decidable by enumeration
    assert ev(checked, "Agent", "exists(i in NATURAL | not exists(x, y in REAL | in.wayP(x, y) == i + 1))",
              vals) is True


# -- offline checking -------------------------------------------------------------

def test_sensor_fault_is_flagged_at_the_wrong_status_with_guarantee_1(checked: Any, cfg: Any) -> None:
    res = verdicts(checked, cfg, "sensor_fault.jsonl")
    assert res.counts["violated"] >= 1
    v = res.first_violation
    assert v["where"] == "sensor_fault.jsonl:47" and v["guarantee"] == 1
    line = (TRACES / "sensor_fault.jsonl").read_text().splitlines()[46]
    assert '"radiationStatus"' in line and '"orange"' in line
    assert v["values"]["in.r"] == "300.0" and v["values"]["out.radiationStatus"] == "orange"
    assert "out.radiationStatus == red" in v["formula"]


def test_nominal_run_does_not_fail_the_sensor(checked: Any, cfg: Any) -> None:
    """No violation, nothing undecided (issue 47): each command ``inspect(i)``
    reaches the sensor with the previous waypoint's reading, and the reading
    that follows comes before any answer, so the command's question is
    superseded (the sensor owes the latest one an answer) and the answer is
    judged against the new reading (docs/semantics.md)."""
    res = verdicts(checked, cfg, "nominal.jsonl")
    assert res.counts["violated"] == 0 and res.counts["satisfied"] == 11
    assert res.counts["inconclusive"] == 0 and res.counts["open"] == 0 and res.counts["superseded"] == 5
    assert res.first_violation is None and res.first_assumption_violation is None


def test_environment_fault_is_blamed_on_the_environment(checked: Any, cfg: Any) -> None:
    res = verdicts(checked, cfg, "env_fault.jsonl")
    assert res.counts["violated"] == 0 and res.counts["assumption violated"] >= 1
    a = res.first_assumption_violation
    assert a["assumption"] == "0 <= in.r" and a["blame"] == "environment" and a["values"]["in.r"] == "-5.0"


def test_upstream_node_is_blamed_for_an_input_it_produces(checked: Any, cfg: Any) -> None:
    res = verdicts(checked, cfg, "nominal.jsonl", "Navigation")
    a = res.first_assumption_violation
    assert a is not None and a["blame"] == "upstream node(s) Localisation"


@pytest.mark.parametrize("run", ["nominal", "sensor_fault", "env_fault"])
def test_bag_and_log_give_the_same_verdicts(checked: Any, cfg: Any, run: str) -> None:
    nodes = list(checked.nodes.values())
    n1, r1 = check_trace(checked, nodes, read_trace(TRACES / f"{run}.jsonl"), cfg.rules, cfg.horizon)
    n2, r2 = check_trace(checked, nodes, read_trace(TRACES / f"{run}_bag", MSG), cfg.rules, cfg.horizon)
    assert n1 == n2
    for a, b in zip(r1, r2):
        assert a.counts == b.counts
        for key in ("first_violation", "first_assumption_violation"):
            x, y = getattr(a, key), getattr(b, key)
            assert (x is None) == (y is None)
            if x is not None:
                assert x["event"] == y["event"] and x.get("guarantee") == y.get("guarantee")


# -- RML and ROSMonitoring config --------------------------------------------------------

@pytest.fixture()
def exported(tmp_path: Path) -> Path:
    # The whole workspace input: the plan names files of every backend, and
    # loading it checks that they exist.
    for rel in ("contracts", "backends"):
        shutil.copytree(REPO / rel, tmp_path / rel)
    return tmp_path


def target(root: Path, node: str, config: dict[str, Any]) -> NodeTarget:
    checked = load([root / RCL])
    return NodeTarget(root=root, checked=checked, node=checked.nodes[node], config=config,
                      contract_files=(RCL,), plan_file="contracts/plan.yaml",
                      artifacts=root / "artifacts" / "monitors" / node)


def entry(*traces: str) -> dict[str, Any]:
    return {"backend": "monitors", "mapping": "backends/monitors/mapping.yaml", "horizon": 2.0,
            "traces": [f"backends/monitors/traces/{t}" for t in traces]}


def test_agent_rml_has_one_term_per_guarantee_and_parses(exported: Path) -> None:
    MonitorsBackend().export(target(exported, "Agent", entry()))
    text = (exported / "artifacts/monitors/Agent/Agent.rml").read_text()
    RML_GRAMMAR.parse(text)
    terms = [ln for ln in text.splitlines() if ln.startswith("G") and " = " in ln]
    assert [t.split(" = ")[0] for t in terms] == ["G1", "G2", "G3"]
    assert all(t.endswith("}*;") for t in terms)
    assert "Main = G1 /\\ G2 /\\ G3;" in text
    # event type names start lower-case; the topic is the topic name, fields flattened
    assert "inspected(x1) matches {topic: 'inspected', id: x1};" in text
    g2 = terms[1][len("G2 = "):-1]
    # the paper's t2 (lines 1611-1640): not at, or not at waypoint i, or inspected(i), or inspect(i)
    assert g2 == "{let xp, yp, i; (((not_at(xp, yp) \\/ not_wayP(xp, yp, i)) \\/ inspected(i)) \\/ " \
                 "command_inspect(i))}*"


def test_every_generated_rml_parses_and_inexpressible_parts_are_named(exported: Path) -> None:
    for node in ("Localisation", "Navigation", "Agent", "RadiationSensor"):
        MonitorsBackend().export(target(exported, node, entry()))
        text = (exported / f"artifacts/monitors/{node}/{node}.rml").read_text()
        if "Main = " in text:
            RML_GRAMMAR.parse(text)
    loc = (exported / "artifacts/monitors/Localisation/Localisation.rml").read_text()
    assert "G1 is not expressible in RML: exists_unique" in loc and "Main =" not in loc


def test_rml_grammar_rejects_what_the_compiler_rejects() -> None:
    for bad in ("Main = max(x);", "At(x) matches {topic: 'at'};\nMain = all;",
                "at(x) matches {topic: 'gazebo/at'};\nMain = at(x);"):
        with pytest.raises(lark.exceptions.LarkError):
            RML_GRAMMAR.parse(bad)


def test_config_is_yaml_with_the_documented_keys(checked: Any) -> None:
    data = yaml.safe_load(render_config(checked, "ros2"))
    assert set(data) == {"ros_version", "nodes", "monitors"}
    ids = []
    for m in data["monitors"]:
        mon = m["monitor"]
        assert {"id", "log", "silent", "oracle", "topics"} <= set(mon)
        assert mon["id"].isidentifier()
        ids.append(mon["id"])
        assert set(mon["oracle"]) == {"url", "port", "action"}
        for t in mon["topics"]:
            assert set(t) == {"name", "type", "action", "ordering"}
            assert t["type"] == "gazebo_radiation_plugin.msg.Snapshot"
            assert t["ordering"] == {"enabled": True, "source": "header_stamp", "max_delay_ms": 50}
    assert len(set(ids)) == len(ids) == 4
    assert render_config(checked, "ros2") == render_config(checked, "ros2")
    assert data["nodes"] == []
    named = yaml.safe_load(render_config(checked, "ros1", {
        "RadiationSensor": {"name": "radiation_sensor", "package": "rover", "path": "launch/rover.launch"},
        "Agent": {"name": "agent"}}))
    assert named["nodes"] == [{"node": {"name": "agent"}},
                              {"node": {"name": "radiation_sensor", "package": "rover", "path": "launch/rover.launch"}}]


def test_backend_evidence_for_the_bundled_runs(exported: Path) -> None:
    t = target(exported, "RadiationSensor", entry("nominal.jsonl", "sensor_fault.jsonl", "env_fault.jsonl"))
    b = MonitorsBackend()
    obs = b.export(t)
    assert [o.instance for o in obs] == ["nominal_jsonl", "sensor_fault_jsonl", "env_fault_jsonl"]
    evs = {o.instance: b.run(o, t) for o in obs}
    assert evs["nominal_jsonl"].status == "discharged"
    assert evs["sensor_fault_jsonl"].status == "failed"
    assert evs["env_fault_jsonl"].status == "discharged"  # the environment is blamed, not the sensor
    m = evs["sensor_fault_jsonl"].details["monitoring"]
    assert m["first_violation"]["guarantee"] == 1 and len(m["sha256"]) == 64 and m["events_read"] > 50
    # the run's duration in trace time: its first event to its last, as the file has them
    import json as _json
    times = [_json.loads(line)["time"] for line in
             (exported / "backends/monitors/traces/nominal.jsonl").read_text().splitlines() if line.strip()]
    nominal = evs["nominal_jsonl"].details["monitoring"]
    assert nominal["duration_s"] == pytest.approx(max(times) - min(times)) and nominal["duration_s"] > 0
    assert "rosbags" in evs["nominal_jsonl"].tool_version
    assert "blamed on the environment" in evs["env_fault_jsonl"].explanation


def test_backend_unreadable_trace_is_an_error_record(exported: Path) -> None:
    t = target(exported, "RadiationSensor", entry("nominal.jsonl"))
    b = MonitorsBackend()
    [o] = b.export(t)
    path = exported / "backends/monitors/traces/nominal.jsonl"
    path.write_text(path.read_text() + "{oops\n")
    e = b.run(o, t)
    assert e.status == "error" and "nominal.jsonl:64:" in e.explanation


def test_cli_reports_verdicts_then_a_located_error(exported: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = exported / "bad.jsonl"
    bad.write_text('{"topic": "r", "time": 0.0, "value": 1.0}\nnot json\n')
    rc = main(["monitor", "-w", str(exported), str(TRACES / "sensor_fault.jsonl"), str(bad)])
    out, err = capsys.readouterr()
    assert rc == 2
    assert "RadiationSensor: " in out and "failed" in out
    assert err.strip().startswith(f"{bad}:2:") and "error:" in err
    rc = main(["monitor", "-w", str(exported), "--horizon", "2", str(TRACES / "nominal.jsonl")])
    out, _ = capsys.readouterr()
    assert "RadiationSensor: 11 satisfied, 2 incomplete input, 5 superseded" in out
    assert rc == 1  # the published Agent and Navigation contracts are violated by any run


def test_evaluate_answers_none_on_values_of_the_wrong_form(checked: Any) -> None:
    wayp = FiniteFunction({(0.0, 0.0): 0}, None, 2)  # partial: no result outside the table
    assert ev(checked, "Agent", "exists(x, y in REAL | in.wayP(x, y) + 1 == 1)", {"in.wayP": wayp}) is True
    assert ev(checked, "Agent", "forall(x, y in REAL | in.wayP(x, y) + 1 >= 1)", {"in.wayP": wayp}) is None


def test_joint_enumeration_of_argument_tuples_matches_brute_force(checked: Any) -> None:
    """x, y used only as the argument tuple of wayP and move: enumerated jointly over the
    table keys and the command's arguments; compared with a search over a grid."""
    grid = [0.0, 1.0, 2.0, 5.0]
    wayp = FiniteFunction({(0.0, 0.0): 0, (1.0, 2.0): 1, (2.0, 1.0): 2}, None, 2)
    for cmd in (Term("move", (1.0, 2.0)), Term("move", (2.0, 1.0)), Term("move", (5.0, 5.0)), Term("inspect", (1,))):
        vals = {"in.wayP": wayp, "out.command": cmd}
        for k in (0, 1, 2, 3):
            want = any(wayp(x, y) == k and cmd == Term("move", (x, y)) for x in grid for y in grid)
            got = ev(checked, "Agent", f"exists(x, y in REAL | in.wayP(x, y) == {k} and out.command == move(x, y))",
                     vals)
            assert got is want, (cmd, k)
            want_all = all(not (wayp(x, y) == k) or cmd == Term("move", (x, y)) for x in grid for y in grid)
            got_all = ev(checked, "Agent", f"forall(x, y in REAL | in.wayP(x, y) == {k} -> out.command == move(x, y))",
                         vals)
            assert got_all is want_all, (cmd, k)


def test_mapping_ros_nodes_are_checked(tmp_path: Path) -> None:
    from rclverify.backends.monitors.config import ConfigError
    (tmp_path / "m.yaml").write_text("ros_nodes:\n  Agent: {name: agent, launch: x}\n")
    with pytest.raises(ConfigError, match="ros_nodes must map"):
        load_mapping(tmp_path, "m.yaml")
    (tmp_path / "m.yaml").write_text("ros_nodes:\n  Agent: {name: agent, package: rover}\n")
    assert load_mapping(tmp_path, "m.yaml").ros_nodes == {"Agent": {"name": "agent", "package": "rover"}}
