"""ROSMonitoring's offline log: one JSON object per line.

ROSMonitoring's monitors log every observed message as a JSON object with
the keys ``topic`` and ``time`` and the message's fields flattened beside
them (its ``log`` action).  Blank lines are skipped.

A line is read by msgspec's JSON decoder (compiled, strict RFC 8259, about
four times JSON's scanner) when it can be: it reads every JSON text that
Python's ``json`` reads to the same value (floats correctly rounded,
integers of any size exact, duplicate keys the last, strings alike:
compared on 300,000 random numbers and the corner cases of
``tests/traces/test_traces.py``), and rejects what ``json`` reads beyond the
standard (``NaN``, ``Infinity``, numbers that overflow to infinity, lone
surrogates).  A line it rejects is read again by the scanner and
``json.loads`` path below, as before: the same events, the same errors.
Bytes that are not UTF-8 are a located error.  (orjson was measured too: it
reads an integer beyond 64 bits as a float, which a log's exact semantics
cannot take unchecked; docs/monitors.md.)
"""
from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Any, Iterable, Iterator, cast

import msgspec

from rclverify.traces.events import FLAT_STAMPS, Event, TraceError, header_stamp


#: JSON's scanner with :func:`json.loads`'s defaults: one object read without the
#: general entry point's checks, which :func:`read_jsonl` leaves to ``json.loads``
#: for any line the scanner does not read whole (so every error is worded as before)
_SCAN = json.JSONDecoder().scan_once  # type: ignore[attr-defined]  # set by JSONDecoder.__init__, not in the stubs
_JSON_SPACE = " \t\n\r"
#: One compiled decoder, any JSON value (module docstring).
_FAST = msgspec.json.Decoder().decode
_FAST_ERROR = (msgspec.DecodeError, ValueError)  # ValueError: bytes that are not UTF-8, among others
#: The largest finite float: an integer 'time' beyond it has no float (its seconds would be infinite).
_MAX_FLOAT = sys.float_info.max


def read_jsonl(path: Path) -> Iterator[Event]:
    """Stream the events of a ROSMonitoring log.

    Raises :class:`TraceError` ``file:line:col: error: ...`` on the first line
    that is not a JSON object with a string ``topic`` and a finite numeric
    ``time`` (JSON's ``NaN``/``Infinity``, which Python accepts, are refused);
    the events before it have already been yielded.

    Each line is read by msgspec (module docstring); a line msgspec
    rejects goes to JSON's scanner (``json.loads``'s
    own checks cost twice the scan); any other line, or one the scanner
    does not read whole up to JSON whitespace, goes through ``json.loads``,
    which reads it, or reports it, as before.  Bytes that are not UTF-8
    raise a located :class:`TraceError`.
    """
    with path.open("rb") as fh:
        yield from read_lines(path, fh)


def read_lines(path: Path, chunks: Iterable[bytes], lineno: int = 0, index: int = 0,
               end: list[int] | None = None) -> Iterator[Event]:
    """The events of some lines of the log at ``path``, as :func:`read_jsonl` reads them.

    ``chunks``: the log's bytes split after each ``b"\\n"`` (a file opened
    ``"rb"``, or the lines of a block, :mod:`.jsonl_blocks`); a bare
    ``b"\\r"`` inside a chunk also ends a line.  ``lineno``: the lines before
    the first (1-based numbers follow it), ``index``: the events before it.
    ``end``, when given, is set to ``[lineno, index]`` after the last line
    read (also when a line raises).  Raises :class:`TraceError` as
    :func:`read_jsonl`.
    """
    name = path.name
    fast, fast_error, slow, inf, flat = _FAST, _FAST_ERROR, _slow, math.inf, FLAT_STAMPS
    try:
        for chunk in chunks:  # split at b"\n"; a bare b"\r" also ends a line (universal newlines, as text mode read it)
            for raw in chunk.splitlines(True) if b"\r" in chunk else (chunk,):
                lineno += 1
                try:
                    obj: Any = fast(raw)
                except fast_error:
                    obj = None
                except RecursionError:  # a value nested deeper than any reader goes
                    raise TraceError(f"{path}:{lineno}:1: error: the line nests arrays or objects too deeply to "
                                     "read (thousands of levels); no message is that deep") from None
                if type(obj) is not dict:  # what msgspec rejects, a blank line, or a value that is no object
                    obj = slow(path, lineno, raw)
                    if obj is None:
                        continue
                topic, time = obj.get("topic"), obj.get("time")
                if not (type(time) is float and type(topic) is str and -inf < time < inf):
                    time = _checked(path, lineno, topic, time)
                del obj["topic"], obj["time"]  # the message's fields, in their order (the object is this line's own)
                # a header's stamp is the message's own time: what it answers is decided by it (docs/semantics.md)
                stamp = header_stamp(obj) if "header" in obj or flat[0] in obj or flat[1] in obj else None
                # heard later than the live lateness bound (the live log says how long after its time)
                late = obj.pop("late_s") if "late_s" in obj else 0.0
                yield Event(index, float(time), topic.lstrip("/"), obj, f"{name}:{lineno}", stamp,
                            late=late if type(late) is float and late > 0 else 0.0)
                index += 1
    finally:
        if end is not None:
            end[:] = [lineno, index]


