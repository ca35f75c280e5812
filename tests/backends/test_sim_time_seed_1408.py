"""Generated seed 1408 with a seeded defect (8 nodes, rclpy source beside a CPU burner, ``/clock`` at x0.5
from 100 s changing to x1, every node under ``use_sim_time``), kept as its live log and its bag.

Alarm4 answers 1.3 of its 1.2 s deadline after each reading in simulated time (the seeded ``late``
node).  Its last reading before the run ended was due at 107.858 s on ``/clock``, which ``/clock`` passed
at 1795924736.595 s.  Live, a ``/clock`` message was heard 53 ms after the watermark passed it (its log
line carries ``late_s``); the deadline monitor learned when ``/clock`` passed that deadline only from a
message released after its own clock had gone past it, and left the obligation ``currently_false`` at
the run's end ("-27 ms left"), where the log and the bag, read in stamp order, give ``false``: live !=
log.  A ``/clock`` message heard late now expires what it shows passed at the monitor's clock
(backends/monitors/deadlines.py; the unit case and its control:
tests/backends/test_deadline_sim_time.py).  Here: the log's lines fed in the order the live run released
them (a late line at the clock it came at, its publication as its stamp, as the engine releases it) give
that obligation ``false``, as the log and the bag read offline do."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from rclverify.backends.monitors.config import load_mapping
from rclverify.backends.monitors.deadline_records import DeadlineVerdict
from rclverify.backends.monitors.deadlines import DeadlineMonitor
from rclverify.backends.monitors.recorded import check_recorded
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.traces.events import Event

WS = Path(__file__).resolve().parents[1] / "data" / "robot_seed1408"
TRIGGER = 1795924735.398516  # the last reading's stamp on the run's clock


def _checked() -> tuple[Any, Any]:
    rcl = (WS / "contracts" / "robot.rcl").read_text()
    return check([parse_text(rcl, "robot.rcl")]), load_mapping(WS, "mapping.yaml")


def _verdict_at(seen: list[DeadlineVerdict], finished: list[DeadlineVerdict]) -> str:
    at = [v for v in [*seen, *finished] if abs(v.trigger_stamp - TRIGGER) < 1e-6]
    assert at, [v.trigger_stamp for v in seen][-5:]
    return at[-1].verdict


def _released(lines: list[dict[str, Any]]) -> list[Event]:
    """The log's lines as the live engine released them: in the order written, a line heard later than the
    bound (``late_s``) at the clock it came at, its publication as its stamp."""
    out, clock = [], float("-inf")
    for k, x in enumerate(lines):
        fields = {f: v for f, v in x.items() if f not in ("topic", "time", "late_s")}
        t = float(x["time"])
        if "late_s" in x and t < clock:
            out.append(Event(k, clock, x["topic"], fields, f"live:{k + 1}", stamp=t, source=t, late=x["late_s"]))
        else:
            clock = max(clock, t)
            out.append(Event(k, t, x["topic"], fields, f"live:{k + 1}"))
    return out


def test_the_live_release_order_gives_the_deadline_the_log_gives() -> None:
    checked, cfg = _checked()
    lines = [json.loads(x) for x in (WS / "runs" / "live.jsonl").read_text().splitlines()]
    assert [x["topic"] for x in lines if "late_s" in x] == ["clock"]  # the one message heard late
    seen: list[DeadlineVerdict] = []
    mon = DeadlineMonitor(checked, checked.nodes["Alarm4"], cfg.rules, seen.append, horizon=cfg.horizon)
    for ev in _released(lines):
        mon.feed(ev)
    finished = mon.pending_verdicts()
    mon.finish()
    assert _verdict_at(seen, finished) == "false"


def test_the_log_and_the_bag_read_offline_give_it_false() -> None:
    checked, cfg = _checked()
    for trace in ("runs/live.jsonl", "runs/bag"):
        got: list[DeadlineVerdict] = []
        check_recorded(checked, [checked.nodes["Alarm4"]], cfg, WS, str(WS / trace), lambda w: None,
                       on_verdict=lambda kind, v, stamp: got.append(v) if kind == "deadline" else None)
        assert _verdict_at(got, []) == "false", trace
