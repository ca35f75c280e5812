"""Managed nodes' transition events read from a recorded run (docs/monitors.md, "Lifecycle nodes
in a recorded run").

A managed node publishes each state change on ``<node>/transition_event``
(``lifecycle_msgs/msg/TransitionEvent``: ``timestamp`` in ns of the node's clock, ``transition``,
``start_state`` and ``goal_state``, each an ``id`` and a ``label``).  A ROS 2 bag that recorded the
topic (``rclverify monitor --live --record BAG``, ``ros2 bag record``) holds them as messages,
flattened by the bag reader (``goal_state.id``); a JSON-lines log holds them as any message, nested
or flattened.  :func:`transitions` reads them out of a run's events; :func:`read_run` reads the
run (:func:`rclverify.traces.read_trace`) with its transitions, for
:func:`rclverify.cli.lifecycle_runs.judge_recorded`, which judges it as the live run does.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Iterable, Mapping, Sequence

from rclverify.traces.events import Event

#: The topic's last name and the states' words (lifecycle_msgs/msg/State's ids).
SUFFIX = "/transition_event"
STATE_WORDS = {0: "unknown", 1: "unconfigured", 2: "inactive", 3: "active", 4: "finalized", 10: "configuring",
               11: "cleaningup", 12: "shuttingdown", 13: "activating", 14: "deactivating", 15: "errorprocessing"}


@dataclass(frozen=True)
class Transition:
    """One transition event: the managed node's fully qualified name ``node``, ``time`` (s: the
    event's ``timestamp`` when set, else its recorded time), the ``start`` and ``goal`` state ids,
    and ``where`` the run holds it (``run.jsonl:12``, ``bag: message 4``)."""

    node: str
    time: float
    start: int
    goal: int
    where: str

    def __str__(self) -> str:
        return (f"{self.where}: {self.node} {STATE_WORDS.get(self.start, self.start)} -> "
                f"{STATE_WORDS.get(self.goal, self.goal)} at {self.time:.3f} s")


def _field(fields: Mapping[str, object], *path: str) -> object:
    """A field read flattened (``goal_state.id``) or nested (``{"goal_state": {"id": 3}}``)."""
    flat = fields.get(".".join(path))
    if flat is not None:
        return flat
    cur: object = fields
    for p in path:
        cur = cur.get(p) if isinstance(cur, Mapping) else None
    return cur


def transition_of(event: Event) -> Transition | None:
    """``event`` as a :class:`Transition` when it is one (its topic ends ``/transition_event`` and its
    ``goal_state.id`` and ``start_state.id`` are integers), else ``None``."""
    if not event.topic.endswith(SUFFIX):
        return None
    goal, start = _field(event.fields, "goal_state", "id"), _field(event.fields, "start_state", "id")
    if not isinstance(goal, int) or isinstance(goal, bool) or not isinstance(start, int) or isinstance(start, bool):
        return None
    stamp = _field(event.fields, "timestamp")
    at = stamp / 1e9 if isinstance(stamp, (int, float)) and not isinstance(stamp, bool) and stamp > 0 else event.time
    return Transition("/" + event.topic[: -len(SUFFIX)].strip("/"), float(at), start, goal, event.where)


def transitions(events: Iterable[Event]) -> list[Transition]:
    """The transition events among ``events``, in the order read."""
    return [t for t in map(transition_of, events) if t is not None]


def read_run(path: Path, msg_dirs: Sequence[Path] = ()) -> tuple[list[Event], list[Transition]]:
    """The events of the recorded run at ``path`` (a log or a bag, :func:`rclverify.traces.read_trace`)
    in the order read, and its transitions.  Raises :class:`rclverify.traces.events.TraceError`
    (located) for a run that cannot be read."""
    from rclverify.traces import read_trace  # deferred: the package imports its readers lazily
    events = list(read_trace(path, msg_dirs))
    return events, transitions(events)


__all__ = ["STATE_WORDS", "SUFFIX", "Transition", "read_run", "transition_of", "transitions"]
