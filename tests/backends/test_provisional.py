"""Issue 106: a verdict the live run gives early is marked provisional; every other one is final.

With a lateness bound, the online engine releases a message once its
watermark has passed it (every writer heard past its time, or silent for
longer than the bound): its verdicts are then final, whatever the run does
after (a message later than the bound changes them only to undecided).
When the run stops, :meth:`OnlineEngine.finish` judges what the watermark
had not passed yet: those verdicts are marked ``provisional``
(docs/semantics.md, "Provisional verdicts").

The oracle: a fuse node (two sensors at 200 and 300 ms, an answer to each
``a`` 5-15 ms later, from the ``b`` it had) is heard with per-topic delivery
delays within the bound, on 20 seeded runs; each run is cut at a random
moment.  Every verdict the cut run gives without the mark equals the
verdict the whole run gives on the same message; the marked ones are the
only ones that may differ, and over the seeds some do (the control: the
mark is not decoration).  With no lateness bound (``--reorder-window 0``,
messages judged in the order heard) nothing is marked.
"""
from __future__ import annotations

import random
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors.check import Verdict
from rclverify.backends.monitors.config import load_mapping
from rclverify.backends.monitors.online import OnlineEngine
from rclverify.lang.typecheck import load

FUSE = """
node Fuse {
  inputs( a : REAL, b : REAL )
  outputs( alert : BOOL )
  topics( pkg/A a matches(in.a), pkg/B b matches(in.b), pkg/Alert alert matches(out.alert) )
  assume( TRUE )
  guarantee( out.alert <=> (in.a <= 1.0 and in.b >= 2.0) )
}
"""
MAPPING = "topics:\n  a: {fields: [value]}\n  b: {fields: [value]}\n  alert: {fields: [data]}\n"
WINDOW, TICK = 0.05, 0.01


def _run(rnd: random.Random, seconds: float = 4.0) -> list[tuple[float, str, float, dict[str, Any]]]:
    """(arrival, topic, source time, fields), in arrival order: each topic delivered in order
    (a reliable writer), 1-40 ms after its source time."""
    sent: list[tuple[str, float, dict[str, Any]]] = []
    bs = [(1.0 + 0.3 * k + rnd.uniform(0, 0.02), rnd.choice([1.5, 2.0, 2.5])) for k in range(int(seconds / 0.3))]
    for k in range(int(seconds / 0.2)):
        t = 1.1 + 0.2 * k + rnd.uniform(0, 0.02)
        a = rnd.choice([0.5, 1.0, 1.5])
        had = [v for s, v in bs if s < t]
        sent.append(("a", t, {"value": a}))
        if had:
            sent.append(("alert", t + rnd.uniform(0.005, 0.015), {"data": a <= 1.0 and had[-1] >= 2.0}))
    sent += [("b", s, {"value": v}) for s, v in bs]
    last: dict[str, float] = {}
    heard = []
    for topic, t, fields in sorted(sent, key=lambda x: x[1]):
        arrival = max(last.get(topic, 0.0), t + rnd.uniform(0.001, 0.04))
        last[topic] = arrival
        heard.append((arrival, topic, t, fields))
    return sorted(heard, key=lambda x: x[0])


def _judge(ws: Path, heard: list[tuple[float, str, float, dict[str, Any]]], stop: float,
           window: float = WINDOW) -> dict[str, Verdict]:
    """The live engine fed what arrived before ``stop`` (s), its timer every 10 ms, then finished:
    the latest verdict of each message (by its position in the run)."""
    checked = load([ws / "c.rcl"])
    rules = load_mapping(ws, "mapping.yaml").rules
    got: list[Verdict] = []
    eng = OnlineEngine(checked, [checked.nodes["Fuse"]], rules, 0.5, reorder_window=window, on_verdict=got.append)
    now = heard[0][0]
    for k, (arrival, topic, t, fields) in enumerate(heard):
        if arrival > stop:
            break
        while now + TICK <= arrival:
            now += TICK
            eng.tick(now)
        eng.push(topic, fields, t, f"{topic} sent at {t:.6f}")
    eng.finish()
    return {v.where: v for v in got}


@pytest.fixture(scope="module")
def ws(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("provisional")
    (d / "c.rcl").write_text(FUSE)
    (d / "mapping.yaml").write_text(MAPPING)
    return d


def test_a_verdict_not_marked_provisional_is_the_whole_runs(ws: Path) -> None:
    marked = differ = final = 0
    for seed in range(20):
        rnd = random.Random(seed)
        heard = _run(rnd)
        whole = _judge(ws, heard, float("inf"))
        cut = _judge(ws, heard, rnd.uniform(heard[0][0] + 0.5, heard[-1][0]))
        for where, v in cut.items():
            w = whole[where]
            if v.provisional:
                marked += 1
                differ += (v.verdict, v.guarantee) != (w.verdict, w.guarantee)
            else:
                final += 1
                assert (v.verdict, v.guarantee, v.question) == (w.verdict, w.guarantee, w.question), (seed, v, w)
    # the control: the cut runs' marked verdicts include some the whole run decides otherwise
    assert final > 300 and marked > 20 and differ > 0, (final, marked, differ)


def test_a_run_whose_watermark_passed_everything_has_no_provisional_verdict(ws: Path) -> None:
    heard = _run(random.Random(7))
    quiet = heard + [(heard[-1][0] + 1.0, "b", heard[-1][0] + 0.99, {"value": 1.5})]  # every writer heard past
    checked = load([ws / "c.rcl"])
    rules = load_mapping(ws, "mapping.yaml").rules
    got: list[Verdict] = []
    eng = OnlineEngine(checked, [checked.nodes["Fuse"]], rules, 0.5, reorder_window=WINDOW, on_verdict=got.append)
    now = quiet[0][0]
    for arrival, topic, t, fields in quiet:
        while now + TICK <= arrival:
            now += TICK
            eng.tick(now)
        eng.push(topic, fields, t)
    for _ in range(100):  # a second more: the watermark passes the last message
        now += TICK
        eng.tick(now)
    eng.finish()
    assert got and not [v for v in got if v.provisional]
    assert "provisional" not in got[-1].to_json()
    # the control: stopped at once after the last message, its verdicts are given early
    cut = _judge(ws, heard, float("inf"))
    early = [v for v in cut.values() if v.provisional]
    assert early and all(v.to_json().get("provisional") is True for v in early)


def test_without_a_lateness_bound_nothing_is_provisional(ws: Path) -> None:
    heard = _run(random.Random(3))
    got = _judge(ws, heard, heard[len(heard) // 2][0], window=0.0)
    assert got and not [v for v in got.values() if v.provisional]
