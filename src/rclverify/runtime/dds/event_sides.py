"""Whose introspection events pair a link's calls, and the endpoints of a
link the call taps do not hear (:mod:`.services`, docs/ros2.md "Every
endpoint of a call accounted for").

For a service or an action, the side whose introspection events pair the
calls (:meth:`EventSides._side`, by :func:`~.introspection.side_of` on the
endpoints that publish them with contents); on the DDS source a side only
when it hears every call, on the rclpy source (events only) the side some
endpoint publishes, the other endpoints told to the call book as not
judged (:meth:`EventSides._coverage`) and listed with the links not heard
(:meth:`EventSides.unheard`).  When the side changes while calls are open,
those calls are unpaired.  Mixed into :class:`~.services.CallTaps`, which
provides the attributes annotated on the class.
"""
from __future__ import annotations

from typing import Any

from rclverify.ros.live.dds import ACTION_INFIX
from rclverify.backends.monitors.dds_calls import CallBook
from rclverify.runtime.dds.bus import Tap
from rclverify.runtime.dds.call_times import ENDPOINT_GRACE_S, RECENT_S, SETTLE_S
from rclverify.runtime.dds.introspection import EVENT_SUFFIX, SIDES, side_of, uncovered
from rclverify.runtime.dds.order import OrderPairer
from rclverify.runtime.dds.shadow import SHADOW

#: the introspection event parts of an action that tell its goals and results (cancel's only tell cancels)
_GOAL_EVENTS = ("goal_event", "result_event")


