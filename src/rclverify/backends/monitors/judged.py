"""What a monitoring run was asked to judge and did not (silence is never green).

``rclverify monitor`` (a recorded run or ``--live``) is asked to judge the
monitored contracts' **items**: each node, each topic its ``topics(...)``
names, each service and action its links name, and each node's timed
guarantees (``triggered by ... within ...``, the deadlines).  A run that
heard nothing of an item judged none of it: whatever its other verdicts,
that item is neither satisfied nor violated, and a run whose every item
went unheard is no evidence at all.  :func:`not_judged` lists those items,
one record each (docs/monitors.md, "Silence is never green"):

``{"kind": "node"|"topic"|"service"|"action"|"deadline", "name": ...,
"node": <the contract node naming it>, "reason": <one of REASONS>,
"detail": <one sentence>}``

A reason is one of :data:`REASONS`: ``nothing heard`` (no message of it
reached the monitor), ``type refused`` (a publisher of it was seen with a
type or QoS the monitor's reader cannot take; the live bus's warning
names it), ``not decoded`` (messages came but did not decode as the
contract's type), ``not paired`` (answers of a service or action came
whose request or goal was not heard or could not be matched to them),
``no answer`` (calls or goals came, no reply or result), ``no verdict``
(messages came but decided nothing: every input outside the assumption,
or no accepted trigger event), ``endpoint not heard`` (a server or client
of a service or action was not heard with contents: its introspection
off or metadata, so the link is not judged for it, whatever else of it
was; docs/monitors.md, "Every endpoint of a call accounted for").  A link
with an answer whose request was not heard (made before the monitor
started) is ``not paired`` whatever else of it was judged.
``rclverify monitor --strict`` exits 1 when the list is not empty.

Standard library only, shared by the offline command (:mod:`.cli`) and
the live runs (:mod:`.live`, :mod:`.dds_live`).
"""
from __future__ import annotations

import functools
from collections import Counter
from dataclasses import dataclass, field
from typing import Any, Iterable, Iterator, Mapping

from rclverify.lang.types import CheckedNode
from rclverify.backends.monitors.stamp_order import StampWatch
from rclverify.backends.monitors.verdicts import LINK_TOPICS

REASONS = ("nothing heard", "type refused", "not decoded", "not paired", "no answer", "no verdict",
           "endpoint not heard")
#: the parts of a link that open a call (a service's request, an action's goal) and that answer one
_OPENS = ("request", "goal")
_ANSWERS = ("response", "result")


@dataclass
class Heard:
    """What a run heard, as counts.  ``messages``: topic or link part
    (``"speed"``, ``"estop/request"``, no leading ``/``) -> messages heard
    (for a link part: calls or answers paired to their call); ``orphans``:
    link part -> answers heard whose call was not; ``decode_errors``: topic
    (or a tap's key naming the link) -> messages that did not decode;
    ``warnings``: the live bus's warning lines (a refused publisher names
    its topic); ``publishers``: topic -> publishers the live reader matched
    (``None`` offline); ``unseen``: link name (``"/estop"``) -> what the
    run's source could not hear of it (the rclpy source without
    introspection events: run_origin.py), added to its item's detail."""

    messages: dict[str, int] = field(default_factory=dict)
    orphans: dict[str, int] = field(default_factory=dict)
    decode_errors: Mapping[str, int] = field(default_factory=dict)
    warnings: Iterable[str] = ()
    publishers: Mapping[str, int] | None = None
    unseen: Mapping[str, str] = field(default_factory=dict)


def _where(block: Any, row: int) -> str:
    """Where row ``row`` of a columnar block was read."""
    return str(block[row].where)


