"""Issue 106, fault 8: a ``superseded`` the live run gives early is provisional and withdrawn when its answer comes.

A relay copies its reading's header stamp onto an answer it publishes 450 ms
later, after the next reading (one every 300 ms).  Its first answer reaches
the live engine later than the lateness bound: its writer, not heard yet,
held no watermark back, so the next reading was released first and the
first reading got ``superseded``.  The run read in stamp order (the recorded
path) puts that answer before the next reading: the first reading is
answered and has no verdict of its own.  Live, the ``superseded`` goes out
``provisional`` (a writer of the node's outputs not heard past the reading
yet, :attr:`NodeMonitor.answers_heard_past`) and the late answer, paired
with the reading by its copied stamp, withdraws it (a ``withdrawn`` verdict
on the reading's message, the count back by one): the final live verdicts
are the recorded path's, verdict by verdict, and so are the counts.

The controls: a reading the relay never answers (its first answer, as late,
copies the next reading's stamp) is ``superseded`` offline, and stays
``superseded`` live (provisional, never withdrawn); a reading skipped once
the relay's writer has been heard is ``superseded`` on both paths and final
live (not provisional).  The online engine is fed the messages in the order
they reach the monitor (1 ms after publication), its timer every 10 ms, as
:mod:`rclverify.runtime.live` does.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

from rclverify.backends.monitors.check import NodeResult, Verdict
from rclverify.backends.monitors.config import load_mapping
from rclverify.backends.monitors.online import OnlineEngine
from rclverify.lang.typecheck import load
from test_judge_event_time import _msg, _workspace
from test_judge_writers import COPY, COPY_MAPPING, PERIOD, WINDOW, _verdicts_offline

DELAY = 0.45


def _relay(skip: frozenset[int] = frozenset(), n: int = 10) -> list[dict[str, Any]]:
    """Readings ``i`` every 300 ms from 1 s, each copied 450 ms later onto an answer carrying its
    stamp, but for the readings ``skip`` (no answer)."""
    sent = []
    for i in range(n):
        t = 1.0 + i * PERIOD
        sent.append(_msg("x", t, t, value=float(i)))
        if i not in skip:
            sent.append(_msg("r", t + DELAY, t, range=float(i)))
    sent.append(_msg("tick", 1.0 + n * PERIOD + 3.0, None, data=0))
    return sorted(sent, key=lambda x: x["time"])


def _live(ws: Path, lines: list[dict[str, Any]]) -> tuple[list[Verdict], NodeResult]:
    """Every verdict the online engine gives, in order, and the node's result."""
    checked = load([ws / "contracts" / "c.rcl"])
    rules = load_mapping(ws, "mapping.yaml").rules
    got: list[Verdict] = []
    eng = OnlineEngine(checked, [checked.nodes["Relay"]], rules, 1.0, reorder_window=WINDOW, on_verdict=got.append)
    now = lines[0]["time"]
    for k, line in enumerate(lines):
        while now + 0.01 <= line["time"] + 0.001:
            now += 0.01
            eng.tick(now)
        eng.push(line["topic"], {x: v for x, v in line.items() if x not in ("topic", "time")}, line["time"],
                 f"run.jsonl:{k + 1}")
    (result,) = eng.finish()
    return got, result


def _final(got: list[Verdict]) -> list[tuple[str, str]]:
    """Each message's last verdict, none where it is ``withdrawn`` (bench/_robot_verdicts.py ``finals``)."""
    last = {v.where: v.verdict for v in got}
    return sorted((w, v) for w, v in last.items() if v != "withdrawn")


def _offline_counts(ws: Path, run: Path) -> dict[str, int]:
    from rclverify.backends.monitors.recorded import check_recorded
    checked = load([ws / "contracts" / "c.rcl"])
    got = check_recorded(checked, [checked.nodes["Relay"]], load_mapping(ws, "mapping.yaml"), ws, str(run),
                         lambda w: None)
    return dict(got.results[0].counts)


def test_the_first_reading_superseded_early_is_withdrawn_by_its_late_answer(tmp_path: Path) -> None:
    lines = _relay()
    ws, run = _workspace(tmp_path, COPY, lines, COPY_MAPPING)
    offline = _verdicts_offline(ws, run)
    assert [v for _, v in offline] == ["satisfied"] * 10, offline  # one per answer
    assert "run.jsonl:1" not in dict(offline)  # the first reading: answered, no verdict of its own
    got, result = _live(ws, lines)
    on_first = [(v.verdict, v.provisional) for v in got if v.where == "run.jsonl:1"]
    assert on_first == [("superseded", True), ("withdrawn", False)], on_first
    withdrawn = next(v for v in got if v.verdict == "withdrawn")
    assert "answers that one by its header stamp" in withdrawn.reason and "withdrawn" in withdrawn.reason
    assert _final(got) == offline
    assert result.counts["superseded"] == 0 and result.counts == _offline_counts(ws, run), result.counts


def test_the_control_a_reading_never_answered_stays_superseded_live_as_offline(tmp_path: Path) -> None:
    """The relay's first answer, as late, copies the second reading's stamp: it answers that one, and
    the first reading stays ``superseded`` (given early, so provisional) on both paths, never withdrawn."""
    lines = _relay(skip=frozenset({0}))
    ws, run = _workspace(tmp_path, COPY, lines, COPY_MAPPING)
    offline = _verdicts_offline(ws, run)
    assert dict(offline)["run.jsonl:1"] == "superseded", offline
    got, result = _live(ws, lines)
    assert [(v.verdict, v.provisional) for v in got if v.where == "run.jsonl:1"] == [("superseded", True)]
    # the second reading, superseded as early by the third, is the one the late answer withdraws
    assert [v.where for v in got if v.verdict == "withdrawn"] == ["run.jsonl:2"]
    assert _final(got) == offline
    assert result.counts["superseded"] == 1 and result.counts == _offline_counts(ws, run), result.counts


def test_the_control_a_reading_skipped_once_the_relay_was_heard_is_superseded_and_final(tmp_path: Path) -> None:
    """Reading 5 unanswered, the relay's writer heard long before: ``superseded`` live, not provisional,
    as offline; the first reading's early one is withdrawn as above."""
    lines = _relay(skip=frozenset({5}))
    ws, run = _workspace(tmp_path, COPY, lines, COPY_MAPPING)
    offline = _verdicts_offline(ws, run)
    assert [v for _, v in offline].count("superseded") == 1, offline
    got, result = _live(ws, lines)
    superseded = [v for v in got if v.verdict == "superseded"]
    assert [(v.where, v.provisional) for v in superseded] == [("run.jsonl:1", True), (
        next(w for w, v in offline if v == "superseded"), False)], superseded
    assert _final(got) == offline
    assert result.counts == _offline_counts(ws, run), result.counts
