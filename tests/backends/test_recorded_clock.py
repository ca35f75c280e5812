"""``rclverify monitor RUN`` hands a run's ``/clock`` messages to the deadline monitor, in the run's order.

The deadline monitor of a node under ``use_sim_time`` reads the run's
``/clock`` (rosgraph_msgs/Clock) to judge its deadlines in simulated time
(traces/sim_clock.py).  Offline (:func:`rclverify.backends.monitors.recorded.check_recorded`),
every reading of a run gives it each ``/clock`` message as an event (topic
``clock``, ``fields["clock"]`` its simulated time) at the time the reader
gives an unstamped message, interleaved by time with the contract's topics:
a live log (nested ``clock``), a ROSMonitoring log (flattened ``clock.sec``),
a ROS 2 bag (sqlite3, MCAP) and a ROS 1 bag, event by event or in a log's
blocks (the batch deadline judge's columns), and read again in stamp order
(a run recorded out of it): each clock line placed at its time.

The probe is what the monitor the recorded run builds is handed (its
``feed`` and ``feed_block``, wrapped around the real ones): no monitor is
replaced.  Controls: the same run without ``/clock`` gives the same verdicts
on the contract's topics (the untimed check's, and the deadlines' for a node
that keeps the run's clock, ``use_sim_time: false``), no warning and no item
"not judged", and its monitor is handed no clock event.
"""
from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors import batch_deadlines, recorded
from rclverify.backends.monitors.batch_deadlines import deadline_monitor
from rclverify.backends.monitors.config import load_mapping
from rclverify.lang.typecheck import load
from rclverify.traces import jsonl_blocks
from rclverify.traces.sim_clock import clock_value_ns, is_clock_topic

from test_clock_read import FORMS, RUN, _sim_ns, write_run  # the run's writer (tests/traces)

RELAY = """
node Relay {
  inputs( x : REAL )
  outputs( y : REAL )
  topics( std_msgs/Float64 x matches(in.x), std_msgs/Float64 y matches(out.y) )
  guarantee( out.y > in.x ) triggered by in.x within 100 ms
}
"""


def _workspace(tmp: Path, sim: str) -> Path:
    (tmp / "contracts").mkdir(parents=True)
    (tmp / "contracts" / "c.rcl").write_text(RELAY)
    (tmp / "mapping.yaml").write_text("topics:\n  x: {fields: [data]}\n  y: {fields: [data]}\n" + sim)
    return tmp


class Probe:
    """What each deadline monitor :func:`recorded.check_recorded` builds is handed, one list per monitor
    (one per read of the run): ``(topic, time, the simulated time in ns of a clock event else its data)``,
    an event's or a block row's (a block's row read from its ``topics`` and ``times`` columns)."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch) -> None:
        self.reads: list[list[tuple[str, float, Any]]] = []
        self.blocks = 0
        make = deadline_monitor

        def spied(*args: Any, **kwargs: Any) -> Any:
            m: Any = make(*args, **kwargs)
            seen: list[tuple[str, float, Any]] = []
            self.reads.append(seen)
            feed = m.feed

            def feed_spy(ev: Any) -> None:
                seen.append(_row(ev.topic, ev.time, ev))
                feed(ev)
            m.feed = feed_spy
            block_feed = getattr(m, "feed_block", None)
            if block_feed is not None:
                def block_spy(block: Any) -> None:
                    self.blocks += 1
                    seen.extend(_row(t, when, block[i]) for i, (t, when) in enumerate(zip(block.topics,
                                                                                           block.times.tolist())))
                    block_feed(block)
                m.feed_block = block_spy
            return m
        monkeypatch.setattr(batch_deadlines, "deadline_monitor", spied)  # what check_recorded calls (imported there when used)

    @property
    def last(self) -> list[tuple[str, float, Any]]:
        """What the monitor of the read the verdicts are of (the last) was handed."""
        return self.reads[-1]


def _row(topic: str, time: float, ev: Any) -> tuple[str, float, Any]:
    return topic, time, clock_value_ns(ev.fields) if is_clock_topic(topic) else ev.fields.get("data")


def _want(clock: bool = True) -> list[tuple[str, Any, Any]]:
    return [(topic, pytest.approx(t / 1e9, abs=1e-6), _sim_ns(v) if topic == "clock" else v)
            for t, topic, v in RUN if clock or topic != "clock"]


def _check(ws: Path, run: Path, verdicts: bool = True) -> dict[str, Any]:
    """What ``rclverify monitor RUN`` says of ``run``: the verdicts on the contract's topics, the
    deadlines (and, with ``verdicts``, each trigger's final verdict: the run is then streamed, where
    without them a log is read in blocks), the items not judged, the warnings, how it was ordered."""
    checked = load([ws / "contracts" / "c.rcl"])
    warnings: list[str] = []
    finals: dict[float, str] = {}

    def verdict(kind: str, v: Any, _: float | None) -> None:
        if kind == "deadline":
            finals[v.trigger_stamp] = v.verdict
    got = recorded.check_recorded(checked, [checked.nodes["Relay"]], load_mapping(ws, "mapping.yaml"), ws,
                                  str(run), warnings.append, on_verdict=verdict if verdicts else None)
    where = re.compile(re.escape(run.name) + r"(:\d+|: message \d+)")
    return {"results": [dict(r.counts) for r in got.results],
            "deadlines": [dict(d.counts) for d in got.deadlines], "finals": finals,
            "not_judged": got.not_judged, "warnings": warnings,
            "order": (where.sub("RUN", got.stamp_order), got.stale)}


@pytest.mark.parametrize("form", FORMS)
def test_the_clock_is_handed_to_the_deadline_monitor_in_the_run_s_order_and_changes_no_verdict(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, form: str) -> None:
    ws = _workspace(tmp_path / "ws", "use_sim_time: false\n")
    probe = Probe(monkeypatch)
    monkeypatch.setattr(jsonl_blocks, "BLOCK_BYTES", 256)  # a log read a few lines at a time: several blocks
    (ws / "clock").mkdir()
    (ws / "plain").mkdir()
    run, plain = write_run(ws / "clock" / "run", form), write_run(ws / "plain" / "run", form, clock=False)
    with_clock = _check(ws, run)
    assert probe.last == _want()  # every /clock sample, in order, interleaved by time with the contract's topics
    in_blocks = _check(ws, run, verdicts=False)
    assert probe.last == _want()
    assert bool(probe.blocks) is (form in ("log", "flat-log"))  # a log: the batch deadline judge's blocks
    without = _check(ws, plain)
    assert probe.last == _want(clock=False)
    assert not any(is_clock_topic(t) for t, _, _ in probe.last)
    assert with_clock == without
    assert in_blocks == _check(ws, plain, verdicts=False) == {**without, "finals": {}}
    assert without["not_judged"] == [] and without["warnings"] == [] and without["order"] == ("", "")
    assert without["deadlines"][0]["false"] == 4 and without["results"][0]["violated"] == 4


def test_a_run_the_node_keeps_in_simulated_time_gives_the_untimed_verdicts_of_the_run_without_clock(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Under ``use_sim_time`` the deadlines are the deadline monitor's to judge in simulated time; the
    untimed check, its topics' items judged and the warnings are those of the run without ``/clock``."""
    ws = _workspace(tmp_path / "ws", "use_sim_time: true\n")
    probe = Probe(monkeypatch)
    (ws / "clock").mkdir()
    (ws / "plain").mkdir()
    with_clock = _check(ws, write_run(ws / "clock" / "run", "log"))
    assert probe.last == _want()
    without = _check(ws, write_run(ws / "plain" / "run", "log", clock=False))
    for key in ("results", "warnings", "order"):
        assert with_clock[key] == without[key], key
    untimed = [[i for i in got["not_judged"] if i["kind"] != "deadline"] for got in (with_clock, without)]
    assert untimed == [[], []]


