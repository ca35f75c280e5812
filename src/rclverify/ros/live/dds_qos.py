"""The QoS of DDS endpoints, the rule by which a reader and a writer match,
and the reader QoS that hears every publisher of a topic.

A DDS reader receives a writer's samples only when the writer *offers* at
least what the reader *requests*, policy by policy ("requested/offered", DDS
1.4, 2.2.3): reliability (reliable > best effort), durability (persistent >
transient > transient-local > volatile), deadline (the offered period at most
the requested one), liveliness (the offered kind at least the requested one,
the offered lease at most the requested one), ownership (equal kinds), a
partition in common (DDS 2.2.3.13; ``*``/``?`` patterns on one side only)
and a data representation the reader accepts (the writer's first one, DDS
XTypes 1.3, 7.6.3.1.1).  The monitor's readers are chosen by
:func:`reader_for`: the weakest request that every discovered publisher
satisfies, so a best-effort sensor is heard (the QoS trap of ogma#592: a
reliable reader hears no best-effort writer); where no single reader can
match every publisher (one offers exclusive ownership, another shared), the
publishers left out are named in a warning, never silently missed.

A reader never requests keep-all history: a monitor that stops reading must
not slow a reliable publisher down (DDS flow control); it keeps the last
:data:`READER_DEPTH` samples per writer instead, and takes them as they come.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from fnmatch import fnmatchcase
from typing import Any, Iterable

from rclverify.ros.extract.shapes import QosJson

INFINITE_NS = 0x7FFFFFFFFFFFFFFF
DURABILITY = ("volatile", "transient_local", "transient", "persistent")
LIVELINESS = ("automatic", "manual_by_participant", "manual_by_topic")
XCDR1, XCDR2 = 0, 2
#: history depth of the monitor's readers (samples per writer)
READER_DEPTH = 1000


@dataclass(frozen=True)
class QosProfile:
    """The policies that decide matching (times in ns, :data:`INFINITE_NS` for none).

    ``depth`` is ``None`` for keep-all history; ``representations`` is the
    data representation list in Cyclone's order, XCDR1 first (a writer uses
    the first, a reader accepts any)."""

    reliable: bool = True
    durability: str = "volatile"
    depth: int | None = 10
    deadline_ns: int = INFINITE_NS
    liveliness: str = "automatic"
    lease_ns: int = INFINITE_NS
    exclusive: bool = False
    partitions: tuple[str, ...] = ()
    representations: tuple[int, ...] = (XCDR1,)
    #: the endpoint's USER_DATA as discovery reports it (ROS 2's ``typehash=RIHS01_...;``); not a matching policy
    user_data: bytes = field(default=b"", compare=False, repr=False)

    def describe(self) -> str:
        """``reliable, transient_local, keep_last(1)`` and any policy off its default."""
        parts = ["reliable" if self.reliable else "best_effort", self.durability,
                 "keep_all" if self.depth is None else f"keep_last({self.depth})"]
        if self.deadline_ns != INFINITE_NS:
            parts.append(f"deadline {self.deadline_ns / 1e9:g} s")
        if self.liveliness != "automatic" or self.lease_ns != INFINITE_NS:
            lease = "" if self.lease_ns == INFINITE_NS else f" {self.lease_ns / 1e9:g} s"
            parts.append(f"liveliness {self.liveliness}{lease}")
        if self.exclusive:
            parts.append("exclusive ownership")
        if self.partitions and self.partitions != ("",):
            parts.append("partitions " + ",".join(self.partitions))
        return ", ".join(parts)

    def to_json(self) -> QosJson:
        return {"reliability": "reliable" if self.reliable else "best_effort", "durability": self.durability,
                "history": "keep_all" if self.depth is None else f"keep_last({self.depth})",
                "deadline_ns": self.deadline_ns, "liveliness": self.liveliness, "lease_ns": self.lease_ns,
                "ownership": "exclusive" if self.exclusive else "shared", "partitions": list(self.partitions)}


def _policies(qos: Any) -> dict[str, Any]:
    return {getattr(p, "__scope__", type(p).__name__): p for p in qos} if qos is not None else {}


def _kind(p: Any) -> str:
    """A policy's kind (``Reliable``, ``TransientLocal`` ...): the binding names
    its classes ``Reliability.Reliable`` and so on."""
    return type(p).__name__.rsplit(".", 1)[-1]


def from_dds(qos: Any) -> QosProfile:
    """The :class:`QosProfile` of a cyclonedds ``Qos`` (as discovery reports
    an endpoint's; a policy missing from it has its DDS default)."""
    p = _policies(qos)
    rel = p.get("Reliability")
    dur = p.get("Durability")
    hist = p.get("History")
    live = p.get("Liveliness")
    own = p.get("Ownership")
    part = p.get("Partition")
    rep = p.get("DataRepresentation")
    reps: list[int] = []
    if rep is not None:
        reps = [XCDR1] if rep.use_cdrv0_representation else []
        reps += [XCDR2] if rep.use_xcdrv2_representation else []
    return QosProfile(
        reliable=rel is not None and _kind(rel) == "Reliable",
        durability={"Volatile": "volatile", "TransientLocal": "transient_local", "Transient": "transient",
                    "Persistent": "persistent"}.get(_kind(dur), "volatile") if dur is not None else "volatile",
        depth=getattr(hist, "depth", None) if hist is not None and _kind(hist) == "KeepLast"
        else (None if hist is not None else 1),
        deadline_ns=int(getattr(p.get("Deadline"), "deadline", INFINITE_NS)),
        liveliness={"Automatic": "automatic", "ManualByParticipant": "manual_by_participant",
                    "ManualByTopic": "manual_by_topic"}.get(_kind(live), "automatic")
        if live is not None else "automatic",
        lease_ns=int(getattr(live, "lease_duration", INFINITE_NS)),
        exclusive=own is not None and _kind(own) == "Exclusive",
        partitions=tuple(getattr(part, "partitions", ()) or ()),
        representations=tuple(reps) or (XCDR1,),
        user_data=bytes(getattr(p.get("Userdata"), "data", b"") or b""))


def to_dds(q: QosProfile, user_data: bytes = b"") -> Any:
    """A cyclonedds ``Qos`` with these policies (and ``user_data`` when given)."""
    from cyclonedds.core import Policy, Qos  # deferred: start-up (loads cyclonedds and more only when called)
    pol: list[Any] = [
        Policy.Reliability.Reliable(max_blocking_time=100_000_000) if q.reliable else Policy.Reliability.BestEffort,
        {"volatile": Policy.Durability.Volatile, "transient_local": Policy.Durability.TransientLocal,
         "transient": Policy.Durability.Transient, "persistent": Policy.Durability.Persistent}[q.durability],
        Policy.History.KeepAll if q.depth is None else Policy.History.KeepLast(depth=q.depth),
        Policy.Deadline(deadline=q.deadline_ns),
        {"automatic": Policy.Liveliness.Automatic, "manual_by_participant": Policy.Liveliness.ManualByParticipant,
         "manual_by_topic": Policy.Liveliness.ManualByTopic}[q.liveliness](lease_duration=q.lease_ns),
        Policy.Ownership.Exclusive if q.exclusive else Policy.Ownership.Shared,
        Policy.DataRepresentation(use_cdrv0_representation=XCDR1 in q.representations,
                                  use_xcdrv2_representation=XCDR2 in q.representations),
    ]
    if q.partitions:
        pol.append(Policy.Partition(partitions=list(q.partitions)))
    if user_data:
        pol.append(Policy.Userdata(data=user_data))
    return Qos(*pol)


def _wild(p: str) -> bool:
    return any(c in p for c in "*?[")


def partitions_match(a: Iterable[str], b: Iterable[str]) -> bool:
    """Whether two partition lists share a partition (an empty list is the
    default partition ``""``; a pattern matches a plain name, two patterns
    never match each other, DDS 1.4, 2.2.3.13)."""
    xs, ys = list(a) or [""], list(b) or [""]
    for x in xs:
        for y in ys:
            if x == y and not (_wild(x) and _wild(y)):
                return True
            if _wild(x) != _wild(y) and (fnmatchcase(y, x) if _wild(x) else fnmatchcase(x, y)):
                return True
    return False


def mismatches(offered: QosProfile, requested: QosProfile) -> list[str]:
    """The policies on which writer QoS ``offered`` fails reader QoS
    ``requested`` (empty: they match), each as one phrase."""
    out = []
    if requested.reliable and not offered.reliable:
        out.append("reliability: the writer offers best_effort, the reader requests reliable")
    if DURABILITY.index(offered.durability) < DURABILITY.index(requested.durability):
        out.append(f"durability: the writer offers {offered.durability}, the reader requests {requested.durability}")
    if offered.deadline_ns > requested.deadline_ns:
        out.append(f"deadline: the writer offers {offered.deadline_ns / 1e9:g} s, the reader requests "
                   f"{requested.deadline_ns / 1e9:g} s")
    if LIVELINESS.index(offered.liveliness) < LIVELINESS.index(requested.liveliness) \
            or offered.lease_ns > requested.lease_ns:
        out.append(f"liveliness: the writer offers {offered.liveliness} (lease {offered.lease_ns / 1e9:g} s), "
                   f"the reader requests {requested.liveliness} (lease {requested.lease_ns / 1e9:g} s)")
    if offered.exclusive != requested.exclusive:
        out.append("ownership: the writer's is " + ("exclusive" if offered.exclusive else "shared")
                   + ", the reader's " + ("exclusive" if requested.exclusive else "shared"))
    if not partitions_match(offered.partitions, requested.partitions):
        out.append(f"partition: the writer's {list(offered.partitions) or ['']} and the reader's "
                   f"{list(requested.partitions) or ['']} have none in common")
    if offered.representations[:1] and offered.representations[0] not in requested.representations:
        out.append(f"data representation: the writer uses XCDR{2 if offered.representations[0] == XCDR2 else 1}, "
                   "which the reader does not accept")
    return out


def reader_for(offers: list[QosProfile]) -> tuple[QosProfile, list[int]]:
    """The reader QoS that matches the most of ``offers`` (every one when one
    reader can), and the indices of the offers it cannot match.

    Reliable only when every offer is reliable; the weakest offered
    durability, capped at transient-local (a monitor has no durability
    service); infinite deadline and lease, automatic liveliness (they match
    any writer); the ownership kind more offers have (shared on a tie); the
    partitions the offers name (plain names; a pattern is matched by the
    names the others give); both data representations accepted; keep-last
    :data:`READER_DEPTH`."""
    if not offers:
        return QosProfile(reliable=False, depth=READER_DEPTH, representations=(XCDR1, XCDR2)), []
    exclusive = sum(o.exclusive for o in offers) > len(offers) / 2
    names = sorted({p for o in offers for p in (o.partitions or ("",)) if not _wild(p)})
    dur = min(DURABILITY.index(o.durability) for o in offers)
    req = QosProfile(reliable=all(o.reliable for o in offers), durability=DURABILITY[min(dur, 1)],
                     depth=READER_DEPTH, exclusive=exclusive,
                     partitions=tuple(names) if names != [""] else (), representations=(XCDR1, XCDR2))
    return req, [k for k, o in enumerate(offers) if mismatches(o, req)]


def writer_profile(reliable: bool = True, transient_local: bool = False, depth: int = 1000) -> QosProfile:
    """A writer QoS of the monitor (verdicts: reliable, volatile; the last
    verdict per node: reliable, transient-local, depth 1; ROS 2's latching)."""
    return replace(QosProfile(), reliable=reliable, durability="transient_local" if transient_local else "volatile",
                   depth=depth)


__all__ = ["DURABILITY", "INFINITE_NS", "LIVELINESS", "QosProfile", "READER_DEPTH", "XCDR1", "XCDR2", "from_dds",
           "mismatches", "partitions_match", "reader_for", "to_dds", "writer_profile"]