class EventSides:
    """The introspection side of each link and its endpoints' coverage (module docstring)."""

    book: CallBook
    events: bool  # calls heard through introspection events only (the rclpy source)
    kinds: dict[str, str]  # link -> "service" | "action"
    specs: dict[str, tuple[str, Any, Any, str]]  # tap key -> (link, struct, request header, part)
    taps: dict[str, Tap]
    _node_of: Any  # a writer's ROS node (the bus's discovery)
    _ends: Any  # name -> (serving nodes, calling nodes): the graph API's (the rclpy bus)
    _disc: Any
    _pairers: dict[str, OrderPairer]
    _sides: dict[str, str | None]
    sided: set[str]
    _levels: dict[tuple[str, str], str]
    metadata_events: dict[str, int]
    content_events: dict[str, int]
    _uncovered: dict[tuple[str, str, str], float]
    unjudged: dict[str, dict[str, str]]
    _ends_seen: dict[tuple[str, str], dict[str, float]]
    _shadow_guids: dict[str, set[bytes]]

    def unheard(self) -> dict[str, str]:
        """Events only (module docstring): each link (``/s``) with what the
        run could not hear of it: no introspection event of its server or of
        every client (none of its calls), or only events at metadata level
        (counted: heard, but without a request or response to judge), and each endpoint said not judged
        (:meth:`_coverage`: its calls not all heard with contents); ``{}`` on
        the DDS source."""
        if not self.events:
            return {}
        out = {}
        for name, kind in sorted(self.kinds.items()):
            metadata_only = self.metadata_events.get(name, 0) > 0 and not self.content_events.get(name)
            said = [] if name in self.sided and not metadata_only else [self._silence(name, kind)]
            said += list(self.unjudged.get(name, {}).values())
            if said:
                out[name] = "; ".join(said)
        return out

    def _silence(self, name: str, kind: str) -> str:
        """Why no call of link ``name`` (a ``service`` or an action) was paired: no introspection event
        was heard of it, or only events at metadata level (counted), which carry no request or response."""
        topics = (f"{name}{EVENT_SUFFIX}" if kind == "service" else
                  f"{name}{ACTION_INFIX}send_goal{EVENT_SUFFIX}, get_result's, cancel_goal's")
        calls = "calls" if kind == "service" else "goals or results"
        n = self.metadata_events.get(name, 0)
        if n:
            return (f"{n} introspection event(s) of it were heard ({topics}), all at metadata level: their "
                    f"request and response contents are not introspected, so none of its {calls} could be "
                    "judged; configure its server's (or every client's) introspection with CONTENTS "
                    "(ServiceIntrospectionState.CONTENTS; docs/ros2.md, \"Enabling service introspection\")")
        if kind == "service":
            return (f"no introspection event of its server or of every client was heard ({topics}): none of its "
                    "calls was heard")
        return (f"no introspection event of its own services was heard ({topics}): none of its goals or results "
                "was heard (its feedback and status topics are)")

    # -- endpoints -------------------------------------------------------------------------------
    def _owner(self, guid: bytes) -> str:
        """The endpoint a writer belongs to: its ROS node (``/ns/name``), else its participant."""
        return self._node_of(bytes(guid)) or bytes(guid[:12]).hex()

    def _level(self, name: str, writer: bytes | None, s: Any) -> None:
        """Note an event without the request or response it is about: its endpoint publishes metadata only."""
        kind = int(s.info.event_type)
        body = s.request if kind in (SIDES["server"][0], SIDES["client"][0]) else s.response
        counts = self.content_events if body else self.metadata_events
        counts[name] = counts.get(name, 0) + 1
        if writer is not None and not body:
            self._levels[(name, self._owner(writer))] = "metadata"

    def _publishing(self, name: str, part: str) -> set[str]:
        """The endpoints that publish the introspection events of tap ``part`` of ``name`` (an action's
        goal and result events both, for ``goal_event``/``result_event``): the graph API's report of the
        event publishers (the rclpy source) and the writers the tap hears, by owner."""
        parts = _GOAL_EVENTS if part in _GOAL_EVENTS else (part,)
        graph = (getattr(self._disc, "services", None) or {}) if self._ends is not None else {}
        reported = graph.get(name, {}).get("events") if part != "cancel_event" else None
        found: set[str] | None = None
        for p in parts:
            ev = self.taps.get(f"call:{name}:{p}")
            heard = {self._owner(g) for g in ev.heard} if ev is not None else set()
            found = heard if found is None else found & heard
        return (found or set()) | set(reported or ())

    def _contents(self, name: str, part: str) -> set[str]:
        """:meth:`_publishing` without the endpoints seen publishing metadata only."""
        return {o for o in self._publishing(name, part) if self._levels.get((name, o)) != "metadata"}

    def _read_shadows(self) -> None:
        """The DDS source: each reply topic's shadow writers (:mod:`.shadow`, this monitor's and any
        other's), which are no servers, as discovery shows them now."""
        if self.events or self._disc is None:
            return
        for key, (_name, _struct, _header, part) in self.specs.items():
            if part != "reply":
                continue
            try:
                topic = self.taps[key].dds_topic
                self._shadow_guids[topic] = {p.guid for p in self._disc.publishers(topic)
                                             if SHADOW in p.qos.user_data}
            except (RuntimeError, KeyError):  # discovery changed under us (the DDS thread): next time
                continue

    def _coverage(self, now: float) -> None:
        """Events only: every endpoint of each link not heard with contents for
        :data:`ENDPOINT_GRACE_S` s (:func:`~.introspection.uncovered`: its
        introspection off or metadata, from the graph API's endpoints and
        event publishers, read again at each look) is told to the book as not
        judged (:meth:`~.dds_calls.CallBook.unjudged`), once per reason."""
        if not self.events or self._ends is None:
            return
        now_uncovered: set[tuple[str, str, str]] = set()
        for name, kind in self.kinds.items():
            servers, clients = self._ends(name)
            part = "event" if kind == "service" else "goal_event"
            pubs = self._publishing(name, part)
            parts = ("event",) if kind == "service" else ("goal_event", "result_event", "cancel_event")
            for what, ends in (("servers", servers), ("clients", clients),
                               *((p, pubs if p == part else self._publishing(name, p)) for p in parts)):
                seen = self._ends_seen.setdefault((name, what), {})
                seen.update(dict.fromkeys(ends, now))
                for gone in [e for e, t in seen.items() if t < now - 10 * RECENT_S]:
                    del seen[gone]
            levels = {o: self._levels.get((name, o), "contents") for o in pubs}
            for end, why in uncovered(set(servers), set(clients), levels).items():
                k = (name, end, why)
                now_uncovered.add(k)
                since = self._uncovered.setdefault(k, now)
                said = self.unjudged.setdefault(name, {})
                if now - since >= ENDPOINT_GRACE_S and said.get(end) != why:
                    said[end] = why
                    self.book.unjudged(name, end, why, max(self.book.now, now - SETTLE_S))
        for k in [k for k in self._uncovered if k not in now_uncovered]:
            del self._uncovered[k]

    def _side(self, name: str, stamp: float, part: str = "event", writer: bytes | None = None) -> str | None:
        """Which side's introspection events (tap ``part``) pair the calls of
        service or action ``name`` at the sample stamped ``stamp``
        (:func:`~.introspection.side_of` on the endpoints that publish them
        with contents).  The DDS source takes a side only when it hears every
        call (every server publishes, or every client), else it pairs the
        request and reply topics; the rclpy source, which hears nothing else,
        takes the side some endpoint publishes (the others are said not
        judged: :meth:`_coverage`), the endpoints read up to :data:`RECENT_S`
        s before the sample's stamp and the event's own ``writer`` counted
        (a node that left since was there).  When the side changes (an event writer
        discovered after calls began, gone, or seen to publish metadata only),
        the calls the other source opened can no longer be answered by it:
        they are unpaired."""
        ev = self.taps.get(f"call:{name}:{part}")
        if ev is None:
            side = None
        elif self._ends is not None:
            servers, clients = self._ends(name)
            recent = {what: {e for e, t in self._ends_seen.get((name, what), {}).items() if t >= stamp - RECENT_S}
                      for what in ("servers", "clients", part)}
            pubs = self._contents(name, part) | {o for o in recent[part] if self._levels.get((name, o)) != "metadata"}
            if writer is not None and self._levels.get((name, self._owner(writer))) != "metadata":
                pubs.add(self._owner(writer))
            side = side_of(pubs, set(servers) | recent["servers"], set(clients) | recent["clients"],
                           partial=self.events)
        else:
            rep, req = (self.taps.get(f"call:{name}:{p}") for p in ("reply", "request"))
            if rep is None or req is None:
                side = None
            else:
                shadows = self._shadow_guids.get(rep.dds_topic, set())
                side = side_of(self._contents(name, part), {self._owner(g) for g in rep.heard if g not in shadows},
                               {self._owner(g) for g in req.heard})
        memo = f"{name}:{part}"
        if side is not None:
            self.sided.add(name)
        if self._sides.setdefault(memo, side) == side:
            return side
        was, self._sides[memo] = self._sides[memo], side
        why = (f"{name}'s introspection events {'began' if was is None else 'changed or stopped'} while this call "
               "was open: its answer may come through the other source, and the two cannot be matched")
        link = name.strip("/")
        keys = [k for k, c in self.book.calls.items()
                if c.name == link and k and (part != "event" or k[0] in ("ev", "w"))]
        for k in keys:
            self.book.unpaired(k, stamp, why, "response" if part == "event" else "result")
        self._pairers.pop(name, None)
        return side