def _out_of_stamp_order(path: Path, clock: bool) -> Path:
    """``RUN`` as a log whose messages carry their header stamps, with the input stamped 1.3 s recorded after
    the answer stamped 50 ms later (a reordering beyond the transport skew): read again in stamp order."""
    lines: list[dict[str, Any]] = []
    held: dict[str, Any] | None = None
    for t, topic, v in RUN:
        if topic == "clock":
            if clock:
                sec, nsec = divmod(_sim_ns(v), 1_000_000_000)
                lines.append({"topic": "/clock", "time": t / 1e9, "clock": {"sec": sec, "nanosec": nsec}})
            continue
        sec, nsec = divmod(t, 1_000_000_000)
        line = {"topic": topic, "time": t / 1e9, "header": {"stamp": {"sec": sec, "nanosec": nsec}}, "data": v}
        if topic == "x" and t == RUN[9][0]:
            held = line
            continue
        lines.append(line)
        if held is not None and topic == "y":
            held["time"] = t / 1e9 + 0.001  # recorded after the answer, stamped before it
            lines.append(held)
            held = None
    path.write_text("".join(json.dumps(x) + "\n" for x in lines))
    return path


def test_a_run_read_again_in_stamp_order_places_each_clock_line_at_its_time(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    ws = _workspace(tmp_path / "ws", "use_sim_time: false\n")
    probe = Probe(monkeypatch)
    with_clock = _check(ws, _out_of_stamp_order(ws / "clock.jsonl", clock=True))
    assert len(probe.reads) == 2  # read again in stamp order
    assert probe.last == _want()  # the input at its stamp, before the clock line after it
    assert probe.reads[0] != _want()  # control: the first read, in recording order, is not
    without = _check(ws, _out_of_stamp_order(ws / "plain.jsonl", clock=False))
    assert probe.last == _want(clock=False)
    assert with_clock["order"][0].startswith("judged in stamp order")
    assert with_clock == without


def test_a_node_kept_in_simulated_time_on_a_run_without_clock_says_its_triggers_were_undecided(
        tmp_path: Path) -> None:
    """A run without ``/clock`` of a node said to keep simulated time: every trigger undecided (its simulated
    time is not known), and the item "not judged" of its deadlines says so and why (not that no trigger was
    accepted).  Control: the same run with ``/clock`` decides them, no item."""
    ws = _workspace(tmp_path / "ws", "use_sim_time: true\n")
    (ws / "clock").mkdir()
    (ws / "plain").mkdir()
    without = _check(ws, write_run(ws / "plain" / "run", "log", clock=False))
    assert set(without["finals"].values()) == {"undecided"}
    (item,) = without["not_judged"]
    assert (item["kind"], item["reason"]) == ("deadline", "no verdict")
    assert item["detail"].startswith("12 trigger event(s) were undecided in ")
    assert "no /clock message was heard" in item["detail"] and "accepted" not in item["detail"]
    with_clock = _check(ws, write_run(ws / "clock" / "run", "log"))
    assert with_clock["not_judged"] == [] and with_clock["deadlines"][0]["false"] > 0
