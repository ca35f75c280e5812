"""Replies paired with requests by their order alone, and only where the
order makes it certain.

A reply whose request identity the monitor cannot read (rmw_fastrtps:
:mod:`.dds_wire`) answers one of the requests of its service written before
it that its server has not answered yet.  The rules (docs/monitors.md,
"Services and actions over DDS"):

* **The servers come from discovery**: every writer the monitor's reply
  reader matched on the service's reply topic (never a monitor's shadow
  writer, :mod:`.dds_shadow`), and a writer whose reply arrives before its
  match was seen.  Each server answers every request it receives (DDS
  delivers a request to every request reader), so each server's replies are
  paired on their own: with two servers, each request is two calls, one per
  server (:meth:`OrderPairer.request`), and a wrong answer of either is
  judged, never dropped.
* **One outstanding request per server**: when exactly one request the
  server has not answered was written before its reply, the reply is that
  request's.  With several, which one it answers cannot be known: those
  requests are *undecided* (their verdicts inconclusive, with the reason),
  and since one of them is still unanswered, the next reply is undecided
  too unless no request of the group can be left (a *pool* of requests of
  which ``left`` are still unanswered, not which).
* **Nothing missed**: a request written before the monitor's request reader
  matched its writer is not heard.  Its reply may come later and look like
  the answer of a request heard; so a reply stamped less than ``window``
  seconds (the monitor's horizon) after a request writer began to be heard
  is undecided where it would be paired, with the reason naming the writer.
  A service whose calls its introspection events paired, then no longer
  do (a server made again without them), is paired from then on by a
  pairer that knows the servers and writers discovered before
  (:meth:`OrderPairer.again`): a writer's window runs from the later of its
  match and its last request the events took, the one request the order
  did not hear whose reply may still come.
  Requests heard before a server's reply writer was matched are not waited
  for by it (their replies may have gone unheard): they are undecided when
  the server appears.
* A reply no outstanding request can be its is an *orphan*: counted and
  logged with its fields, never judged against a call.

Order is the DDS source timestamps' order (the writers' clocks: one host,
or hosts whose clocks are synchronised), samples being handed in that order
(:mod:`.dds_services`).  Service introspection (:mod:`.dds_introspection`)
pairs calls exactly and needs none of this.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Iterable, Mapping

#: requests remembered per service and server (the oldest unanswered one is forgotten beyond it, and said)
MAX_OPEN = 10_000

_NO_IDENTITY = ("without the request's identity (rmw_fastrtps carries it in RTPS inline QoS, which the "
                "monitor's DDS reader does not see)")


@dataclass(frozen=True)
class Pending:
    """One call waiting for a reply: ``key`` is what its reply answers (a
    call's or a goal's identity, with the server's GUID in hex last when the
    service has several servers), ``stamp`` its request's source timestamp
    (s), ``label`` how the log names it, ``writer`` the request writer's GUID
    (``None`` unknown)."""

    key: tuple[Any, ...]
    stamp: float
    label: str
    writer: bytes | None = None


@dataclass(frozen=True)
class Outcome:
    """What one reply tells: ``answers`` the call it certainly answers
    (``None``: none), ``undecided`` the calls it makes undecidable,
    ``reason`` why (one sentence), ``orphan`` when no call can be its."""

    answers: Pending | None = None
    undecided: tuple[Pending, ...] = ()
    reason: str = ""
    orphan: bool = False


@dataclass
class _Server:
    """One server's calls not answered yet (module docstring)."""

    since: float
    open: list[Pending] = field(default_factory=list)
    pool: list[Pending] = field(default_factory=list)
    left: int = 0


