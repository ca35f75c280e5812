"""The rclpy agent's commands (:mod:`agent`): the monitor's command lines,
read from stdin in a thread of their own, and the message classes they
name.

Each line is one JSON command (:class:`Command`); :func:`read_commands`
queues it for the agent's main thread and wakes its executor, except a
write to a writer already made, published at once in the reading thread.
Imported by the agent as a top-level module (its folder is the script's),
so it imports the standard library only.
"""
from __future__ import annotations

import base64
import importlib
import json
import queue
import sys
from typing import Any, Protocol, TypedDict


class Writers(Protocol):
    """What :func:`read_commands` reads of the agent: its writers made so far (id -> rclpy publisher)."""

    writers: dict[int, Any]


def message_class(type_name: str) -> Any:
    """The message class of ``pkg/kind/Name``; an action's feedback message
    (``pkg/action/A_FeedbackMessage``) is ``A.Impl.FeedbackMessage`` in rosidl's Python."""
    pkg, kind, name = type_name.strip("/").split("/")
    module = importlib.import_module(f"{pkg}.{kind}")
    if not hasattr(module, name) and kind == "action" and "_" in name:
        base, _, part = name.rpartition("_")
        return getattr(getattr(module, base).Impl, part)
    return getattr(module, name)


class Command(TypedDict, total=False):
    """One command line of the monitor (module docstring): ``op`` and the keys of that op."""
    op: str
    id: int
    topic: str
    type: str
    name: str
    action: bool
    depth: int
    reliable: bool
    transient_local: bool
    raw: str
    hash: str
    node: str
    ns: str
    linger: float


def read_commands(q: queue.Queue[Command | None], wake: Any, agent: Writers) -> None:
    """Queue each command line, and wake the executor (a guard condition) so it is done at once; but
    publish a write to a writer already made here at once, without waking the executor (a verdict
    then costs the agent no executor turn: at 1000 messages/s, one message a turn, the two turns a
    message were most of its CPU).  A writer's writes go through the queue for the whole run when its
    first write came before it was made, so each writer's writes keep the order sent."""
    queued: set[int] = set()  # writers whose writes go through the queue
    for line in sys.stdin:
        if line.strip():
            c = json.loads(line)
            if c.get("op") == "write":
                w = int(c["id"])
                writer = agent.writers.get(w) if w not in queued else None
                if writer is not None:
                    writer.publish(base64.b64decode(c["raw"]))
                    continue
                queued.add(w)
            q.put(c)
            wake.trigger()
    q.put(None)
    wake.trigger()


__all__ = ["Command", "Writers", "message_class", "read_commands"]