def line_event(path: Path, lineno: int, index: int, raw: bytes) -> Event | None:
    """The event of line ``lineno`` (``raw``, its bytes) of the log at ``path``,
    event ``index``: what :func:`read_lines` makes of it, ``None`` for a
    blank line.  Raises :class:`TraceError` as :func:`read_lines`."""
    return next(read_lines(path, (raw,), lineno - 1, index), None)


def _checked(path: Path, lineno: int, topic: Any, time: Any) -> float | int:
    """``time`` when ``topic`` is a string and ``time`` a finite number
    (not a bool); else raises the located :class:`TraceError`."""
    if not isinstance(topic, str):
        raise TraceError(f"{path}:{lineno}:1: error: the event has no string 'topic'")
    if isinstance(time, bool) or not isinstance(time, (int, float)):
        raise TraceError(f"{path}:{lineno}:1: error: the event has no numeric 'time'")
    if not -math.inf < time < math.inf or (type(time) is int and not -_MAX_FLOAT <= time <= _MAX_FLOAT):
        raise TraceError(f"{path}:{lineno}:1: error: the event's 'time' is {time!r}, not a finite number")
    return time


def _slow(path: Path, lineno: int, raw: bytes) -> dict[str, object] | None:
    """The object of line ``lineno`` (``raw``, its bytes) read by JSON's
    scanner or, failing that, ``json.loads``, which words every error;
    ``None`` for a blank line.  Raises :class:`TraceError` located at the
    line (and column) for bytes that are not UTF-8, malformed JSON or a
    value that is not an object."""
    try:
        line = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        col = len(raw[:exc.start].decode("utf-8", "replace")) + 1
        raise TraceError(f"{path}:{lineno}:{col}: error: the line is not UTF-8 text "
                         f"(byte 0x{raw[exc.start]:02x})") from None
    if line[-1:] == "\r" or line[-2:] == "\r\n":  # the line's end as text mode gave it: "\n" (errors' columns)
        line = line.rstrip("\n")[:-1] + "\n"
    if line[:1] == "{":
        try:
            obj, end = _SCAN(line, 0)
        except (StopIteration, ValueError, RecursionError):
            pass
        else:
            rest = len(line) - end
            if not rest or (rest == 1 and line[-1] == "\n") or not line[end:].strip(_JSON_SPACE):
                return cast("dict[str, object]", obj)  # a line that starts with "{" scans to an object
            # else more than JSON whitespace after the object: json.loads says what
    if not line.strip():
        return None
    try:
        obj = json.loads(line)
    except json.JSONDecodeError as exc:
        raise TraceError(f"{path}:{lineno}:{exc.colno}: error: malformed JSON: {exc.msg}") from None
    except RecursionError:
        raise TraceError(f"{path}:{lineno}:1: error: the line nests arrays or objects too deeply to read "
                         "(thousands of levels); no message is that deep") from None
    if not isinstance(obj, dict):
        raise TraceError(f"{path}:{lineno}:1: error: expected a JSON object, got {type(obj).__name__}")
    return obj
