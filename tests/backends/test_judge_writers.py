"""Issue 106: a watermark per writer, offline and live alike.

A relay copies its reading's header stamp onto an answer it publishes 450 ms
later, after the next reading (one every 300 ms).  Offline, the stamp-order
reader places each answer after its reading; live, the engine releases a
reading only once every writer heard has been heard past its stamp or has
been silent longer than the lateness bound on its own clock
(:meth:`OnlineEngine.watermark`), so each answer is released after its
reading and before the next one, as offline.  Each run is judged by the
recorded path and by the online engine fed the same messages in the order
they reached the monitor (1 ms after publication), its timer ticking every
10 ms and a deadline monitor fed what the engine releases, as
:mod:`rclverify.runtime.live` does.  The control: the relay adding 0.5 to
every fourth reading stays red, live as offline.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors.check import check_trace
from rclverify.backends.monitors.config import load_mapping
from rclverify.backends.monitors.deadlines import DeadlineMonitor
from rclverify.backends.monitors.online import OnlineEngine
from rclverify.backends.monitors.stamp_order import StampWatch, in_stamp_order, second_read
from rclverify.lang.typecheck import load
from rclverify.traces import read_trace
from test_judge_event_time import _msg, _offline, _stamp, _workspace

COPY = """
node Relay {
  inputs( x : REAL )
  outputs( r : REAL )
  topics( pkg/Reading x matches(in.x), pkg/Range r matches(out.r) )
  assume( TRUE )
  guarantee( out.r == in.x ) triggered by in.x within 950 ms
}
"""
COPY_MAPPING = "topics:\n  x: {fields: [value]}\n  r: {fields: [range]}\n"
WINDOW, PERIOD = 0.05, 0.3


def _copying_relay(delay: float, defect: bool = False, n: int = 12) -> list[dict[str, Any]]:
    """Readings 0, 1, 2 ... every 300 ms from 1 s, each copied ``delay`` s later onto an
    answer carrying the reading's stamp (``defect``: every fourth answer 0.5 too high)."""
    sent = []
    for i in range(n):
        t = 1.0 + i * PERIOD
        sent.append(_msg("x", t, t, value=float(i)))
        sent.append(_msg("r", t + delay, t, range=float(i) + (0.5 if defect and i % 4 == 3 else 0.0)))
    sent.append(_msg("tick", 1.0 + n * PERIOD + 3.0, None, data=0))
    return sorted(sent, key=lambda x: x["time"])


def _verdicts_offline(ws: Path, run: Path, node: str = "Relay") -> list[tuple[str, str]]:
    """The node's verdicts (where, verdict) as the recorded path judges the run (read again in stamp order)."""
    checked = load([ws / "contracts" / "c.rcl"])
    cfg = load_mapping(ws, "mapping.yaml")
    watch = StampWatch(0.0)
    for ev in read_trace(run):
        watch.see(ev)
    lag, _, _ = second_read(watch, str(run), True)
    events = read_trace(run) if lag is None else in_stamp_order(read_trace(run), lag)
    got: list[Any] = []
    check_trace(checked, [checked.nodes[node]], events, cfg.rules, 1.0, got.append)
    return sorted((v.where, v.verdict) for v in got)


def _verdicts_live(ws: Path, lines: list[dict[str, Any]]) -> tuple[list[tuple[str, str]], dict[str, int],
                                                                      list[float]]:
    """The online engine's final verdicts (each message's last; none where it is ``withdrawn``), the
    deadline counts, and the watermark at each answer's arrival."""
    checked = load([ws / "contracts" / "c.rcl"])
    rules = load_mapping(ws, "mapping.yaml").rules
    got: list[Any] = []
    dm = DeadlineMonitor(checked, checked.nodes["Relay"], rules, lambda v: None, horizon=1.0)
    eng = OnlineEngine(checked, [checked.nodes["Relay"]], rules, 1.0, reorder_window=WINDOW, on_verdict=got.append,
                       on_event=dm.feed)
    now, marks = lines[0]["time"], []
    for k, line in enumerate(lines):
        while now + 0.01 <= line["time"] + 0.001:
            now += 0.01
            eng.tick(now)
            dm.advance(eng.watermark(now))
        if line["topic"] == "r":
            marks.append(eng.watermark(now))
        eng.push(line["topic"], {x: v for x, v in line.items() if x not in ("topic", "time")}, line["time"],
                 f"run.jsonl:{k + 1}")
    eng.finish()
    last = {v.where: v.verdict for v in got}
    return sorted((w, v) for w, v in last.items() if v != "withdrawn"), dict(dm.finish().counts), marks


