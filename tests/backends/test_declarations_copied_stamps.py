"""``progress( within K steps )`` where a node's answers are placed before their publication.

An output placed at a stamp older than its publication (a stamp copied from a question, a clock
standing still: ``Event.source`` later than its place, docs/semantics.md "Event time") may answer
any question asked until it was published.  A row of more than K accepted steps with no output
placed among it, but as many such outputs published among them as bring the row within K, is not
decided: ``inconclusive`` with why, never ``false`` (three relays' answers so placed while the
``/clock`` was paused gave ``false`` at three correct relays: generated seed 1147,
tests/backends/test_clock_paused_seed_1147.py).  The
controls stay ``false``: a relay answering none of its readings there, and one whose copies were
published before the row began.
"""
from __future__ import annotations

from typing import Any

from rclverify.backends.monitors.declarations import check_declarations
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.traces.events import Event

RELAY = """node Relay {
  inputs( x : REAL )
  outputs( r : REAL )
  topics( std_msgs/Float32 s matches(in.x), std_msgs/Float32 r matches(out.r) )
  assume( TRUE )
  guarantee( out.r == in.x )
  progress( within 2 steps )
}
"""
PERIOD = 0.2  # s between readings
DELAY = 0.025  # s from a reading to its answer


def _run(paused: str) -> list[Event]:
    """Ten readings, each answered 25 ms later, but readings 5-7: ``paused="copies"`` answered by
    outputs placed at the answer to reading 4 (published 25 ms after their own reading);
    ``"none"`` not answered; ``"early"``: their three copies published before reading 5."""
    evs: list[Event] = []

    def add(t: float, topic: str, v: float, stamp: float | None = None, source: float | None = None) -> None:
        evs.append(Event(len(evs), t, topic, {"data": v}, f"run: message {len(evs)}", stamp, source))

    at4 = 4 * PERIOD + DELAY
    for i in range(10):
        t = i * PERIOD
        add(t, "s", float(i))
        if i < 5 or i > 7:
            add(t + DELAY, "r", float(i))
        if i == 4 and paused != "none":  # the copies, placed here at the answer to reading 4
            for k in (5, 6, 7):
                published = (k * PERIOD + DELAY) if paused == "copies" else at4 + 0.01 * (k - 4)
                add(at4, "r", float(k), at4, published)
    return evs


def _progress(paused: str) -> Any:
    c = check([parse_text(RELAY, "relay.rcl")])
    [row] = check_declarations(c, c.nodes["Relay"], _run(paused), {}).rows()
    return row


def test_a_row_its_copies_published_among_may_answer_is_inconclusive_with_why() -> None:
    row = _progress("copies")
    assert row["verdict"] == "inconclusive", row
    assert "3 such message(s)" in row["reason"] and "may answer them" in row["reason"], row["reason"]


def test_control_a_relay_answering_none_of_three_readings_is_false() -> None:
    row = _progress("none")
    assert row["verdict"] == "false" and "3 accepted steps in a row unanswered" in row["reason"], row


def test_control_copies_published_before_the_row_answer_none_of_it() -> None:
    row = _progress("early")
    assert row["verdict"] == "false" and "3 accepted steps in a row unanswered" in row["reason"], row
