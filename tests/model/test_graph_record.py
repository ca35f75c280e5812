"""Recorded ROS 2 graphs read with no ROS 2 running (docs/nodl.md, "A recorded graph";
src/rclverify/model/nodl/graph_record.py, the readers in cli/nodl.py and cli/ros.py).

tests/data/nodl/recorded holds two recordings tests/model/test_nodl_live.py made of its real rclpy nodes on
Fast DDS (``Guard`` as its document says, ``Base`` with four seeded mismatches, ``Dock`` not running), one
through each source: ``graph_rclpy.json`` (``nodl check --ros2 --source rclpy --record-graph``) and
``graph_dds.json`` (``--source dds``: rclverify's own DDS participant).  They are read here by ``nodl check
--graph`` and ``ros diff --graph`` against tests/data/nodl/ws: the findings the live run gave, the same from
either recording, nothing at ``Guard`` (the control) until a difference is seeded into a recording; usage
errors and recordings that are not ones refused in one line."""
from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest

from rclverify.cli.commands import main

DATA = Path(__file__).parent.parent / "data" / "nodl"
RECORDED = {"rclpy": DATA / "recorded" / "graph_rclpy.json", "dds": DATA / "recorded" / "graph_dds.json"}
#: the first place and code of each finding the live run gave (tests/model/test_nodl_live.py)
FOUND = [("nodl/Base.nodl.json:1:1", "nodl-live-undeclared]"), ("nodl/Base.nodl.json:10:32", "nodl-live-type]"),
         ("nodl/Base.nodl.json:14:14", "nodl-live-absent]"), ("nodl/Base.nodl.json:6:91", "nodl-live-qos]"),
         ("nodl/Dock.nodl.yaml:1:1", "nodl-live-unmatched]")]


@pytest.fixture()
def ws(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    root = tmp_path / "ws"
    shutil.copytree(DATA / "ws", root)
    monkeypatch.chdir(root)
    return root


def _document_lines(err: str) -> list[str]:
    return [ln for ln in err.splitlines() if ln.startswith("nodl/")]


def _items(out: str) -> list[str]:
    return [ln.strip() for ln in out.splitlines() if ln.startswith("  ")]


def _seeded(tmp_path: Path, source: str, **change: Any) -> Path:
    """The recording of ``source`` with Guard's /stop publisher changed by ``change``."""
    data = json.loads(RECORDED[source].read_text(encoding="utf-8"))
    [pub] = [e for e in data["endpoints"]["/stop"]["pubs"] if e["node"] == "Guard"]
    pub.update(change)
    out = tmp_path / f"seeded_{source}.json"
    out.write_text(json.dumps(data, indent=1), encoding="utf-8")
    return out


@pytest.mark.parametrize("source", RECORDED)
def test_nodl_check_reads_each_sources_recording_as_the_live_run_read_it(
        ws: Path, source: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["nodl", "check", "--graph", str(RECORDED[source])]) == 1
    got = capsys.readouterr()
    label = "rclpy on rmw_fastrtps_cpp" if source == "rclpy" else "DDS domain "
    assert f"2 document(s) matched to a running node ({label}" in got.out and "Traceback" not in got.err
    lines = _document_lines(got.err)
    assert sorted((ln.split(": ", 1)[0], ln.rsplit("[", 1)[1]) for ln in lines) == sorted(FOUND)
    assert not [ln for ln in lines if "/Guard" in ln]  # Guard runs as its document says: the control


def test_a_difference_seeded_into_a_recording_is_found_by_both_commands(
        ws: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    seeded = _seeded(tmp_path, "dds", reliable=False)
    assert main(["nodl", "check", "--graph", str(seeded)]) == 1
    guard = [ln for ln in _document_lines(capsys.readouterr().err) if "node /Guard" in ln]
    assert guard and all("/stop's reliability is BEST_EFFORT" in ln and "[nodl-live-qos]" in ln for ln in guard)
    assert main(["ros", "diff", "--nodl", "nodl", "--graph", str(RECORDED["dds"])]) == 1
    made = _items(capsys.readouterr().out)
    assert len(made) == 5 and not [i for i in made if "/Guard" in i]  # the recording as made: the control
    assert main(["ros", "diff", "--nodl", "nodl", "--graph", str(seeded)]) == 1
    got = _items(capsys.readouterr().out)
    new = [i for i in got if i not in made]  # Guard at its document's line, and the connection DDS does not make
    assert len(new) == 2 and all(i in got for i in made), new
    assert new[1].startswith("nodl/Guard.nodl.yaml:10:") and "/stop's reliability is BEST_EFFORT" in new[1]
    assert "/stop (std_msgs/Bool): node /Base subscribes with reliable" in new[0], new[0]
    assert "node /Guard publishes with best_effort" in new[0] and "DDS does not connect them (reliability" in new[0]


def test_ros_diff_gives_the_same_items_from_either_sources_recording(
        ws: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The two recordings of one system differ in the source's label only: ros diff's items, with the label
    taken out, are the same."""
    got = {}
    for source, path in RECORDED.items():
        assert main(["ros", "diff", "--nodl", "nodl", "--graph", str(path)]) == 1
        out = capsys.readouterr()
        assert "source: recorded (the graph recorded in " in out.err
        label = json.loads(path.read_text(encoding="utf-8")).get("source") or "rclpy on rmw_fastrtps_cpp"
        got[source] = [i.replace(label, "SOURCE") for i in _items(out.out)]
    assert got["rclpy"] == got["dds"] and any(i.startswith("SOURCE: /Base publishes /odom") for i in got["dds"])


def test_usage_errors_and_recordings_that_are_not_ones(ws: Path, tmp_path: Path,
                                                       capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["ros", "diff", "--nodl", "nodl", "--graph", str(RECORDED["dds"]), "--bag", "x.bag"]) == 2
    assert "exactly one running side" in capsys.readouterr().err
    assert main(["ros", "diff", "--nodl", "nodl", "--graph", str(RECORDED["dds"]),
                 "--record-graph", str(tmp_path / "again.json")]) == 2
    assert "--record-graph FILE writes the graph --ros2 reads" in capsys.readouterr().err
    assert not (tmp_path / "again.json").exists()
    assert main(["ros", "diff", "--nodl", "nodl", "--graph", str(tmp_path / "none.json")]) == 1
    err = capsys.readouterr().err
    assert f"{tmp_path / 'none.json'}:1:1: error: cannot read the recorded graph" in err and "Traceback" not in err
    bad = _seeded(tmp_path, "rclpy", durability="sometimes")
    assert main(["ros", "diff", "--nodl", "nodl", "--graph", str(bad)]) == 1
    err = capsys.readouterr().err
    assert f"{bad}:" in err and "durability: is volatile or transient_local" in err
    data = json.loads(RECORDED["dds"].read_text(encoding="utf-8"))
    data["source"] = 40
    (tmp_path / "source.json").write_text(json.dumps(data, indent=1), encoding="utf-8")
    assert main(["nodl", "check", "--graph", str(tmp_path / "source.json")]) == 1
    err = capsys.readouterr().err
    line = next(i for i, ln in enumerate((tmp_path / "source.json").read_text().splitlines(), 1) if '"source"' in ln)
    assert f"{tmp_path / 'source.json'}:{line}:" in err and "source: is a text" in err
