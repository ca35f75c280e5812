"""Issue 106: a ``superseded`` given to a question placed by an input heard late is provisional, live as on its log.

A node fuses two inputs (``out.r == in.x + in.y``) and copies the stamp of
the question it answers onto its answer, published 450 ms later.  The
reading ``y`` stamped 1.2 s reaches the monitor 160 ms after it was
published, later than the 50 ms lateness bound: by then the reading ``x``
stamped 1.3 s has raised its question, so ``y``'s question is placed at its
stamp, before it, with no output answering it yet (:mod:`rclverify.backends.monitors.late`,
``_place``): ``superseded``.  Its answer, stamped 1.2 s, may still come: the
node's writer has not been heard past 1.2 s (its first answer not heard
yet).  It comes 290 ms later; the run read in stamp order (the live run's
log, the run as published) puts it before ``x``'s question, so ``y``'s
question is answered and has no verdict of its own.  Live, the
``superseded`` goes out ``provisional`` and that answer withdraws it (a
``withdrawn`` verdict follows), as fault 8's fix does for a question raised
in order (``test_superseded_withdrawn``).  Before, it was final and stayed:
live had one ``superseded`` more than its log.  The control: the node never
answers ``y``'s question, which stays ``superseded`` (provisional live,
never withdrawn) on every path.

Each run goes through the live run (:class:`rclverify.runtime.live.LiveRun`,
its timer every 10 ms) and the offline check of the run as published and
of the live run's own log; each message's final verdict is compared by its
topic and header stamp.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from rclverify.backends.monitors import recorded
from rclverify.backends.monitors.config import load_mapping
from rclverify.lang.typecheck import load
from rclverify.runtime.live import LiveRun
from rclverify.traces.events import Event, header_stamp
from test_judge_event_time import _msg

FUSE = """
node Fuse {
  inputs( x : REAL, y : REAL )
  outputs( r : REAL )
  topics( pkg/Reading x matches(in.x), pkg/Reading y matches(in.y), pkg/Range r matches(out.r) )
  assume( TRUE )
  guarantee( out.r == in.x + in.y )
}
"""
MAPPING = "topics:\n  x: {fields: [value]}\n  y: {fields: [value]}\n  r: {fields: [range]}\n"

Final = dict[tuple[str, float], str]


def _run(answer_y: bool) -> list[tuple[float, dict[str, Any]]]:
    """(arrival, line): ``y`` 0.9, ``x`` 1.0 and 1.3 heard at once, ``y`` stamped 1.2 heard at 1.36 (late),
    the answers (their question's stamp copied) 450 ms after their questions; ``answer_y``: ``y``'s too."""
    heard = [(0.901, _msg("y", 0.9, 0.9, value=1.0)), (1.001, _msg("x", 1.0, 1.0, value=0.0)),
             (1.301, _msg("x", 1.3, 1.3, value=3.0)), (1.36, _msg("y", 1.2, 1.2, value=1.0)),
             (1.451, _msg("r", 1.45, 1.0, range=1.0)), (1.751, _msg("r", 1.75, 1.3, range=4.0)),
             (3.0, _msg("tick", 3.0, None, data=0))]
    if answer_y:
        heard.append((1.651, _msg("r", 1.65, 1.2, range=1.0)))
    return sorted(heard, key=lambda h: h[0])


def _workspace(tmp: Path) -> Path:
    (tmp / "contracts").mkdir()
    (tmp / "contracts" / "c.rcl").write_text(FUSE)
    (tmp / "contracts" / "plan.yaml").write_text("contracts: [contracts/c.rcl]\n")
    (tmp / "mapping.yaml").write_text(MAPPING)
    return tmp


def _live(ws: Path, heard: list[tuple[float, dict[str, Any]]]) -> tuple[Final, list[dict[str, Any]], Path]:
    """Each message's final verdict live (none where the last is ``withdrawn``), every verdict published, the log."""
    checked = load([ws / "contracts" / "c.rcl"])
    log = ws / "live" / "live.jsonl"
    published: list[str] = []
    run = LiveRun(checked, [checked.nodes["Fuse"]], load_mapping(ws, "mapping.yaml").rules, 1.0, log,
                  reorder_window=0.05, publish=published.append)
    placed: dict[int, tuple[str, float]] = {}  # event index -> (topic, its header stamp)
    write = run.engine.on_event

    def event(ev: Event) -> None:
        stamp = header_stamp(ev.fields)
        placed[ev.index] = (ev.topic, ev.time if stamp is None else stamp)
        if write is not None:
            write(ev)
    run.engine.on_event = event
    now = heard[0][0]
    for arrival, line in heard:
        while now + 0.01 <= arrival + 1e-9:
            now += 0.01
            run.tick(now)
        run.push(line["topic"], {k: v for k, v in line.items() if k not in ("topic", "time")}, line["time"])
    for _ in range(100):
        now += 0.01
        run.tick(now)
    run.stop()
    verdicts = [m for m in map(json.loads, published) if m.get("node") == "Fuse"]
    last = {placed[v["event"]]: v["verdict"] for v in verdicts}
    return {k: v for k, v in last.items() if v != "withdrawn"}, verdicts, log


def _offline(ws: Path, run: Path) -> Final:
    """Each message's final verdict as ``rclverify monitor RUN`` judges ``run``."""
    checked = load([ws / "contracts" / "c.rcl"])
    got: Final = {}

    def verdict(kind: str, v: Any, stamp: float | None) -> None:
        if kind != "deadline":
            got[(v.topic.strip("/"), v.time if stamp is None else stamp)] = v.verdict
    recorded.check_recorded(checked, [checked.nodes["Fuse"]], load_mapping(ws, "mapping.yaml"), ws, str(run),
                            lambda w: None, on_verdict=verdict)
    return got


def _judged(tmp: Path, answer_y: bool) -> tuple[Final, list[dict[str, Any]], Final, Final]:
    ws = _workspace(tmp)
    heard = _run(answer_y)
    published = ws / "run.jsonl"
    published.write_text("".join(json.dumps(x) + "\n" for _, x in sorted(heard, key=lambda h: h[1]["time"])))
    live, verdicts, log = _live(ws, heard)
    return live, verdicts, _offline(ws, published), _offline(ws, log)


def _on_y(verdicts: list[dict[str, Any]]) -> list[tuple[str, bool]]:
    """The verdicts published on the late ``y``'s message (where: its place in the live run)."""
    where = next(v["where"] for v in verdicts if v["verdict"] == "superseded" and "heard after messages" in v["reason"])
    return [(v["verdict"], bool(v.get("provisional"))) for v in verdicts if v["where"] == where]


def test_a_question_placed_late_superseded_early_is_withdrawn_by_its_answer_live_as_on_its_log(
        tmp_path: Path) -> None:
    live, verdicts, offline, log = _judged(tmp_path, answer_y=True)
    assert ("y", 1.2) not in offline and "superseded" not in offline.values(), offline  # answered: none of its own
    assert live == offline == log, (live, offline, log)
    assert _on_y(verdicts) == [("superseded", True), ("withdrawn", False)], verdicts
    assert all("answers that one by its header stamp" in v["reason"] for v in verdicts if v["verdict"] == "withdrawn")


def test_the_control_a_question_placed_late_never_answered_stays_superseded_live_as_on_its_log(
        tmp_path: Path) -> None:
    live, verdicts, offline, log = _judged(tmp_path, answer_y=False)
    assert offline[("y", 1.2)] == "superseded", offline
    assert live == offline == log, (live, offline, log)
    assert _on_y(verdicts) == [("superseded", True)], verdicts  # provisional when given, never withdrawn
