"""NoDL documents against the endpoints the code creates (the ROS scan; docs/nodl.md, "Against the code"): the
packages `generate ros2` makes from tests/data/nodl/ws, scanned, against their own documents (the control) and
against the workspace's hand-written ones and seeded edits."""
from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from rclverify.cli.commands import main
from rclverify.model.nodl.document import read_document
from rclverify.ros.graph.scan import scan
from rclverify.ros.ground.nodl_code import check_code, resolve

WS = Path(__file__).parent.parent / "data" / "nodl" / "ws"


@pytest.fixture(scope="module")
def tree(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    root = tmp_path_factory.mktemp("nodl_code")
    ws = root / "ws"
    shutil.copytree(WS, ws)
    assert main(["generate", "ros2", "-w", str(ws), "-o", str(ws / "gen"), "--system", "robot"]) == 0
    return ws, scan([ws / "gen"], base=ws).graph.nodes


def _generated_docs(ws: Path, tmp: Path) -> dict:
    out = {}
    for pkg in ("guard", "base", "dock"):
        path = tmp / f"{pkg}.nodl.yaml"
        shutil.copy(ws / "gen" / pkg / "nodl" / f"{pkg}.nodl.yaml", path)
        out[pkg] = read_document(path, path.name)
    return out


def test_generated_documents_match_the_scanned_generated_code(tree, tmp_path: Path) -> None:
    ws, nodes = tree
    matched, found = check_code(_generated_docs(ws, tmp_path), nodes, ws)
    assert matched == {"base": "/Base", "dock": "/Dock", "guard": "/Guard"}
    assert found == []


def test_a_seeded_type_and_an_endpoint_the_code_lacks_are_found(tree, tmp_path: Path) -> None:
    ws, nodes = tree
    doc = tmp_path / "guard.nodl.yaml"
    shutil.copy(ws / "gen" / "guard" / "nodl" / "guard.nodl.yaml", doc)
    doc.write_text(doc.read_text().replace("sensor_msgs/msg/LaserScan", "sensor_msgs/msg/PointCloud2")
                   + "service_clients:\n- name: /reset\n  type: std_srvs/srv/Empty\n")
    _, found = check_code({"guard": read_document(doc, doc.name)}, nodes, ws)
    assert sorted((f.code, f.severity) for f in found) == [("nodl-code-absent", "warning"), ("nodl-code-type", "error")]
    t = next(f for f in found if f.code == "nodl-code-type")
    assert (t.locs[0].file, t.locs[1].file) == ("gen/guard/guard/node.py", "guard.nodl.yaml")
    assert "/scan has type sensor_msgs/msg/LaserScan in the scanned code and sensor_msgs/msg/PointCloud2" in t.message


def test_the_hand_written_documents_against_the_generated_code(tree, capsys) -> None:
    """The workspace's documents ask for QoS the generated nodes do not give, and lack their verdict topics."""
    ws, _ = tree
    assert main(["nodl", "check", "-w", str(ws), "--ros", str(ws / "gen")]) == 1
    captured = capsys.readouterr()
    assert "3 document(s) matched to a node of the scanned code" in captured.out
    codes = sorted({ln.rsplit("[", 1)[1] for ln in captured.err.splitlines()})
    assert codes == ["nodl-code-qos]", "nodl-code-undeclared]"]
    assert "/scan's reliability is RELIABLE in the code (QOS_DEPTH) and BEST_EFFORT in its NoDL document" in captured.err
    assert "node /Dock has /Dock/contract_verdict (std_msgs/msg/String) in publishers in the scanned code" in captured.err


def test_names_resolve_in_the_scanned_nodes_namespace() -> None:
    assert resolve("x", "/ns/n", "/ns") == "/ns/x" and resolve("x", "/n", "/") == "/x"
    assert resolve("~/x", "/ns/n", "/ns") == "/ns/n/x" and resolve("/a/b", "/ns/n", "/ns") == "/a/b"