@pytest.mark.parametrize("delay", [0.35, 0.45, 0.59], ids=["after the next reading", "450 ms", "near two periods"])
def test_a_stamp_copying_relay_answering_after_the_next_reading_is_green_live_as_offline(
        tmp_path: Path, delay: float) -> None:
    """Fault 3 of the robot generator: the correct relay was ``inconclusive`` live (the readings
    disagree: its answer judged against the next reading too) and ``satisfied`` offline."""
    lines = _copying_relay(delay)
    ws, run = _workspace(tmp_path, COPY, lines, COPY_MAPPING)
    statuses, deadlines = _offline(ws, run, "Relay")
    assert statuses == ["discharged", "discharged"] and deadlines == [{"true": 12, "currently_false": 0, "false": 0}]
    offline = _verdicts_offline(ws, run)
    assert [v for _, v in offline] == ["satisfied"] * 12
    live, counts, marks = _verdicts_live(ws, lines)
    assert counts == deadlines[0]
    # verdict by verdict: the first reading, superseded when the next was released, before the relay's first
    # answer told how long after its stamp it publishes, has that verdict withdrawn when the answer comes late
    assert live == offline
    # held: once the relay was heard, each answer arrives with the watermark at or before its stamp
    assert all(m <= 1.0 + i * PERIOD + 1e-9 for i, m in enumerate(marks) if i >= 1), marks


def test_the_control_a_stamp_copying_relay_with_a_defect_is_red_live_as_offline(tmp_path: Path) -> None:
    lines = _copying_relay(0.45, defect=True)
    ws, run = _workspace(tmp_path, COPY, lines, COPY_MAPPING)
    statuses, deadlines = _offline(ws, run, "Relay")
    assert statuses == ["failed", "failed"] and deadlines == [{"true": 9, "currently_false": 0, "false": 3}]
    offline = _verdicts_offline(ws, run)
    assert {w for w, v in offline if v == "violated"} == {"run.jsonl:9", "run.jsonl:17", "run.jsonl:24"}  # answers 3, 7, 11
    live, counts, _ = _verdicts_live(ws, lines)
    assert counts == deadlines[0]
    assert live == offline
    # the live log (runtime/live.py's lines: the copies' stamps carried to their readings' times) judged again
    logged = tmp_path / "live" / "run.jsonl"
    logged.parent.mkdir()
    _workspace(logged.parent, COPY, _released(ws, lines), COPY_MAPPING)
    again = _verdicts_offline(logged.parent, logged)
    assert sorted(v for _, v in again) == sorted(v for _, v in offline), again


