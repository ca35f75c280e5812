"""The command line as a new user meets it (issue 30, items 3, 7, 8 and 10;
issue 35 item 10): a four-node drone written with `rclverify init`, its
status, `explain` of every id the outputs show, ROS grounding errors on the
terminal, `--strict`'s last line, `check contracts/*.rcl` in the bundled
workspace, `init --from-ros` file names, and what the docs say of them."""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from rclverify.cli.commands import main

ROOT = Path(__file__).resolve().parents[2]
SRC = ROOT / "src"
NODES = "BatteryMonitor,Geofence,MissionPlanner,FlightController"
LOCATED = re.compile(r"^(?P<file>[^:\n]+):(?P<line>\d+):(?P<col>\d+): error: (?P<msg>.+)$")


def _env() -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": str(SRC) + os.pathsep + os.environ.get("PYTHONPATH", "")}


def _run(cwd: Path, *argv: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, *argv], cwd=cwd, env=_env(), capture_output=True, text=True, timeout=300)


def _drone(root: Path) -> Path:
    """The new user's workspace: four nodes, the first requirement renamed SAFE-ALT."""
    ws = root / "drone"
    assert main(["init", str(ws), "--nodes", NODES]) == 0
    plan = ws / "contracts" / "plan.yaml"
    plan.write_text(plan.read_text(encoding="utf-8").replace("  - id: REQ1\n", "  - id: SAFE-ALT\n", 1), encoding="utf-8")
    return ws


ROS_PACKAGE = {
    "package.xml": '<?xml version="1.0"?>\n<package format="2"><name>drone</name><version>0.1.0</version>'
                   "<description>A drone.</description><maintainer email=\"dev@example.com\">dev</maintainer>"
                   "<license>MIT</license><buildtool_depend>catkin</buildtool_depend></package>\n",
    "scripts/battery_monitor.py": 'import rospy\nfrom std_msgs.msg import Float64\nrospy.init_node("battery_monitor")\n'
                                  'pub = rospy.Publisher("battery", Float64, queue_size=1)\n',
    "scripts/flight_controller.py": 'import rospy\nfrom std_msgs.msg import Float64\nrospy.init_node("flight_controller")\n'
                                    'sub = rospy.Subscriber("battery", Float64, lambda m: None)\n',
}


def _ros_package(where: Path) -> None:
    for rel, text in ROS_PACKAGE.items():
        (where / rel).parent.mkdir(parents=True, exist_ok=True)
        (where / rel).write_text(text, encoding="utf-8")


@pytest.fixture(scope="module")
def drone(tmp_path_factory: pytest.TempPathFactory) -> Path:
    ws = _drone(tmp_path_factory.mktemp("newuser"))
    r = _run(ws, "-m", "doit", "verify")
    assert r.returncode == 0, r.stdout + r.stderr
    return ws


@pytest.fixture(scope="module")
def grounded(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, subprocess.CompletedProcess[str]]:
    """The drone grounded in ROS software where only two of its four nodes exist."""
    ws = _drone(tmp_path_factory.mktemp("grounded"))
    _ros_package(ws / "ros" / "drone")
    with (ws / "contracts" / "plan.yaml").open("a", encoding="utf-8") as f:
        f.write("ros:\n  workspaces: [ros]\n")
    return ws, _run(ws, "-m", "doit", "verify", "--strict")


# ---------------------------------------------------------------------------
# item 3: explain accepts the ids the outputs show
# ---------------------------------------------------------------------------

