"""The contracts served as a ROSMonitoring oracle over WebSocket.

ROSMonitoring's generated monitors (ROS 1 and ROS 2) send each observed
message to an external oracle as one WebSocket text message: a JSON object
with ``topic``, ``time`` and the message's fields flattened beside them
(ROSMonitoring's docs/architecture.md, "Event Shape"), and expect one JSON
object back with a ``verdict`` among ``currently_true``,
``currently_false``, ``true``, ``false`` and ``unknown`` (the vocabulary its
monitors publish on ``/<monitor_id>/monitor_verdict``).  Messages arrive
already ordered by the monitor (its ``ordering`` by ``header.stamp``).

Each connection is one run: its own :class:`~.online.OnlineEngine` over
the served nodes' contracts (no reorder window; the oracle has no clock of
its own, so a missing answer is decided at the first event past the
horizon).  The answer to an event is the state of the run after it, read as
RV-LTL's four values (docs/monitors.md, "ROSMonitoring oracle"):

* ``false``: a guarantee was violated (at this event or before): the run
  violates the contract whatever follows (it stays ``false``);
* ``currently_false``: no violation, but input events still wait for their
  answer (this prefix does not satisfy the contract, an extension may);
* ``currently_true``: no violation and nothing pending;
* ``unknown``: an event or obligation the engine could not decide
  (``inconclusive``), or an event that is not a JSON object with a string
  ``topic`` and a finite numeric ``time`` (then with ``error``);
* ``true`` is never answered: a response obligation on an unbounded run
  can always still be violated.

Assumption violations do not make the answer ``false`` (the node is not at
fault); they are listed with the event's other verdicts under
``rclverify`` (node, verdict, guarantee, values ...) beside ``verdict``.
"""
from __future__ import annotations

import asyncio
import json
import math
from typing import Any, Iterable, Mapping

from ...rcl.types import Checked, CheckedNode
from ...traces.mapping import TopicRule
from .check import Verdict
from .online import OnlineEngine

ORACLE_VERDICTS = ("currently_true", "currently_false", "true", "false", "unknown")


class OracleRun:
    """One oracle connection's run: answers one event at a time (:meth:`answer`)."""

    def __init__(self, checked: Checked, nodes: Iterable[CheckedNode], rules: Mapping[str, TopicRule],
                 horizon: float) -> None:
        self._new: list[Verdict] = []
        self.engine = OnlineEngine(checked, list(nodes), rules, horizon, on_verdict=self._new.append)
        self.violated = False
        self.undecided = False
        self.events = 0

    def answer(self, text: str | bytes) -> dict[str, Any]:
        """The reply (a JSON-ready dict) to one event message."""
        try:
            event = json.loads(text)
        except (ValueError, UnicodeDecodeError) as exc:
            return {"verdict": "unknown", "error": f"not JSON: {exc}"}
        if not isinstance(event, dict):
            return {"verdict": "unknown", "error": "the event is not a JSON object"}
        topic, time = event.get("topic"), event.get("time")
        if not isinstance(topic, str):
            return {"verdict": "unknown", "error": "the event has no string 'topic'"}
        if isinstance(time, bool) or not isinstance(time, (int, float)) or not math.isfinite(time):
            return {"verdict": "unknown", "error": "the event has no finite numeric 'time'"}
        self.events += 1
        fields = {k: v for k, v in event.items() if k not in ("topic", "time")}
        self._new.clear()
        self.engine.tick(float(time))
        self.engine.push(topic, fields, float(time), f"event {self.events}")
        decided = [v.to_json() for v in self._new]
        self.violated = self.violated or any(v["verdict"] == "violated" for v in decided)
        now_undecided = any(v["verdict"] == "inconclusive" for v in decided)
        pending = any(m.pending for m in self.engine.monitors)
        if self.violated:
            verdict = "false"
        elif now_undecided:
            verdict = "unknown"
        elif pending:
            verdict = "currently_false"
        else:
            verdict = "currently_true"
        return {"verdict": verdict, "rclverify": decided}


async def serve(checked: Checked, nodes: list[CheckedNode], rules: Mapping[str, TopicRule], horizon: float,
                port: int, host: str = "127.0.0.1", ready: Any = None, stop: Any = None) -> None:
    """Serve until ``stop`` (an :class:`asyncio.Event`) is set, or forever.

    ``ready`` (an :class:`asyncio.Event`) is set once the socket listens.
    Raises ``OSError`` when the port cannot be bound."""
    from websockets.asyncio.server import serve as ws_serve
    from websockets.exceptions import ConnectionClosed

    async def handler(ws: Any) -> None:
        run = OracleRun(checked, nodes, rules, horizon)
        try:
            async for message in ws:
                await ws.send(json.dumps(run.answer(message)))
        except ConnectionClosed:
            return

    async with ws_serve(handler, host, port, ping_interval=None, max_size=2**22):
        if ready is not None:
            ready.set()
        if stop is None:
            await asyncio.Future()
        else:
            await stop.wait()


__all__ = ["ORACLE_VERDICTS", "OracleRun", "serve"]