class Counted:
    """A recorded run's events passed on unchanged, counted per topic into
    ``heard`` (topic without ``/`` -> events) as they are read.  A log the
    batch path reads in blocks (``events.blocks``, rows.py) keeps that path:
    its blocks are passed on and counted by their ``topics`` column, so
    counting never turns the columnar reading into one event at a time.
    ``watch`` (a :class:`.stamp_order.StampWatch`) sees every event's place
    on the run's clock, a columnar block by its first and last time."""

    def __init__(self, events: Iterable[Any], heard: dict[str, int], watch: StampWatch | None = None) -> None:
        self.events, self.heard, self.watch = events, heard, watch

    def __iter__(self) -> Iterator[Any]:
        heard = self.heard
        see = self.watch.see if self.watch is not None else None
        for ev in self.events:
            key = ev.topic.strip("/")
            heard[key] = heard.get(key, 0) + 1
            if see is not None:
                see(ev)
            yield ev

    def blocks(self, fields: Any, rows: int) -> Iterator[Any] | None:
        """The source's blocks (``None`` when it has none), counted."""
        source = getattr(self.events, "blocks", None)
        got = source(fields, rows) if source is not None else None
        return None if got is None else self._counted(got)

    def _counted(self, blocks: Iterator[Any]) -> Iterator[Any]:
        heard = self.heard
        watch = self.watch
        for block in blocks:
            if watch is not None:
                if isinstance(block, list):
                    for ev in block:
                        watch.see(ev)
                else:  # a columnar block: unstamped messages, their times
                    watch.see_times(block.times, functools.partial(_where, block))
            counts = getattr(block, "topic_counts", None)  # a bag block counts its connections' codes
            if counts is None:
                topics = [ev.topic for ev in block] if isinstance(block, list) else block.topics
            for key, n in (counts() if counts is not None else Counter(topics)).items():
                key = key.strip("/")
                heard[key] = heard.get(key, 0) + n
            yield block


#: the ``orphans`` keys (``"<link>/<key>"``) counting a link's endpoints not heard with contents and its
#: answers whose request was not heard (:func:`count_call_line`)
UNJUDGED, UNDECIDED = "unjudged", "undecided"


def count_call_line(obj: Mapping[str, object], messages: dict[str, int], orphans: dict[str, int]) -> None:
    """Count one call line of a live log (``kind`` ``"call"``, the DDS call
    book's) as the live run counts what it heard: a paired part (a line with
    an ``index``) into ``messages``, an answer heard without its call
    (``orphan``) into ``orphans``, both keyed ``"<link>/<part>"`` (no leading
    ``/``); an orphan that is no unpaired call (its request was not heard)
    also under ``"<link>/undecided"``, an endpoint not heard with contents
    (``part`` ``unjudged``) under ``"<link>/unjudged"``; other lines are not
    counted."""
    if obj.get("kind") != "call" or obj.get("link") is None:
        return
    link = str(obj["link"]).strip("/")
    if obj.get("part") == UNJUDGED:
        orphans[f"{link}/{UNJUDGED}"] = orphans.get(f"{link}/{UNJUDGED}", 0) + 1
        return
    key = f"{link}/{obj.get('part')}"
    book = messages if "index" in obj else orphans if obj.get("orphan") else None
    if book is not None:
        book[key] = book.get(key, 0) + 1
    if book is orphans and not obj.get("unpaired"):
        orphans[f"{link}/{UNDECIDED}"] = orphans.get(f"{link}/{UNDECIDED}", 0) + 1


