"""examples/manipulator live: sixteen real rclpy nodes on Fast DDS (a
lifecycle battery, a service with introspection, an action, unstamped
inputs answered within a millisecond, stamped inputs, an answer stamped at
publish), with both cores kept busy by the suite's own workers
(docs/semantics.md, "Event time"; the bench adds CPU burners).

* the correct robot, heard through rclpy and recorded: every node's answers
  judged, none violated, none undecided, both ``progress`` declarations
  held, ``--strict`` exit 0; its log and its bag, checked offline, give
  the same verdicts answer for answer;
* the robot with all seven seeded defects, heard through the monitor's own
  DDS participant: red at exactly the seven defects' nodes, and the two
  correct nodes beside them green;
* its NoDL documents against the running nodes (docs/nodl.md).

Before messages were placed at their publishers' source timestamps, the
correct robot read red (a false ``progress`` declaration, offline counts
differing from live).

bench/manipulator_live.py runs both many times (docs/scale.md)."""
from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any, Iterator

import pytest
from _ros2 import ros2_env, ros2_python

from rclverify.cli.commands import main

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "manipulator"
sys.path.insert(0, str(EXAMPLE))
from watch import node_status as _status, watch  # noqa: E402  (the example's own harness)

NODES = ["ObstacleGuard", "Battery", "ChargeMonitor", "JointLimiter", "SpeedGovernor", "Docking", "Planner",
         "EStop", "Arm"]
#: CPU-burning processes beside the robot: none in the suite, whose own three workers keep both cores busy
#: (bench/manipulator_live.py adds two, ten runs: docs/scale.md)
BURNERS = 0
#: seeded defect -> the node it makes red (examples/manipulator/robot.py)
DEFECTS = {"guard_last_beam": "ObstacleGuard", "charge_lt": "ChargeMonitor", "limiter_first_five": "JointLimiter",
           "governor_cap": "SpeedGovernor", "docking_threshold": "Docking", "estop_always": "EStop",
           "arm_spoilt": "Arm"}


@pytest.fixture(scope="module")
def correct(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    tmp = tmp_path_factory.mktemp("manipulator-correct")
    yield watch(tmp, ros2_python(), ros2_env(tmp), source="rclpy", record=True, burners=BURNERS)


@pytest.fixture(scope="module")
def defective(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    """The defective robot through DDS; while its nodes still run, its NoDL documents checked live."""
    tmp = tmp_path_factory.mktemp("manipulator-defects")
    env = ros2_env(tmp)
    yield watch(tmp, ros2_python(), env, source="dds", defects="all", burners=BURNERS,
                after=lambda: _nodl_live(tmp, env))


def _nodl_live(tmp: Path, env: dict[str, str]) -> tuple[Any, Any]:
    """``rclverify nodl check --ros2`` on a copy of the example, then on the copy with the Docking document
    declaring a publisher the contract does not name (statically a warning, live an error)."""
    import shutil
    import subprocess
    py = ros2_python()
    ws = tmp / "ws"
    shutil.copytree(EXAMPLE, ws, ignore=shutil.ignore_patterns("artifacts", "reports", ".doit*", "__pycache__"))

    def check() -> subprocess.CompletedProcess[str]:
        return subprocess.run([sys.executable, "-m", "rclverify.cli.commands", "nodl", "check", "-w", str(ws),
                               "--ros2", "--source", "rclpy", "--ros2-python", str(py), "--wait", "2"],
                              cwd=tmp, env=dict(env, PYTHONPATH=str(EXAMPLE.parents[1] / "src")),
                              capture_output=True, text=True, timeout=120)
    first = check()
    doc = ws / "nodl" / "Docking.nodl.yaml"
    doc.write_text(doc.read_text().replace("publishers:\n", "publishers:\n- name: dock_status\n"
                                                             "  type: std_msgs/msg/String\n"
                                                             "  qos: {history: KEEP_LAST, depth: 10, reliability: "
                                                             "RELIABLE, durability: VOLATILE}\n", 1))
    return first, check()


def test_the_correct_robot_is_green_live(correct: dict[str, Any]) -> None:
    rec = correct["record"]
    assert correct["code"] == 0, correct["out"]
    assert _status(rec) == dict.fromkeys(NODES, "discharged"), correct["out"]
    for n in rec["nodes"]:
        c = n["counts"]
        assert c.get("violated", 0) == 0 and c.get("inconclusive", 0) == 0, (n["node"], c)
    assert {d["node"]: d["status"] for d in rec["declarations"]} == {"ObstacleGuard": "discharged",
                                                                     "Planner": "discharged"}, rec["declarations"]
    assert "estop [True, False, True, False, False, True] arm [2, 5, 8]" in correct["robot"], correct["robot"]


def test_the_correct_robots_log_and_bag_give_its_verdicts(correct: dict[str, Any],
                                                          capsys: pytest.CaptureFixture[str]) -> None:
    live = {n["node"]: n["counts"] for n in correct["record"]["nodes"]}
    for trace in ("live.jsonl", "bag"):
        capsys.readouterr()
        code = main(["monitor", "-w", str(EXAMPLE), "--mapping", "contracts/mapping.yaml", "--json",
                     *[a for n in NODES[:7] for a in ("--node", n)], str(correct["tmp"] / trace)])
        got = {e["node"]: e["counts"] for e in json.loads(capsys.readouterr().out) if "counts" in e}
        assert code == 0, got
        for node in NODES[:7]:
            assert got[node].get("violated", 0) == 0, (trace, node, got[node])
            assert got[node].get("satisfied", 0) == live[node].get("satisfied", 0), (trace, node, got[node], live[node])


def test_each_defect_is_red_at_its_own_node_only(defective: dict[str, Any]) -> None:
    status = _status(defective["record"])
    assert defective["code"] == 1, defective["out"]
    red = {n for n, s in status.items() if s == "failed"}
    assert red == set(DEFECTS.values()), status
    assert status["Battery"] == status["Planner"] == "discharged", status



def test_its_nodl_documents_match_the_contracts_and_the_running_robot(defective: dict[str, Any]) -> None:
    """examples/manipulator/nodl/ (written by ``rclverify nodl write`` from the contracts) agrees with the
    contracts and with the sixteen running rclpy nodes (the library's own ends, introspection events and
    the lifecycle interface, are not the nodes' and no finding; the defects change no interface);
    control: a Docking document declaring a publisher the contract does not name (statically a warning)
    is an error against the running node, which has no such endpoint."""
    first, control = defective["after"]
    assert first.returncode == 0 and "9 document(s) matched to a running node" in first.stdout, \
        first.stdout + first.stderr
    assert "0 error(s), 0 warning(s)" in first.stdout, first.stdout
    out = control.stdout + control.stderr
    assert control.returncode == 1 and "dock_status" in out and "nodl-live-absent" in out, out


def test_the_log_holds_the_robots_time(correct: dict[str, Any]) -> None:
    """Every answer is placed after the question it answers, though many were heard before it: an
    unstamped /dock_cmd after its unstamped /dock_range, at their publishers' source times (on receipt
    times a correct robot read red: docs/semantics.md, "Event time")."""
    log = [json.loads(x) for x in (correct["tmp"] / "live.jsonl").read_text().splitlines()]
    order = [x["topic"] for x in log if x.get("topic") in ("dock_range", "dock_cmd")]
    assert len(order) >= 70 and order[:2] == ["dock_range", "dock_cmd"], order[:6]
    assert all(a != b for a, b in zip(order, order[1:])), order  # question, answer, question, answer ...
