"""Whether a writer's offered QoS and a reader's requested QoS match: the DDS request-offered rules ROS 2 applies.

The rules are those of the DDS specification (v1.4, section 2.2.3, the
"RxO" policies) as rmw states them for ROS 2 (``rmw/qos_profiles.h``,
``rmw_qos_profile_check_compatible``; the ROS 2 documentation's "Quality of
Service settings", "QoS compatibilities"): a writer (publisher, or the
answering side of a service) offers, a reader requests, and they connect
only when every policy offered is at least what is requested:

* **reliability**: a ``RELIABLE`` reader and a ``BEST_EFFORT`` writer do not connect;
* **durability**: a ``TRANSIENT_LOCAL`` reader and a ``VOLATILE`` writer do not connect;
* **deadline**: the writer's period must not be longer than the reader's
  (0, the schema's "no deadline", is infinitely long);
* **liveliness**: ``AUTOMATIC`` < ``MANUAL_BY_TOPIC``; the writer's kind must
  be at least the reader's, and its lease duration not longer (0: infinite).

Decisions where the rules need a value (docs/nodl.md): a policy the
document leaves out, or writes ``SYSTEM_DEFAULT``, has rmw's default
(``rmw_qos_profile_default``: ``RELIABLE``, ``VOLATILE``, no deadline,
``AUTOMATIC``, infinite lease), what every rmw shipped with ROS 2 gives it;
``BEST_AVAILABLE`` adapts to the endpoints it discovers (rmw ``types.h``),
so it is never judged incompatible.  History, depth and lifespan are not
request-offered policies and are never judged.
"""
from __future__ import annotations

from dataclasses import dataclass

from rclverify.model.nodl.document import QoS

#: rmw's defaults for a policy left out or written ``SYSTEM_DEFAULT`` (``rmw_qos_profile_default``).
DEFAULTS = {"reliability": "RELIABLE", "durability": "VOLATILE", "liveliness": "AUTOMATIC"}
#: Each ordered policy's values, weakest first (DDS's order of "at least").
ORDER = {"reliability": ("BEST_EFFORT", "RELIABLE"), "durability": ("VOLATILE", "TRANSIENT_LOCAL"),
         "liveliness": ("AUTOMATIC", "MANUAL_BY_TOPIC")}
#: The requested-offered durations: (field, what it is called).
DURATIONS = (("deadline_ns", "deadline"), ("liveliness_lease_duration_ns", "liveliness lease duration"))


@dataclass(frozen=True)
class Mismatch:
    """One policy the writer offers below what the reader requests: ``policy`` as the schema
    names it, ``offered`` and ``requested`` as judged (defaults filled in), ``why`` in words."""

    policy: str
    offered: str
    requested: str
    why: str


def _kind(q: QoS | None, policy: str) -> str:
    value = getattr(q, policy, None) if q is not None else None
    return DEFAULTS[policy] if value in (None, "SYSTEM_DEFAULT") else str(value)


def _ns(q: QoS | None, name: str) -> int:
    value = getattr(q, name, None) if q is not None else None
    return int(value) if value else 0


def _words(ns: int) -> str:
    return "none (infinite)" if ns == 0 else f"{ns} ns"


def mismatches(offered: QoS | None, requested: QoS | None) -> list[Mismatch]:
    """Every request-offered policy that keeps writer ``offered`` and reader ``requested`` apart
    (module docstring; ``None``: a document without ``qos``, every policy rmw's default); empty
    when they connect."""
    out: list[Mismatch] = []
    for policy, order in ORDER.items():
        o, r = _kind(offered, policy), _kind(requested, policy)
        if "BEST_AVAILABLE" in (o, r) or o not in order or r not in order:
            continue
        if order.index(o) < order.index(r):
            out.append(Mismatch(policy, o, r, f"a {r} reader does not connect to a {o} writer"))
    for name, what in DURATIONS:
        o_ns, r_ns = _ns(offered, name), _ns(requested, name)
        if r_ns and (o_ns == 0 or o_ns > r_ns):
            out.append(Mismatch(name, _words(o_ns), _words(r_ns),
                                f"the writer's {what} ({_words(o_ns)}) is longer than the reader's ({_words(r_ns)})"))
    return out


__all__ = ["DEFAULTS", "DURATIONS", "Mismatch", "ORDER", "mismatches"]
