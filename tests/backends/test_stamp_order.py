"""One clock per recorded run (backends/monitors/stamp_order.py): a run whose
messages were recorded out of their header-stamp order is judged by every
engine in stamp order, offline (`rclverify monitor TRACE`) and in the
pipeline, from a log or a ROS 2 bag; a stream that cannot be read again gives
no green.  The oracle: the same run written in stamp order gives the same
verdicts."""
from __future__ import annotations

import json
import os
import random
import shutil
import threading
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors import recorded
from rclverify.backends.monitors.config import load_mapping
from rclverify.backends.monitors.deadline_text import deadline_status
from rclverify.backends.monitors.stamp_order import StampWatch, in_stamp_order
from rclverify.cli.commands import main
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.traces.events import Event

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "safety_stop"

#: A question recorded late but stamped early: the request stamped 1.2 s arrives after the response
#: stamped 1.5 s.  On the stamps' clock the request's 200 ms deadline passes at 1.4 s unanswered.
LATE_QUESTION = [("estop/request", 1.5, 1.4, {"data": False}), ("estop/response", 1.6, 1.5, {"success": False}),
                 ("estop/request", 1.7, 1.2, {"data": True})]
#: The control: every answer on time by the stamps, recorded out of order.
ON_TIME = [("estop/request", 1.5, 1.4, {"data": True}), ("estop/response", 1.55, 1.3, {"success": True}),
           ("estop/request", 1.6, 1.2, {"data": True}), ("estop/response", 1.62, 1.5, {"success": True})]


def _line(topic: str, rec: float, stamp: float, fields: dict[str, Any]) -> str:
    secs = int(stamp)
    return json.dumps({"topic": topic, "time": rec, "header": {"stamp": {"secs": secs, "nsecs": round(
        (stamp - secs) * 1e9)}}, **fields})


def _write(path: Path, rows: list[tuple[str, float, float, dict[str, Any]]]) -> Path:
    path.write_text("".join(_line(*r) + "\n" for r in rows))
    return path


@pytest.fixture(scope="module")
def checked() -> Any:
    return check([parse_text((EXAMPLE / "contracts" / "safety_stop.rcl").read_text(), "s.rcl")])


def _statuses(checked: Any, trace: Path) -> list[str]:
    cfg = load_mapping(EXAMPLE, None)
    run = recorded.check_recorded(checked, [checked.nodes["Base"]], cfg, EXAMPLE, str(trace), lambda w: None)
    return [run.verdict(r, str(trace))[0] for r in run.results] + [deadline_status(d, str(trace))[0]
                                                                    for d in run.deadlines]


def test_a_question_recorded_late_but_stamped_early_misses_its_deadline(tmp_path: Path,
                                                                         capsys: pytest.CaptureFixture[str]) -> None:
    trace = _write(tmp_path / "late.jsonl", LATE_QUESTION)
    assert main(["monitor", "-w", str(EXAMPLE), "--node", "Base", str(trace)]) == 1
    out = capsys.readouterr().out
    assert "missed Base's deadline" in out and "judged in stamp order: 1 message(s)" in out
    # the oracle: the same run recorded in stamp order
    ordered = _write(tmp_path / "ordered.jsonl", sorted(LATE_QUESTION, key=lambda r: r[2]))
    assert main(["monitor", "-w", str(EXAMPLE), "--node", "Base", str(ordered)]) == 1


def test_the_control_on_time_by_the_stamps_stays_green(tmp_path: Path, checked: Any) -> None:
    trace = _write(tmp_path / "on_time.jsonl", ON_TIME)
    assert _statuses(checked, trace) == ["discharged", "discharged"]
    assert main(["monitor", "-w", str(EXAMPLE), "--node", "Base", str(trace)]) == 0


def test_the_pipeline_judges_the_same_run_on_the_same_clock(tmp_path: Path) -> None:
    from rclverify.app.pipeline import Workspace
    from rclverify.backends.monitors.backend import MonitorsBackend
    ws = tmp_path / "ws"
    shutil.copytree(EXAMPLE, ws, ignore=shutil.ignore_patterns("artifacts", "reports"))
    _write(ws / "traces" / "nominal.jsonl", LATE_QUESTION)
    w = Workspace(ws)
    index = [i for i, e in enumerate(w.plan.evidence["Base"]) if e.config.get("backend") == "monitors"][0]
    target = w.target("Base", index)
    (ob,) = [o for o in MonitorsBackend().export(target) if o.data.get("trace") == "traces/nominal.jsonl"]
    ev = MonitorsBackend().run(ob, target)
    assert ev.status == "failed" and "judged in stamp order" in ev.explanation
    _write(ws / "traces" / "nominal.jsonl", ON_TIME)
    assert MonitorsBackend().run(ob, target).status == "discharged"


