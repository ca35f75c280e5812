"""Each answer judged against the question in force at its stamp (issue 63, rows 3, 4 and 9).

Small workspaces written here, JSON-lines runs checked by ``rclverify
monitor`` (the batch path where the node takes it, the event path else),
the streaming engine with the batch path off, and the live engine
(:class:`OnlineEngine`) fed the same messages in the order they were heard:

* row 3: a question heard late (a later line) with an earlier stamp (the
  line's ``time`` or its header stamp) is the question an answer stamped
  after it answers; it is never judged against the question before it;
* row 4: a press released 10 ms later is answered by a stop, not by an
  output computed from the release (docs/semantics.md, "Deadlines");
* row 9: (a) an input whose latest message is a NaN makes what reads it
  undecided, never the value before the NaN; (b) a deadline is compared in
  integer nanoseconds, an answer at exactly ``t + d`` is in time.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors.check import check_trace
from rclverify.backends.monitors.deadlines import check_deadlines
from rclverify.backends.monitors.online import OnlineEngine
from rclverify.cli.commands import main
from rclverify.lang.typecheck import load
from rclverify.traces import read_trace

SENSOR = """
context { Stat : {red, orange, green} ; }
node Sensor {
  inputs( r : REAL, on : BOOL )
  outputs( status : Stat )
  topics( pkg/Reading r matches(in.r), pkg/Switch on matches(in.on), pkg/Status status matches(out.status) )
  assume( 0 <= in.r )
  guarantee( in.on -> ((in.r < 120 -> out.status == green) and (120 <= in.r -> out.status == red)) )
}
"""

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

STOPPER = """
node Stopper {
  inputs( b : BOOL )
  outputs( stop : BOOL )
  topics( std_msgs/Bool b matches(in.b), std_msgs/Bool stop matches(out.stop) )
  assume( TRUE )
  guarantee( in.b -> out.stop ) triggered by in.b within 200 ms
}
"""

MAPPING = "topics:\n  r: {fields: [value]}\n  on: {fields: [flag]}\n  status: {fields: [level]}\n" \
          "  b: {fields: [data]}\n  stop: {fields: [data]}\n"


def _workspace(tmp: Path, rcl: str, lines: list[dict[str, Any]], skew: float | None = None) -> tuple[Path, Path]:
    (tmp / "contracts").mkdir(exist_ok=True)
    (tmp / "contracts" / "c.rcl").write_text(rcl)
    (tmp / "contracts" / "plan.yaml").write_text("contracts: [contracts/c.rcl]\n")
    (tmp / "mapping.yaml").write_text(MAPPING + (f"skew: {skew}\n" if skew is not None else ""))
    run = tmp / "run.jsonl"
    run.write_text("".join(json.dumps(x) + "\n" for x in lines))
    return tmp, run


def _monitor(ws: Path, run: Path, capsys: pytest.CaptureFixture[str], horizon: str = "2") -> tuple[int, str]:
    rc = main(["monitor", "-w", str(ws), "--mapping", "mapping.yaml", "--horizon", horizon, str(run)])
    return rc, capsys.readouterr().out


def _engines(ws: Path, run: Path, node: str, horizon: float = 2.0) -> dict[str, list[tuple[int, str]]]:
    """The verdicts (event, verdict) of the batch path, the event path and the live engine on ``run``."""
    from rclverify.backends.monitors.config import load_mapping
    checked = load([ws / "contracts" / "c.rcl"])
    rules = load_mapping(ws, "mapping.yaml").rules
    out: dict[str, list[tuple[int, str]]] = {}
    for name, batch in (("batch", True), ("events", False)):
        got: list[Any] = []
        check_trace(checked, [checked.nodes[node]], read_trace(run), rules, horizon, got.append, batch=batch)
        out[name] = sorted((v.event, v.verdict) for v in got)
    got = []
    eng = OnlineEngine(checked, [checked.nodes[node]], rules, horizon, reorder_window=0.0, on_verdict=got.append)
    for ev in read_trace(run):  # heard in the log's order, each at its own time (or header stamp)
        eng.push(ev.topic, dict(ev.fields), ev.time, ev.where)
    eng.finish()
    out["live"] = sorted((v.event, v.verdict) for v in got)
    return out


# -- row 4 ---------------------------------------------------------------------------

def test_a_press_released_before_its_answer_is_not_answered_by_a_non_stop(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Row 4: in.b true (a press), in.b false 10 ms later (its release), then
    stop false: the press's deadline demands a stop; an output computed from
    the release does not answer it.  Before: "answered", rc 0."""
    ws, run = _workspace(tmp_path, STOPPER, [
        {"topic": "b", "time": 1.0, "data": True}, {"topic": "b", "time": 1.01, "data": False},
        {"topic": "stop", "time": 1.05, "data": False}, {"topic": "b", "time": 2.0, "data": False}])
    checked = load([ws / "contracts" / "c.rcl"])
    got: list[Any] = []
    [res] = check_deadlines(checked, [checked.nodes["Stopper"]], read_trace(run), {}, got.append)
    assert [(v.trigger_where, v.verdict) for v in got if not v.update] == [
        ("run.jsonl:2", "true"), ("run.jsonl:1", "false"), ("run.jsonl:4", "currently_false")]
    first = res.first_false
    assert first is not None and first.trigger_where == "run.jsonl:1"
    assert "the output at run.jsonl:3 did not satisfy guarantee 1" in first.reason
    rc, out = _monitor(ws, run, capsys)
    assert rc == 1 and "missed Stopper's deadline" in out
    # a stop within the 200 ms answers the press (and the release: in.b false holds it too)
    ws, run = _workspace(tmp_path, STOPPER, [
        {"topic": "b", "time": 1.0, "data": True}, {"topic": "b", "time": 1.01, "data": False},
        {"topic": "stop", "time": 1.05, "data": True}])
    got.clear()
    [res] = check_deadlines(checked, [checked.nodes["Stopper"]], read_trace(run), {}, got.append)
    assert res.counts == {"true": 2, "currently_false": 0, "false": 0}


