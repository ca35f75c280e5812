"""A recorded bag carries the live run's end (traces/bag_end.py, docs/ros2.md "The run's end in the bag"), so a
deadline the live clock passed unanswered is ``false`` on the bag as on the log (issue 106, fault 9).

Seed 545 of the robot generator (tests/data/robot_seed545; docs/monitors.md "Generated robots", fault 9):
its bag ends with its last message, 0.4 s before a deadline of the defective Relay6 that the live clock
passed (its log goes on to 1795881804.826 s).  Its messages are recorded again here through the live
monitor's recorder (:class:`~rclverify.runtime.dds.bag.BagRecorder`, both storages, each message at its
time, the late ones said late), once told the run's end (the time the log's last line carries, where
the live clock had gone) and once not: with the end, the bag's verdicts equal the log's, verdict by
verdict; without it (the control; the reader's path is one for both storages), the bag differs from the log on that one deadline, ``currently_false``.

Seed 545 run live again with the new recorder (tests/data/robot_seed545_end: the same 8-node robot and
contracts, ``bench/robot_generator.py --seeds 545 --nodes 8 --defect --actions``, DDS source, wall clock;
its log, its MCAP bag and the live run's ``--verdicts``): its bag ends 2 s after its last message, and
the defective relay's last ``false`` deadline, due after the clock of every recorded message, is decided
on the bag by that end, as live and on the log: live = log = bag verdict by verdict.  (The same seed
judged by the sources before the change: live != bag on that one deadline, 2 runs of 2; after: 0
disagreements, 3 runs of 3, docs/monitors.md fault 9.)
"""
from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path
from typing import Any

import pytest
import yaml

from rclverify.backends.monitors.config import load_mapping
from rclverify.backends.monitors.recorded import check_recorded
from rclverify.backends.monitors.verdict_lines import verdict_record
from rclverify.lang.typecheck import load
from rclverify.runtime.dds.bag import BagRecorder
from rclverify.traces import bag_end, read_trace
from rclverify.traces.bag import typestore
from rclverify.traces.bag_late import KEY as LATE_KEY

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
from _robot_verdicts import compare, finals, read_records  # noqa: E402

SEED_545 = Path(__file__).resolve().parents[1] / "data" / "robot_seed545"
#: seed 545 recorded live again by the recorder that writes the run's end
SEED_545_END = Path(__file__).resolve().parents[1] / "data" / "robot_seed545_end"


def _offline(ws: Path, trace: str) -> list[dict[str, Any]]:
    """The recorded path's verdicts of ``trace`` in workspace ``ws``, as ``--verdicts`` writes them."""
    checked = load([ws / "contracts" / "robot.rcl"])
    cfg = load_mapping(ws, "mapping.yaml", 1.0)
    got: list[dict[str, Any]] = []
    check_recorded(checked, list(checked.nodes.values()), cfg, ws, str(ws / trace), lambda w: None,
                   on_verdict=lambda kind, v, stamp: got.append(verdict_record(kind, v, stamp)))
    return got


def _log_end(log: Path) -> float:
    """The latest time a line of the live log carries: where the live run's clock had gone."""
    return max(float(json.loads(line)["time"]) for line in log.read_text(encoding="utf-8").splitlines() if line)


def _recorded_again(ws: Path, storage: str, end: float | None) -> str:
    """The stored bag's messages written through the recorder to ``runs/again`` (its path relative to ``ws``)."""
    from rosbags.highlevel import AnyReader
    stored = ws / "runs" / "bag"
    with AnyReader([stored], default_typestore=typestore([ws / "interfaces"])) as reader:
        conns = {c.topic.strip("/"): c for c in reader.connections}
        items = [(c.topic.strip("/"), t, raw) for c, t, raw in reader.messages()]
    calls = {t: (c.msgtype, c.msgdef.data, c.digest) for t, c in conns.items()
             if t.endswith("_service_event") or t.startswith("rclverify/")}
    topics = {t: c.msgtype for t, c in conns.items() if t not in calls}
    meta = yaml.safe_load((stored / "metadata.yaml").read_text(encoding="utf-8"))
    late = json.loads(meta["rosbag2_bagfile_information"]["custom_data"][LATE_KEY])
    rec = BagRecorder(ws / "runs" / "again", storage, topics, [ws / "interfaces"], calls=calls)
    for topic, xs in late.items():
        for ns, late_s in xs:
            rec.late(topic.strip("/"), ns / 1e9, late_s)
    for topic, t, raw in items:
        rec.write(topic, t, raw)
    if end is not None:
        rec.end(end)
    out = rec.close()
    assert "failed" not in out, out
    return "runs/again"


@pytest.fixture(scope="module")
def log() -> dict[Any, Any]:
    """The final verdicts of seed 545's live log."""
    return finals(_offline(SEED_545, "runs/live.jsonl"))


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_a_bag_ending_where_the_live_clock_did_gives_the_logs_deadline_verdicts(
        tmp_path: Path, storage: str, log: dict[Any, Any]) -> None:
    ws = tmp_path / "ws"
    shutil.copytree(SEED_545, ws)
    end = _log_end(ws / "runs" / "live.jsonl")
    again = _recorded_again(ws, storage, end)
    events = list(read_trace(ws / again, [ws / "interfaces"]))
    last = max(events, key=lambda ev: ev.time)  # the run's end, the bag's latest message, in a standard type
    assert (last.topic, last.fields) == (bag_end.TOPIC, dict(zip(("sec", "nanosec"), bag_end.split_ns(
        round(end * 1e9)))))
    assert [d.text(("log", "bag")) for d in compare(log, finals(_offline(ws, again)))] == []


def test_control_the_same_bag_without_the_end_leaves_the_deadline_currently_false(
        tmp_path: Path, log: dict[Any, Any]) -> None:
    ws = tmp_path / "ws"
    shutil.copytree(SEED_545, ws)
    again = _recorded_again(ws, "mcap", None)
    assert bag_end.TOPIC not in {ev.topic for ev in read_trace(ws / again, [ws / "interfaces"])}
    found = compare(log, finals(_offline(ws, again)))
    assert [(d.node, d.item, d.a and d.a["verdict"], d.b and d.b["verdict"]) for d in found] == [
        ("Relay6", "deadline", "false", "currently_false")], [d.text(("log", "bag")) for d in found]


def test_seed_545_recorded_live_with_its_end_gives_live_equal_log_equal_bag_verdict_by_verdict() -> None:
    ws = SEED_545_END
    events = list(read_trace(ws / "runs" / "bag", [ws / "interfaces"]))
    ends = [ev for ev in events if ev.topic == bag_end.TOPIC]
    assert len(ends) == 1 and ends[0].time == max(ev.time for ev in events)
    bag_records = _offline(ws, "runs/bag")
    # the case of fault 9 is there: a false deadline decided only by the run's end (the bag's clock at it)
    clock = f"(clock at {ends[0].time:.3f} s)"
    decided_at_end = [r for r in bag_records if r["item"] == "deadline" and r["verdict"] == "false"
                      and clock in r["reason"]]
    assert [r["node"] for r in decided_at_end] == ["Relay6"], decided_at_end
    live, log, bag = (finals(read_records(ws / "runs" / "live.verdicts.jsonl")),
                      finals(_offline(ws, "runs/live.jsonl")), finals(bag_records))
    assert [d.text(("log", "bag")) for d in compare(log, bag)] == []
    assert [d.text(("live", "bag")) for d in compare(live, bag)] == []