@dataclass
class OrderPairer:
    """The calls of one service waiting for a reply, per server (module
    docstring).  ``window`` is the start-up window (s) after a request
    writer began to be heard; ``who(guid)`` names a writer (its ROS node
    when discovery knows it)."""

    service: str
    window: float = 0.0
    who: Callable[[bytes], str] = field(default=lambda guid: guid.hex())
    servers: dict[bytes, _Server] = field(default_factory=dict)
    #: request writer -> the instant (s) from which its requests are heard
    heard_since: dict[bytes, float] = field(default_factory=dict)
    #: requests heard while no server was known (a server appearing takes those written after its match)
    unserved: list[Pending] = field(default_factory=list)
    forgotten: int = 0

    @property
    def pool(self) -> list[Pending]:
        """The calls of every server's pool (undecided, one of them perhaps still waiting)."""
        return [p for s in self.servers.values() for p in s.pool]

    # -- discovery -----------------------------------------------------------------------------
    def hearing(self, writer: bytes, since: float) -> None:
        """The monitor hears request writer ``writer`` from ``since`` (s) on
        (its reader matched it then, or was made again then)."""
        self.heard_since[writer] = since

    def discovered(self, servers: Iterable[bytes], now: float) -> list[tuple[Pending, str]]:
        """The reply writers the monitor's reader matches at ``now`` (s);
        returns the calls left undecided, each with the reason: those of a
        server gone, and those heard before a new server's match."""
        out: list[tuple[Pending, str]] = []
        current = set(servers)
        for g in [g for g in self.servers if g not in current]:
            gone = self.servers.pop(g)
            out += [(p, f"{self.who(g)}, a server of {self.service}, left before answering it")
                    for p in gone.open + gone.pool]
        for g in sorted(current - set(self.servers)):
            out += self._add_server(g, now)
        return out

    def _add_server(self, g: bytes, since: float) -> list[tuple[Pending, str]]:
        self.servers[g] = srv = _Server(since)
        early = [p for p in self.unserved if p.stamp < since]
        if len(self.servers) == 1:
            srv.open = [p for p in self.unserved if p.stamp >= since]
        self.unserved = []
        return [(p, f"it was written before the monitor heard {self.who(g)}, a server of {self.service}: its "
                 "reply may have gone unheard") for p in early]

    def again(self, unheard: Mapping[bytes, float]) -> OrderPairer:
        """A pairer of this service with no call open, for its calls once they change hands between its
        introspection events and its request and reply topics (this one set aside): the servers this one
        knows, each known since it was, and each request writer heard from the later of when this one began
        hearing it and ``unheard[writer]``, the stamp (s) of that writer's last request this one did not hear
        (the events took it; module docstring, "Nothing missed")."""
        since = dict(self.heard_since)
        for w, t in unheard.items():
            since[w] = max(since.get(w, t), t)
        return OrderPairer(self.service, self.window, self.who, {g: _Server(s.since) for g, s in self.servers.items()},
                           since, forgotten=self.forgotten)

    # -- calls ---------------------------------------------------------------------------------
    def request(self, p: Pending) -> list[Pending]:
        """A request was written at ``p.stamp``; returns the calls to open for
        it: ``p`` itself with at most one server, else one per server (its
        key and label naming the server)."""
        if p.writer is not None:
            self.heard_since.setdefault(p.writer, p.stamp)
        if not self.servers:
            self.unserved.append(p)
            return [p]
        if len(self.servers) == 1:
            calls = [p]
            self._queue(next(iter(self.servers.values())), p)
            return calls
        calls = []
        for g, srv in sorted(self.servers.items()):
            q = Pending(p.key + (g.hex(),), p.stamp, f"{p.label} answered by {self.who(g)}", p.writer)
            self._queue(srv, q)
            calls.append(q)
        return calls

    def _queue(self, srv: _Server, p: Pending) -> None:
        srv.open.append(p)
        if len(srv.open) > MAX_OPEN:
            srv.open.pop(0)
            self.forgotten += 1

    def reply(self, stamp: float, server: bytes | None) -> Outcome:
        """A reply written at ``stamp`` (s) by the writer ``server`` (its GUID, ``None`` unknown)."""
        g = server if server is not None else b""
        if g not in self.servers:  # its reply came before discovery told it (or the writer is unknown)
            self._add_server(g, min([stamp] + [p.stamp for p in self.unserved]))
        srv = self.servers[g]
        cands = [p for p in srv.open if p.stamp <= stamp]
        if srv.left == 0 and not cands:
            return Outcome(orphan=True)
        young = sorted(w for w, t in self.heard_since.items() if t <= stamp < t + self.window)
        if srv.left == 0 and len(cands) == 1 and not young:
            srv.open.remove(cands[0])
            return Outcome(cands[0])
        if not cands:  # an answer to one of the pool: which, nobody knows
            srv.left -= 1
            if srv.left == 0:
                srv.pool = []
            return Outcome()
        srv.open = [p for p in srv.open if p.stamp > stamp]
        why = self._why(srv, cands, young if srv.left == 0 and len(cands) == 1 else [])
        srv.pool += cands
        srv.left += len(cands) - 1
        if srv.left == 0:
            srv.pool = []
        return Outcome(None, tuple(cands), why)

    def _why(self, srv: _Server, cands: list[Pending], young: list[bytes]) -> str:
        if young:
            return (f"the monitor began hearing the requests of {', '.join(self.who(w) for w in young[:3])} less "
                    f"than {self.window:g} s before this reply of {self.service}: a request written before could "
                    f"still be waiting for it, and {_NO_IDENTITY} the order cannot tell; start the monitor before "
                    "the clients call, or enable service introspection (docs/ros2.md)")
        names = ", ".join(p.label for p in (srv.pool + cands)[:4]) + (" ..." if len(srv.pool) + len(cands) > 4
                                                                       else "")
        if srv.left:
            return (f"a reply of {self.service} could not be paired with its request earlier, so one of "
                    f"{len(srv.pool)} requests ({names}) may still be waiting for this reply; {_NO_IDENTITY} the "
                    "order cannot tell which request this reply answers")
        return (f"{len(cands)} requests of {self.service} were unanswered when this reply was written ({names}); "
                f"{_NO_IDENTITY} the order cannot tell which one it answers; service introspection pairs them "
                "exactly (docs/ros2.md)")


__all__ = ["MAX_OPEN", "OrderPairer", "Outcome", "Pending"]
