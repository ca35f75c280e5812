"""ROS 2 on the wire, without ROS: a DDS participant of Eclipse Cyclone DDS
(the ``cyclonedds`` Python binding, whose wheel carries the C library) and the
conventions ROS 2's middleware layer puts on DDS.

What this module knows (read from rmw_cyclonedds, ``rmw_node.cpp``,
``serdata.cpp``, ``Serialization.cpp``, and the ROS 2 design article "Topic and
Service name mapping to DDS"):

* **Domain.**  ``ROS_DOMAIN_ID`` (default 0, at most 232 on Linux, where the
  ports of higher domains overflow) is the DDS domain; Cyclone reads its own
  configuration from ``CYCLONEDDS_URI`` (network interface, multicast,
  unicast peers) when the participant is created.
* **Names.**  A ROS topic ``/scan`` is the DDS topic ``rt/scan``; a service
  ``/estop`` is ``rq/estopRequest`` (requests) and ``rr/estopReply``
  (replies); an action ``/move`` is the services
  ``/move/_action/send_goal``, ``/move/_action/get_result``,
  ``/move/_action/cancel_goal`` and the topics ``/move/_action/feedback`` and
  ``/move/_action/status``.  A type ``pkg/msg/T`` is the DDS type
  ``pkg::msg::dds_::T_``; a service's parts are ``pkg::srv::dds_::T_Request_``
  and ``..._Response_``; an action's ``pkg::action::dds_::T_SendGoal_Request_``,
  ``T_FeedbackMessage_``, ``T_Goal_`` and so on.
* **Data.**  Plain CDR (XCDR1, the only representation rmw_cyclonedds
  allows), little-endian on the usual machines, after a 4-byte
  encapsulation header.
* **Nodes.**  DDS knows participants and endpoints, not nodes: each ROS 2
  context publishes ``rmw_dds_common/msg/ParticipantEntitiesInfo`` on the
  DDS topic ``ros_discovery_info`` (reliable, transient-local, keep-last 1):
  its participant's GID and, per node, the namespace, the name and the GIDs
  of the node's readers and writers (a GID is the DDS GUID, 16 bytes; ROS 2
  Foxy, Galactic and Humble send it in a 24-byte array padded with zeros
  (``Gid.msg``: ``char[24] data``), Iron and newer in a 16-byte one
  (``char[16]`` since rmw_dds_common 2.0.0): :func:`decode_participant_info`
  reads both, deciding by the sample: exactly one layout reads it whole).

Raw access (:func:`take_raw`, :func:`write_raw`) goes one level under the
binding's ``DataReader.take``/``DataWriter.write`` (its ``_clayer`` module,
which those methods call): the bytes as they travel, for the service header,
the bag recorder and the republisher of ``--enforce`` (docs/monitors.md,
"ROS 2 over DDS").

``ros_discovery_info`` (which node owns which readers and writers) is
:mod:`.discovery_info`'s.
"""
from __future__ import annotations

import functools
import os
from typing import Any, Mapping

from rclverify.core.extras import MissingExtra

#: The highest ROS_DOMAIN_ID usable on Linux (ROS 2 documentation, "The ROS_DOMAIN_ID").
MAX_DOMAIN_ID = 232
DISCOVERY_TOPIC = "ros_discovery_info"
DISCOVERY_TYPE = "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_"
#: the hidden part of an action's topic and service names
ACTION_INFIX = "/_action/"
ACTION_SERVICES = ("send_goal", "get_result", "cancel_goal")
ACTION_TOPICS = ("feedback", "status")


class DdsUnavailable(Exception):
    """DDS cannot be joined as asked (the binding is missing, a bad
    ``ROS_DOMAIN_ID``, a Cyclone configuration that does not load); ``str`` says why."""


class DdsExtraMissing(DdsUnavailable, MissingExtra):
    """The ``cyclonedds`` binding is not installed: rclverify's ``[ros2]``
    extra is missing (one line naming it; commands exit 1 for it, as for
    every missing extra: docs/install.md)."""


