"""Issue 106: the judge's pairing, lateness and clocks, offline and live alike.

Small workspaces written here; each run is a JSON-lines log as the live
monitor writes it (each line's ``time`` the publisher's source time, a
header stamp where the message has one), judged offline (``rclverify
monitor LOG``, the recorded path) and by the live engine
(:class:`OnlineEngine` with its lateness bound, fed the same messages in the
order they reached the monitor, its timer ticking as the live worker's
does, the deadline monitors fed the released messages and the timer's
clock as :mod:`rclverify.runtime.live` feeds them).  Each case has its
control: a correct node and a seeded defect.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors import recorded
from rclverify.backends.monitors.config import load_mapping
from rclverify.backends.monitors.deadline_records import DeadlineVerdict
from rclverify.backends.monitors.deadline_text import deadline_status
from rclverify.backends.monitors.deadlines import DeadlineMonitor
from rclverify.backends.monitors.online import OnlineEngine
from rclverify.lang.typecheck import load

RELAY = """
node Relay {
  inputs( b : BOOL )
  outputs( stop : BOOL )
  topics( std_msgs/Bool b matches(in.b), std_msgs/Bool stop matches(out.stop) )
  assume( TRUE )
  guarantee( in.b -> out.stop ) triggered by in.b within 100 ms
}
"""

MAPPING = "topics:\n  b: {fields: [data]}\n  stop: {fields: [data]}\n"


def _stamp(t: float) -> dict[str, Any]:
    sec = int(t)
    return {"header": {"stamp": {"sec": sec, "nanosec": round((t - sec) * 1e9)}}}


def _msg(topic: str, source: float, stamp: float | None, **fields: Any) -> dict[str, Any]:
    return {"topic": topic, "time": source, **(_stamp(stamp) if stamp is not None else {}), **fields}


def _workspace(tmp: Path, rcl: str, lines: list[dict[str, Any]], mapping: str = MAPPING) -> tuple[Path, Path]:
    (tmp / "contracts").mkdir(exist_ok=True)
    (tmp / "contracts" / "c.rcl").write_text(rcl)
    (tmp / "contracts" / "plan.yaml").write_text("contracts: [contracts/c.rcl]\n")
    (tmp / "mapping.yaml").write_text(mapping)
    run = tmp / "run.jsonl"
    run.write_text("".join(json.dumps(x) + "\n" for x in lines))
    return tmp, run


def _offline(ws: Path, run: Path, node: str) -> tuple[list[str], list[dict[str, int]]]:
    """The recorded path's statuses (the node's, then its deadlines') and deadline counts."""
    checked = load([ws / "contracts" / "c.rcl"])
    cfg = load_mapping(ws, "mapping.yaml")
    got = recorded.check_recorded(checked, [checked.nodes[node]], cfg, ws, str(run), lambda w: None)
    return ([got.verdict(r, str(run))[0] for r in got.results] +
            [deadline_status(d, str(run))[0] for d in got.deadlines], [dict(d.counts) for d in got.deadlines])


def _live(ws: Path, heard: list[tuple[float, dict[str, Any]]], node: str, window: float = 0.05,
          period: float = 0.01) -> tuple[list[DeadlineVerdict], dict[str, int], OnlineEngine]:
    """The live engine fed ``heard`` (arrival time, log line) in arrival order, its timer
    ticking every ``period`` s; the node's deadline monitor fed what the engine releases."""
    checked = load([ws / "contracts" / "c.rcl"])
    rules = load_mapping(ws, "mapping.yaml").rules
    verdicts: list[DeadlineVerdict] = []
    dm = DeadlineMonitor(checked, checked.nodes[node], rules, verdicts.append, horizon=2.0)
    eng = OnlineEngine(checked, [checked.nodes[node]], rules, 2.0, reorder_window=window, on_event=dm.feed)
    now = min(a for a, _ in heard)
    for arrival, line in sorted(heard, key=lambda x: x[0]):
        while now + period <= arrival:
            now += period
            eng.tick(now)
            dm.advance(now - window)
        fields = {k: v for k, v in line.items() if k not in ("topic", "time")}
        eng.push(line["topic"], fields, line["time"])
    for _ in range(40):
        now += period
        eng.tick(now)
        dm.advance(now - window)
    eng.finish()
    return verdicts, dm.finish().counts, eng


