"""Autoware System Designer designs read and written (docs/nodl.md, "Autoware System Designer"): a small design
of our own (a lidar driver, a perception module of a filter and a tracker, a planner) imported into a workspace
whose contracts check and whose NoDL documents agree; a filter's deadline too long for the tracker's timeout
refuted at the design's field and at the contracts' clauses, with the design that fits as its control and the
workspace's own deadlines read by ``--check``; an input nobody wires left undecided; export -> import giving the
same workspace; malformed files each one located line."""
from __future__ import annotations

import textwrap
from fractions import Fraction
from pathlib import Path

import pytest

from rclverify.cli.commands import main
from rclverify.model.nodl.design import read_design
from rclverify.model.nodl.design_write import duration

HEAD = "autoware_system_design_format: 0.3.0\n"
NODES = {
    "node/LidarDriver.node.yaml": """\
        name: LidarDriver.node
        package: {name: rover_sensing, provider: test}
        launch: {plugin: rover::LidarDriver}
        subscribers: []
        publishers:
          - name: points
            message_type: sensor_msgs/msg/PointCloud2
            qos: {reliability: best_effort, durability: volatile}
        param_files: []
        param_values: []
        processes:
          - name: scan
            trigger_conditions:
              - periodic: 10.0
                timeout: 0.2
            outcomes:
              - to_output: points
        """,
    "node/Filter.node.yaml": """\
        name: Filter.node
        package: {name: rover_perception, provider: test}
        launch: {plugin: rover::Filter}
        subscribers:
          - name: points
            message_type: sensor_msgs/msg/PointCloud2
            qos: {reliability: best_effort}
        publishers:
          - name: objects
            message_type: rover_msgs/msg/Objects
        param_files: []
        param_values: []
        processes:
          - name: filter
            trigger_conditions:
              - on_input: points
                timeout: FILTER_TIMEOUT
            outcomes:
              - to_output: objects
        """,
    "node/Tracker.node.yaml": """\
        name: Tracker.node
        package: {name: rover_perception, provider: test}
        launch: {plugin: rover::Tracker}
        subscribers:
          - name: objects
            message_type: rover_msgs/msg/Objects
        publishers:
          - name: tracks
            message_type: rover_msgs/msg/Tracks
            qos: {reliability: reliable, durability: transient_local}
        servers:
          - name: reset
            message_type: std_srvs/srv/Trigger
        param_files: []
        param_values: []
        processes:
          - name: update
            trigger_conditions:
              - on_input: objects
                timeout: 0.3
                error_rate: 4
            outcomes:
              - to_trigger: publish
          - name: publish
            trigger_conditions:
              - on_trigger: update
            outcomes:
              - to_output: tracks
        """,
    "node/Planner.node.yaml": """\
        name: Planner.node
        package: {name: rover_planning, provider: test}
        launch: {plugin: rover::Planner}
        subscribers:
          - name: tracks
            message_type: rover_msgs/msg/Tracks
            qos: {reliability: reliable, durability: transient_local}
          - name: goal
            message_type: geometry_msgs/msg/PoseStamped
        publishers:
          - name: path
            message_type: nav_msgs/msg/Path
        clients:
          - name: reset
            message_type: std_srvs/srv/Trigger
        param_files: []
        param_values: []
        processes:
          - name: plan
            trigger_conditions:
              - and:
                  - on_input: tracks
                    timeout: 0.6
                  - once: tracks
            outcomes:
              - to_output: path
          - name: replan
            trigger_conditions:
              - on_input: goal
                timeout: 1.0
            outcomes:
              - to_output: path
        """,
    "module/Perception.module.yaml": """\
        name: Perception.module
        instances:
          - name: filter
            entity: Filter.node
          - name: tracker
            entity: Tracker.node
        subscribers:
          - name: points
        publishers:
          - name: objects
        servers:
          - name: reset
        connections:
          - - subscriber.points
            - filter.subscriber.points
          - - filter.publisher.objects
            - tracker.subscriber.objects
          - - tracker.publisher.tracks
            - publisher.objects
          - - tracker.server.reset
            - server.reset
        """,
    "system/Rover.system.yaml": """\
        name: Rover.system
        modes:
          - name: default
            default: true
        components:
          - name: lidar
            entity: LidarDriver.node
            path: /sensing/lidar
          - name: perception
            entity: Perception.module
            path: /perception
          - name: planner
            entity: Planner.node
        connections:
          - - perception.subscriber.points
            - lidar.publisher.points
          - - perception.publisher.objects
            - planner.subscriber.tracks
          - - planner.client.reset
            - perception.server.reset
        """,
}