def import_cyclonedds() -> Any:
    """The ``cyclonedds`` package; raises :class:`DdsExtraMissing` when it
    is not installed and :class:`DdsUnavailable` when it does not load,
    each with the remedy."""
    try:
        import cyclonedds  # deferred: optional or conditional (inside a block)
        import cyclonedds.domain  # noqa: F401  (loads the C library: fails here when it cannot); deferred: optional or conditional (inside a block)
        return cyclonedds
    except ImportError as exc:
        from rclverify.core.extras import installed  # deferred: optional or conditional (inside a block)
        if not installed("cyclonedds"):
            raise DdsExtraMissing("cyclonedds", "ROS 2 over DDS") from None
        raise DdsUnavailable(f"the cyclonedds Python binding does not load ({exc})") from None


def domain_id(env: Mapping[str, str] | None = None) -> int:
    """The DDS domain ROS 2 uses: ``ROS_DOMAIN_ID`` (default 0).

    Raises :class:`DdsUnavailable` for a value that is not an integer in
    0..:data:`MAX_DOMAIN_ID`."""
    raw = (os.environ if env is None else env).get("ROS_DOMAIN_ID", "").strip()
    if not raw:
        return 0
    try:
        d = int(raw)
    except ValueError:
        raise DdsUnavailable(f"ROS_DOMAIN_ID={raw!r} is not a number (0 to {MAX_DOMAIN_ID})") from None
    if not 0 <= d <= MAX_DOMAIN_ID:
        raise DdsUnavailable(f"ROS_DOMAIN_ID={d} is outside 0..{MAX_DOMAIN_ID}")
    return d


#: What rclverify adds to the user's Cyclone configuration (read after it, so it wins on these two settings):
#: * ``AllowInvalidTryConstruct``: Fast DDS 3 (ROS 2 Kilted's default middleware) announces XTypes type
#:   objects whose sequence and array elements carry no try-construct flag, which DDS-XTypes 1.3
#:   (7.3.4.4.4) requires and Cyclone otherwise refuses, printing ``ddsi_xt_type_init_impl with invalid type
#:   object`` on stderr for each such type;
#: * ``IgnoreTypeInformation`` for eProsima's vendor id (1.15, DDS-RTPS 2.5 9.3.1.5): Fast DDS's type lookup
#:   service answers a request for a type's *minimal* identifier with its *complete* type object, so Cyclone
#:   compares the monitor's minimal type with Fast DDS's complete one, never finds them identical, and refuses
#:   every type that nests a struct in a sequence or array ("not delimited", DDS-XTypes 7.2.4.4.4.4).  Fast
#:   DDS's endpoints are then matched on the type name, as ROS 2's middlewares match each other, and the
#:   monitor compares the layout itself (the ROS 2 type hash its writers announce, :mod:`.dds_layout`).
COMPATIBILITY = ("<Compatibility><AllowInvalidTryConstruct>true</AllowInvalidTryConstruct>"
                 "<IgnoreTypeInformation>1.15</IgnoreTypeInformation></Compatibility>")
_domains: dict[int, Any] = {}  # the domains this process configured (kept alive: a Domain entity ends with it)


def configure_domain(d: int) -> None:
    """Create domain ``d`` with the user's configuration (``CYCLONEDDS_URI``: files and XML fragments, comma
    separated, as Cyclone reads it) followed by :data:`COMPATIBILITY`; a domain this process already has
    (made here or by the caller) is left as it is."""
    from cyclonedds.core import DDSException  # deferred: start-up (loads cyclonedds and more only when called)
    from cyclonedds.domain import Domain  # deferred: start-up (loads cyclonedds and more only when called)
    if d in _domains:
        return
    user = os.environ.get("CYCLONEDDS_URI", "").strip().strip(",")
    try:
        _domains[d] = Domain(d, f"{user},{COMPATIBILITY}" if user else COMPATIBILITY)
    except DDSException as exc:
        if exc.code != DDSException.DDS_RETCODE_PRECONDITION_NOT_MET:  # not "exists already": the config
            raise