# -- a relay copying its question's stamp, its answer heard after the watermark passed the deadline ----------

def _relay(answer_source: float, answer_stamp: float, value: bool = True) -> list[dict[str, Any]]:
    return [_msg("b", 1.0, 1.0, data=True), _msg("stop", answer_source, answer_stamp, data=value),
            _msg("tick", 1.5, None, data=0)]


def test_a_stamp_copying_answer_heard_late_meets_its_deadline_live_as_offline(tmp_path: Path) -> None:
    """The relay answered at 1.05 s (source time), copying the question's stamp
    1.0 s; the answer reached the monitor at 1.3 s, after the watermark (the
    clock less 50 ms) had passed the deadline 1.1 s.  Before: live ``false``,
    "answered after 0 ms, -100 ms past the deadline"; offline met."""
    lines = _relay(1.05, 1.0)
    ws, run = _workspace(tmp_path, RELAY, lines)
    statuses, counts = _offline(ws, run, "Relay")
    assert counts == [{"true": 1, "currently_false": 0, "false": 0}]
    assert statuses[-1] == "discharged"
    verdicts, live, eng = _live(ws, [(1.0, lines[0]), (1.3, lines[1]), (1.5, lines[2])], "Relay")
    assert eng.late == 1  # it did come after the watermark
    assert live == counts[0]
    assert [v.verdict for v in verdicts][:2] == ["false", "true"]  # the clock's false, withdrawn by the answer
    assert "met on the answer's own stamp" in verdicts[-1].reason and "-100 ms" not in verdicts[-1].reason


@pytest.mark.parametrize("lines, why", [
    (_relay(1.25, 1.25), "its own stamp is past the deadline"),
    (_relay(1.05, 1.0, value=False), "a wrong answer, stamp copied"),
])
def test_the_controls_a_late_stamp_or_a_wrong_answer_stay_false(tmp_path: Path, lines: list[dict[str, Any]],
                                                                 why: str) -> None:
    ws, run = _workspace(tmp_path, RELAY, lines)
    statuses, counts = _offline(ws, run, "Relay")
    assert counts == [{"true": 0, "currently_false": 0, "false": 1}], why
    assert statuses[-1] == "failed", why
    _, live, _ = _live(ws, [(1.0, lines[0]), (1.3, lines[1]), (1.5, lines[2])], "Relay")
    assert live == counts[0], why


def test_a_stamp_copying_answer_heard_in_time_is_met_without_a_false(tmp_path: Path) -> None:
    # the correct relay heard within the lateness bound of its (copied) stamp: met, no false ever given
    lines = _relay(1.02, 1.0)
    ws, _ = _workspace(tmp_path, RELAY, lines)
    verdicts, live, eng = _live(ws, [(1.0, lines[0]), (1.03, lines[1]), (1.5, lines[2])], "Relay")
    assert eng.late == 0 and [v.verdict for v in verdicts][0] == "true" and live["true"] == 1


# -- clocks: a driver's stamps seconds off the wall clock, simulated time -------------------------------------

BAND = """
context { Stat : {red, orange, green} ; }
node Band {
  inputs( r : REAL )
  outputs( status : Stat )
  topics( pkg/Reading r matches(in.r), pkg/Status status matches(out.status) )
  assume( 0 <= in.r )
  guarantee( (in.r < 120 -> out.status == green) and (120 <= in.r -> out.status == red) )
}
"""
BAND_MAPPING = "topics:\n  r: {fields: [value]}\n  status: {fields: [level]}\n"
#: the readings, one a second: each differs from the one two periods before it
VALUES = [50.0, 130.0, 130.0, 50.0, 50.0, 130.0, 130.0, 50.0]
WALL = 1_700_000_000.0


