"""A lateness column for the batch path's random oracles: messages of a run marked as heard later than the
lateness bound, as a live log's ``late_s`` marks them (docs/semantics.md, "Event time")."""
from __future__ import annotations

import random

from rclverify.traces.events import Event


def heard_late(events: list[Event], rnd: random.Random, p: float) -> list[Event]:
    """``events``, each marked heard late with probability ``p`` (by 20 ms, 80 ms or 0.3 s: past a 5 ms
    horizon and the next questions' stamps); ``rnd`` draws only these, so a run's other draws stay its own."""
    return [Event(ev.index, ev.time, ev.topic, ev.fields, ev.where, ev.stamp, ev.source,
                  rnd.choice([0.02, 0.08, 0.3])) if rnd.random() < p else ev for ev in events]
