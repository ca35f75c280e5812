"""Reply writers that keep the monitor's request readers from hiding a
service from its clients.

rmw_fastrtps tells a client that its server is available only when, on
the service's topics, the readers of requests and the writers of replies
are as many as each other, both in the graph its participant discovered
and among the endpoints its own request writer and reply reader matched
(``rmw_service_server_is_available.cpp``: a server is one request reader
and one reply writer).  The monitor's reader on ``rq/<s>Request`` is one
more request reader and no reply writer: from the moment a client
discovers it, ``service_is_ready()`` is false and ``wait_for_service()``
waits for ever (measured: true 0.05 s after the start, false from 1.1 s,
when the monitor's reader appeared).  A monitor must not change what it
watches, so beside each of its request readers it keeps one reply writer on
the service's reply topic, of the reader's type, that never writes, **only
while a real server of the service is there** (discovery shows a reply
writer that is not such a shadow): with no server, a shadow would make a
client believe one is there.  The shadows announce ``rclverify=shadow;``
in their USER_DATA, so that a second monitor does not count another's
shadow as a server.  rmw_cyclonedds pairs a service's reader and writer by
the ``serviceid`` in their USER_DATA and ignores endpoints without one
(the monitor's readers and these writers alike).
"""
from __future__ import annotations

from typing import Any

from rclverify.ros.live.dds_qos import QosProfile

#: the USER_DATA of a shadow reply writer
SHADOW = b"rclverify=shadow;"
#: request part -> reply part of the call taps (:mod:`.dds_services`)
REPLY_OF = {"request": "reply", "goal_request": "goal_reply", "result_request": "result_reply",
            "cancel_request": "cancel_reply"}


class Shadows:
    """The shadow reply writers of one monitor (module docstring).  ``pairs``
    are ``(request tap, reply tap)`` (:class:`~.dds_bus.Tap`); ``bus`` makes
    the writers (:meth:`~.dds_bus.Bus.writer`) and its discovery tells the
    servers."""

    def __init__(self, bus: Any, pairs: list[tuple[Any, Any]]) -> None:
        self.bus, self.pairs = bus, pairs
        self.writers: dict[str, Any] = {}  # reply topic -> its shadow writer
        self.made = 0

    def update(self) -> None:
        """Make a shadow where the monitor reads a service's requests and a
        server of it is there; drop it where no server is left."""
        for rq, rr in self.pairs:
            try:
                servers = [p for p in self.bus.discovery.publishers(rr.dds_topic) if SHADOW not in p.qos.user_data]
            except RuntimeError:  # discovery changed under us (the DDS thread): next time
                return
            want = rq.reader is not None and bool(servers)
            have = self.writers.get(rr.dds_topic)
            if want and have is None:
                self.writers[rr.dds_topic] = self.bus.writer(
                    rr.dds_topic, rr.struct, QosProfile(reliable=True, durability="volatile", depth=1), SHADOW)
                self.made += 1
            elif have is not None and not want:
                del self.writers[rr.dds_topic]
                have.__del__()


__all__ = ["REPLY_OF", "SHADOW", "Shadows"]
