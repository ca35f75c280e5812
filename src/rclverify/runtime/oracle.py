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

A client cannot make the server grow or fail (docs/monitors.md, "Hostile
clients"): JSON nested deeper than :data:`MAX_EVENT_DEPTH` is answered
``unknown`` before it is decoded, a connection holds a bounded number of
unanswered events (:class:`OracleLimits`: past it the server stops
reading, so the client's sends wait) and is dropped when it does not read
its answers within ``stall_s`` seconds; its state goes when it closes.
"""
from __future__ import annotations

import asyncio
import json
import math
import re
from dataclasses import dataclass
from typing import Any, Iterable, Mapping

from rclverify.lang.types import Checked, CheckedNode
from rclverify.traces.mapping import TopicRule
from rclverify.backends.monitors.check import Verdict
from rclverify.backends.monitors.online import OnlineEngine
from rclverify.runtime.shapes import OracleReply

ORACLE_VERDICTS = ("currently_true", "currently_false", "true", "false", "unknown")

#: Deepest nesting of arrays and objects an event may have.  ROSMonitoring
#: flattens a message's fields beside ``topic`` and ``time`` (a field may
#: be an array or an object of a few levels); deeper JSON is answered
#: ``unknown`` before it is decoded (Python's decoder recurses per level).
MAX_EVENT_DEPTH = 64
_STRUCTURE = re.compile(r'"(?:[^"\\]|\\.)*"|[\[\]{}]')


def json_depth(text: str | bytes) -> int:
    """How deeply the arrays and objects of the JSON ``text`` nest (0 for a
    scalar; brackets inside strings do not count), in one pass without
    recursion; for a text with at most :data:`MAX_EVENT_DEPTH` brackets in
    all, their number (an upper bound, found without a scan), and for one
    nested deeper than the limit, ``MAX_EVENT_DEPTH + 1`` (the scan stops there).  Raises
    ``UnicodeDecodeError`` for bytes that are not UTF-8."""
    if isinstance(text, bytes):
        text = text.decode("utf-8")
    if text.count("[") + text.count("{") <= MAX_EVENT_DEPTH:
        return text.count("[") + text.count("{")  # an upper bound, within the limit: no scan
    depth = deepest = 0
    for m in _STRUCTURE.finditer(text):
        c = m.group()
        if c in "[{":
            depth += 1
            if depth > deepest:
                deepest = depth
                if deepest > MAX_EVENT_DEPTH:
                    return deepest  # deeper than the limit: how much deeper does not matter
        elif c in "]}":
            depth -= 1
    return deepest


class OracleRun:
    """One oracle connection's run: answers one event at a time (:meth:`answer`)."""

    def __init__(self, checked: Checked, nodes: Iterable[CheckedNode], rules: Mapping[str, TopicRule],
                 horizon: float) -> None:
        self._new: list[Verdict] = []
        self.engine = OnlineEngine(checked, list(nodes), rules, horizon, on_verdict=self._new.append)
        self.violated = False
        self.undecided = False
        self.events = 0

    def answer(self, text: str | bytes) -> OracleReply:
        """The reply (a JSON-ready dict) to one event message.  Never raises
        for what a client sends: JSON nested deeper than
        :data:`MAX_EVENT_DEPTH` is refused before it is decoded (``unknown``
        with ``error``), as is anything else that is not an event."""
        try:
            depth = json_depth(text)
            if depth > MAX_EVENT_DEPTH:
                return {"verdict": "unknown", "error": f"the event nests deeper than {MAX_EVENT_DEPTH} levels "
                                                       f"(arrays and objects; limit {MAX_EVENT_DEPTH})"}
            event = json.loads(text)
        except (ValueError, UnicodeDecodeError, RecursionError) as exc:
            return {"verdict": "unknown", "error": f"not JSON: {str(exc) or exc.__class__.__name__}"}
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


def encode(reply: Mapping[str, object]) -> bytes:
    """A reply as compact UTF-8 JSON (a NaN or an infinity, which JSON has no
    number for, is written as its string, ``"nan"``)."""
    try:
        return json.dumps(reply, allow_nan=False, separators=(",", ":")).encode()
    except ValueError:
        return json.dumps(_json_safe(reply), separators=(",", ":")).encode()


def _json_safe(v: Any) -> Any:
    if isinstance(v, float) and not math.isfinite(v):
        return repr(v)
    if isinstance(v, dict):
        return {str(k): _json_safe(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_json_safe(x) for x in v]
    return v


async def _send_batch(ws: Any, replies: list[bytes]) -> None:
    """Send each reply as its own WebSocket text frame, the frames written to the
    socket in one write (one system call and one TCP segment for a batch,
    instead of one each): websockets' documented pattern for writing from
    user code (``send_context`` around ``protocol.send_text``), with the
    protocol's output joined."""
    if len(replies) == 1:
        await ws.send(replies[0], text=True)
        return
    async with ws.send_context():
        for r in replies:
            ws.protocol.send_text(r)
        chunks = ws.protocol.data_to_send()
        if all(chunks):  # no end-of-stream marker among them: one write
            ws.transport.write(b"".join(chunks))
        else:  # a close queued meanwhile: websockets' own handling of each chunk
            for c in chunks:
                if c:
                    ws.transport.write(c)
                elif ws.transport.can_write_eof():
                    ws.transport.write_eof()
                else:
                    ws.transport.close()


async def _woken(wake: asyncio.Event, ws: Any, stall_s: float) -> bool:
    """Wait for ``wake``; ``False`` when replies already written wait in the
    transport's buffer and none of them left it for ``stall_s`` seconds (the
    client reads nothing).  websockets stops reading a connection whose
    writes are paused, so such a client's events no longer arrive and the
    wait for them would never end: the stall must be seen here, not only
    while a batch is being sent."""
    while True:
        before = _unread(ws.transport)
        try:
            await asyncio.wait_for(wake.wait(), stall_s)
            return True
        except asyncio.TimeoutError:
            now = _unread(ws.transport)
            if now and now >= before:
                return False


def _unread(transport: Any) -> int:
    """Bytes written to the connection that the client has not taken: the
    transport's buffer and, where the system tells (Linux's ``TIOCOUTQ``),
    the socket's send queue.  A client that reads nothing leaves its replies
    in the kernel (a loopback socket's send buffer holds megabytes), and
    TCP then backs off resending the client's own data, so no event arrives
    either (seen: retransmission time-outs of 6.5 s with the client's
    receive buffer full)."""
    n = int(transport.get_write_buffer_size())
    sock = transport.get_extra_info("socket")
    try:
        import fcntl  # deferred: optional or conditional (inside a block)
        import struct  # deferred: optional or conditional (inside a block)
        import termios  # deferred: optional or conditional (inside a block)
        if sock is not None:
            n += struct.unpack("i", fcntl.ioctl(sock.fileno(), termios.TIOCOUTQ, b"\0\0\0\0"))[0]
    except (ImportError, AttributeError, OSError, ValueError):  # no such query here: the buffer alone
        pass
    return n


def _answer(run: OracleRun, message: Any) -> OracleReply:
    """``run.answer(message)``; an error the engine did not foresee is
    answered ``unknown`` with its reason instead of closing the connection."""
    try:
        return run.answer(message)
    except Exception as exc:  # noqa: BLE001 - one event's failure must not end the run or the server
        return {"verdict": "unknown", "error": f"the event could not be checked: {exc.__class__.__name__}: {exc}"}


@dataclass
class OracleLimits:
    """What one connection may hold (back-pressure, docs/monitors.md,
    "ROSMonitoring oracle"): ``inbox`` events and ``inbox_bytes`` bytes of
    them received but not answered yet (past either, the server stops
    reading the connection, so the client's sends wait: TCP flow control),
    and ``stall_s`` seconds that a batch of replies may wait for the client
    to read them before the connection is dropped."""

    inbox: int = 256
    inbox_bytes: int = 2**22
    stall_s: float = 30.0


@dataclass
class OracleStats:
    """What the server holds, for tests and monitoring of the server: open
    ``connections``, the most events one connection held unanswered
    (``peak_inbox``, never above :attr:`OracleLimits.inbox`), ``answered``
    events, connections ``dropped`` because the client did not read its
    replies within :attr:`OracleLimits.stall_s`."""

    connections: int = 0
    peak_inbox: int = 0
    answered: int = 0
    dropped: int = 0


async def serve(checked: Checked, nodes: list[CheckedNode], rules: Mapping[str, TopicRule], horizon: float,
                port: int, host: str = "127.0.0.1", ready: Any = None, stop: Any = None,
                limits: OracleLimits | None = None, stats: OracleStats | None = None) -> None:
    """Serve until ``stop`` (an :class:`asyncio.Event`) is set, or forever.

    ``ready`` (an :class:`asyncio.Event`) is set once the socket listens.
    ``limits`` bound what a connection holds (:class:`OracleLimits`); the
    server counts into ``stats`` (:class:`OracleStats`).  A connection's
    run and its queues are freed when it closes.
    Raises ``OSError`` when the port cannot be bound."""
    from websockets.asyncio.server import serve as ws_serve  # deferred: start-up (loads websockets and more only when called)

    lim = limits or OracleLimits()
    st = stats if stats is not None else OracleStats()

    async def handler(ws: Any) -> None:
        await _Connection(ws, OracleRun(checked, nodes, rules, horizon), lim, st).serve()

    async with ws_serve(handler, host, port, ping_interval=None, max_size=2**22):
        if ready is not None:
            ready.set()
        if stop is None:
            await asyncio.Future()
        else:
            await stop.wait()


class _Connection:
    """One client's connection: its run, the inbox of messages read and not
    yet answered (bounded by ``lim``), and the counts it adds to ``st``."""

    def __init__(self, ws: Any, run: OracleRun, lim: OracleLimits, st: OracleStats) -> None:
        self.ws, self.run, self.lim, self.st = ws, run, lim, st
        self.inbox: list[Any] = []
        self.held = 0  # bytes in inbox
        self.wake, self.space = asyncio.Event(), asyncio.Event()
        self.closed = False

    async def read(self) -> None:
        """Read messages into the inbox until the client closes."""
        from websockets.exceptions import ConnectionClosed  # deferred: start-up (loads websockets and more only when called)
        # websockets hands over every message already received without
        # suspending, so the inbox fills with everything that arrived in one
        # read from the socket before the replies are written; a full inbox stops the
        # reading until the replies went out (websockets then stops reading
        # the socket: the client's sends wait)
        lim, st, inbox = self.lim, self.st, self.inbox
        try:
            async for message in self.ws:
                inbox.append(message)
                self.held += len(message)
                st.peak_inbox = max(st.peak_inbox, len(inbox))
                self.wake.set()
                while len(inbox) >= lim.inbox or self.held >= lim.inbox_bytes:
                    self.space.clear()
                    await self.space.wait()
        except ConnectionClosed:
            pass
        finally:
            self.closed = True
            self.wake.set()

    def drop(self) -> None:
        """The client does not read its replies: its connection is dropped."""
        self.st.dropped += 1
        self.ws.transport.abort()

    async def serve(self) -> None:
        """Answer the inbox batch by batch until the client closes or is dropped."""
        from websockets.exceptions import ConnectionClosed  # deferred: start-up (loads websockets and more only when called)
        st, lim = self.st, self.lim
        st.connections += 1
        reader = asyncio.create_task(self.read())
        try:
            while True:
                if not await _woken(self.wake, self.ws, lim.stall_s):  # replies unread for stall_s: drop it
                    self.drop()
                    return
                self.wake.clear()
                if self.inbox:
                    batch = self.inbox[:]
                    del self.inbox[:]
                    self.held = 0
                    replies = [encode(_answer(self.run, m)) for m in batch]
                    st.answered += len(batch)
                    self.space.set()
                    try:
                        await asyncio.wait_for(_send_batch(self.ws, replies), lim.stall_s)
                    except asyncio.TimeoutError:  # the client does not read its replies: drop it
                        self.drop()
                        return
                elif self.closed:
                    return
        except ConnectionClosed:
            return
        finally:
            reader.cancel()
            self.inbox.clear()
            st.connections -= 1


__all__ = ["MAX_EVENT_DEPTH", "ORACLE_VERDICTS", "OracleLimits", "OracleRun", "OracleStats", "json_depth", "serve"]
