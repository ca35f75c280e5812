"""One row per cause (issue 64): a requirement refuted only because a side
condition fails joins that side condition's row, names its culprit (the
supervisor's 45 N, not the correct gripper driver), and says it is a
consequence; a culprit node or guarantee never reads "discharged" (report,
terminal table, argument, editor hover)."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import msgspec
import pytest

from _typed_rows import typed_report
from rclverify.records.node_rows import CulpritOf
from rclverify.report.argument.model import Argument, Element, propagate
from rclverify.cli.commands import main
from rclverify.report.culprits import marked_nodes

from _grip_ws import make


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    ws = make(tmp_path_factory.mktemp("grip") / "ws")
    assert main(["verify", "-w", str(ws)]) == 0
    out: dict[str, Any] = json.loads((ws / "reports" / "assurance.json").read_text(encoding="utf-8"))
    out["_ws"] = str(ws)
    return out


def _row_of(report: dict[str, Any], member: str) -> dict[str, Any]:
    return next(g for g in report["problems"] if member in [m["id"] for m in g["members"]])


def test_consequence_joins_the_side_condition_row(report: dict[str, Any]) -> None:
    row = _row_of(report, "REQ-FORCE")
    ids = [m["id"] for m in row["members"]]
    assert "GripperDriver.sc2" in ids  # the cause and its consequence: one row
    assert sorted(row["key"]) == ["assumption:GripperDriver:1", "guarantee:Supervisor:1"]
    req = next(m for m in row["members"] if m["id"] == "REQ-FORCE")
    assert req["consequence_of"] == ["GripperDriver.sc2"]
    # the correct driver's guarantee is no culprit of it
    assert "guarantee:GripperDriver:1" not in [c["id"] for c in row["culprits"]]
    d = next(x for x in report["diagnoses"] if x["id"] == "REQ-FORCE")
    assert d["consequence_of"] == ["GripperDriver.sc2"]
    assert "refuted only because side condition GripperDriver.sc2" in d["sentence"]
    assert not any("GripperDriver" in c["what"] and "guarantee" in c["what"] for c in d["culprits"])


def test_no_culprit_reads_discharged(report: dict[str, Any]) -> None:
    sup = next(n for n in report["nodes"] if n["name"] == "Supervisor")
    assert sup["status"] == "failed"
    assert sup["guarantees"][0]["status"] == "failed"
    assert sup["culprit_of"] and sup["culprit_of"][0]["status"] == "failed"
    md = (Path(report["_ws"]) / "reports" / "assurance.md").read_text(encoding="utf-8")
    assert "REQ-FORCE`](#" in md and "(a consequence of GripperDriver.sc2)" in md
    arg = json.loads((Path(report["_ws"]) / "reports" / "argument.json").read_text(encoding="utf-8"))
    goal = next(e for e in arg["elements"] if e["id"] == "G-Supervisor.g1")
    assert goal["status"] == "failed" and goal.get("defeated") is True


def test_marked_nodes_raises_only_what_a_row_names() -> None:
    rep = typed_report({
        "nodes": [{"name": "A", "status": "discharged", "guarantees": [{"index": 1, "status": "discharged"},
                                                                      {"index": 2, "status": "discharged"}]},
                  {"name": "B", "status": "discharged", "guarantees": [{"index": 1, "status": "discharged"}]}],
        "problems": [{"status": "problem", "sentence": "s", "culprits": [{"id": "guarantee:A:2"}]},
                     {"status": "inconclusive", "sentence": "t", "culprits": [{"id": "assumption:B:1"}]}]})
    given = msgspec.json.encode(rep.nodes)
    a, b = marked_nodes(rep.nodes, rep.problems)
    assert msgspec.json.encode(rep.nodes) == given  # new rows: the report's own are left as they were
    assert a.status == "failed" and a.guarantees[1].status == "failed"
    assert a.culprit_of == a.guarantees[1].culprit_of == [CulpritOf(status="failed", sentence="s")]
    assert a.guarantees[0].status == "discharged" and a.guarantees[0].culprit_of is msgspec.UNSET
    assert b == rep.nodes[1]  # an assumption is where the victim is, not a culprit node


def test_a_defeated_goal_is_never_better_than_its_defeater() -> None:
    els = {"G": Element("G", "goal", "g", supported_by=("Sn",), defeated=True),
           "Sn": Element("Sn", "solution", "ok", status="discharged"),
           "CSn": Element("CSn", "counter_solution", "culprit", status="failed", challenges=("G",)),
           "G2": Element("G2", "goal", "h", supported_by=("Sn2",)),
           "Sn2": Element("Sn2", "solution", "ok", status="discharged")}
    out = propagate(Argument("G", els)).elements
    assert out["G"].status == "failed"
    assert out["G2"].status == "discharged"


def test_hover_names_the_problem(report: dict[str, Any]) -> None:
    from rclverify.tools.lsp.hover import _ENV
    text = _ENV.get_template("hover.md.j2").render(
        kind="node", name="Supervisor", status="failed", culprit_of=[{"status": "failed", "sentence": "S allows 45."}],
        contract="node Supervisor {}", guarantees=[], producers=[], consumers=[])
    assert "last run: `failed`" in text and "culprit of a problem (`failed`): S allows 45." in text
    assert "discharged" not in text


ARM = """\
node Planner {
  inputs( index : NATURAL )
  outputs( joint : NATURAL )
  assume( in.index <= 5 )
  guarantee( out.joint == in.index + 1 )
}