# -- row 9 ---------------------------------------------------------------------------

def test_an_answer_at_exactly_the_deadline_is_in_time(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Row 9b: pressed at 0.7 s, stopped at 0.9 s, `within 200 ms`: 0.7 + 0.2 is
    0.8999999999999999 in doubles, and the stop was "0 ms past the deadline".
    In integer nanoseconds it is at the deadline: in time.  One nanosecond
    later is late, and said so in microseconds, not "0 ms"."""
    ws, run = _workspace(tmp_path, STOPPER, [
        {"topic": "b", "time": 0.7, "data": True}, {"topic": "stop", "time": 0.9, "data": True}])
    checked = load([ws / "contracts" / "c.rcl"])
    [res] = check_deadlines(checked, [checked.nodes["Stopper"]], read_trace(run), {})
    assert res.counts == {"true": 1, "currently_false": 0, "false": 0}
    rc, out = _monitor(ws, run, capsys)
    assert rc == 0 and "missed" not in out
    # header stamps (ROS 2's sec/nanosec) are read exactly: 0.9 s + 1 ns is late, and said to be
    got: list[Any] = []
    ws, run = _workspace(tmp_path, STOPPER, [
        {"topic": "b", "time": 5.0, "header": {"stamp": {"sec": 1700000000, "nanosec": 700_000_000}}, "data": True},
        {"topic": "stop", "time": 5.0, "header": {"stamp": {"sec": 1700000000, "nanosec": 900_000_001}},
         "data": True}])
    [res] = check_deadlines(checked, [checked.nodes["Stopper"]], read_trace(run), {}, got.append)
    assert res.counts["false"] == 1 and got[0].reason == "answered after 200 ms, 1 ns past the deadline of 200 ms"
    run.write_text(run.read_text().replace("900000001", "900000000"))
    [res] = check_deadlines(checked, [checked.nodes["Stopper"]], read_trace(run), {})
    assert res.counts["true"] == 1


def test_an_input_after_a_nan_is_not_judged_against_the_stale_value(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Row 9a: r = 50 answered green; r = NaN (unreadable); the switch comes
    on again and the sensor answers red (it read 300).  The value before the
    NaN (50) no longer stands: the switch's question is undecided, not a
    violation of "< 120 -> green"; the next readable r is judged."""
    lines = [{"topic": "on", "time": 0.0, "flag": True}, {"topic": "r", "time": 0.1, "value": 50.0},
             {"topic": "status", "time": 0.15, "level": "green"}, {"topic": "r", "time": 0.2, "value": "NaN"},
             {"topic": "on", "time": 0.3, "flag": True}, {"topic": "status", "time": 0.35, "level": "red"},
             {"topic": "r", "time": 0.4, "value": 300.0}, {"topic": "status", "time": 0.45, "level": "red"}]
    ws, run = _workspace(tmp_path, SENSOR, lines)
    run.write_text(run.read_text().replace('"NaN"', "NaN"))
    got = _engines(ws, run, "Sensor")
    assert got["events"] == got["batch"] == got["live"]
    verdicts = dict(got["events"])
    assert verdicts[2] == "satisfied" and verdicts[3] == "inconclusive" and verdicts[4] == "inconclusive"
    assert 5 not in verdicts and verdicts[7] == "satisfied"  # owed nothing while r is unreadable; then judged
    rc, out = _monitor(ws, run, capsys)
    assert rc == 0 and "violated" not in out
    # the deadline monitor: a trigger while the input is unreadable gets no deadline verdict (undecided)
    timed = SENSOR.replace(
        "out.status == red)) )", "out.status == red)) ) triggered by in.on within 100 ms")
    (ws / "contracts" / "c.rcl").write_text(timed)
    checked = load([ws / "contracts" / "c.rcl"])
    from rclverify.backends.monitors.config import load_mapping
    rules = load_mapping(ws, "mapping.yaml").rules
    [res] = check_deadlines(checked, [checked.nodes["Sensor"]], read_trace(run), rules)
    assert res.counts["false"] == 0 and res.unaccepted == {"assumption violated": 0, "incomplete input": 1,
                                                           "undecided": 1}


# -- row 3 ---------------------------------------------------------------------------

def _stamped(t: float, epoch: int = 1700000000) -> dict[str, Any]:
    sec = int(t)
    return {"header": {"stamp": {"sec": epoch + sec, "nanosec": round((t - sec) * 1e9)}}}


@pytest.mark.parametrize("skew", [None, 0])
@pytest.mark.parametrize("headers", [False, True])
def test_a_question_heard_late_is_the_one_an_answer_stamped_after_it_answers(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], skew: float | None, headers: bool) -> None:
    """Row 3: r = 50 at 1.0 s answered green; a green stamped 1.5 s; then, on a
    later line, r = 130 stamped 1.2 s.  In force at 1.5 s is r = 130: the green
    is false for it.  Before: judged against r = 50, "2 satisfied", rc 0.
    With header stamps the lines' times are in order and the stamps are not;
    each line's time is its source time, on the stamps' clock: each output
    published at its stamp, the late reading 0.31 s after its stamp (a stamp
    seconds off its source time runs in another clock, and an output
    published well after its stamp may answer the questions asked meanwhile:
    docs/semantics.md "Event time")."""
    rows = [("r", 1.0, 50.0), ("status", 1.1, "green"), ("status", 1.5, "green"), ("r", 1.2, 130.0),
            ("status", 1.6, "red")]
    lines = []
    for k, (topic, t, v) in enumerate(rows):
        key = "value" if topic == "r" else "level"
        lines.append({"topic": topic, "time": 1700000000 + (1.0, 1.1, 1.5, 1.51, 1.6)[k] if headers else t, key: v,
                      **(_stamped(t) if headers else {})})
    ws, run = _workspace(tmp_path, BAND, lines, skew)
    got = _engines(ws, run, "Band")
    assert got["events"] == got["batch"] == got["live"]
    assert got["events"] == [(1, "satisfied"), (2, "satisfied"), (2, "violated"), (4, "satisfied")]
    rc, out = _monitor(ws, run, capsys)
    # recorded out of stamp order: every engine judges the run in stamp order (backends/monitors/stamp_order.py)
    assert rc == 1 and "answering the question at run.jsonl:4" in out and "judged in stamp order" in out


