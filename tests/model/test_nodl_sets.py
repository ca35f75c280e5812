"""NoDL document sets checked against each other with no contract (docs/nodl.md, "Document sets";
ros-tooling/nodl#182's cases): never-connecting QoS, a type mismatch, a subscription nobody publishes, a
client nobody serves, each with its control; names resolved in a node's namespace; `nodl check DIR` in CI
form (exit code, SARIF 2.1.0 validated against its schema); a workspace's documents without a contract
checked against each other."""
from __future__ import annotations

import json
import shutil
import textwrap
from pathlib import Path

import jsonschema
import pytest

from rclverify.cli.commands import main
from rclverify.model.nodl.check import check, read_all, shown
from rclverify.model.nodl.document import Resolver
from rclverify.model.nodl.sets import SetResult, check_set, resolve, set_files
from rclverify.stages.workspace import Workspace

DATA = Path(__file__).parent.parent / "data"
SARIF_SCHEMA = json.loads((DATA / "sarif-schema-2.1.0.json").read_text(encoding="utf-8"))
#: one validator for the module's logs (jsonschema.validate would check the schema itself on every call)
SARIF = jsonschema.validators.validator_for(SARIF_SCHEMA)(SARIF_SCHEMA)

CAMERA = """\
nodl_version: 2
publishers:
  - name: image
    type: sensor_msgs/msg/Image
    qos:
      history: KEEP_LAST
      depth: 1
      reliability: {reliability}
"""
VIEWER = """\
nodl_version: 2
subscriptions:
  - name: /image
    type: {type}
    qos:
      history: KEEP_LAST
      depth: 5
      reliability: RELIABLE
"""