node Arm {
  inputs( joint : NATURAL )
  outputs( cmd : NATURAL )
  assume( in.joint <= 5 )
  guarantee( out.cmd == in.joint )
}
"""

ARM_PLAN = """\
name: "joints"
contracts: [contracts/arm.rcl]
requirements:
  - id: REQ-JOINT
    text: The planner only ever names one of the arm's six joints.
    formal: "always Planner.out.joint <= 5"
    supported_by:
      - {node: Planner, guarantees: [1]}
nodes:
  Planner: {}
  Arm: {}
"""


def test_a_temporal_requirement_names_the_off_by_one(tmp_path: Path) -> None:
    (tmp_path / "contracts").mkdir()
    (tmp_path / "contracts" / "arm.rcl").write_text(ARM, encoding="utf-8")
    (tmp_path / "contracts" / "plan.yaml").write_text(ARM_PLAN, encoding="utf-8")
    (tmp_path / "dodo.py").write_text("from pathlib import Path\nfrom rclverify.app.tasks import build_tasks, doit_config\n"
                                      "DOIT_CONFIG = doit_config()\nglobals().update(build_tasks(Path(__file__).parent))\n",
                                      encoding="utf-8")
    assert main(["verify", "-w", str(tmp_path)]) == 0
    report = json.loads((tmp_path / "reports" / "assurance.json").read_text(encoding="utf-8"))
    d = next(x for x in report["diagnoses"] if x["id"] == "REQ-JOINT")
    assert d["node"] == "Planner" and d["culprits"][0]["source"] == "contracts/arm.rcl:5:3"
    assert "with `1` as `0` (off by one)" in d["sentence"]
    assert "in.index + 0" in d["repairs"][0]["diff"]
    row = _row_of(report, "REQ-JOINT")  # the slip's row: the side condition it also breaks
    assert "Arm.sc1" in [m["id"] for m in row["members"]] and "guarantee:Planner:1" in row["key"]


def test_a_counterexample_through_a_refuted_side_condition_says_so(report: dict[str, Any]) -> None:
    from rclverify.diagnosis.requirement import _passes_through
    from rclverify.diagnosis.shapes import report_rows
    from rclverify.records.requirement_check import RequirementCheckRow
    from rclverify.stages.workspace import Workspace
    ws = Workspace(Path(report["_ws"]), "contracts/plan.yaml")
    cone = ["Supervisor", "GripperDriver"]
    rows = report_rows(report)

    def q(force: str) -> RequirementCheckRow:
        return RequirementCheckRow.of({"counterexample": [
            {"node": "Supervisor", "values": {"in.request": "0", "out.force": force}},
            {"node": "GripperDriver", "values": {"in.force": force, "out.applied": force}}]})
    assert [sc.id for sc in _passes_through(ws, rows, q("41"), cone)] == ["GripperDriver.sc2"]
    assert _passes_through(ws, rows, q("35"), cone) == []  # the driver's assumption holds there
    assert _passes_through(ws, rows, q("4x"), cone) == []  # a value that does not read shows nothing


MONITORED = """\
node Supervisor {
  inputs( request : REAL )
  outputs( force : REAL )
  topics( std_msgs/Float64 request matches(in.request),
          std_msgs/Float64 force matches(out.force) )
  assume( 0 <= in.request and in.request <= 100 )
  guarantee( 0 <= out.force and out.force <= 45 )
}