def _design(root: Path, filter_timeout: str = "0.15", edit: dict[str, tuple[str, str]] | None = None) -> Path:
    for rel, text in NODES.items():
        body = HEAD + textwrap.dedent(text).replace("FILTER_TIMEOUT", filter_timeout)
        if edit and rel in edit:
            body = body.replace(*edit[rel])
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(body, encoding="utf-8")
    return root


def _files(root: Path) -> dict[str, str]:
    return {p.relative_to(root).as_posix(): p.read_text(encoding="utf-8") for p in sorted(root.rglob("*")) if p.is_file()}


PLAN = "contracts/plan.yaml"


def _made(ws: Path) -> dict[str, str]:
    """The files of workspace ``ws`` the import writes, the design's copy (design/) aside."""
    return {k: v for k, v in _files(ws).items() if not k.startswith("design/")}


def _at(path: Path, text: str, nth: int = 1) -> str:
    """``file:line:col`` of the ``nth`` line of ``path`` holding ``text``, as the messages show it."""
    hits = [(i, ln.index(text) + 1) for i, ln in enumerate(path.read_text(encoding="utf-8").splitlines(), 1) if text in ln]
    line, col = hits[nth - 1]
    return f"{line}:{col}"


def test_a_design_is_flattened_into_nodes_and_wires_through_module_boundaries(tmp_path: Path) -> None:
    d = read_design(_design(tmp_path / "design"))
    assert list(d.nodes) == ["lidar", "perception_filter", "perception_tracker", "planner"]
    wires = {(w.writer, w.writer_port, w.reader, w.reader_port, w.role) for w in d.wires}
    assert wires == {("lidar", "points", "perception_filter", "points", "publisher"),
                     ("perception_filter", "objects", "perception_tracker", "objects", "publisher"),
                     ("perception_tracker", "tracks", "planner", "tracks", "publisher"),  # through the module's boundary
                     ("perception_tracker", "reset", "planner", "reset", "server")}
    assert d.nodes["planner"].topics[("subscriber", "tracks")] == "/perception/tracker/tracks"
    assert d.nodes["planner"].topics[("subscriber", "goal")] == "/planner/goal"  # wired to nothing: its own name
    assert d.nodes["perception_filter"].topics[("subscriber", "points")] == "/sensing/lidar/points"


