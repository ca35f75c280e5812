"""A first trigger heard later than the lateness bound, before every input has a value at its stamp.

docs/semantics.md, "Deadlines": a trigger message before every input has a value raises no question and
gets no deadline verdict, however late it was heard; "Event time": a message heard late is put at its own
time.  The case (seed 955 of the robot generator, tests/backends/test_generated_seed_faults.py): a
two-input node's trigger ``in.x`` stamped 1.00 s, its other input ``in.c`` stamped 1.10 s, and the
trigger heard 0.2 s after ``in.c``, past the 50 ms bound.  Read in stamp order (the recorded path, a log
or a bag) the trigger is ``incomplete input`` (no deadline verdict) and ``in.c``'s message raises a
question the node owes nothing.  Live (the online engine with its lateness bound, the deadline monitor
fed what it releases, as ``runtime/live.py`` feeds it) the same verdicts, verdict by verdict, and the
same run heard in stamp order gives them too.  The seeded defect: the deadline monitor reading a late
trigger's inputs as heard (``in.c`` already set) and the ``incomplete input`` given to ``in.c`` when it
was heard left standing: two verdicts differ, so the comparison judges something.  The same for an
answer heard before the late first trigger, and for a later input heard late (its value not in force
after a message stamped after it), each with its seeded defect.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors import deadline_questions, recorded
from rclverify.backends.monitors.config import load_mapping
from rclverify.backends.monitors.deadlines import DeadlineMonitor
from rclverify.backends.monitors.late import Late
from rclverify.backends.monitors.online import OnlineEngine
from rclverify.backends.monitors.verdict_lines import verdict_record
from rclverify.lang.typecheck import load
from rclverify.traces.events import header_stamp_ns

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
from _robot_verdicts import compare, finals  # noqa: E402

FUSE = """
node Fuse {
  inputs( x : REAL, c : REAL )
  outputs( low : BOOL )
  topics( std_msgs/Float32 x matches(in.x), std_msgs/Float32 c matches(in.c), std_msgs/Bool low matches(out.low) )
  assume( TRUE )
  guarantee( out.low <=> (in.x <= 1.0 or in.c < 2.0) ) triggered by in.x within 300 ms
}
"""

MAPPING = "topics:\n  x: {fields: [data]}\n  c: {fields: [data]}\n  low: {fields: [data]}\n"


def _msg(topic: str, stamp: float, **fields: Any) -> dict[str, Any]:
    sec = int(stamp)
    return {"topic": topic, "time": stamp, "header": {"stamp": {"sec": sec, "nanosec": round((stamp - sec) * 1e9)}},
            **fields}


#: the run in stamp order: the first trigger (x = 5, no value of c yet), c = 3, the next trigger (x = 0.5) and
#: its answer (true: x <= 1), the next (x = 4) and its answer (false: neither holds), a last message moving the clock
RUN = [_msg("x", 1.00, data=5.0), _msg("c", 1.10, data=3.0), _msg("x", 1.40, data=0.5), _msg("low", 1.45, data=True),
       _msg("x", 1.70, data=4.0), _msg("low", 1.75, data=False), _msg("c", 2.50, data=3.0)]


def _workspace(tmp: Path) -> tuple[Path, Path]:
    (tmp / "contracts").mkdir(exist_ok=True)
    (tmp / "contracts" / "c.rcl").write_text(FUSE)
    (tmp / "contracts" / "plan.yaml").write_text("contracts: [contracts/c.rcl]\n")
    (tmp / "mapping.yaml").write_text(MAPPING)
    run = tmp / "run.jsonl"
    run.write_text("".join(json.dumps(x) + "\n" for x in RUN))
    return tmp, run


def _offline(ws: Path, run: Path) -> list[dict[str, Any]]:
    """The recorded path's verdict records of the run's log (read in stamp order)."""
    checked = load([ws / "contracts" / "c.rcl"])
    cfg = load_mapping(ws, "mapping.yaml")
    got: list[dict[str, Any]] = []
    recorded.check_recorded(checked, [checked.nodes["Fuse"]], cfg, ws, str(run), lambda w: None,
                            on_verdict=lambda kind, v, stamp: got.append(verdict_record(kind, v, stamp)))
    return got


def _live(ws: Path, heard: list[tuple[float, dict[str, Any]]]) -> tuple[list[dict[str, Any]], int]:
    """The online engine (lateness bound 50 ms, timer every 10 ms) fed ``heard`` (arrival time, log line) in
    arrival order, the deadline monitor fed what it releases and the watermark: its verdict records and the
    number of messages it heard later than the bound."""
    checked = load([ws / "contracts" / "c.rcl"])
    rules = load_mapping(ws, "mapping.yaml").rules
    got: list[dict[str, Any]] = []
    released: list[Any] = []
    dm = DeadlineMonitor(checked, checked.nodes["Fuse"], rules, lambda v: got.append(verdict_record("deadline", v)),
                         horizon=2.0)

    def feed(ev: Any) -> None:
        released.append(ev)
        dm.feed(ev)

    def answer(v: Any) -> None:
        ns = header_stamp_ns(released[int(v.where.removeprefix("message "))].fields)
        got.append(verdict_record("guarantee", v, None if ns is None else ns / 1e9))
    eng = OnlineEngine(checked, [checked.nodes["Fuse"]], rules, 2.0, reorder_window=0.05, on_verdict=answer,
                       on_event=feed)
    now = heard[0][0]
    for arrival, line in sorted(heard, key=lambda x: x[0]):
        while now + 0.01 <= arrival + 1e-9:
            now += 0.01
            eng.tick(now)
            dm.advance(eng.watermark(now))
        eng.push(line["topic"], {k: v for k, v in line.items() if k not in ("topic", "time")}, line["time"])
    for _ in range(40):
        now += 0.01
        eng.tick(now)
        dm.advance(eng.watermark(now))
    eng.finish()
    dm.finish()
    return got, eng.late


#: heard late: the first trigger 0.2 s after c (1.30 s), every other message at its stamp
LATE = [(1.10, RUN[1]), (1.30, RUN[0])] + [(line["time"], line) for line in RUN[2:]]
#: the control: heard in stamp order, each at its stamp
IN_TIME = [(line["time"], line) for line in RUN]


def _by_message(records: list[dict[str, Any]]) -> dict[tuple[str, str, float], str]:
    return {(b[1], b[2], round(r["time"], 6)): r["verdict"] for b, rs in finals(records).items() for r in rs}


def test_a_late_first_trigger_gets_no_deadline_verdict_live_as_in_stamp_order(tmp_path: Path) -> None:
    ws, run = _workspace(tmp_path)
    offline = _offline(ws, run)
    got = _by_message(offline)
    # read in stamp order: the first trigger incomplete and no deadline for it; c owed nothing; the two
    # later triggers' deadlines met by their answers, both answers satisfied
    assert ("guarantee", "x", 1.0) in got and got[("guarantee", "x", 1.0)] == "incomplete input", got
    assert ("deadline", "", 1.0) not in got and ("guarantee", "c", 1.1) not in got, got
    assert got[("deadline", "", 1.4)] == "true" and got[("guarantee", "low", 1.45)] == "satisfied", got
    assert got[("deadline", "", 1.7)] == "true" and got[("guarantee", "low", 1.75)] == "satisfied", got
    live, late = _live(ws, LATE)
    assert late == 1  # the first trigger did come after the watermark
    assert [d.text(("live", "log")) for d in compare(finals(live), finals(offline))] == []
    # given when heard, then withdrawn once the late trigger gave c's message every input at its stamp
    assert [r["verdict"] for r in live if r["topic"] == "c" and r["time"] == 1.1] == ["incomplete input", "withdrawn"]


def test_the_control_the_same_run_heard_in_time_gives_the_same_verdicts(tmp_path: Path) -> None:
    ws, run = _workspace(tmp_path)
    offline = _offline(ws, run)
    live, late = _live(ws, IN_TIME)
    assert late == 0
    assert [d.text(("live", "log")) for d in compare(finals(live), finals(offline))] == []
    assert _by_message(live) == _by_message(_live(ws, LATE)[0])


def test_the_seeded_defect_inputs_read_as_heard_make_live_differ(tmp_path: Path,
                                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    """The deadline monitor reading a late trigger's inputs as heard, and a completed message's
    ``incomplete input`` left standing: the first trigger's deadline ``true`` live (answered by the
    next trigger's answer), c's message ``incomplete input``: the comparison finds both."""
    ws, run = _workspace(tmp_path)
    offline = _offline(ws, run)
    monkeypatch.setattr(deadline_questions, "inputs_at", lambda mon, stamp, ns, mine: {
        k: v for k, v in mon.values.items() if k.startswith("in.")})
    monkeypatch.setattr(Late, "_incomplete_withdrawn", lambda self, e, by: None)
    live, _ = _live(ws, LATE)
    found = {(d.item, d.topic, round(d.time, 6)) for d in compare(finals(live), finals(offline))}
    assert found == {("deadline", "(guarantee 1)", 1.0), ("guarantee", "c", 1.1)}, found


COMPLETE = [_msg("c", 0.95, data=3.0), _msg("x", 1.00, data=0.5), _msg("low", 1.05, data=True),
            _msg("c", 2.50, data=3.0)]
#: the trigger heard 0.3 s late, after its answer
COMPLETE_LATE = [(0.95, COMPLETE[0]), (1.06, COMPLETE[2]), (1.30, COMPLETE[1]), (2.50, COMPLETE[3])]


@pytest.mark.parametrize("defect", [False, True])
def test_a_late_first_trigger_with_every_input_at_its_stamp_gets_its_deadline_and_its_answer(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, defect: bool) -> None:
    """The other control: c stamped 0.95 s, before the trigger, heard in time; the trigger (x = 0.5) heard
    0.3 s late, after its answer stamped 1.05 s (true).  Every input has a value at its stamp: a question,
    its deadline ``true`` and its answer ``satisfied``, live as in stamp order (the inputs at its stamp
    come from the messages before the first question; the answer, ``unasked`` when judged, is judged
    against the late question when it is placed).  The seeded defect: the answer's ``unasked`` forgotten,
    so the late question's revision finds no verdict to replace and gives none: live differs on it."""
    ws, log = _workspace(tmp_path)
    log.write_text("".join(json.dumps(x) + "\n" for x in COMPLETE))
    offline = _offline(ws, log)
    got = _by_message(offline)
    assert got[("deadline", "", 1.0)] == "true" and got[("guarantee", "low", 1.05)] == "satisfied", got
    if defect:
        answers_late = Late._answers_late

        def forgetting(self: Any, *args: Any) -> None:
            self._unasked.clear()
            answers_late(self, *args)
        monkeypatch.setattr(Late, "_answers_late", forgetting)
    live, late = _live(ws, COMPLETE_LATE)
    assert late == 1
    found = [(d.item, d.topic, round(d.time, 6)) for d in compare(finals(live), finals(offline))]
    assert found == ([("guarantee", "low", 1.05)] if defect else []), found