node GripperDriver {
  inputs( force : REAL )
  outputs( applied : REAL )
  topics( std_msgs/Float64 force matches(in.force),
          std_msgs/Float64 applied matches(out.applied) )
  assume( 0 <= in.force and in.force <= 40 )
  guarantee( 0 <= out.applied and out.applied <= in.force )
}
"""


def test_a_run_whose_assumption_the_side_condition_lets_fail_joins_its_row(tmp_path: Path) -> None:
    (tmp_path / "contracts").mkdir()
    (tmp_path / "runs").mkdir()
    (tmp_path / "contracts" / "cell.rcl").write_text(MONITORED, encoding="utf-8")
    (tmp_path / "mapping.yaml").write_text("topics:\n  request: {fields: [data]}\n  force: {fields: [data]}\n"
                                           "  applied: {fields: [data]}\n", encoding="utf-8")
    (tmp_path / "runs" / "run.jsonl").write_text(
        '{"topic": "request", "time": 1.0, "data": 50.0}\n{"topic": "force", "time": 1.01, "data": 45.0}\n'
        '{"topic": "applied", "time": 1.02, "data": 45.0}\n', encoding="utf-8")
    entry = "      - {backend: monitors, mapping: mapping.yaml, traces: [runs/run.jsonl]}\n"
    (tmp_path / "contracts" / "plan.yaml").write_text(
        'name: "gripm"\ncontracts: [contracts/cell.rcl]\nrequirements: []\nnodes:\n'
        f"  Supervisor:\n    evidence:\n{entry}  GripperDriver:\n    evidence:\n{entry}", encoding="utf-8")
    (tmp_path / "dodo.py").write_text("from pathlib import Path\nfrom rclverify.app.tasks import build_tasks, doit_config\n"
                                      "DOIT_CONFIG = doit_config()\nglobals().update(build_tasks(Path(__file__).parent))\n",
                                      encoding="utf-8")
    assert main(["verify", "-w", str(tmp_path)]) == 0
    report = json.loads((tmp_path / "reports" / "assurance.json").read_text(encoding="utf-8"))
    row = _row_of(report, "GripperDriver.sc2")
    run = next(m for m in row["members"] if m["id"] == "GripperDriver.g0.monitors.run_jsonl")
    assert run["consequence_of"] == ["GripperDriver.sc2"] and "blamed on the upstream node(s) Supervisor" in run["sentence"]
    assert "guarantee:Supervisor:1" in row["key"]


def test_explain_names_what_a_culprit_causes(report: dict[str, Any], capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["explain", "-w", report["_ws"], "Supervisor"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("Supervisor [failed]") and "Supervisor.g1 [failed]" in out
    assert "culprit of a problem [failed]: GripperDriver assumes `in.force <= 40`" in out
    assert "[discharged]" not in out
