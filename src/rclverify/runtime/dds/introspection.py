"""ROS 2 service introspection (Iron and later) as the source of a call's
identity where the wire has none the monitor can read (rmw_fastrtps,
:mod:`.dds_wire`).

A server or client that enables introspection (rclpy
``configure_introspection(clock, qos, ServiceIntrospectionState.CONTENTS)``,
rclcpp the same; ROS 2 design "Service introspection", REP-2012) publishes
on ``<service>/_service_event`` one sample per step of each call, of type
``<pkg>/srv/<Srv>_Event``: ``info`` (``service_msgs/msg/ServiceEventInfo``:
``event_type`` REQUEST_SENT 0, REQUEST_RECEIVED 1, RESPONSE_SENT 2,
RESPONSE_RECEIVED 3; ``stamp``; ``client_gid`` (``char[16]``);
``sequence_number``), ``request`` (``<Srv>_Request[<=1]``), ``response``
(``<Srv>_Response[<=1]``); with ``CONTENTS`` the request or response is
there, with ``METADATA`` only ``info``.  ``client_gid`` + ``sequence_number``
name the call on both sides (rmw_fastrtps gives the client's reply-reader
GUID as its gid exactly so that the server's events and the client's agree:
``rmw_get_gid_for_client.cpp``), so calls are paired exactly however many
are outstanding.

Which events are read: the servers' (REQUEST_RECEIVED, RESPONSE_SENT) when
every server publishes them with contents (they cover every client), else
the clients' (REQUEST_SENT, RESPONSE_RECEIVED) when every client does;
never both (a call would be counted twice).  An endpoint publishes
``contents`` until one of its events comes without the request or response
it is about (``metadata``).  :func:`event_side` decides from the
writers discovery reports on the event topic and on the service's reply and
request topics, and the node each belongs to (a service's event writer is
its server's node's, a client's its client's node's).  The event type is made here from the service's request and
response structs (rosidl makes it the same way: ``rosidl_generator_type_description``
adds ``<Srv>_Event`` to every service); ``ServiceEventInfo`` is defined here
when the interface files do not define it (rosbags' store predates it).
"""
from __future__ import annotations

from typing import Any, Callable, Iterable

from rclverify.runtime.dds.types import TypeBook

#: ServiceEventInfo.event_type values
REQUEST_SENT, REQUEST_RECEIVED, RESPONSE_SENT, RESPONSE_RECEIVED = 0, 1, 2, 3
#: per side, its (request event, response event)
SIDES = {"server": (REQUEST_RECEIVED, RESPONSE_SENT), "client": (REQUEST_SENT, RESPONSE_RECEIVED)}
EVENT_SUFFIX = "/_service_event"
_INFO = "service_msgs/msg/ServiceEventInfo"


def event_struct(types: TypeBook, srv_type: str) -> type:
    """The struct of ``<pkg>/srv/<Srv>_Event`` for service type ``pkg/Srv`` (or
    ``pkg/srv/Srv``), or ``<pkg>/action/<A>_<Svc>_Event`` for an action's own
    service ``pkg/action/A_SendGoal`` or ``A_GetResult``: ``info``, ``request[<=1]``, ``response[<=1]`` (module
    docstring).  Raises :class:`~.dds_types.DdsTypeError` for a service the
    interface files do not define."""
    if "/action/" in srv_type:  # an action's own service (``pkg/action/T_SendGoal``)
        base = srv_type
    else:
        pkg, _, rest = srv_type.replace("/srv/", "/").partition("/")
        base = f"{pkg}/srv/{rest}"
    for part in ("Request", "Response"):
        types.struct(f"{base}_{part}", srv_type)
    types._synth(_INFO, [("event_type", (1, ("uint8", 0))), ("stamp", (2, "builtin_interfaces/msg/Time")),
                         ("client_gid", (3, ((1, ("char", 0)), 16))), ("sequence_number", (1, ("int64", 0)))])
    types._synth(f"{base}_Event", [("info", (2, _INFO)), ("request", (4, ((2, f"{base}_Request"), 1))),
                                   ("response", (4, ((2, f"{base}_Response"), 1)))])
    return types.struct(f"{base}_Event", srv_type)


def event_side(event_writers: Iterable[bytes], reply_writers: Iterable[bytes], request_writers: Iterable[bytes],
               owner: Callable[[bytes], str | None] = lambda g: None) -> str | None:
    """``"server"`` when every server of the service publishes introspection
    events, ``"client"`` when every client does, else ``None``.  Arguments
    are writer GUIDs (16 bytes each) and ``owner(guid)``: the ROS node a
    writer belongs to (``ros_discovery_info``, ``None`` not known yet), else
    its participant (the GUID prefix: every node of one process shares it)."""
    def who(g: bytes) -> str:
        return owner(bytes(g)) or bytes(g[:12]).hex()
    return side_of({who(g) for g in event_writers}, {who(g) for g in reply_writers},
                   {who(g) for g in request_writers})


def side_of(publishers: set[str], servers: set[str], clients: set[str], partial: bool = False) -> str | None:
    """:func:`event_side` on names: ``publishers`` of the event topic with
    contents (a node seen publishing metadata only is left out by the
    caller), the service's (or action's) ``servers`` and ``clients``, each
    named by its node (``/ns/name``; the rclpy source reads them from the
    graph API) or its participant.  ``"server"`` when every server is among
    the publishers, ``"client"`` when every client is (either side then hears
    every call); with ``partial``, else ``"server"`` when some server is,
    ``"client"`` when some client is (the calls of the others are not heard:
    :func:`uncovered` names them); else ``None``."""
    if not publishers:
        return None
    if servers and servers <= publishers:
        return "server"
    if clients and clients <= publishers:
        return "client"
    if partial:
        return "server" if servers & publishers else "client" if clients & publishers else None
    return None


def uncovered(servers: set[str], clients: set[str], levels: dict[str, str]) -> dict[str, str]:
    """The endpoints of a service or action whose calls are not all heard
    with contents: ``"server /ns/n"`` or ``"client /ns/n"`` -> why.
    ``levels``: node -> the introspection it publishes (``"contents"`` or
    ``"metadata"``; a node absent publishes none: ``off``).  A call is heard
    with contents when its server or its client publishes contents events, so
    an endpoint is covered when it publishes contents itself or when every
    endpoint of the other side does (docs/ros2.md, "Every endpoint of a call
    accounted for")."""
    full = {n for n, level in levels.items() if level == "contents"}
    out: dict[str, str] = {}
    for role, mine, other, others in (("server", servers, clients, "client"), ("client", clients, servers, "server")):
        if other and other <= full:
            continue
        for n in sorted(mine - full):
            has = ("publishes introspection events without contents (METADATA)" if levels.get(n) == "metadata"
                   else "publishes no introspection events (off)")
            out[f"{role} {n}"] = f"{role} {n} {has}, and not every {others} of it publishes contents: its calls " \
                                 "are not all heard"
    return out


def event_key(sample: Any) -> tuple[str, int]:
    """A call's identity in an event: ``(client gid as hex, sequence number)``."""
    return bytes(sample.info.client_gid).hex(), int(sample.info.sequence_number)


__all__ = ["EVENT_SUFFIX", "REQUEST_RECEIVED", "REQUEST_SENT", "RESPONSE_RECEIVED", "RESPONSE_SENT", "SIDES",
           "event_key", "event_side", "event_struct", "side_of", "uncovered"]