def test_import_writes_a_workspace_that_checks_and_decides_each_monitoring_field(tmp_path: Path, capsys,
                                                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    _design(tmp_path / "design")
    monkeypatch.chdir(tmp_path)
    assert main(["import", "autoware-design", "design", "-o", "ws"]) == 0
    out, err = capsys.readouterr()
    rcl = (tmp_path / "ws/contracts/design.rcl").read_text(encoding="utf-8")
    assert "guarantee( out.objects == out.objects ) triggered by in.points within 150 ms" in rcl
    assert "guarantee( out.tracks == out.tracks ) triggered by in.objects within 300 ms" in rcl  # via to_trigger
    assert "periodic( out.points, 100 ms )" in rcl and "triggered by in.goal within 1000 ms" in rcl
    plan = (tmp_path / "ws/contracts/plan.yaml").read_text(encoding="utf-8")
    assert "{from: perception_tracker.tracks, to: planner.tracks}" in plan
    assert "node perception_tracker: in.objects's timeout holds: the contracts let it wait at most 250 ms <= 300 ms" in out
    assert "node planner: in.tracks's timeout holds: the contracts let it wait at most 550 ms <= 600 ms" in out
    # the goal comes from outside the design: nothing bounds its gaps, which is said, not passed
    assert "planner process replan's in.goal: timeout 1 s is not decided: planner.in.goal has no producer" in err
    assert "[design-undecided]" in err and "Traceback" not in err
    # the workspace written checks, and its NoDL documents agree with each other and its contracts
    monkeypatch.chdir(tmp_path / "ws")
    assert main(["check", "contracts/design.rcl"]) == 0
    assert main(["nodl", "check", "nodl", "--external", "/planner/goal"]) == 0
    assert main(["nodl", "check"]) == 0  # the services are in the documents only: warnings (nodl-extra)
    # nothing is overwritten without --force
    monkeypatch.chdir(tmp_path)
    assert main(["import", "autoware-design", "design", "-o", "ws"]) == 1
    assert "exists; nothing is overwritten unless --force" in capsys.readouterr().err


def test_a_deadline_the_next_timeout_cannot_meet_is_refuted_at_the_design_and_the_contracts(
        tmp_path: Path, capsys, monkeypatch: pytest.MonkeyPatch) -> None:
    _design(tmp_path / "design", filter_timeout="0.25")
    monkeypatch.chdir(tmp_path)
    assert main(["import", "autoware-design", "design", "-o", "ws"]) == 1
    err = capsys.readouterr().err
    tracker, rcl = tmp_path / "design/node/Tracker.node.yaml", tmp_path / "ws/contracts/design.rcl"
    line, col = _at(tracker, "timeout: 0.3").split(":")
    timeout_at = f"design/node/Tracker.node.yaml:{line}:{int(col) + len('timeout: ')}"  # the value
    periodic_at = f"contracts/design.rcl:{_at(rcl, 'periodic( out.points')}"
    filter_at = f"contracts/design.rcl:{_at(rcl, 'triggered by in.points').split(':')[0]}:3"  # the guarantee
    refuted = [ln for ln in err.splitlines() if ln.startswith(timeout_at)]
    assert len(refuted) == 1 and "[design-timeout]" in refuted[0], err
    assert "timeout 0.3 s cannot be met: the contracts let it wait 350 ms > 300 ms" in refuted[0]
    assert f"(also at {periodic_at}, {filter_at})" in refuted[0]  # the chain's two clauses, in the contract
    assert any(ln.startswith(periodic_at) and "[design-timeout]" in ln for ln in err.splitlines())
    assert "error_rate 4 Hz cannot be met: the contracts let it wait 350 ms > 250 ms" in err
    # the control: the design whose filter answers within 150 ms holds, checked against this workspace as it
    # stands (--check reads the contracts' deadlines: still 250 ms here, so still refuted) ...
    _design(tmp_path / "fits")
    assert main(["import", "autoware-design", "fits", "--check", "-w", "ws"]) == 1
    capsys.readouterr()
    # ... and once the contract's deadline is the design's 150 ms, nothing is refuted
    rcl.write_text(rcl.read_text(encoding="utf-8").replace("in.points within 250 ms", "in.points within 150 ms"),
                   encoding="utf-8")
    assert main(["import", "autoware-design", "fits", "--check", "-w", "ws"]) == 0
    out = capsys.readouterr().out
    assert "in.objects's error_rate holds: the contracts let it wait at most 250 ms <= 250 ms" in out


def test_export_then_import_gives_the_same_workspace(tmp_path: Path, capsys, monkeypatch: pytest.MonkeyPatch) -> None:
    _design(tmp_path / "design")
    monkeypatch.chdir(tmp_path)
    assert main(["import", "autoware-design", "design", "-o", "ws1"]) == 0
    assert main(["export", "autoware-design", "-w", "ws1", "-o", "exported"]) == 0
    exported = read_design(tmp_path / "exported")
    assert list(exported.nodes) == ["lidar", "perception_filter", "perception_tracker", "planner"]
    assert main(["import", "autoware-design", "exported", "-o", "ws2"]) == 0
    # every file the import makes is the same (the plan's design key too), and each workspace holds the design
    # it was imported from (ws1 the hand-written one, ws2 the export), which its plan names
    assert _made(tmp_path / "ws1") == _made(tmp_path / "ws2") and 'design: "design"' in _made(tmp_path / "ws1")[PLAN]
    assert _files(tmp_path / "ws1/design") == _files(tmp_path / "design")
    assert _files(tmp_path / "ws2/design") == _files(tmp_path / "exported")
    assert main(["export", "autoware-design", "-w", "ws2", "-o", "exported2"]) == 0
    assert _files(tmp_path / "exported2") == _files(tmp_path / "exported")  # export -> import -> export: equal
    # the control: an edited contract is carried by the export, so the round trip is not vacuous
    rcl = tmp_path / "ws1/contracts/design.rcl"
    rcl.write_text(rcl.read_text(encoding="utf-8").replace("within 150 ms", "within 100 ms"), encoding="utf-8")
    assert main(["export", "autoware-design", "-w", "ws1", "-o", "exported", "--force"]) == 0
    assert "timeout: 0.1" in (tmp_path / "exported/node/perception_filter.node.yaml").read_text(encoding="utf-8")
    assert main(["import", "autoware-design", "exported", "-o", "ws2", "--force"]) == 0
    assert _made(tmp_path / "ws1") == _made(tmp_path / "ws2")
    assert "in.points within 100 ms" in (tmp_path / "ws2/contracts/design.rcl").read_text(encoding="utf-8")
    assert _files(tmp_path / "ws2/design") == _files(tmp_path / "exported")  # the edited design, copied


def test_import_names_the_design_in_the_plan_and_keeps_an_existing_plans_other_content(
        tmp_path: Path, capsys, monkeypatch: pytest.MonkeyPatch) -> None:
    """A new plan names the design copied into the workspace (design: "design"), and the design stage's check
    reads it; a design already inside the workspace is named where it is, not copied; an existing plan is never
    replaced: its design key is set (replaced, or added) and every other line kept, comments and all."""
    _design(tmp_path / "design")
    monkeypatch.chdir(tmp_path)
    assert main(["import", "autoware-design", "design", "-o", "ws"]) == 0
    from rclverify.stages.workspace import Workspace
    assert Workspace(tmp_path / "ws", PLAN).plan.design == "design"
    _design(tmp_path / "ws2" / "arch" / "rover")
    assert main(["import", "autoware-design", "ws2/arch/rover", "-o", "ws2"]) == 0
    assert 'design: "arch/rover"' in (tmp_path / "ws2" / PLAN).read_text(encoding="utf-8")
    assert not (tmp_path / "ws2/design").exists()  # named where it lies
    plan = tmp_path / "ws" / PLAN
    own = ("# the robot's plan, edited by hand\nname: Rover\ncontracts:\n  - contracts/design.rcl\n"
           "design: old/place\n  # a stray continuation\nros:\n  workspaces: [src]\n")
    plan.write_text(own, encoding="utf-8")
    capsys.readouterr()
    assert main(["import", "autoware-design", "design", "-o", "ws", "--force"]) == 0
    assert plan.read_text(encoding="utf-8") == own.replace("design: old/place\n  # a stray continuation\n",
                                                           'design: "design"\n')
    assert "the plan's other content kept" in capsys.readouterr().out
    plan.write_text("name: Rover\ncontracts: [contracts/design.rcl]", encoding="utf-8")  # no key, no final newline
    assert main(["import", "autoware-design", "design", "-o", "ws", "--force"]) == 0
    assert plan.read_text(encoding="utf-8") == 'name: Rover\ncontracts: [contracts/design.rcl]\ndesign: "design"\n'
    # the control: without --force nothing is written, the plan included
    plan.write_text(own, encoding="utf-8")
    assert main(["import", "autoware-design", "design", "-o", "ws"]) == 1
    assert plan.read_text(encoding="utf-8") == own


@pytest.mark.parametrize(("rel", "old", "new", "where", "says"), [
    ("node/Filter.node.yaml", "format: 0.3.0", "format: 1.0.0", "1:32", "autoware_system_design_format 1.0.0: read are"),
    ("node/Filter.node.yaml", "name: Filter.node", "name: Filtre.node", "2:7", "a node file's name is its file name"),
    ("module/Perception.module.yaml", "entity: Tracker.node", "entity: Tracer.node", "7:13", "entity 'Tracer.node' is no"),
    ("module/Perception.module.yaml", "- filter.subscriber.points", "- filter.subscriber.cloud", "15:5",
     "perception/filter has no subscriber 'cloud'"),
    ("node/Filter.node.yaml", "on_input: points", "on_input: cloud", "17:19", "on_input 'cloud' names no subscriber"),
    ("node/Filter.node.yaml", "timeout: 0.15", "timeout: -1", "18:18", "timeout is a positive number (s)"),
    ("system/Rover.system.yaml", "- lidar.publisher.points", "- lidar.points", "17:7", "'lidar.points' is no port path"),
    ("node/Tracker.node.yaml", "  - name: tracks\n", "  - name: [tracks\n", "10:17", "not YAML"),
    ("node/Filter.node.yaml", "timeout: 0.15", "timeout: .inf", "18:18", "timeout is a positive number (s)"),
    ("node/Filter.node.yaml", "on_input: points", "on_input: [points]", "17:19", "on_input names a port"),
    ("node/Filter.node.yaml", "qos: {reliability: best_effort}", "qos: fast", "8:10", "qos is a mapping"),
    ("module/Perception.module.yaml", "entity: Tracker.node", "entity: Perception.module", "6:5",
     "Perception.module is an instance of itself (through Perception.module -> Perception.module)"),
])
def test_a_malformed_design_is_one_located_line(tmp_path: Path, capsys, monkeypatch: pytest.MonkeyPatch,
                                                rel: str, old: str, new: str, where: str, says: str) -> None:
    _design(tmp_path / "design", edit={rel: (old, new)})
    monkeypatch.chdir(tmp_path)
    assert main(["import", "autoware-design", "design", "-o", "ws"]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"design/{rel}:{where}: error: ") and says in err, err
    assert "Traceback" not in err and not (tmp_path / "ws").exists()


def test_usage_errors_exit_2(tmp_path: Path, capsys, monkeypatch: pytest.MonkeyPatch) -> None:
    _design(tmp_path / "design")
    monkeypatch.chdir(tmp_path)
    assert main(["import", "autoware-design", "design"]) == 2  # neither -o nor --check
    assert main(["import", "autoware-design", "missing", "-o", "ws"]) == 2
    assert main(["export", "autoware-design"]) == 2  # no -o
    assert "Traceback" not in capsys.readouterr().err


@pytest.mark.parametrize(("s", "text"), [(Fraction(1, 10), "100 ms"), (Fraction(3, 10000), "300 us"),
                                         (Fraction(10, 33), "303030303 ns")])
def test_durations_are_written_exactly_where_a_unit_allows(s: Fraction, text: str) -> None:
    assert duration(s) == text


def test_an_unwired_input_the_model_feeds_by_name_and_a_node_without_contract_are_said(
        tmp_path: Path, capsys, monkeypatch: pytest.MonkeyPatch) -> None:
    """The planner's goal renamed objects: the design wires it to nothing, the system model feeds it from the
    filter's output of that name (design-unwired, a warning at the port and the contract's input); checked
    against a workspace of other nodes, each design trigger with a monitoring field has no contract (an error)."""
    _design(tmp_path / "design", edit={"node/Planner.node.yaml": ("goal", "objects")})
    monkeypatch.chdir(tmp_path)
    assert main(["import", "autoware-design", "design", "-o", "ws"]) == 0
    err = capsys.readouterr().err
    planner = tmp_path / "design/node/Planner.node.yaml"
    line = _at(planner, "- name: objects").split(":")[0]
    unwired = [ln for ln in err.splitlines() if ln.startswith(f"design/node/Planner.node.yaml:{line}:")]
    assert len(unwired) == 1 and "[design-unwired]" in unwired[0], err
    assert "feeds it from perception_filter.out.objects by equal names" in unwired[0]
    assert "(also at contracts/design.rcl:" in unwired[0]
    # the control: the design as written (goal) has no such warning (above: only design-undecided)
    _design(tmp_path / "plain")
    assert main(["import", "autoware-design", "plain", "-o", "ws2"]) == 0
    assert "design-unwired" not in capsys.readouterr().err
    other = Path(__file__).parent.parent / "data" / "nodl" / "ws"
    assert main(["import", "autoware-design", "plain", "--check", "-w", str(other)]) == 1
    err = capsys.readouterr().err
    assert "the design's node perception_tracker has no contract [design-missing]" in err


def test_a_folder_with_two_systems_needs_one_named_and_nothing_is_read_from_outside(
        tmp_path: Path, capsys, monkeypatch: pytest.MonkeyPatch) -> None:
    root = _design(tmp_path / "design")
    (root / "system/Other.system.yaml").write_text(
        (root / "system/Rover.system.yaml").read_text(encoding="utf-8").replace("Rover.system", "Other.system"),
        encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    assert main(["import", "autoware-design", "design", "-o", "ws"]) == 1
    assert "the design needs one *.system.yaml (systems in the folder: Other, Rover; name one with --system)" \
        in capsys.readouterr().err
    assert main(["import", "autoware-design", "design", "-o", "ws", "--system", "Rover"]) == 0
    capsys.readouterr()
    outside = tmp_path / "Elsewhere.node.yaml"
    outside.write_text(HEAD + "name: Elsewhere.node\n", encoding="utf-8")
    (root / "node/Elsewhere.node.yaml").symlink_to(outside)
    assert main(["import", "autoware-design", "design", "-o", "ws3", "--system", "Rover"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("design/node/Elsewhere.node.yaml:1:1: error: leads outside the design folder") and \
        "Traceback" not in err


def test_the_design_stage_record_is_sarif_results_and_junit_cases_at_the_design_files_lines(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The stage's record of the refuted design (filter within 250 ms) as SARIF and JUnit: the tracker's timeout
    an error result at its line in Tracker.node.yaml with the two contract clauses as related locations, and a
    failing case there; the filter's own timeout (met: the control) a note and a passing case."""
    import xml.etree.ElementTree as ET
    from _typed_rows import typed_report
    from rclverify.report.junit import junit_tree
    from rclverify.report.sarif import sarif_log
    from rclverify.stages.design import design_row, stage_design
    from rclverify.stages.workspace import Workspace
    _design(tmp_path / "design", filter_timeout="0.25")
    monkeypatch.chdir(tmp_path)
    assert main(["import", "autoware-design", "design", "-o", "ws"]) == 1
    ws = Workspace(tmp_path / "ws", PLAN)
    stage_design(ws)
    report = typed_report({"design": design_row(ws)})
    results = [r for r in sarif_log(report)["runs"][0]["results"] if r["ruleId"] == "RCL-DESIGN"]
    by = {(r["properties"]["node"], r["properties"]["field"], r["properties"]["trigger"]): r for r in results}
    tracker = by[("perception_tracker", "timeout", "in.objects")]
    loc = tracker["locations"][0]["physicalLocation"]
    line = int(_at(tmp_path / "ws/design/node/Tracker.node.yaml", "timeout: 0.3").split(":")[0])
    assert (loc["artifactLocation"]["uri"], loc["region"]["startLine"]) == ("design/node/Tracker.node.yaml", line)
    assert tracker["level"] == "error" and "[design-timeout]" in tracker["message"]["text"]
    assert [r["physicalLocation"]["artifactLocation"]["uri"] for r in tracker["relatedLocations"]] == ["contracts/design.rcl"] * 2
    met = by[("perception_filter", "timeout", "in.points")]
    assert met["level"] == "note" and "holds" in met["message"]["text"]
    [suite] = [s for s in junit_tree(report).iter("testsuite") if s.get("name") == "design"]
    cases = {c.get("name"): c for c in suite.iter("testcase")}
    failed = cases["perception_tracker in.objects timeout"]
    assert failed.get("line") == str(line) and failed.find("failure") is not None
    assert len(cases["perception_filter in.points timeout"]) == 0  # passes
    assert suite.get("tests") == str(len(results)) and ET.tostring(suite).count(b"<failure") == int(suite.get("failures") or 0)