def _released(ws: Path, lines: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """What the live monitor's log holds of ``lines`` heard 1 ms after publication (runtime/live.py, ``_event``)."""
    checked = load([ws / "contracts" / "c.rcl"])
    out: list[dict[str, Any]] = []

    def log(ev: Any) -> None:
        late = {"late_s": round(ev.late, 6)} if ev.late else {}
        out.append({"topic": ev.topic, "time": ev.source if late and ev.source is not None else ev.time, **late,
                    **dict(ev.fields)})
    eng = OnlineEngine(checked, [checked.nodes["Relay"]], load_mapping(ws, "mapping.yaml").rules, 1.0,
                       reorder_window=WINDOW, on_event=log)
    now = lines[0]["time"]
    for line in lines:
        while now + 0.01 <= line["time"] + 0.001:
            now += 0.01
            eng.tick(now)
        eng.push(line["topic"], {x: v for x, v in line.items() if x not in ("topic", "time")}, line["time"])
    eng.finish()
    return out



def _on_simulated_time(lines: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """``lines`` with every header stamp on a /clock at half the wall clock's rate from 100 s (another
    clock than the source times: traces/event_time.py), the relay's copies still its readings' stamps."""
    out = []
    for line in lines:
        if "header" in line:
            st = line["header"]["stamp"]
            line = {**line, **_stamp(100.0 + (st["sec"] + st["nanosec"] / 1e9 - 1.0) * 0.5)}
        out.append(line)
    return out


@pytest.mark.parametrize("defect", [False, True], ids=["correct", "control: defective"])
def test_a_stamp_copying_relay_on_simulated_time_is_paired_by_its_copied_stamps_live_as_offline(
        tmp_path: Path, defect: bool) -> None:
    """Fault 5 of the robot generator: both writers' stamps run in another clock and were set aside,
    so each answer, placed at its source time after the next reading, was judged against that reading:
    the correct relay violated.  A copied stamp equal to its reading's, in the clock both share, names
    that reading: the answer is placed at the reading's time.  The correct relay is satisfied, the
    defective one violated on answers 3, 7 and 11 only, live verdict by verdict as offline."""
    lines = _on_simulated_time(_copying_relay(0.45, defect=defect))
    ws, run = _workspace(tmp_path, COPY, lines, COPY_MAPPING)
    statuses, deadlines = _offline(ws, run, "Relay")
    offline = _verdicts_offline(ws, run)
    violated = {w for w, v in offline if v == "violated"}
    assert violated == ({"run.jsonl:9", "run.jsonl:17", "run.jsonl:24"} if defect else set()), offline
    assert len(offline) == 12 and {v for _, v in offline} <= {"satisfied", "violated"}, offline
    assert statuses == (["failed", "failed"] if defect else ["discharged", "discharged"]), statuses
    live, counts, _ = _verdicts_live(ws, lines)
    assert counts == deadlines[0]
    assert live == offline
    # the live log (runtime/live.py's lines: the copies' stamps carried to their readings' times) judged again
    logged = tmp_path / "live" / "run.jsonl"
    logged.parent.mkdir()
    _workspace(logged.parent, COPY, _released(ws, lines), COPY_MAPPING)
    again = _verdicts_offline(logged.parent, logged)
    assert sorted(v for _, v in again) == sorted(v for _, v in offline), again


def _released(ws: Path, lines: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """What the live monitor's log holds of ``lines`` heard 1 ms after publication (runtime/live.py, ``_event``)."""
    checked = load([ws / "contracts" / "c.rcl"])
    out: list[dict[str, Any]] = []

    def log(ev: Any) -> None:
        late = {"late_s": round(ev.late, 6)} if ev.late else {}
        out.append({"topic": ev.topic, "time": ev.source if late and ev.source is not None else ev.time, **late,
                    **dict(ev.fields)})
    eng = OnlineEngine(checked, [checked.nodes["Relay"]], load_mapping(ws, "mapping.yaml").rules, 1.0,
                       reorder_window=WINDOW, on_event=log)
    now = lines[0]["time"]
    for line in lines:
        while now + 0.01 <= line["time"] + 0.001:
            now += 0.01
            eng.tick(now)
        eng.push(line["topic"], {x: v for x, v in line.items() if x not in ("topic", "time")}, line["time"])
    eng.finish()
    return out


def test_a_writer_is_past_a_time_once_heard_past_it_or_silent_past_the_bound_on_its_own_clock(
        tmp_path: Path) -> None:
    """The watermark's rule itself: a reading at 1.3 s is held while the relay (publishing 450 ms
    after its stamps) may still send an answer stamped before it, and released when the relay's
    answer stamped 1.3 s comes, or when the relay has been silent past 1.3 s + 450 ms + the bound."""
    ws, _ = _workspace(tmp_path, COPY, _copying_relay(0.45), COPY_MAPPING)
    checked = load([ws / "contracts" / "c.rcl"])
    rules = load_mapping(ws, "mapping.yaml").rules
    eng = OnlineEngine(checked, [checked.nodes["Relay"]], rules, 1.0, reorder_window=WINDOW)
    eng.push("x", {"value": 0.0, **_stamp(1.0)}, 1.0)
    eng.push("r", {"range": 0.0, **_stamp(1.0)}, 1.45)  # the relay: 450 ms after its stamp
    eng.push("x", {"value": 1.0, **_stamp(1.3)}, 1.3)
    assert eng.watermark(1.5) == pytest.approx(1.0)     # the relay was heard up to 1.0 s only
    assert eng.watermark(1.75) == pytest.approx(1.25)   # silent: 1.75 - 0.45 - 0.05 on its own clock
    assert eng.watermark(1.80) == pytest.approx(1.30)
    eng.push("r", {"range": 1.0, **_stamp(1.3)}, 1.75)
    assert eng.watermark(1.76) == pytest.approx(1.30)   # heard up to 1.3 s: it may still send one stamped later
    assert eng.watermark(2.30) == pytest.approx(1.80)   # silent since: 2.3 - 0.45 - 0.05
    # the control: a writer publishing at its stamps holds nothing beyond the bound
    eng2 = OnlineEngine(checked, [checked.nodes["Relay"]], rules, 1.0, reorder_window=WINDOW)
    eng2.push("x", {"value": 0.0, **_stamp(1.0)}, 1.0)
    eng2.push("r", {"range": 0.0, **_stamp(1.01)}, 1.01)
    assert eng2.watermark(1.5) == pytest.approx(1.45)


# -- what the node had: an input heard later than the lateness bound decides no violation --------------------

FLEET = """
node Fleet {
  inputs( a : REAL, b : REAL )
  outputs( c : REAL )
  topics( pkg/A a matches(in.a), pkg/B b matches(in.b), pkg/C c matches(out.c) )
  assume( TRUE )
  guarantee( out.c == in.a + in.b ) triggered by in.a within 500 ms
}
"""
FLEET_MAPPING = "topics:\n  a: {fields: [value]}\n  b: {fields: [value]}\n  c: {fields: [value]}\n"


def _fleet(b_delay: float, defect: bool = False) -> list[tuple[float, dict[str, Any]]]:
    """A fleet manager answering each ``a`` (every 200 ms from 1.05 s) 10 ms later with
    ``a + b`` for the ``b`` it has received; ``b`` changes from 1 to 2 at 1.43 s and reaches
    the node and the monitor ``b_delay`` s after it was published (unstamped: each line's
    time its source time).  ``defect``: the answer to the fifth ``a`` is 0.5 too high.
    Returns (arrival, line) in arrival order."""
    heard = [(1.001, _msg("b", 1.0, None, value=1.0)), (1.43 + b_delay, _msg("b", 1.43, None, value=2.0))]
    for i in range(6):
        ta = 1.05 + 0.2 * i
        had = 1.0 if ta + 0.01 < 1.43 + b_delay else 2.0
        heard.append((ta + 0.001, _msg("a", ta, None, value=float(i))))
        heard.append((ta + 0.011, _msg("c", ta + 0.01, None, value=i + had + (0.5 if defect and i == 4 else 0.0))))
    heard.append((4.0, _msg("tick", 4.0, None, data=0)))
    return sorted(heard, key=lambda x: x[0])


def _fleet_run(tmp: Path, heard: list[tuple[float, dict[str, Any]]]) -> tuple[list[tuple[str, str]],
                                                                               list[tuple[str, str]], list[Any]]:
    """The online engine fed ``heard`` in arrival order (timer every 10 ms), its released
    messages logged as the live monitor logs them (runtime/live.py: a message heard later
    than the bound at its source time with ``late_s``), and that log judged offline.
    Returns (live verdicts, offline verdicts, the live verdicts' objects)."""
    tmp.mkdir(exist_ok=True)
    ws, _ = _workspace(tmp, FLEET, [], FLEET_MAPPING)
    checked = load([ws / "contracts" / "c.rcl"])
    rules = load_mapping(ws, "mapping.yaml").rules
    got: list[Any] = []
    logged: list[str] = []

    def log(ev: Any) -> None:  # the live log's line (runtime/live.py, _event)
        late = {"late_s": round(ev.late, 6)} if ev.late else {}
        logged.append(json.dumps({"topic": ev.topic, "time": ev.source if late and ev.source is not None else ev.time,
                                  **late, **dict(ev.fields)}))
    eng = OnlineEngine(checked, [checked.nodes["Fleet"]], rules, 1.0, reorder_window=WINDOW, on_verdict=got.append,
                       on_event=log)
    now = 1.0
    for arrival, line in heard:
        while now + 0.01 <= arrival:
            now += 0.01
            eng.tick(now)
        eng.push(line["topic"], {x: v for x, v in line.items() if x not in ("topic", "time")}, line["time"])
    eng.finish()
    run = ws / "run.jsonl"
    run.write_text("".join(x + "\n" for x in logged))
    # live, a verdict names the message by the order released ("message 7"): the log's line 8
    live = sorted((f"run.jsonl:{int(v.where.split()[-1]) + 1}", v.verdict) for v in got)
    return live, _verdicts_offline(ws, run, "Fleet"), got


def test_an_answer_judged_with_an_input_the_node_had_not_received_is_undecided_not_violated(tmp_path: Path) -> None:
    """Issue 106's fleet manager: its second input reached it 70 ms late (past the 50 ms bound);
    its answer to the next ``a``, computed with the ``b`` it had, was ``violated``.  Now
    ``inconclusive``, saying what would decide it; the next answers (``b`` received) are judged."""
    live, offline, got = _fleet_run(tmp_path, _fleet(0.07))
    assert live == offline
    undecided = [v for v in got if v.verdict == "inconclusive"]
    assert [v.verdict for v in got].count("violated") == 0 and len(undecided) == 1, got
    assert "later than the lateness bound" in undecided[0].reason and "copied" in undecided[0].reason
    assert [v for _, v in live].count("satisfied") == 5


def test_the_controls_an_input_in_time_and_a_defect_elsewhere_stay_red(tmp_path: Path) -> None:
    # the same node whose b came within the bound and which answered with the old b anyway: violated
    heard = [(a, x) for a, x in _fleet(0.07)]
    heard = sorted([(a - 0.05 if x["topic"] == "b" and x["time"] == 1.43 else a, x) for a, x in heard],
                   key=lambda h: h[0])
    live, offline, got = _fleet_run(tmp_path / "in-time", heard)
    assert live == offline and [v.verdict for v in got].count("violated") == 1, got
    # a defect in an answer asked after the late input was heard: red, live as offline
    live, offline, got = _fleet_run(tmp_path / "defect", _fleet(0.07, defect=True))
    assert live == offline
    assert [v.verdict for v in got].count("violated") == 1 and [v.verdict for v in got].count("inconclusive") == 1