def test_explain_accepts_requirement_node_and_guarantee_ids(drone: Path, capsys: pytest.CaptureFixture[str]) -> None:
    w = ["-w", str(drone)]
    # what `status` and the summary table show: the requirement, the nodes
    assert main(["status", *w]) == 0
    out = capsys.readouterr().out
    assert "requirements: 2 proved, evidence outstanding" in out and "| FlightController " in out
    assert main(["explain", *w, "SAFE-ALT"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("requirement SAFE-ALT: proved, evidence outstanding [unverified]")
    assert "The output of FlightController stays within 0..100." in out  # its statement
    assert "formal: 0 <= FlightController.out.flight_controller_value" in out
    assert "used: FlightController guarantee 1: " in out and "(contracts/flight_controller.rcl:23:14)" in out
    # a node: its guarantees, their evidence status, its problems
    assert main(["explain", *w, "FlightController"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("FlightController [unverified] (node, contracts/flight_controller.rcl:")
    assert "FlightController.g1 [unverified]" in out and "FlightController.g2 [unverified]" in out
    assert "evidence: none: no evidence entry of the plan covers it" in out
    assert "supports: SAFE-ALT" in out and "side conditions: 2/2 proved" in out and "problems: none" in out
    # the same node by its file stem, a guarantee in the forms the outputs use
    assert main(["explain", *w, "flight_controller"]) == 0
    assert capsys.readouterr().out.startswith("FlightController [unverified] (node,")
    for form in ("Geofence.g2", "Geofence g2", "geofence guarantee 2"):
        assert main(["explain", *w, form]) == 0
        out = capsys.readouterr().out
        assert out.startswith("Geofence.g2 [unverified] (guarantee 2 of Geofence, contracts/geofence.rcl:26:3)"), form
        assert "in.battery_monitor_value <= 50 -> out.geofence_value <= in.battery_monitor_value" in out
        assert "supports: REQ2" in out
    # a side condition, a health check, a SARIF rule id
    assert main(["explain", *w, "Geofence.sc1"]) == 0
    assert "Geofence.sc1 [discharged] (side condition of Geofence" in capsys.readouterr().out
    assert main(["explain", *w, "BatteryMonitor.assumption-satisfiable"]) == 0
    out = capsys.readouterr().out
    assert "[ok] (health check of BatteryMonitor)" in out and "witness:" in out and "counterexample" not in out
    assert main(["explain", *w, "RCL-REQ-EVIDENCE"]) == 0
    out = capsys.readouterr().out
    assert "2 results in reports/assurance.sarif:" in out and "contracts/plan.yaml:28:14: Requirement SAFE-ALT" in out


def test_explain_suggests_near_ids_when_nothing_matches(drone: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["explain", "-w", str(drone), "SAFE-ALTT"]) == 1
    (line,) = capsys.readouterr().err.splitlines()
    m = LOCATED.match(line)
    assert m and m["file"].endswith("reports/assurance.json") and "'SAFE-ALTT'" in m["msg"]
    assert "did you mean SAFE-ALT" in m["msg"]
    assert main(["explain", "-w", str(drone), "FlightControler.g1"]) == 1
    assert "did you mean FlightController.g1" in capsys.readouterr().err


@pytest.mark.parametrize("name", ["reports/assurance.json", "artifacts/report/summary.json"])
@pytest.mark.parametrize("text", ["[]", "null", '"a string"', "{}", '{"meta": {"workspace": "w", "strict_ok": true}}',
                                  '{"meta": [], "summary": {}}', "{not json"])
def test_last_run_files_of_another_shape_are_one_located_line(drone: Path, tmp_path: Path, name: str, text: str,
                                                             capsys: pytest.CaptureFixture[str]) -> None:
    ws = tmp_path / "ws"
    shutil.copytree(drone, ws)
    (ws / name).write_text(text, encoding="utf-8")
    commands = [["explain", "SAFE-ALT"], ["status"]] if name.startswith("reports") else [["status"]]
    for argv in commands:
        if name.startswith("reports") and argv == ["status"]:  # status reads the JSON report without a summary file
            (ws / "artifacts/report/summary.json").unlink()
        assert main([argv[0], "-w", str(ws), *argv[1:]]) == 1, argv
        out, err = capsys.readouterr()
        (line,) = err.splitlines()
        m = LOCATED.match(line)
        assert m and m["file"] == str(ws / name) and (m["line"], m["col"]) == ("1", "1"), line
        assert "Traceback" not in out + err


def test_a_broken_summary_ends_doit_verify_in_one_line_not_a_traceback(drone: Path, tmp_path: Path) -> None:
    ws = tmp_path / "ws"
    shutil.copytree(drone, ws)
    (ws / "artifacts/report/summary.json").write_text("[]", encoding="utf-8")
    r = _run(ws, "-m", "rclverify.cli.commands", "status")
    assert r.returncode == 1 and "Traceback" not in r.stderr
    assert r.stderr.strip() == f"{Path('artifacts/report/summary.json')}:1:1: error: summary record is not a JSON " \
                               "object: altered outside rclverify; run `rclverify verify` (or `doit verify`) to write it again"


# ---------------------------------------------------------------------------
# item 7: the terminal
# ---------------------------------------------------------------------------

def test_grounding_errors_are_on_the_overall_line_and_in_the_problem_list(
        grounded: tuple[Path, subprocess.CompletedProcess[str]], capsys: pytest.CaptureFixture[str]) -> None:
    ws, r = grounded
    report = json.loads((ws / "reports/assurance.json").read_text())
    assert report["grounding"]["counts"]["error"] == 2  # Geofence and MissionPlanner are in no ROS node
    for text in (r.stdout, None):
        if text is None:
            assert main(["status", "-w", str(ws)]) == 0
            text = capsys.readouterr().out
        lines = text.splitlines()
        overall = next(line for line in lines if line.startswith("overall: "))
        assert overall.endswith("; 2 ROS grounding errors."), overall
        k = lines.index(next(line for line in lines if line.startswith("2 ROS grounding errors: ")))
        listed = lines[k + 1:k + 3]
        assert all(re.match(r"^  contracts/\w+\.rcl:\d+:\d+: contract node \w+ is not in the ROS graph: .*"
                            r"\(ROS-NODE-NOT-IN-GRAPH\)$", x) for x in listed), listed
        assert any(x.startswith("  contracts/geofence.rcl:18:1: contract node Geofence ") for x in listed)
        assert any(x.startswith("  contracts/mission_planner.rcl:18:1: contract node MissionPlanner ") for x in listed)


def test_strict_ends_in_one_sentence_naming_why(grounded: tuple[Path, subprocess.CompletedProcess[str]]) -> None:
    ws, r = grounded
    assert r.returncode == 1
    assert "TaskFailed" not in r.stdout + r.stderr and "taskid" not in r.stdout + r.stderr
    last = r.stdout.rstrip().splitlines()[-1]
    assert last == ("--strict failed: 8 guarantees are unverified (no obligation covers them): "
                    "BatteryMonitor.g1, BatteryMonitor.g2, Geofence.g1, Geofence.g2, ...; 2 formal requirements are "
                    "not met (SAFE-ALT, REQ2); 2 ROS grounding errors "
                    "(`rclverify ros check`) (reports/assurance.html)."), last
    r2 = _run(ws, "-m", "rclverify.cli.commands", "verify", "--strict")
    assert r2.returncode == 1 and r2.stdout.rstrip().splitlines()[-1] == last
    assert "TaskFailed" not in r2.stdout + r2.stderr


def test_a_problem_sentence_is_cut_at_a_clause_boundary_or_not_at_all() -> None:
    from rclverify.report.diagnosis_text import clause_cut
    from rclverify.report.problems import first_sentence
    from rclverify.report.summary import group_sentence
    whole = ("backends/hoare/rs.imp and guarantee 1 of RadiationSensor (contracts/r.rcl:86:3) disagree on their "
             "constants: the program compares with 10/20 (backends/hoare/rs.imp:15: 10, backends/hoare/rs.imp:18: 20) "
             "where the guarantee uses 120/250; on in.command = inspect(0), in.r = 10 the program gives "
             "out.radiationStatus = orange, which the conjunct `(0 <= in.r and in.r < 120) -> out.radiationStatus == "
             "green` (contracts/r.rcl:88:11) rules out.")
    # the report's row keeps a prefix; what the terminal shows is the whole first sentence
    from rclverify.records.problem_rows import ProblemRow
    from tests.records._typed_rows import complete
    group = ProblemRow.of(complete(ProblemRow, {"sentence": first_sentence(whole, 300),
                                                "members": [{"sentence": whole + " More follows."}]}))
    assert group_sentence(group) == whole
    assert clause_cut(whole) == whole  # short enough: whole
    cut = clause_cut(whole, 300)
    assert cut.endswith("where the guarantee uses 120/250; ..."), cut  # at the clause boundary
    assert not cut.endswith("gives ...")
    # a boundary inside parentheses or a formula is none; no boundary: whole
    assert clause_cut("f(a: b; c) " + "x" * 50, 20) == "f(a: b; c) " + "x" * 50


def test_the_first_sentence_does_not_end_inside_a_parenthesis_or_a_formula() -> None:
    """A ``;`` or ``.`` before a capital letter ends the first sentence only outside parentheses and
    backquotes: the case study's REQ4 sentence names nodes after each ``;`` of its parenthesis, and its
    terminal line was cut after the first one, mid-parenthesis and with no ``...``."""
    from rclverify.report.diagnosis_text import whole_first_sentence
    from rclverify.report.problems import first_sentence
    text = ("Requirement REQ4 (`eventually (a; B)`, contracts/plan.yaml:67:7) is refuted by a run in which no node "
            "accepts its input (Agent.in.at never has a value: Navigation never publishes Navigation.out.at; "
            "Navigation.in.command never has a value: Agent never publishes Agent.out.command), so none ever "
            "answers. Declare the initial value.")
    whole = text[:text.index(" Declare")]
    assert whole_first_sentence(text) == whole
    assert first_sentence(text) == whole  # under the row's 400 characters
    assert first_sentence(text, 100).endswith(" ...") and len(first_sentence(text, 100)) <= 104
    assert whole_first_sentence("One. Two.") == "One." and whole_first_sentence("one; Two") == "one;"
    assert whole_first_sentence("no end at all") == "no end at all"


# ---------------------------------------------------------------------------
# item 8: `rclverify check contracts/*.rcl` in the bundled workspace
# ---------------------------------------------------------------------------

def test_check_of_every_contract_of_the_bundled_workspace_works(capsys: pytest.CaptureFixture[str],
                                                               monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)
    files = sorted(str(p.relative_to(ROOT)) for p in (ROOT / "contracts").glob("*.rcl"))
    assert "contracts/agent_repaired.rcl" in files  # re-declares the context: the replacement contract
    assert main(["check", *files]) == 0
    out, err = capsys.readouterr()
    assert "already declared" not in out + err and err == ""
    assert "contracts/agent_repaired.rcl: the plan's replacement for Agent, checked in its own scope" in out
    assert out.splitlines()[-1].startswith(f"{len(files)} file(s): 0 errors")
    # from elsewhere, the plan beside the files groups them all the same
    monkeypatch.chdir(ROOT / "docs")
    assert main(["check", *(str(ROOT / f) for f in files)]) == 0
    capsys.readouterr()


def test_without_a_plan_the_files_are_one_scope(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    shutil.copy(ROOT / "contracts/remote_inspection.rcl", tmp_path / "a.rcl")
    shutil.copy(ROOT / "contracts/agent_repaired.rcl", tmp_path / "b.rcl")
    # no plan: one system, so the second context and Agent clash, located
    assert main(["check", "a.rcl", "b.rcl"]) == 1
    assert "error: node 'Agent' is already defined at" in capsys.readouterr().err
    # a plan naming b.rcl as the replacement: its own scope
    (tmp_path / "contracts").mkdir()
    for f in ("a.rcl", "b.rcl"):
        (tmp_path / f).rename(tmp_path / "contracts" / f)
    (tmp_path / "contracts/plan.yaml").write_text("contracts: [contracts/a.rcl]\nnodes:\n  Agent:\n"
                                                 "    replacement: contracts/b.rcl:Agent\n", encoding="utf-8")
    assert main(["check", "contracts/a.rcl", "contracts/b.rcl"]) == 0
    capsys.readouterr()


# ---------------------------------------------------------------------------
# item 10: file names of init --from-ros, and what the docs say
# ---------------------------------------------------------------------------

def test_init_from_ros_names_contract_files_in_snake_case_as_init_does(tmp_path: Path) -> None:
    _ros_package(tmp_path / "src" / "drone")
    assert main(["init", str(tmp_path / "ws"), "--from-ros", str(tmp_path / "src")]) == 0
    names = sorted(p.name for p in (tmp_path / "ws/contracts").glob("*.rcl"))
    assert names == ["battery_monitor.rcl", "flight_controller.rcl", "ros_types.rcl"]
    assert "node BatteryMonitor {" in (tmp_path / "ws/contracts/battery_monitor.rcl").read_text()
    assert main(["init", str(tmp_path / "plain"), "--nodes", "BatteryMonitor"]) == 0
    assert (tmp_path / "plain/contracts/battery_monitor.rcl").is_file()


def test_a_no_op_run_prints_the_table_and_the_docs_say_so(drone: Path) -> None:
    r = _run(drone, "-m", "doit", "verify")
    assert r.returncode == 0 and ".  " not in r.stdout  # no task ran
    assert "| total " in r.stdout and r.stdout.startswith("-- ") and "overall: unverified" in r.stdout
    ci = (ROOT / "docs/ci.md").read_text(encoding="utf-8")
    assert "prints\n  no table" not in ci and "no table" not in ci.replace("\n  ", " ")


def test_the_command_reference_lists_every_ros_command() -> None:
    import argparse

    from rclverify.cli.ros import add_parsers
    sub = argparse.ArgumentParser().add_subparsers(dest="command")
    add_parsers(sub)
    ros = sub.choices["ros"]
    commands: Any = next(a for a in ros._actions if isinstance(a, argparse._SubParsersAction)).choices
    # The command reference moved from the README to docs/commands.md (issue 66).
    reference = (ROOT / "docs/commands.md").read_text(encoding="utf-8")
    block = reference.split("## Command line", 1)[1].split("```", 2)[1]
    assert sorted(commands) == ["check", "diff", "scan"]
    for name in commands:
        assert f"rclverify ros {name}" in block, name
    assert "rclverify init DIR --from-ros PATH" in block


def test_explain_leaves_out_an_optional_file_of_another_shape(drone: Path, tmp_path: Path,
                                                              capsys: pytest.CaptureFixture[str]) -> None:
    ws = tmp_path / "ws"
    shutil.copytree(drone, ws)
    (ws / "reports/assurance.sarif").write_text('{"runs": "x"}', encoding="utf-8")
    (ws / "reports/argument.json").write_text('{"elements": 3}', encoding="utf-8")
    assert main(["explain", "-w", str(ws), "SAFE-ALT"]) == 0
    assert capsys.readouterr().out.startswith("requirement SAFE-ALT: ")
    assert main(["explain", "-w", str(ws), "RCL-REQ-EVIDENCE"]) == 1  # known only from the SARIF log
    (line,) = capsys.readouterr().err.splitlines()
    assert LOCATED.match(line) and "Traceback" not in line