def make_participant(domain: int | None = None) -> Any:
    """A DDS participant in ``domain`` (default :func:`domain_id`), configured
    by ``CYCLONEDDS_URI`` and :data:`COMPATIBILITY`.  Raises :class:`DdsUnavailable`
    when Cyclone refuses (a configuration file that does not parse, no usable interface)."""
    import_cyclonedds()
    from cyclonedds.core import DDSException  # deferred: start-up (loads cyclonedds and more only when called)
    from cyclonedds.domain import DomainParticipant  # deferred: start-up (loads cyclonedds and more only when called)
    d = domain_id() if domain is None else domain
    try:
        configure_domain(d)
        return DomainParticipant(d)
    except DDSException as exc:
        uri = os.environ.get("CYCLONEDDS_URI", "")
        raise DdsUnavailable(f"Cyclone DDS cannot join domain {d}"
                             + (f" with CYCLONEDDS_URI={uri}" if uri else "") + f": {exc}") from None


# -- names ------------------------------------------------------------------------------------

def absolute_name(name: str) -> str:
    return "/" + name.strip().strip("/")


def topic_name(ros_topic: str) -> str:
    """``/scan`` (or ``scan``) -> ``rt/scan``."""
    return "rt" + absolute_name(ros_topic)


def request_topic(service: str) -> str:
    """``/estop`` -> ``rq/estopRequest``."""
    return "rq" + absolute_name(service) + "Request"


def reply_topic(service: str) -> str:
    """``/estop`` -> ``rr/estopReply``."""
    return "rr" + absolute_name(service) + "Reply"


def ros_name(dds_topic: str) -> tuple[str, str]:
    """``(kind, ROS name)`` of a DDS topic: ``("topic", "/scan")`` for
    ``rt/scan``, ``("request", "/estop")`` for ``rq/estopRequest``,
    ``("reply", "/estop")`` for ``rr/estopReply``, ``("dds", name)`` for a
    topic outside ROS 2's conventions (``ros_discovery_info``, plain DDS)."""
    if dds_topic.startswith("rt/"):
        return "topic", dds_topic[2:]
    if dds_topic.startswith("rq/") and dds_topic.endswith("Request"):
        return "request", dds_topic[2:-len("Request")]
    if dds_topic.startswith("rr/") and dds_topic.endswith("Reply"):
        return "reply", dds_topic[2:-len("Reply")]
    return "dds", dds_topic


def dds_type(ros_type: str, kind: str = "msg") -> str:
    """``pkg/msg/T`` (or ``pkg/T`` with ``kind``) -> ``pkg::msg::dds_::T_``;
    ``pkg/srv/T_Request`` -> ``pkg::srv::dds_::T_Request_``."""
    parts = [p for p in ros_type.replace("::", "/").split("/") if p]
    if len(parts) == 2:
        parts = [parts[0], kind, parts[1]]
    *ns, name = parts
    return "::".join(ns) + "::dds_::" + name + "_"


def ros_type(dds_name: str) -> str | None:
    """``pkg::msg::dds_::T_`` -> ``pkg/msg/T`` (``None`` when the name is not
    in ROS 2's form); a service part keeps its suffix
    (``pkg/srv/T_Request``), as the request and reply topics carry it."""
    ns, sep, name = dds_name.partition("::dds_::")
    if not sep or not name.endswith("_") or not ns:
        return None
    return "/".join(ns.split("::")) + "/" + name[:-1]


def service_type(request_or_reply_type: str | None) -> str | None:
    """``pkg/srv/T_Request`` or ``pkg/srv/T_Response`` -> ``pkg/srv/T``
    (``pkg/action/T_SendGoal_Request`` -> ``pkg/action/T_SendGoal``)."""
    if not request_or_reply_type:
        return None
    for suffix in ("_Request", "_Response"):
        if request_or_reply_type.endswith(suffix):
            return request_or_reply_type[: -len(suffix)]
    return request_or_reply_type