def not_judged(nodes: Iterable[CheckedNode], heard: Heard, statuses: Mapping[str, Iterable[tuple[str, str]]],
               deadlines: Mapping[str, Mapping[str, int]], where: str,
               decided: Mapping[str, int] | None = None,
               undecided_why: Mapping[str, str] | None = None) -> list[dict[str, str]]:
    """The items of ``nodes``' contracts the run did not judge (module docstring).

    ``statuses``: node name -> its ``(status, explanation)`` pairs (the
    untimed check's, the live calls'); a node is judged when one of them is
    not ``pending``.  ``deadlines``: node name -> its deadline verdict counts
    (``true``, ``false``, ``currently_false``, summed over the topic and the
    call deadline monitors; a node absent has none), with ``undecided``
    where the caller counts the triggers given no verdict because it was
    undecided (:data:`.deadline_records.UNACCEPTED`: an answer within the
    transport skew of its deadline, a simulated time not known); a node's
    deadlines are judged when one trigger got ``true`` or ``false``.
    ``undecided_why``: node name -> why its first undecided trigger was, said
    in its item's detail.  ``where``: the run, as
    the details say it (``"in run.jsonl"``, ``"during the live run"``).
    ``decided``: node name -> its answers decided satisfied or violated; a
    node with none, no deadline decided and only ``inconclusive`` (or
    ``pending``) statuses decided nothing: an item "nothing decided"
    (every message undecided, a NaN on every input: never green).
    Returns the records in contract order: nodes, then topics, links and
    deadlines, each item once."""
    nodes = list(nodes)
    out: list[dict[str, str]] = []
    warnings = list(heard.warnings)
    for n in nodes:
        pairs = list(statuses.get(n.name, ()))
        if pairs and all(s == "pending" for s, _ in pairs):
            keys = _keys(n)
            if all(not heard.messages.get(t) for t in keys):
                out.append(_item("node", n.name, n.name, "nothing heard",
                                 f"no message on {', '.join('/' + t for t in keys) or 'its topics (none)'} {where}"))
            else:
                out.append(_item("node", n.name, n.name, "no verdict", pairs[0][1]))
        elif decided is not None and pairs and all(s in ("pending", "inconclusive") for s, _ in pairs):
            dl = deadlines.get(n.name, {})
            if not decided.get(n.name, 0) and not dl.get("true", 0) and not dl.get("false", 0):
                why = next(e for s, e in pairs if s == "inconclusive")
                out.append(_item("node", n.name, n.name, "nothing decided", why))
    seen: set[str] = set()
    for n in nodes:
        for t in n.node.topics:
            key = t.field.strip("/")
            if key in seen or heard.messages.get(key):
                continue
            seen.add(key)
            reason, detail = _silent_topic(key, t.msg_type, heard, warnings, where)
            out.append(_item("topic", "/" + key, n.name, reason, detail))
    for n in nodes:
        for lk in n.node.links:
            key = lk.name.strip("/")
            if key in seen:
                continue
            seen.add(key)
            found = _silent_link(key, lk.kind, heard, where)
            if found is not None:
                out.append(_item(lk.kind, "/" + key, n.name, *found))
    for n in nodes:
        timed = [k for k, c in enumerate(n.node.guarantees, 1) if c.trigger is not None]
        c = deadlines.get(n.name, {})
        if not timed or c.get("true", 0) or c.get("false", 0):
            continue
        triggers = sorted({f"in.{g.trigger.name}" for g in n.node.guarantees if g.trigger is not None})
        pending, undecided = c.get("currently_false", 0), c.get("undecided", 0)
        first = (undecided_why or {}).get(n.name)
        reason, detail = (("no verdict", f"{pending} trigger event(s) were still within their deadline {where}")
                          if pending else
                          ("no verdict", f"{undecided} trigger event(s) were undecided {where}"
                                         + (f"; the first: {first}" if first else ""))
                          if undecided else
                          ("no verdict", f"trigger events came but none was accepted (the assumption) {where}")
                          if _heard_any(n, heard, triggers) else
                          ("nothing heard", f"no event of its trigger(s) {', '.join(triggers)} {where}"))
        out.append(_item("deadline", f"{n.name} guarantee(s) {', '.join(map(str, timed))}", n.name, reason, detail))
    return out


def _item(kind: str, name: str, node: str, reason: str, detail: str) -> dict[str, str]:
    return {"kind": kind, "name": name, "node": node, "reason": reason, "detail": detail}


def _keys(n: CheckedNode) -> list[str]:
    """Every topic and link part a node's contract names (no leading ``/``)."""
    keys = [t.field.strip("/") for t in n.node.topics]
    for lk in n.node.links:
        keys += [f"{lk.name.strip('/')}/{p}" for p in LINK_TOPICS[lk.kind]]
    return keys


def _heard_any(n: CheckedNode, heard: Heard, triggers: list[str]) -> bool:
    """Whether a message carrying one of ``triggers`` (``in.x``) was heard."""
    names = {t[3:] for t in triggers}
    keys = [t.field.strip("/") for t in n.node.topics if t.match is not None and t.match.name in names]
    for lk in n.node.links:
        keys += [f"{lk.name.strip('/')}/{p}" for p, v in zip(LINK_TOPICS[lk.kind], lk.parts) if v.name in names]
    return any(heard.messages.get(k) for k in keys)