def _alarm_run(offset: float | None, lag_readings: int = 0, sim: bool = False) -> list[dict[str, Any]]:
    """A driver publishing ``VALUES`` one a second on the wall clock, stamping each
    ``offset`` s off its publish time (``sim``: on a simulated clock at 100 s); an
    alarm answering each 10 ms later, unstamped, with the status of the reading
    ``lag_readings`` before (0: the correct node)."""
    lines = []
    for i, v in enumerate(VALUES):
        t = WALL + i
        stamp = (100.0 + i) if sim else (t + offset if offset is not None else None)
        lines.append(_msg("r", t, stamp, value=v))
        seen = VALUES[max(i - lag_readings, 0)]
        lines.append(_msg("status", t + 0.01, None, level="green" if seen < 120 else "red"))
    return lines


def _band_offline(ws: Path, run: Path) -> tuple[str, str, list[tuple[str, str]]]:
    """The recorded path's status and explanation, and the verdicts (where, verdict) of
    the run as the recorded path orders it (its second read, when it makes one)."""
    from rclverify.backends.monitors.check import check_trace
    from rclverify.backends.monitors.stamp_order import StampWatch, in_stamp_order, second_read
    from rclverify.traces import read_trace
    checked = load([ws / "contracts" / "c.rcl"])
    cfg = load_mapping(ws, "mapping.yaml")
    got = recorded.check_recorded(checked, [checked.nodes["Band"]], cfg, ws, str(run), lambda w: None)
    status, text = got.verdict(got.results[0], str(run))
    watch = StampWatch(getattr(cfg.rules, "skew", None) or 0.0)
    for ev in read_trace(run):
        watch.see(ev)
    lag, _, _ = second_read(watch, str(run), True)
    events = read_trace(run) if lag is None else in_stamp_order(read_trace(run), lag)
    verdicts: list[Any] = []
    check_trace(checked, [checked.nodes["Band"]], events, cfg.rules, 0.5, verdicts.append)
    return status, text, sorted((v.where, v.verdict) for v in verdicts)


def _band_live(ws: Path, lines: list[dict[str, Any]]) -> tuple[list[tuple[str, str]], OnlineEngine]:
    checked = load([ws / "contracts" / "c.rcl"])
    rules = load_mapping(ws, "mapping.yaml").rules
    verdicts: list[Any] = []
    eng = OnlineEngine(checked, [checked.nodes["Band"]], rules, 0.5, reorder_window=0.05, on_verdict=verdicts.append)
    now = lines[0]["time"]
    for k, line in enumerate(lines):  # heard 1 ms after it was published, the timer every 10 ms
        while now + 0.01 <= line["time"] + 0.001:
            now += 0.01
            eng.tick(now)
        eng.push(line["topic"], {x: v for x, v in line.items() if x not in ("topic", "time")}, line["time"],
                 f"run.jsonl:{k + 1}")
    eng.finish()
    return sorted((v.where, v.verdict) for v in verdicts), eng


@pytest.mark.parametrize("offset, sim", [(-2.0, False), (0.3, False), (2.0, False), (None, True)],
                         ids=["2 s behind", "0.3 s ahead", "2 s ahead", "simulated time at 100 s"])
def test_a_writer_in_another_clock_is_named_and_placed_never_a_violation(tmp_path: Path, offset: float | None,
                                                                        sim: bool) -> None:
    """Row 4 (and row 2's simulated time): the correct alarm was ``failed``
    ("5 satisfied, 10 violated" for 5 alarms); its answers were judged against
    the reading the shifted stamps put before them."""
    lines = _alarm_run(offset, sim=sim)
    ws, run = _workspace(tmp_path, BAND, lines, BAND_MAPPING)
    status, text, offline = _band_offline(ws, run)
    assert status == "discharged", text
    assert "/r: header stamps" in text and "another clock (8 of 8 stamped message(s)" in text, text
    assert [v for _, v in offline].count("satisfied") == len(VALUES) and "violated" not in [v for _, v in offline]
    live, eng = _band_live(ws, lines)
    assert live == offline
    assert [line.split(":")[0] for line in eng.clock_lines()] == ["/r"]


@pytest.mark.parametrize("offset, sim", [(-2.0, False), (0.3, False), (2.0, False), (None, True)],
                         ids=["2 s behind", "0.3 s ahead", "2 s ahead", "simulated time at 100 s"])
