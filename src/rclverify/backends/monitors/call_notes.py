"""What no call's trace can decide, still said (docs/monitors.md, "Every
endpoint of a call accounted for"): an answer whose request was not heard
(:meth:`CallNotes.orphan`) and an endpoint of a link not heard with
contents (:meth:`CallNotes.unjudged`) each keep the link's nodes from
``discharged`` (one more ``inconclusive``) and are named in their
explanation (:meth:`CallNotes.with_notes`).  Mixed into
:class:`~.dds_calls.CallBook`, which gives the state declared below.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

from rclverify.lang.types import CheckedNode
from rclverify.backends.monitors.check import NodeResult

#: undecided answers named one by one (client gid and sequence number); the rest are counted
NAMED = 5


class CallNotes:
    """The notes part of :class:`~.dds_calls.CallBook` (module docstring)."""

    links: dict[str, list[tuple[CheckedNode, CheckedNode, bool]]]
    results: dict[str, NodeResult]
    counts: dict[str, int]
    index: int
    #: link -> answers heard whose request was not: ``{"count", "first"}`` (the first :data:`NAMED` keys)
    undecided: dict[str, dict[str, Any]]
    #: link -> endpoint (``"server /ns/n"``) -> why its calls were not all heard with contents
    unjudged_ends: dict[str, dict[str, str]]

    if TYPE_CHECKING:  # the book's log sink
        def _log(self, obj: dict[str, Any]) -> None: ...

    def orphan(self, name: str, key: tuple[Any, ...], stamp: float) -> None:
        """An answer (reply or result) of link ``name`` stamped ``stamp`` (s)
        whose request was not heard (made before the monitor started, or of
        an endpoint it does not hear): counted (``orphan_answers``), its key
        named among the first :data:`NAMED` (``undecided``), and every node of
        the link kept from ``discharged``: one more ``inconclusive`` answer,
        the reason naming the count and the first keys (docs/monitors.md,
        "Every endpoint of a call accounted for")."""
        link = name.strip("/")
        self.counts["orphan_answers"] += 1
        if link not in self.links:
            return
        u = self.undecided.setdefault(link, {"count": 0, "first": []})
        u["count"] += 1
        if len(u["first"]) < NAMED:
            u["first"].append(key_json(key))
        self._mark(link, f"{link} answer {_named(key_json(key))}", stamp, self._said(link, "undecided"))

    def unjudged(self, name: str, endpoint: str, why: str, stamp: float) -> None:
        """Endpoint ``endpoint`` (``"server /ns/n"``, ``"client /ns/n"``) of
        link ``name`` was not heard with contents from ``stamp`` (s), ``why``:
        the link is not judged for it; every node of the link is kept from
        ``discharged`` (one more ``inconclusive``, with ``why``), and the line
        (``part`` ``unjudged``) goes to the log and the bag."""
        link = name.strip("/")
        ends = self.unjudged_ends.setdefault(link, {})
        if ends.get(endpoint) == why or link not in self.links:
            return
        ends[endpoint] = why
        self._log({"link": link, "part": "unjudged", "time": stamp, "endpoint": endpoint, "reason": why})
        self._mark(link, f"{link} {endpoint}", stamp, self._said(link, "not judged"))

    def _said(self, link: str, which: str) -> str:
        """The sentence of :meth:`notes` about ``link``'s undecided answers or its endpoints not judged."""
        if which == "undecided":
            u = self.undecided[link]
            named = ", ".join(_named(k) for k in u["first"]) + (", ..." if u["count"] > len(u["first"]) else "")
            return (f"{u['count']} answer(s) of /{link} whose request the monitor did not hear (made before it "
                    f"started, or by an endpoint it does not hear) are undecided: {named}")
        ends = self.unjudged_ends[link]
        return f"/{link} is not judged for {len(ends)} endpoint(s): " + "; ".join(ends.values())

    def notes(self, node: str) -> list[str]:
        """What ``node``'s calls leave undecided whatever else of them was
        judged, one sentence per link it serves or calls: the answers whose
        request was not heard (:meth:`orphan`: their count and the first
        :data:`NAMED` keys) and the endpoints not heard with contents
        (:meth:`unjudged`)."""
        out = []
        for link, views in self.links.items():
            if node not in {n.name for n, _v, _t in views}:
                continue
            out += [self._said(link, w) for w, have in (("undecided", self.undecided), ("not judged",
                                                                                       self.unjudged_ends))
                    if have.get(link)]
        return out

    def with_notes(self, node: str, explanation: str) -> str:
        """``explanation`` (a status's, :func:`.summary.verdict_status`) with each of :meth:`notes` it does
        not already say, so a failed or inconclusive status names them too."""
        extra = [n for n in self.notes(node) if n not in explanation]
        return explanation + "".join(f"; {n}" for n in extra)

    def _mark(self, link: str, where: str, stamp: float, reason: str) -> None:
        """Keep each node of ``link`` from ``discharged``: one more ``inconclusive``, ``reason`` its first."""
        for node in dict.fromkeys(view.name for view, _v, _t in self.links[link]):
            res = self.results.setdefault(node, NodeResult(node))
            res.counts["inconclusive"] += 1
            res.first_inconclusive = {"event": self.index, "time": stamp, "where": where, "reason": reason}


def key_json(key: tuple[Any, ...]) -> list[Any]:
    """A call's identity ``key`` as its log line holds it (bytes as hex)."""
    return [k.hex() if isinstance(k, bytes) else k for k in key]


def _named(key: list[Any]) -> str:
    """A call's key as a person reads it: ``client gid G seq N`` for an introspection event's."""
    if key[:1] == ["ev"] and len(key) >= 3:
        return f"client gid {key[1]} seq {key[2]}"
    return ":".join(str(k) for k in key)