def _silent_topic(key: str, typ: str, heard: Heard, warnings: list[str], where: str) -> tuple[str, str]:
    """Why topic ``key`` was not heard: ``(reason, detail)``."""
    refused = [w for w in warnings if f": {key}: " in w and "not heard" in w]
    if refused:
        return "type refused", refused[0].split(": warning: ", 1)[-1]
    bad = heard.decode_errors.get(key, 0)
    if bad:
        return "not decoded", f"{bad} message(s) on /{key} did not decode as {typ} {where}"
    pubs = "" if heard.publishers is None else f" ({heard.publishers.get(key, 0)} publisher(s) matched)"
    return "nothing heard", f"no message on /{key} {where}{pubs}"


def _silent_link(key: str, kind: str, heard: Heard, where: str) -> tuple[str, str] | None:
    """Why link ``key`` was not judged, ``None`` when a call of it was answered;
    with what the run's source could not hear of it (``heard.unseen``)."""
    found = _link_reason(key, kind, heard, where)
    why = heard.unseen.get("/" + key)
    return found if found is None or not why else (found[0], f"{found[1]} (the rclpy source: {why})")


def _link_reason(key: str, kind: str, heard: Heard, where: str) -> tuple[str, str] | None:
    parts = LINK_TOPICS[kind]
    opened = sum(heard.messages.get(f"{key}/{p}", 0) for p in parts if p in _OPENS)
    answered = sum(heard.messages.get(f"{key}/{p}", 0) for p in parts if p in _ANSWERS)
    orphans = sum(heard.orphans.get(f"{key}/{p}", 0) for p in parts)
    what = "call(s)" if kind == "service" else "goal(s)"
    ends, undecided = heard.orphans.get(f"{key}/{UNJUDGED}", 0), heard.orphans.get(f"{key}/{UNDECIDED}", 0)
    if ends:  # whatever else of it was judged (module docstring)
        return "endpoint not heard", (f"{ends} endpoint(s) of /{key} were not heard with contents {where}: the "
                                      f"link is not judged for them")
    if opened and answered and undecided:
        return "not paired", (f"{undecided} answer(s) of /{key} came whose request was not heard (made before the "
                              f"monitor started, or by an endpoint it does not hear): undecided, beside "
                              f"{opened} {what} judged {where}")
    if opened and answered:
        return None
    bad = sum(n for k, n in heard.decode_errors.items() if key in k)
    if bad and not opened:
        return "not decoded", f"{bad} message(s) of /{key} did not decode {where}"
    if orphans:
        return "not paired", (f"{orphans} answer(s) of /{key} were heard but not paired to a {what[:-3]} "
                              f"({opened} {what} heard) {where}")
    if opened:
        return "no answer", f"{opened} {what} of /{key} were heard, none answered {where}"
    return "nothing heard", f"no {what[:-3]} of /{key} was heard {where}"


def explain(entry: dict[str, Any], items: Iterable[Mapping[str, str]]) -> None:
    """Add to a node's ``pending`` entry (``node``, ``status``,
    ``explanation``) why it was not judged, from its ``node`` item of
    ``items``: the status then says the reason itself."""
    for i in items:
        if i["kind"] == "node" and i["node"] == entry.get("node") and entry.get("status") == "pending":
            entry["explanation"] = f"{entry['explanation']} (not judged: {i['reason']}: {i['detail']})"


def strict_line(items: list[dict[str, str]]) -> str:
    """The one line ``--strict`` ends with when ``items`` is not empty."""
    first = items[0]
    return (f"rclverify monitor: --strict: {len(items)} item(s) were not judged; the first: {first['kind']} "
            f"{first['name']}: {first['reason']}: {first['detail']}")


__all__ = ["Counted", "Heard", "REASONS", "UNDECIDED", "UNJUDGED", "count_call_line", "explain", "not_judged", "strict_line"]
