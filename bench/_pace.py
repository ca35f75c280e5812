"""Publishing at a fixed rate, shared by the live monitor benches (ROS 1 and DDS)."""
from __future__ import annotations

import time
from typing import Any, Callable, Sequence


def paced(msgs: Sequence[tuple[str, Any]], rate: float, seconds: float,
          send: Callable[[str, Any], None]) -> tuple[list[tuple[str, float]], float]:
    """Send ``rate * seconds`` messages, cycling through ``msgs`` ((topic,
    message) pairs), each at its due time ``k / rate`` s after the start
    (rate in messages/s).  Returns the (topic, wall-clock send time in s)
    of each, and the elapsed monotonic seconds."""
    n = int(rate * seconds)
    sent: list[tuple[str, float]] = []
    start = time.monotonic()
    for k in range(n):
        wait = start + k / rate - time.monotonic()
        if wait > 0:
            time.sleep(wait)
        topic, msg = msgs[k % len(msgs)]
        t = time.time()
        send(topic, msg)
        sent.append((topic, t))
    return sent, time.monotonic() - start
