"""Replies paired with requests by their order alone, and only where the
order makes it certain.

A reply whose request identity the monitor cannot read (rmw_fastrtps:
:mod:`.dds_wire`) answers one of the requests of its service written before
it and not answered yet.  When there is exactly one such request, across
every client of the service, the reply is that request's; when there are
several, which one it answers cannot be known: those requests are
*undecided* (their verdicts inconclusive, with the reason), and since one of
them is still unanswered, the next reply is undecided too unless no request
of the group can be left (a *pool* of requests of which ``left`` are still
unanswered, not which).  A second server on the service makes every reply
undecided (each server answers each request).  Order is the DDS source
timestamps' order (the writers' clocks: one host, or hosts whose clocks are
synchronised), samples being handed in that order (:mod:`.dds_services`).

This is the service pattern of ROS 2 (a client waits for its answer before
it asks again, one client per service): it is judged call by call; calls
that overlap are said to be undecided, never paired by a guess.  Service
introspection (:mod:`.dds_introspection`) pairs those exactly.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

#: requests remembered per service (the oldest unanswered one is forgotten beyond it, and said)
MAX_OPEN = 10_000


@dataclass(frozen=True)
class Pending:
    """One request heard: ``key`` is what its reply answers (a call's or a
    goal's identity), ``stamp`` its source timestamp (s), ``label`` how the
    log names it."""

    key: tuple[Any, ...]
    stamp: float
    label: str


@dataclass(frozen=True)
class Outcome:
    """What one reply tells: ``answers`` the request it certainly answers
    (``None``: none), ``undecided`` the requests it makes undecidable,
    ``reason`` why (one sentence), ``orphan`` when no request can be its."""

    answers: Pending | None = None
    undecided: tuple[Pending, ...] = ()
    reason: str = ""
    orphan: bool = False


@dataclass
class OrderPairer:
    """The requests of one service waiting for a reply (module docstring)."""

    service: str
    open: list[Pending] = field(default_factory=list)
    pool: list[Pending] = field(default_factory=list)
    left: int = 0
    servers: set[bytes] = field(default_factory=set)
    forgotten: int = 0

    def request(self, p: Pending) -> None:
        """A request was written at ``p.stamp``."""
        self.open.append(p)
        if len(self.open) > MAX_OPEN:
            self.open.pop(0)
            self.forgotten += 1

    def reply(self, stamp: float, server: bytes | None) -> Outcome:
        """A reply written at ``stamp`` (s) by the writer ``server`` (its GUID, ``None`` unknown)."""
        if server is not None:
            self.servers.add(server)
        cands = [p for p in self.open if p.stamp <= stamp]
        if len(self.servers) > 1:
            self.open = [p for p in self.open if p.stamp > stamp]
            return Outcome(None, tuple(cands), f"{len(self.servers)} servers answer {self.service}: each answers "
                           "every request, and without the request's identity a reply cannot be told to be the "
                           "answer of one request rather than another")
        if self.left == 0 and len(cands) == 1:
            self.open.remove(cands[0])
            return Outcome(cands[0])
        if self.left == 0 and not cands:
            return Outcome(orphan=True)
        if not cands:  # an answer to one of the pool: which, nobody knows
            self.left -= 1
            if self.left == 0:
                self.pool = []
            return Outcome()
        self.open = [p for p in self.open if p.stamp > stamp]
        why = self._why(cands)
        self.pool += cands
        self.left += len(cands) - 1
        if self.left == 0:
            self.pool = []
        return Outcome(None, tuple(cands), why)

    def _why(self, cands: list[Pending]) -> str:
        names = ", ".join(p.label for p in (self.pool + cands)[:4]) + (" ..." if len(self.pool) + len(cands) > 4
                                                                        else "")
        if self.left:
            return (f"a reply of {self.service} could not be paired with its request earlier, so one of "
                    f"{len(self.pool)} requests ({names}) may still be waiting for this reply; without the "
                    "request's identity (rmw_fastrtps carries it in RTPS inline QoS, which the monitor's DDS "
                    "reader does not see) the order cannot tell which request this reply answers")
        return (f"{len(cands)} requests of {self.service} were unanswered when this reply was written ({names}); "
                "without the request's identity (rmw_fastrtps carries it in RTPS inline QoS, which the monitor's "
                "DDS reader does not see) the order cannot tell which one it answers; service introspection "
                "pairs them exactly (docs/ros2.md)")


__all__ = ["MAX_OPEN", "OrderPairer", "Outcome", "Pending"]