def _write(folder: Path, node: str, text: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{node}.nodl.yaml"
    path.write_text(textwrap.dedent(text), encoding="utf-8")
    return path


def _check(folder: Path, namespaces: dict[str, list[str]] | None = None, external: tuple[str, ...] = ()) -> SetResult:
    docs = read_all(set_files([folder]), Resolver((), shown(folder), [folder]))
    return check_set(docs, namespaces, external)


def _codes(res: SetResult) -> list[str]:
    return [f.code for f in res.findings]


def _line_col(path: Path, text: str) -> tuple[int, int]:
    for i, ln in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        if text in ln:
            return i, ln.index(text) + 1
    raise AssertionError(text)


# ---- nodl#182's cases, each with its control


def test_a_reliable_reader_and_a_best_effort_writer_never_connect_located_at_both_documents(tmp_path: Path) -> None:
    cam = _write(tmp_path, "Camera", CAMERA.format(reliability="BEST_EFFORT"))
    view = _write(tmp_path, "Viewer", VIEWER.format(type="sensor_msgs/msg/Image"))
    [f] = _check(tmp_path).findings
    assert f.code == "nodl-qos" and f.severity == "error" and "/image" in f.message and "BEST_EFFORT" in f.message
    assert [(loc.file, loc.line, loc.col) for loc in f.locs] == [
        ("Viewer.nodl.yaml", *_line_col(view, "RELIABLE")), ("Camera.nodl.yaml", *_line_col(cam, "BEST_EFFORT"))]
    # the control: the writer offers what the reader requests
    _write(tmp_path, "Camera", CAMERA.format(reliability="RELIABLE"))
    assert _check(tmp_path).findings == []


def test_a_transient_local_reader_and_a_deadline_longer_than_requested_never_connect(tmp_path: Path) -> None:
    _write(tmp_path, "Map", CAMERA.format(reliability="RELIABLE").replace("image", "map"))
    reader = VIEWER.format(type="sensor_msgs/msg/Image").replace("/image", "map") + \
        "      durability: TRANSIENT_LOCAL\n      deadline_ns: 100000000\n"
    _write(tmp_path, "Planner", reader)
    found = _check(tmp_path).findings
    assert [f.code for f in found] == ["nodl-qos", "nodl-qos"]
    assert sorted(p for f in found for p in ("deadline_ns", "durability") if f"({p}: offered" in f.message) == [
        "deadline_ns", "durability"]
    # the control: a transient-local writer within the deadline
    _write(tmp_path, "Map", CAMERA.format(reliability="RELIABLE").replace("image", "map")
           + "      durability: TRANSIENT_LOCAL\n      deadline_ns: 50000000\n")
    assert _check(tmp_path).findings == []


def test_a_type_mismatch_between_publisher_and_subscription(tmp_path: Path) -> None:
    _write(tmp_path, "Camera", CAMERA.format(reliability="RELIABLE"))
    view = _write(tmp_path, "Viewer", VIEWER.format(type="sensor_msgs/msg/CompressedImage"))
    [f] = _check(tmp_path).findings
    assert f.code == "nodl-connect-type" and "CompressedImage" in f.message
    assert (f.locs[0].line, f.locs[0].col) == _line_col(view, "sensor_msgs/msg/CompressedImage")
    # the control: the same type, written with its middle part implied
    _write(tmp_path, "Viewer", VIEWER.format(type="sensor_msgs/Image"))
    assert _check(tmp_path).findings == []


def test_a_subscription_nobody_publishes_unless_declared_external_or_published(tmp_path: Path) -> None:
    view = _write(tmp_path, "Viewer", VIEWER.format(type="sensor_msgs/msg/Image"))
    [f] = _check(tmp_path).findings
    assert f.code == "nodl-no-publisher" and f.severity == "error" and f.message.startswith("topic /image:")
    assert [(loc.file, loc.line, loc.col) for loc in f.locs] == [("Viewer.nodl.yaml", *_line_col(view, "/image"))]
    assert _check(tmp_path, external=("/image",)).findings == []  # control 1: declared external
    assert _codes(_check(tmp_path, external=("/other",))) == ["nodl-no-publisher"]  # another name does not excuse it
    _write(tmp_path, "Camera", CAMERA.format(reliability="RELIABLE"))  # control 2: a publisher present
    assert _check(tmp_path).findings == []


def test_a_service_client_and_an_action_client_nobody_serves(tmp_path: Path) -> None:
    arm = _write(tmp_path, "Arm", """\
        nodl_version: 2
        service_clients:
          - name: ~/reset
            type: std_srvs/srv/Trigger
        action_clients:
          - name: /move
            type: control_msgs/action/FollowJointTrajectory
        """)
    res = _check(tmp_path)
    assert _codes(res) == ["nodl-no-server", "nodl-no-server"]
    assert [f.message.split(":")[0] for f in res.findings] == ["service /Arm/reset", "action /move"]
    assert [(f.locs[0].line, f.locs[0].col) for f in res.findings] == [_line_col(arm, "~/reset"), _line_col(arm, "/move")]
    # the control: a node that serves both (the service by its fully qualified name)
    _write(tmp_path, "Driver", """\
        nodl_version: 2
        service_servers:
          - name: /Arm/reset
            type: std_srvs/srv/Trigger
        action_servers:
          - name: move
            type: control_msgs/action/FollowJointTrajectory
        """)
    assert _check(tmp_path).findings == []
    # a server that is a publisher of the name serves nothing: the lists are paired, not the names only
    _write(tmp_path, "Driver", """\
        nodl_version: 2
        publishers:
          - name: /move
            type: std_msgs/msg/String
            qos: {history: KEEP_LAST, depth: 1, reliability: RELIABLE}
        """)
    assert _codes(_check(tmp_path)) == ["nodl-no-server", "nodl-no-server"]


def test_a_service_or_action_typed_differently_or_a_service_qos_that_never_connects(tmp_path: Path) -> None:
    """#182's type and QoS cases for services and actions: a client and a server of one name typed differently
    (nodl-connect-type at both types), a best-effort server answering a reliable client (nodl-qos, the reply's
    direction); the controls: the same types, and the server reliable."""
    arm = _write(tmp_path, "Arm", """\
        nodl_version: 2
        service_clients:
          - name: /reset
            type: std_srvs/srv/Trigger
            qos: {history: KEEP_LAST, depth: 1, reliability: RELIABLE}
        action_clients:
          - name: /move
            type: control_msgs/action/FollowJointTrajectory
        """)
    driver = _write(tmp_path, "Driver", """\
        nodl_version: 2
        service_servers:
          - name: reset
            type: std_srvs/srv/Empty
            qos: {history: KEEP_LAST, depth: 1, reliability: RELIABLE}
        action_servers:
          - name: move
            type: nav2_msgs/action/FollowPath
        """)
    found = _check(tmp_path).findings
    assert _codes(_check(tmp_path)) == ["nodl-connect-type", "nodl-connect-type"]
    assert sorted(f.message.split(":")[0] for f in found) == ["action /move", "service /reset"]
    reset = next(f for f in found if f.message.startswith("service"))
    assert {(loc.file, loc.line, loc.col) for loc in reset.locs} == {
        ("Arm.nodl.yaml", *_line_col(arm, "std_srvs/srv/Trigger")), ("Driver.nodl.yaml", *_line_col(driver, "std_srvs/srv/Empty"))}
    # the control of the types: the server's types made the clients'
    text = driver.read_text(encoding="utf-8").replace("std_srvs/srv/Empty", "std_srvs/srv/Trigger") \
        .replace("nav2_msgs/action/FollowPath", "control_msgs/action/FollowJointTrajectory")
    driver.write_text(text, encoding="utf-8")
    assert _check(tmp_path).findings == []
    # a best-effort server: its replies never reach the reliable client
    driver.write_text(text.replace("reliability: RELIABLE", "reliability: BEST_EFFORT"), encoding="utf-8")
    [f] = _check(tmp_path).findings
    assert f.code == "nodl-qos" and "/reset" in f.message and "BEST_EFFORT" in f.message
    assert {loc.file for loc in f.locs} == {"Arm.nodl.yaml", "Driver.nodl.yaml"}


# ---- names resolved before they are compared


def test_names_are_resolved_in_each_nodes_namespace(tmp_path: Path) -> None:
    _write(tmp_path, "Camera", CAMERA.format(reliability="RELIABLE"))  # relative: <ns>/image
    _write(tmp_path, "Viewer", VIEWER.format(type="sensor_msgs/msg/Image"))  # absolute: /image
    assert _check(tmp_path).findings == []  # both in the root namespace
    res = _check(tmp_path, {"Camera": ["/robot1"]})
    assert _codes(res) == ["nodl-no-publisher"]  # the camera now publishes /robot1/image
    assert _check(tmp_path, {"Camera": ["/robot1"]}, ("/image",)).findings == []


def test_a_document_given_two_namespaces_is_two_nodes(tmp_path: Path) -> None:
    _write(tmp_path, "Camera", CAMERA.format(reliability="RELIABLE"))
    _write(tmp_path, "Viewer", VIEWER.format(type="sensor_msgs/msg/Image").replace("/image", "image"))
    res = _check(tmp_path, {"Viewer": ["/r1", "/r2"]})
    assert sorted(f.message.split(":")[0] for f in res.findings) == ["topic /r1/image", "topic /r2/image"]
    assert all(f.code == "nodl-no-publisher" for f in res.findings)
    assert {f.message.split(": ")[1].split(" subscribes")[0] for f in res.findings} == {"/r1/Viewer", "/r2/Viewer"}
    # the control: the camera in both namespaces too
    assert _check(tmp_path, {"Viewer": ["/r1", "/r2"], "Camera": ["/r1", "/r2"]}).findings == []


@pytest.mark.parametrize(("name", "node", "ns", "full"), [
    ("x", "n", "/", "/x"), ("x", "n", "/a/b", "/a/b/x"), ("/x", "n", "/a", "/x"), ("~", "n", "/a", "/a/n"),
    ("~/x", "n", "/", "/n/x"), ("~/x", "n", "/a", "/a/n/x"), ("{node}/x", "n", "/a", "/a/n/x"),
    ("{ns}/x", "n", "/", "/x"), ("{ns}/x", "n", "/a", "/a/x")])
def test_resolve_follows_ros2_name_expansion(name: str, node: str, ns: str, full: str) -> None:
    assert resolve(name, node, ns) == full


def test_a_document_included_by_another_is_a_part_not_a_node(tmp_path: Path) -> None:
    _write(tmp_path, "common", """\
        nodl_version: 2
        subscriptions:
          - name: /clock
            type: rosgraph_msgs/msg/Clock
            qos: {history: KEEP_LAST, depth: 1, reliability: BEST_EFFORT}
        """)
    _write(tmp_path, "Arm", "nodl_version: 2\ninclude:\n  - ref: local://common.nodl.yaml\n")
    res = _check(tmp_path)
    assert [m.node for m in res.members] == ["Arm"] and [d.file for d in res.parts] == ["common.nodl.yaml"]
    [f] = res.findings  # found once, for the node that includes it, at the included document's line
    assert f.code == "nodl-no-publisher" and "Arm subscribes" in f.message and f.locs[0].file == "common.nodl.yaml"


# ---- the command, in CI form


def _sarif(path: Path) -> dict:
    log = json.loads(path.read_text(encoding="utf-8"))
    SARIF.validate(log)
    return log


def test_nodl_check_on_a_bare_folder_exits_1_with_sarif_at_the_documents_lines(tmp_path: Path, capsys,
                                                                             monkeypatch: pytest.MonkeyPatch) -> None:
    docs = tmp_path / "docs"
    _write(docs, "Camera", CAMERA.format(reliability="BEST_EFFORT"))
    view = _write(docs, "Viewer", VIEWER.format(type="sensor_msgs/msg/Image")
                  + "service_clients:\n  - name: reset\n    type: std_srvs/srv/Trigger\n")
    monkeypatch.chdir(tmp_path)
    assert main(["nodl", "check", "docs", "--sarif", "out.sarif", "--json", "out.json"]) == 1
    err = capsys.readouterr().err
    line, col = _line_col(view, "reset")
    assert f"docs/Viewer.nodl.yaml:{line}:{col}: error: service /reset: Viewer calls it" in err
    log = _sarif(tmp_path / "out.sarif")
    run = log["runs"][0]
    assert log["version"] == "2.1.0" and [r["id"] for r in run["tool"]["driver"]["rules"]] == ["RCL-NODL"]
    by_code = {r["properties"]["code"]: r for r in run["results"]}
    assert sorted(by_code) == ["nodl-no-server", "nodl-qos"] and all(r["level"] == "error" for r in run["results"])
    region = by_code["nodl-no-server"]["locations"][0]["physicalLocation"]
    assert region["artifactLocation"]["uri"] == "docs/Viewer.nodl.yaml"
    assert (region["region"]["startLine"], region["region"]["startColumn"]) == (line, col)
    related = by_code["nodl-qos"]["relatedLocations"][0]["physicalLocation"]["artifactLocation"]["uri"]
    assert related == "docs/Camera.nodl.yaml"  # the writer's document, the other place of the finding
    assert [(n["node"], n["namespace"]) for n in json.loads((tmp_path / "out.json").read_text())["nodes"]] == [
        ("Camera", "/"), ("Viewer", "/")]
    # the control: the same folder made compatible, the service declared external: exit 0, an empty SARIF run
    _write(docs, "Camera", CAMERA.format(reliability="RELIABLE"))
    assert main(["nodl", "check", "docs", "--external", "/reset", "--sarif", "out.sarif"]) == 0
    assert _sarif(tmp_path / "out.sarif")["runs"][0]["results"] == []


def test_nodl_check_set_usage_and_document_errors_are_one_clear_line(tmp_path: Path, capsys,
                                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    _write(tmp_path / "docs", "Camera", CAMERA.format(reliability="RELIABLE"))
    assert main(["nodl", "check", "docs", "-w", "."]) == 2
    assert main(["nodl", "check", "docs", "--namespace", "Nobody=/a"]) == 2
    assert main(["nodl", "check", "docs", "--namespace", "Camera=/a b"]) == 2
    assert main(["nodl", "check", "missing"]) == 2
    assert main(["nodl", "check", "--external", "/x"]) == 2  # --external belongs to a set
    err = capsys.readouterr().err
    assert "no document of the set is named after node 'Nobody'" in err and "missing: no such file" in err
    assert "Traceback" not in err
    _write(tmp_path / "docs", "Viewer", "nodl_version: 2\nsubscriptions:\n  - name: /image\n    type: 7\n")
    assert main(["nodl", "check", "docs"]) == 1
    assert "docs/Viewer.nodl.yaml:4:11: error: NoDL v2 schema" in capsys.readouterr().err
    assert main(["nodl", "check", "docs/Camera.nodl.yaml"]) == 0  # a file named alone: the control


# ---- with a workspace: documents without a contract are checked against each other


def test_a_workspaces_documents_without_a_contract_are_checked_against_each_other(tmp_path: Path) -> None:
    ws = tmp_path / "ws"
    shutil.copytree(DATA / "nodl" / "ws", ws)
    _write(ws / "nodl", "Camera", CAMERA.format(reliability="BEST_EFFORT"))
    _write(ws / "nodl", "Viewer", VIEWER.format(type="sensor_msgs/msg/Image"))
    checked = Workspace(ws, "contracts/plan.yaml").checked  # the contracts: the documents are read by check
    found = check(checked, ws).findings
    assert sorted((f.code, f.severity) for f in found) == [
        ("nodl-node", "warning"), ("nodl-node", "warning"), ("nodl-qos", "error")]
    _write(ws / "nodl", "Camera", CAMERA.format(reliability="RELIABLE"))  # the control: only the two warnings
    found = check(checked, ws).findings
    assert sorted(f.code for f in found) == ["nodl-node", "nodl-node"]
    # the workspace's check writes SARIF too, its file names relative to the workspace
    assert main(["nodl", "check", "-w", str(ws), "--sarif", str(tmp_path / "ws.sarif")]) == 0
    results = _sarif(tmp_path / "ws.sarif")["runs"][0]["results"]
    assert sorted((r["level"], r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"]) for r in results) == [
        ("warning", "nodl/Camera.nodl.yaml"), ("warning", "nodl/Viewer.nodl.yaml")]


def test_an_include_leading_outside_the_folders_named_is_a_located_error(tmp_path: Path, capsys,
                                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    _write(tmp_path / "elsewhere", "common", CAMERA.format(reliability="RELIABLE"))
    _write(tmp_path / "docs", "Arm", "nodl_version: 2\ninclude:\n  - ref: local://../elsewhere/common.nodl.yaml\n")
    assert main(["nodl", "check", "docs"]) == 1
    assert "docs/Arm.nodl.yaml:3:10: error: include 'local://../elsewhere/common.nodl.yaml': resolves to" in \
        capsys.readouterr().err
    assert main(["nodl", "check", "docs", "elsewhere"]) == 0  # the control: the folder named too