def test_a_ros2_bag_recorded_out_of_stamp_order(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from rosbags.rosbag2 import Writer

    from rclverify.traces.bag import typestore
    ws = tmp_path / "ws"
    shutil.copytree(EXAMPLE, ws, ignore=shutil.ignore_patterns("artifacts", "reports"))
    msgs = ws / "interfaces" / "rcltest" / "msg"
    msgs.mkdir(parents=True)
    (msgs / "StampedData.msg").write_text("std_msgs/Header header\nbool data\n")
    (msgs / "StampedSuccess.msg").write_text("std_msgs/Header header\nbool success\n")
    store = typestore([ws / "interfaces"])
    header, time = store.types["std_msgs/msg/Header"], store.types["builtin_interfaces/msg/Time"]
    with Writer(ws / "traces" / "bag", version=9) as w:
        conns: dict[str, Any] = {}
        for topic, rec, stamp, fields in LATE_QUESTION:
            name = "rcltest/msg/" + ("StampedData" if "data" in fields else "StampedSuccess")
            conn = conns.get(topic) or conns.setdefault(topic, w.add_connection("/" + topic, name, typestore=store))
            msg = store.types[name](header=header(stamp=time(sec=int(stamp), nanosec=round((stamp % 1) * 1e9)),
                                                  frame_id=""), **fields)
            w.write(conn, round(rec * 1e9), store.serialize_cdr(msg, name))
    assert main(["monitor", "-w", str(ws), "--node", "Base", str(ws / "traces" / "bag")]) == 1
    assert "missed Base's deadline" in capsys.readouterr().out


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this platform")
def test_a_stream_that_cannot_be_read_again_gives_no_green(tmp_path: Path, checked: Any) -> None:
    fifo = tmp_path / "run.jsonl"
    os.mkfifo(fifo)
    text = "".join(_line(*r) + "\n" for r in ON_TIME)

    def feed() -> None:
        with open(fifo, "w") as fh:
            fh.write(text)
    writer = threading.Thread(target=feed)
    writer.start()
    try:
        statuses = _statuses(checked, fifo)
    finally:
        writer.join(timeout=10)
    assert statuses[0] == "inconclusive", statuses


def test_the_reorder_buffer_releases_in_stamp_order() -> None:
    rng = random.Random(7)
    for _ in range(200):
        stamps = sorted(rng.uniform(0, 5) for _ in range(rng.randint(0, 30)))
        recs = [s + rng.choice([0.0, 0.0, 0.01, 0.3, 1.2]) for s in stamps]
        order = sorted(range(len(stamps)), key=lambda i: (recs[i], i))
        events = [Event(k, recs[i], "t", {"header": {"stamp": {"secs": int(stamps[i]),
                                                               "nsecs": round((stamps[i] % 1) * 1e9)}}}, f"r:{k}")
                  for k, i in enumerate(order)]
        watch = StampWatch(0.0)
        for e in events:
            watch.see(e)
        got = [e.time for e in in_stamp_order(events, watch.lag)]
        assert got == sorted(got) and len(got) == len(events)


def test_oracle_any_recording_order_gives_the_stamp_order_verdicts(tmp_path: Path, checked: Any) -> None:
    """Random runs of Base's service recorded with random delays: the verdicts of the run as recorded
    equal those of the same messages written in stamp order (each message's time its stamp), except
    that a response recorded more than 20 ms after its stamp with a request stamped in between may
    answer that request (its stamp may be a stale copy: docs/semantics.md, "Event time"), so its
    verdicts there may be inconclusive, never the other colour."""
    rng = random.Random(11)
    for case in range(60):
        rows = []
        t = 1.0
        for _ in range(rng.randint(2, 6)):
            t += rng.choice([0.05, 0.1, 0.2, 0.3])
            topic = rng.choice(["estop/request", "estop/response"])
            fields = {"data": rng.random() < 0.5} if topic.endswith("request") else {"success": rng.random() < 0.5}
            rows.append((topic, round(t + rng.choice([0, 0, 0, 0.1, 0.3, 0.5]), 3), round(t, 3), fields))
        recorded_order = _write(tmp_path / f"rec{case}.jsonl", sorted(rows, key=lambda r: r[1]))
        stamp_order = _write(tmp_path / f"st{case}.jsonl", [(tp, st, st, f) for tp, _, st, f in
                                                            sorted(rows, key=lambda r: r[2])])
        got, oracle = _statuses(checked, recorded_order), _statuses(checked, stamp_order)
        stale = any(tp.endswith("response") and rec - st > 0.02 and
                    any(t2.endswith("request") and st < s2 <= rec for t2, _, s2, _ in rows)
                    for tp, rec, st, _ in rows)
        assert got == oracle or (stale and all(a in (b, "inconclusive") for a, b in zip(got, oracle))), \
            recorded_order.read_text()
