"""Which source and middleware a live run was heard through, carried by its log.

``rclverify monitor --live --ros2`` writes, as its log's first line, one
line of topic :data:`ORIGIN_TOPIC` (``kind: "run"``): the source
(``rclpy`` or ``dds``), the middleware (``rmw``: ``rmw_fastrtps_cpp``, or
the DDS participant's), and a sentence of both; and, before it stops, a
second one (``kind: "unseen"``) listing what that source could not hear
(the links whose calls it heard no introspection event of: docs/ros2.md,
"Two sources").  No contract names that topic, so the engines never read
those lines as messages; :class:`RunOrigin` takes them as the log is read
once, and the monitors backend puts them in the evidence
(``details["monitoring"]["source"]``), which the report shows beside the
trace.  A log written before these lines existed, or by a ROS 1 run, has
none: :attr:`RunOrigin.origin` is ``None`` and nothing is claimed.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Iterable, Iterator, Mapping

if TYPE_CHECKING:
    from rclverify.backends.monitors.shapes import OriginLine, RunSource, UnseenLine


#: the log topic of a run's origin lines
ORIGIN_TOPIC = "rclverify/run"


def origin_line(time: float, source: str, rmw: str, middleware: str) -> OriginLine:
    """The first line of a live log: ``time`` (s, the run's start), ``source``
    (``rclpy`` or ``dds``), ``rmw`` and ``middleware`` (module docstring)."""
    return {"topic": ORIGIN_TOPIC, "time": time, "kind": "run", "source": source, "rmw": rmw,
            "middleware": middleware}


def is_run_start(topic: str, fields: Mapping[str, Any]) -> bool:
    """Whether a log line of ``topic`` with ``fields`` is the start-of-run marker (:func:`origin_line`):
    every message after it is in the recording, so ``first(in.x)`` is decided from it on."""
    return topic == ORIGIN_TOPIC and fields.get("kind") == "run"


def unseen_line(time: float, unseen: list[str]) -> UnseenLine:
    """The line a live run writes before it stops: ``unseen``, one sentence per link it could not hear."""
    return {"topic": ORIGIN_TOPIC, "time": time, "kind": "unseen", "unseen": list(unseen)}


class RunOrigin:
    """The origin of the run whose events pass through :meth:`tap`."""

    def __init__(self) -> None:
        #: ``{"source", "rmw", "middleware", "unseen"}`` once an origin line was read, else ``None``
        self.origin: RunSource | None = None

    def tap(self, events: Iterable[Any]) -> Iterator[Any]:
        """``events`` unchanged; each origin line is kept (its ``fields``) first."""
        for ev in events:
            if ev.topic == ORIGIN_TOPIC:
                self.take(ev.fields)
            yield ev

    def take(self, fields: Mapping[str, object]) -> None:
        """One origin line's keys (module docstring); other kinds are ignored."""
        kind = fields.get("kind")
        if kind == "run":
            self.origin = {"source": str(fields.get("source", "")), "rmw": str(fields.get("rmw", "")),
                           "middleware": str(fields.get("middleware", "")), "unseen": []}
        elif kind == "unseen" and self.origin is not None:
            self.origin["unseen"] = [str(u) for u in _items(fields.get("unseen"))]


def _items(value: object) -> Iterable[object]:
    """A JSON list's items (``()`` for ``None``, ``[]`` or another false value)."""
    if not value:
        return ()
    if not isinstance(value, Iterable):
        raise TypeError(f"'{type(value).__name__}' object is not iterable")
    return value


def unseen_links(origin: Mapping[str, object] | None) -> dict[str, str]:
    """Link name (``"/estop"``) -> what the source could not hear of it, from
    an origin's ``unseen`` sentences (``"/estop: no introspection event ..."``)."""
    out: dict[str, str] = {}
    for line in _items((origin or {}).get("unseen")):
        name, _, why = str(line).partition(": ")
        out[name] = why
    return out


__all__ = ["ORIGIN_TOPIC", "RunOrigin", "is_run_start", "origin_line", "unseen_line", "unseen_links"]