def test_a_late_input_that_changes_a_later_question_is_judged_with_it(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Two inputs: the switch at 1.3 s raised a question with r = 50, answered
    green; r = 130 stamped 1.2 s is heard after both.  In force at the switch's
    question is r = 130: the green is false for it (the question is judged
    again on the inputs in force at its stamp)."""
    lines = [{"topic": "on", "time": 0.0, "flag": True}, {"topic": "r", "time": 0.1, "value": 50.0},
             {"topic": "status", "time": 0.2, "level": "green"}, {"topic": "on", "time": 1.3, "flag": True},
             {"topic": "status", "time": 1.4, "level": "green"}, {"topic": "r", "time": 1.2, "value": 130.0},
             {"topic": "status", "time": 1.5, "level": "red"}]
    ws, run = _workspace(tmp_path, SENSOR, lines)
    got = _engines(ws, run, "Sensor")
    assert got["events"] == got["batch"] == got["live"]
    assert [v for v in got["events"] if v[0] == 4] == [(4, "satisfied"), (4, "violated")]
    assert (6, "satisfied") in got["events"]  # the red after it: r = 130, on: right
    rc, out = _monitor(ws, run, capsys)
    assert rc == 1 and "judged in stamp order" in out


def test_live_the_reorder_window_and_a_message_later_than_it_agree(tmp_path: Path) -> None:
    """Live: within the reorder window (heard 450 ms after its stamp, the window
    500 ms) the reading is put before the green by its stamp (one verdict,
    violated); later than the window (100 ms) it is judged at its stamp when it
    comes: the green's satisfied, then inconclusive, for the node may not have
    had the reading when it answered (docs/semantics.md, "Event time", "Later
    than the bound").  Neither leaves the green satisfied alone."""
    ws, run = _workspace(tmp_path, BAND, [])
    from rclverify.backends.monitors.config import load_mapping
    checked = load([ws / "contracts" / "c.rcl"])
    rules = load_mapping(ws, "mapping.yaml").rules
    for window, want in ((0.5, [(1, "satisfied"), (3, "violated")]),
                         (0.1, [(1, "satisfied"), (2, "inconclusive"), (2, "satisfied")])):
        got: list[Any] = []
        eng = OnlineEngine(checked, [checked.nodes["Band"]], rules, 2.0, reorder_window=window, on_verdict=got.append)
        heard = [("r", 1.0, 50.0, 1.0), ("status", 1.1, "green", 1.1), ("status", 1.5, "green", 1.5),
                 ("r", 1.2, 130.0, 1.65)]
        for topic, t, v, when in heard:
            eng.tick(when)
            eng.push(topic, {**_stamped(t, 0), ("value" if topic == "r" else "level"): v}, when)
        eng.tick(2.0)
        eng.finish()
        assert sorted((v.event, v.verdict) for v in got) == want, window


# -- the differential: a log heard out of order against the same log in stamp order ----------

def _rows_events(rows: list[tuple[str, float, Any]]) -> list[Any]:
    from rclverify.traces.events import Event
    key = {"r": "value", "on": "flag", "status": "level"}
    return [Event(k, t, topic, {key[topic]: v}, f"run.jsonl:{k + 1}") for k, (topic, t, v) in enumerate(rows)]


@pytest.fixture(scope="module")
def contracts(tmp_path_factory: pytest.TempPathFactory) -> Any:
    d = tmp_path_factory.mktemp("order")
    (d / "s.rcl").write_text(SENSOR)
    (d / "b.rcl").write_text(BAND.replace("Stat :", "Stat2 :").replace(": Stat", ": Stat2").replace(
        "{red, orange, green}", "{red2, orange2, green2}").replace("green)", "green2)").replace("red)", "red2)"))
    return load([d / "s.rcl"]), load([d / "b.rcl"])


def _verdicts(checked: Any, node: str, rows: list[tuple[str, float, Any]], rules: Any,
              batch: bool = False, live: bool = False) -> dict[str, set[str]]:
    """Per message (topic and stamp), the verdicts it got: offline (the event path, or the
    batch path), or live (each message received at its stamp, in the order heard, no window)."""
    got: list[Any] = []
    if live:
        key = {"r": "value", "on": "flag", "status": "level"}
        eng = OnlineEngine(checked, [checked.nodes[node]], rules, 1.0, on_verdict=got.append)
        for topic, t, v in rows:
            eng.push(topic, {key[topic]: v}, t)
        eng.finish()
    else:
        check_trace(checked, [checked.nodes[node]], _rows_events(rows), rules, 1.0, got.append, batch=batch)
    out: dict[str, set[str]] = {}
    for v in got:
        stamp = rows[v.event][1]
        out.setdefault(f"{v.topic}@{stamp:.3f}#{v.event}", set()).add(v.verdict)
    return out


def test_an_output_violated_in_stamp_order_is_never_green_alone_heard_out_of_order(contracts: Any) -> None:
    """Random runs of both contracts, each heard with some inputs moved later in
    the log (their stamps kept; equal stamps, late answers, inputs before every
    input has a value among them): every output the run in stamp order (equal
    stamps in the order heard, docs/semantics.md) finds violated is violated
    (or inconclusive) heard out of order too, never satisfied alone; the batch
    path gives the event path's verdicts."""
    import random
    from rclverify.traces.mapping import load_rules
    sensor, band = contracts
    rnd = random.Random(63)
    for case in range(400):
        two = case % 2 == 0
        checked, node = (sensor, "Sensor") if two else (band, "Band")
        green, red = ("green", "red") if two else ("green2", "red2")
        rules = load_rules({"r": {"fields": ["value"]}, "on": {"fields": ["flag"]}, "status": {"fields": ["level"]}})
        rules.skew = rnd.choice([0.0, 0.02])  # type: ignore[attr-defined]
        t, rows = 0.0, []
        if two:
            rows.append(("on", 0.0, True))
        for _ in range(rnd.randint(2, 12)):
            t += rnd.choice([0.01, 0.05, 0.2])
            kind = rnd.random()
            if kind < 0.5 or not two:
                rows.append(("r", t, rnd.choice([50.0, 130.0, 130.0, -1.0])))
            else:
                rows.append(("on", t, rnd.choice([True, False])))
            t += rnd.choice([0.0, 0.003, 0.01, 0.05, 1.5])
            rows.append(("status", t, rnd.choice([green, red])))
        heard = list(rows)
        for _ in range(rnd.randint(1, 3)):  # an input heard later than it was stamped, behind some outputs
            i = rnd.choice([k for k, r in enumerate(heard) if r[0] != "status"])
            row = heard.pop(i)
            heard.insert(min(len(heard), i + rnd.randint(1, 9)), row)
        order = sorted(range(len(heard)), key=lambda k: heard[k][1])  # stamp order, equal stamps as heard
        ordered = {k.split("#")[0] + f"#{order[int(k.split('#')[1])]}": vs
                   for k, vs in _verdicts(checked, node, [heard[k] for k in order], rules).items()}
        late = _verdicts(checked, node, heard, rules)
        assert late == _verdicts(checked, node, heard, rules, batch=True), (case, heard)
        assert late == _verdicts(checked, node, heard, rules, live=True), (case, heard)
        for where, vs in ordered.items():
            if where.startswith("status") and vs == {"violated"}:
                assert late.get(where, set()) & {"violated", "inconclusive"}, (case, where, rows, heard, late)


def test_a_trigger_heard_after_its_answer_is_answered_by_it(tmp_path: Path) -> None:
    """Row 3 for deadlines: the press stamped 1.0 s is heard after the stop
    stamped 1.05 s (another reader, a later line): the stop answers it in
    50 ms.  Before: the press waited for a later stop and was "false" (no
    answer within 200 ms), a false alarm.  A stop stamped with the press but
    heard before it does not answer it (equal stamps in the order heard)."""
    ws, run = _workspace(tmp_path, STOPPER, [
        {"topic": "stop", "time": 1.05, "data": True}, {"topic": "b", "time": 1.0, "data": True},
        {"topic": "b", "time": 2.0, "data": False}])
    checked = load([ws / "contracts" / "c.rcl"])
    got: list[Any] = []
    [res] = check_deadlines(checked, [checked.nodes["Stopper"]], read_trace(run), {}, got.append)
    assert [(v.trigger_where, v.verdict, v.answer_where) for v in got] == [
        ("run.jsonl:2", "true", "run.jsonl:1"), ("run.jsonl:3", "currently_false", "")]
    run.write_text('{"topic": "stop", "time": 1.0, "data": true}\n{"topic": "b", "time": 1.0, "data": true}\n'
                   '{"topic": "b", "time": 2.0, "data": false}\n')
    [res] = check_deadlines(checked, [checked.nodes["Stopper"]], read_trace(run), {})
    assert res.counts["false"] == 1


def test_an_answer_at_exactly_the_horizon_answers_its_question(tmp_path: Path) -> None:
    """Row 9b for the untimed check: r = 50 at 0.7 s, green at 0.9 s, a horizon
    of 0.2 s.  In doubles 0.7 + 0.2 is 0.8999999999999999, and the green was
    judged but its question reported "unanswered: no output within 0.2 s".
    At the horizon, in integer nanoseconds, is within it; a nanosecond past is not."""
    lines = [{"topic": "r", "time": 0.7, "value": 50.0}, {"topic": "status", "time": 0.9, "level": "green"},
             {"topic": "r", "time": 2.0, "value": 50.0}]
    ws, run = _workspace(tmp_path, BAND, lines, skew=0)
    got = _engines(ws, run, "Band", horizon=0.2)
    assert got["events"] == got["batch"] == got["live"] == [(1, "satisfied"), (2, "open")]
    lines[1]["time"] = 0.900000001
    ws, run = _workspace(tmp_path, BAND, lines, skew=0)
    got = _engines(ws, run, "Band", horizon=0.2)
    # a nanosecond past: unanswered, and since no output had been heard yet it is not counted against the node
    # (docs/semantics.md, "Steps"); every engine says so
    assert got["events"] == got["batch"] == got["live"] == [(0, "before first answer"), (1, "satisfied"),
                                                            (2, "open")]


def test_an_answer_heard_before_its_question_within_the_skew_is_no_false_alarm(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The race of every live run: the reading r = 130 stamped 1.6 s is heard 5 ms
    after its answer, red, stamped 1.605 s.  Red is false for the reading before
    (50), so it is held for the transport skew (20 ms); the reading comes within
    it and red is judged against it: satisfied, and the reading is answered.
    Before: "violated" against r = 50, a false alarm (exit 1)."""
    ws, run = _workspace(tmp_path, BAND, [
        {"topic": "r", "time": 1.0, "value": 50.0}, {"topic": "status", "time": 1.1, "level": "green"},
        {"topic": "status", "time": 1.605, "level": "red"}, {"topic": "r", "time": 1.6, "value": 130.0},
        {"topic": "r", "time": 3.0, "value": 50.0}])
    got = _engines(ws, run, "Band", horizon=1.0)
    assert got["events"] == got["batch"] == got["live"] == [(1, "satisfied"), (2, "satisfied"), (4, "open")]
    rc, out = _monitor(ws, run, capsys, horizon="1")
    assert rc == 0 and "2 satisfied, 1 open" in out


def test_a_readable_input_heard_late_does_not_end_a_nan_stamped_after_it(tmp_path: Path) -> None:
    """Rows 3 and 9a together: r = NaN stamped 1.2 s, then r = 130 stamped 1.1 s
    heard after it.  In force from 1.2 s is the NaN: the switch's question at
    1.3 s is undecided (inconclusive), not judged on r = 130; the reading heard
    late is judged at its stamp (its question answered by nothing: superseded)."""
    lines = [{"topic": "on", "time": 0.0, "flag": True}, {"topic": "r", "time": 1.0, "value": 50.0},
             {"topic": "status", "time": 1.05, "level": "green"}, {"topic": "r", "time": 1.2, "value": "NaN"},
             {"topic": "r", "time": 1.1, "value": 130.0}, {"topic": "on", "time": 1.3, "flag": True},
             {"topic": "status", "time": 1.35, "level": "green"}, {"topic": "r", "time": 1.4, "value": 50.0},
             {"topic": "status", "time": 1.45, "level": "green"}]
    ws, run = _workspace(tmp_path, SENSOR, lines)
    run.write_text(run.read_text().replace('"NaN"', "NaN"))
    got = _engines(ws, run, "Sensor")
    assert got["events"] == got["batch"] == got["live"]
    verdicts = dict(got["events"])
    assert verdicts[3] == "inconclusive" and verdicts[5] == "inconclusive" and 6 not in verdicts
    assert verdicts[8] == "satisfied" and "violated" not in verdicts.values()