def test_a_defective_alarm_beside_a_writer_in_another_clock_is_found(tmp_path: Path, offset: float | None,
                                                                     sim: bool) -> None:
    """Row 6: the sensor 2 s ahead, readings one a second: an alarm answering
    each reading with the status of the one two periods before was
    ``discharged`` (each answer judged against the reading two periods before)."""
    lines = _alarm_run(offset, lag_readings=2, sim=sim)
    ws, run = _workspace(tmp_path, BAND, lines, BAND_MAPPING)
    status, text, offline = _band_offline(ws, run)
    assert status == "failed", text
    live, _ = _band_live(ws, lines)
    assert live == offline and ("run.jsonl:6", "violated") in offline


def test_the_control_one_clock_judged_on_its_stamps(tmp_path: Path) -> None:
    # a driver stamping 20 ms before it publishes: one clock, judged on the stamps, nothing named
    lines = _alarm_run(-0.02)
    ws, run = _workspace(tmp_path, BAND, lines, BAND_MAPPING)
    status, text, offline = _band_offline(ws, run)
    assert status == "discharged" and "another clock" not in text, text
    live, eng = _band_live(ws, lines)
    assert live == offline and eng.clock_lines() == []
    # and the defect on one clock
    lines = _alarm_run(-0.02, lag_readings=2)
    ws, run = _workspace(tmp_path, BAND, lines, BAND_MAPPING)
    assert _band_offline(ws, run)[0] == "failed"


# -- a stamp copied from an earlier question: the answer judged against every question it could answer ----------

def _stale_run(level: str, stamp: float) -> list[dict[str, Any]]:
    """r = 50 at 1.0 s, 130 at 1.2 s, 50 at 1.4 s, each answered 10 ms later stamped with its
    question's stamp, but the second answer (``level``) stamped ``stamp``."""
    return [_msg("r", 1.0, 1.0, value=50.0), _msg("status", 1.01, 1.0, level="green"),
            _msg("r", 1.2, 1.2, value=130.0), _msg("status", 1.21, stamp, level=level),
            _msg("r", 1.4, 1.4, value=50.0), _msg("status", 1.41, 1.4, level="green"),
            _msg("tick", 3.0, None, data=0)]


def _stale_reasons(ws: Path, run: Path) -> str:
    """The reason of the verdict on line 4 of ``run`` read in stamp order."""
    from rclverify.backends.monitors.check import check_trace
    from rclverify.backends.monitors.stamp_order import StampWatch, in_stamp_order
    from rclverify.traces import read_trace
    checked = load([ws / "contracts" / "c.rcl"])
    cfg = load_mapping(ws, "mapping.yaml")
    watch = StampWatch(0.02)
    for ev in read_trace(run):
        watch.see(ev)
    got: list[Any] = []
    check_trace(checked, [checked.nodes["Band"]], in_stamp_order(read_trace(run), watch.lag), cfg.rules, 0.5,
                got.append)
    return " | ".join(v.reason for v in got if v.where == "run.jsonl:4")


def _stale_live(ws: Path, lines: list[dict[str, Any]]) -> list[tuple[str, str]]:
    checked = load([ws / "contracts" / "c.rcl"])
    rules = load_mapping(ws, "mapping.yaml").rules
    verdicts: list[Any] = []
    eng = OnlineEngine(checked, [checked.nodes["Band"]], rules, 0.5, reorder_window=0.05, on_verdict=verdicts.append)
    now = 1.0
    for k, line in enumerate(lines):  # heard 1 ms after it was published, the timer every 10 ms
        while now + 0.01 <= line["time"] + 0.001:
            now += 0.01
            eng.tick(now)
        eng.push(line["topic"], {x: v for x, v in line.items() if x not in ("topic", "time")}, line["time"],
                 f"run.jsonl:{k + 1}")
    eng.finish()
    return sorted((v.where, v.verdict) for v in verdicts)


