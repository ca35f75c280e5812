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


#: JSON's scanner with :func:`json.loads`'s defaults: one object read without the
#: general entry point's checks, which :func:`read_jsonl` leaves to ``json.loads``
#: for any line the scanner does not read whole (so every error is worded as before)
_SCAN = json.JSONDecoder().scan_once  # type: ignore[attr-defined]  # set by JSONDecoder.__init__, not in the stubs
_JSON_SPACE = " \t\n\r"


def read_jsonl(path: Path) -> Iterator[Event]:
    """Stream the events of a ROSMonitoring log.

    Raises :class:`TraceError` ``file:line:col: error: ...`` on the first line
    that is not a JSON object with a string ``topic`` and a finite numeric
    ``time`` (JSON's ``NaN``/``Infinity``, which Python accepts, are refused);
    the events before it have already been yielded.

    A line that starts with ``{`` is read by JSON's scanner directly (it is
    most of a log, and ``json.loads``'s own checks cost twice the scan); any
    other line, or one the scanner does not read whole up to JSON
    whitespace, goes through ``json.loads``, which reads it, or reports it,
    exactly as before.
    """
    index = 0
    name = path.name
    scan, space, isfinite = _SCAN, _JSON_SPACE, math.isfinite
    with path.open(encoding="utf-8") as fh:
        for lineno, line in enumerate(fh, 1):
            obj: Any = None  # a line the scanner read whole (never None: it starts with '{')
            if line[:1] == "{":
                try:
                    obj, end = scan(line, 0)
                except (StopIteration, ValueError):
                    obj = None
                else:
                    rest = len(line) - end
                    if rest and not (rest == 1 and line[-1] == "\n") and line[end:].strip(space):
                        obj = None  # more than JSON whitespace after the object: json.loads says what
            if obj is None:
                if not line.strip():
                    continue
                try:
                    obj = json.loads(line)
                except json.JSONDecodeError as exc:
                    raise TraceError(f"{path}:{lineno}:{exc.colno}: error: malformed JSON: {exc.msg}") from None
                if not isinstance(obj, dict):
                    raise TraceError(f"{path}:{lineno}:1: error: expected a JSON object, got {type(obj).__name__}")
            topic, time = obj.get("topic"), obj.get("time")
            if type(topic) is not str and not isinstance(topic, str):
                raise TraceError(f"{path}:{lineno}:1: error: the event has no string 'topic'")
            if type(time) is not float and (isinstance(time, bool) or not isinstance(time, (int, float))):
                raise TraceError(f"{path}:{lineno}:1: error: the event has no numeric 'time'")
            if not isfinite(time):
                raise TraceError(f"{path}:{lineno}:1: error: the event's 'time' is {time!r}, not a finite number")
            del obj["topic"], obj["time"]  # the message's fields, in their order (the object is this line's own)
            yield Event(index, float(time), topic.lstrip("/"), obj, f"{name}:{lineno}")
            index += 1
