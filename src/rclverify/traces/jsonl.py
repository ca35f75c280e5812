"""ROSMonitoring's offline log: one JSON object per line.

ROSMonitoring's monitors log every observed message as a JSON object with
the keys ``topic`` and ``time`` and the message's fields flattened beside
them (its ``log`` action).  Blank lines are skipped.
"""
from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, Iterator

from .events import Event, TraceError


def read_jsonl(path: Path) -> Iterator[Event]:
    """Stream the events of a ROSMonitoring log.

    Raises :class:`TraceError` ``file:line:col: error: ...`` on the first line
    that is not a JSON object with a string ``topic`` and a finite numeric
    ``time`` (JSON's ``NaN``/``Infinity``, which Python accepts, are refused);
    the events before it have already been yielded.
    """
    index = 0
    with path.open(encoding="utf-8") as fh:
        for lineno, line in enumerate(fh, 1):
            if not line.strip():
                continue
            try:
                obj: Any = json.loads(line)
            except json.JSONDecodeError as exc:
                raise TraceError(f"{path}:{lineno}:{exc.colno}: error: malformed JSON: {exc.msg}") from None
            if not isinstance(obj, dict):
                raise TraceError(f"{path}:{lineno}:1: error: expected a JSON object, got {type(obj).__name__}")
            topic, time = obj.get("topic"), obj.get("time")
            if not isinstance(topic, str):
                raise TraceError(f"{path}:{lineno}:1: error: the event has no string 'topic'")
            if isinstance(time, bool) or not isinstance(time, (int, float)):
                raise TraceError(f"{path}:{lineno}:1: error: the event has no numeric 'time'")
            if not math.isfinite(time):
                raise TraceError(f"{path}:{lineno}:1: error: the event's 'time' is {time!r}, not a finite number")
            fields = {k: v for k, v in obj.items() if k not in ("topic", "time")}
            yield Event(index, float(time), topic.lstrip("/"), fields, f"{path.name}:{lineno}")
            index += 1