@pytest.mark.parametrize("level, stamp, status, verdict", [
    ("green", 1.0, "inconclusive", "inconclusive"),  # row 5: a wrong answer, a stale stamp: was discharged
    ("red", 1.0, "inconclusive", "inconclusive"),    # its control: the right answer, a stale stamp: was failed
    ("red", 1.2, "discharged", "satisfied"),         # the correct node, its question's stamp
    ("green", 1.2, "failed", "violated"),            # the defect, its question's stamp
])
def test_an_answer_with_a_stale_stamp_is_judged_against_every_question_it_could_answer(
        tmp_path: Path, level: str, stamp: float, status: str, verdict: str) -> None:
    lines = _stale_run(level, stamp)
    ws, run = _workspace(tmp_path, BAND, lines, BAND_MAPPING)
    got, text, offline = _band_offline(ws, run)
    assert got == status, text
    assert dict(offline)["run.jsonl:4"] == verdict, offline
    if verdict == "inconclusive":
        assert "satisfied" not in [v for w, v in offline if w == "run.jsonl:4"]  # never green first
        reasons = _stale_reasons(ws, run)
        assert "published 210.0 ms after its header stamp, after the question(s) at run.jsonl:3" in reasons, reasons
    assert _stale_live(ws, lines) == offline


@pytest.mark.skipif(not hasattr(__import__("os"), "mkfifo"), reason="no FIFOs on this platform")
@pytest.mark.parametrize("lag", [0, 2], ids=["correct", "defective"])
def test_clocks_that_cannot_be_related_give_no_verdict_either_way(tmp_path: Path, lag: int) -> None:
    """A stream (read once) whose driver stamps 2 s ahead: its messages cannot be placed
    by a second read, so neither the correct alarm nor the defective one gets a verdict
    judged on the shifted stamps: inconclusive, the writer named."""
    import os
    import threading
    lines = _alarm_run(2.0, lag_readings=lag)
    ws, _ = _workspace(tmp_path, BAND, [], BAND_MAPPING)
    fifo = tmp_path / "stream.jsonl"
    os.mkfifo(fifo)
    text = "".join(json.dumps(x) + "\n" for x in lines)

    def feed() -> None:
        with open(fifo, "w") as fh:
            fh.write(text)
    writer = threading.Thread(target=feed)
    writer.start()
    try:
        checked = load([ws / "contracts" / "c.rcl"])
        got = recorded.check_recorded(checked, [checked.nodes["Band"]], load_mapping(ws, "mapping.yaml"), ws,
                                      str(fifo), lambda w: None)
        status, reason = got.verdict(got.results[0], str(fifo))
    finally:
        writer.join(timeout=10)
    assert status == "inconclusive", reason
    assert "/r: header stamps +2.000 s" in reason and "cannot be read a second time" in reason, reason


@pytest.mark.parametrize("value, counts", [(True, {"true": 5, "currently_false": 0, "false": 0}),
                                           (False, {"true": 0, "currently_false": 0, "false": 5})],
                         ids=["correct", "defective"])
def test_deadlines_on_simulated_time_beside_the_wall_clock(tmp_path: Path, value: bool,
                                                           counts: dict[str, int]) -> None:
    """Row 2: questions stamped on the simulated clock (100 s), answers unstamped (their
    source times on the wall clock): every deadline was false, "answered after
    1795807407.964 s".  The questions' writer runs in another clock: placed at their
    source times, the correct relay meets every deadline and the defect misses them,
    offline and live alike."""
    lines: list[dict[str, Any]] = []
    for i in range(5):
        lines.append(_msg("b", WALL + i, 100.0 + i, data=True))
        lines.append(_msg("stop", WALL + i + 0.03, None, data=value))
    lines.append(_msg("tick", WALL + 6, None, data=0))
    ws, run = _workspace(tmp_path, RELAY, lines)
    statuses, offline = _offline(ws, run, "Relay")
    assert offline == [counts]
    assert statuses[-1] == ("discharged" if value else "failed")
    _, live, eng = _live(ws, [(x["time"] + 0.001, x) for x in lines], "Relay")
    assert live == counts and [c.split(":")[0] for c in eng.clock_lines()] == ["/b"]