#: a later input heard late (not the first): c = 3 stamped 1.00 s heard at 1.20 s, after c = 1 stamped 1.10 s;
#: the trigger at 1.30 s (x = 5) reads c = 1 (in force at its stamp): its answer true meets its deadline
LATER = [_msg("c", 0.90, data=3.0), _msg("x", 0.95, data=5.0), _msg("low", 0.97, data=False),
         _msg("c", 1.00, data=3.0), _msg("c", 1.10, data=1.0), _msg("x", 1.30, data=5.0), _msg("low", 1.35, data=True),
         _msg("c", 2.50, data=1.0)]


class _Forgetful(dict[str, int]):
    """The seeded defect's stamps of the inputs in force: none kept, so a message heard late sets its value."""

    def get(self, key: str, default: Any = None) -> Any:
        return default


@pytest.mark.parametrize("defect", [False, True])
def test_an_input_heard_late_leaves_the_value_stamped_after_it_in_force(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, defect: bool) -> None:
    """c = 3 stamped 1.00 s, heard 0.2 s late after c = 1 stamped 1.10 s: read in stamp order the trigger at
    1.30 s has c = 1, and its answer ``true`` meets the deadline; c's late message raises a question owed
    nothing (the guarantee answers ``in.x``): no verdict of its own, as in order, not ``superseded``.  Live
    gives the same verdicts.  The seeded defect: the deadline monitor lets the late message set c = 3 in
    force, the trigger is judged on it and its deadline is ``false`` live."""
    ws, log = _workspace(tmp_path)
    log.write_text("".join(json.dumps(x) + "\n" for x in LATER))
    offline = _offline(ws, log)
    got = _by_message(offline)
    assert got[("deadline", "", 1.3)] == "true" and ("guarantee", "c", 1.0) not in got, got
    if defect:
        init = DeadlineMonitor.__init__

        def forgetful(self: Any, *args: Any, **kw: Any) -> None:
            init(self, *args, **kw)
            self.set_ns = _Forgetful()
        monkeypatch.setattr(DeadlineMonitor, "__init__", forgetful)
    heard = [(line["time"], line) for line in LATER]
    heard[3] = (1.20, LATER[3])
    live, late = _live(ws, heard)
    assert late == 1
    found = [(d.item, d.topic, round(d.time, 6)) for d in compare(finals(live), finals(offline))]
    assert found == ([("deadline", "(guarantee 1)", 1.3)] if defect else []), found