# -- raw samples ------------------------------------------------------------------------------

def take_raw(reader: Any, n: int = 256) -> list[tuple[bytes, Any]]:
    """Up to ``n`` samples of ``reader`` as ``(serialized bytes, sample info)``
    (the bytes with their encapsulation header; samples without data, a
    writer gone, are skipped)."""
    from cyclonedds._clayer import ddspy_take  # deferred: start-up (loads cyclonedds and more only when called)
    from cyclonedds.core import InstanceState, SampleState, ViewState  # deferred: start-up (loads cyclonedds and more only when called)
    ret = ddspy_take(reader._ref, SampleState.Any | ViewState.Any | InstanceState.Any, n)
    if isinstance(ret, int):
        from cyclonedds.core import DDSException  # deferred: optional or conditional (inside a block)
        raise DDSException(ret, "take")
    return [(bytes(data), info) for data, info in ret if info.valid_data]


def write_raw(writer: Any, data: bytes, timestamp_ns: int | None = None) -> None:
    """Write serialized bytes (encapsulation header included) as one sample,
    with ``timestamp_ns`` as its source timestamp when given."""
    from cyclonedds._clayer import ddspy_write, ddspy_write_ts  # deferred: start-up (loads cyclonedds and more only when called)
    data = data.ljust((len(data) + 3) & ~3, b"\0")
    ret = ddspy_write(writer._ref, data) if timestamp_ns is None else ddspy_write_ts(writer._ref, data, timestamp_ns)
    if ret < 0:
        from cyclonedds.core import DDSException  # deferred: optional or conditional (inside a block)
        raise DDSException(ret, "write")


@functools.lru_cache(maxsize=1)
def _humble() -> Any:
    from rosbags.typesys import Stores, get_typestore  # deferred: start-up (loads rosbags and more only when called)
    return get_typestore(Stores.ROS2_HUMBLE)


def type_hash_user_data(ros_type_name: str, store: Any = None) -> bytes:
    """``typehash=RIHS01_...;`` for an endpoint's USER_DATA, as ROS 2 Iron and
    newer announce it (the REP-2011 type hash, :func:`.type_hash.rihs01`, over
    the definitions of rosbags' type ``store``, ROS 2 Humble's by default);
    empty when the store does not know the type."""
    from rclverify.ros.live.type_hash import rihs01  # deferred: start-up (loads rclverify.ros.live, hashlib only when called)
    if store is None:
        store = _humble()
    defs = store.fielddefs

    def fields_of(name: str) -> Any:
        return defs[name][1] if name in defs else None
    try:
        return f"typehash={rihs01(ros_type_name, fields_of)};".encode()
    except Exception:  # a type the store lacks: no hash, as ROS 2 Humble sends none
        return b""


def announced_type_hash(user_data: bytes) -> str | None:
    """The ROS 2 type hash (``RIHS01_<64 hex digits>``, REP-2011) an endpoint's
    USER_DATA announces as ``typehash=...;`` (ROS 2 Iron and newer, every
    middleware: rmw_dds_common ``encode_type_hash_for_user_data_qos``), or
    ``None`` when it announces none (Humble and older, plain DDS)."""
    for item in bytes(user_data).decode("utf-8", errors="replace").split(";"):
        key, _, value = item.partition("=")
        if key.strip() == "typehash" and value.startswith("RIHS01_"):
            return value.strip()
    return None


__all__ = ["ACTION_INFIX", "ACTION_SERVICES", "ACTION_TOPICS", "COMPATIBILITY", "DISCOVERY_TOPIC", "DISCOVERY_TYPE",
           "DdsUnavailable", "MAX_DOMAIN_ID", "NodeInfo", "announced_type_hash", "configure_domain",
           "decode_participant_info", "discovery_struct", "domain_id", "dds_type", "encode_participant_info",
           "import_cyclonedds", "make_participant", "reply_topic", "request_topic", "ros_name", "ros_type",
           "service_type", "take_raw", "topic_name", "type_hash_user_data", "write_raw"]
