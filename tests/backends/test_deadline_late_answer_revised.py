"""Issue 106: a deadline answered late by its own output, then an output stamped within the skew before its trigger.

A relay's trigger is stamped 1.0 s (deadline 100 ms); the live watermark
passes the deadline unanswered (``false``), the relay's own answer, stamped
1.25 s, comes (an update: still ``false``, 150 ms late), and only then an
output stamped 0.3 ms before the trigger, published just after it and
heard 400 ms late.  The run read in stamp order puts that output before the
trigger: it satisfies the guarantee on the trigger's inputs and may be its
answer, and the trigger's own answer came after the deadline, so the
deadline is ``undecided`` (docs/semantics.md, "Deadlines": a ``false`` is
final only where no output within the skew before its trigger could have
met it).  Before, live kept the ``false`` (the late-answered obligation was
no longer kept to revise), and the run as published gave ``false`` too
(its own answer after the deadline, read before the clock passed it),
while the live run's log gave ``undecided``.  Now live, the log and the run
as published give ``undecided``, and the late answer's time margin is
withdrawn with the ``false`` (the guarantee's smallest margin is the next
trigger's).  Controls: the early output beyond the skew (30 ms before) or
wrong leaves the ``false`` and its margin on every path.

Each run goes through the live run (:class:`rclverify.runtime.live.LiveRun`),
the offline check of the run as published and of the live run's own log
(``test_deadline_heard_late``'s helpers).
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors import recorded
from rclverify.backends.monitors.config import load_mapping
from rclverify.lang.typecheck import load
from rclverify.runtime.live import LiveRun
from test_deadline_heard_late import WINDOW, _final, _line, _workspace


def _offline(ws: Path, run: Path) -> tuple[dict[str, int], dict[str, int], dict[float, str], list[Any]]:
    checked = load([ws / "contracts" / "c.rcl"])
    seen: list[dict[str, Any]] = []

    def verdict(kind: str, v: Any, _: float | None) -> None:
        if kind == "deadline":
            seen.append(v.to_json())
    got = recorded.check_recorded(checked, [checked.nodes["Relay"]], load_mapping(ws, "mapping.yaml"), ws, str(run),
                                  lambda w: None, on_verdict=verdict)
    (res,) = got.deadlines
    return dict(res.counts), dict(res.unaccepted), _final(seen), res.to_json()["time_margins"]


def _live(ws: Path, heard: list[tuple[float, dict[str, Any]]]) -> tuple[dict[str, int], dict[str, int],
                                                                         dict[float, str], list[Any], Path]:
    checked = load([ws / "contracts" / "c.rcl"])
    log = ws / "live" / "live.jsonl"
    published: list[str] = []
    run = LiveRun(checked, [checked.nodes["Relay"]], load_mapping(ws, "mapping.yaml").rules, 2.0, log,
                  reorder_window=WINDOW, publish=published.append)
    now = heard[0][0]
    for arrival, line in heard:
        while now + 0.01 <= arrival + 1e-9:
            now += 0.01
            run.tick(now)
        run.push(line["topic"], {k: v for k, v in line.items() if k not in ("topic", "time")}, line["time"])
    for _ in range(30):
        now += 0.01
        run.tick(now)
    (dl,) = run.stop()["topic_deadlines"]
    verdicts = [m for m in map(json.loads, published) if m.get("kind") == "deadline"]
    d = dl["deadlines"]
    return d["counts"], d["unaccepted"], _final(verdicts), d["time_margins"], log


def _judged(tmp: Path, heard: list[tuple[float, dict[str, Any]]]) -> dict[str, Any]:
    ws = _workspace(tmp)
    published = ws / "run.jsonl"
    published.write_text("".join(json.dumps(x) + "\n" for _, x in sorted(heard, key=lambda h: h[1]["time"])))
    *live, log = _live(ws, sorted(heard, key=lambda h: h[0]))
    return {"live": tuple(live), "offline": _offline(ws, published), "log": _offline(ws, log)}


def _run(early_stamp: float, early_value: bool = True) -> list[tuple[float, dict[str, Any]]]:
    """(arrival, line): trigger 1.0 answered late at 1.25 (heard 1.3), the early output (published 1.0005,
    stamped ``early_stamp``) heard at 1.4, and a second trigger 2.0 answered 20 ms late (its margin -20 ms)."""
    return [(1.0, _line("b", 1.0, 1.0, True)), (1.3, _line("stop", 1.25, 1.25, True)),
            (1.4, _line("stop", 1.0005, early_stamp, early_value)),
            (2.0, _line("b", 2.0, 2.0, True)), (2.2, _line("stop", 2.12, 2.12, True)),
            (2.6, _line("tick", 2.6, None, 0))]


def _margin(margins: list[Any]) -> tuple[float | None, int, int]:
    (m,) = margins
    return (None if m["margin_ns"] is None else m["margin_ns"], m["answers"], m["unanswered"])


def test_an_early_output_heard_after_the_late_answer_makes_the_deadline_undecided_live_as_offline(
        tmp_path: Path) -> None:
    got = _judged(tmp_path, _run(0.9997))
    for path in ("live", "offline", "log"):
        counts, unaccepted, finals, margins = got[path]
        assert counts == {"true": 0, "currently_false": 0, "false": 1}, (path, counts)  # the second trigger's
        assert unaccepted["undecided"] == 1, (path, unaccepted)
        assert finals == {1.0: "undecided", 2.0: "false"}, (path, finals)
        # the first trigger's late answer (-150 ms) withdrawn: the smallest margin is the second's (-20 ms)
        assert _margin(margins) == (-20_000_000, 1, 0), (path, margins)


@pytest.mark.parametrize("stamp, value, why", [(0.97, True, "30 ms before the trigger, beyond the 20 ms skew"),
                                                (0.9997, False, "a wrong output within the skew")])
def test_the_controls_beyond_the_skew_or_wrong_leave_the_false_and_its_margin(
        tmp_path: Path, stamp: float, value: bool, why: str) -> None:
    got = _judged(tmp_path, _run(stamp, value))
    for path in ("live", "offline", "log"):
        counts, unaccepted, finals, margins = got[path]
        assert counts["false"] == 2 and unaccepted["undecided"] == 0, (path, why, counts, unaccepted)
        assert finals == {1.0: "false", 2.0: "false"}, (path, why, finals)
        assert _margin(margins) == (-150_000_000, 2, 0), (path, why, margins)
