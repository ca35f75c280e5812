"""A monitored run's identity: what one run is, whatever the form it was recorded in (docs/statistics.md,
"A run's identity").

:func:`run_digest` gives each recorded run (a ROSMonitoring log, a ROS 2
bag in sqlite3 or MCAP, a ROS 1 bag) a hex sha256 over the sorted multiset
of its messages' canonical records, each ``[topic, time, fields]``, the
time relative to the run's first (so a copy with every time shifted by one
offset is the same run).  The
fields are the ones the contracts read: with the entry's topic rules
(:func:`read_fields`: the ``fields`` each rule of the mapping file lists),
a message's other fields are left out, so a copy of a run with a field
added that no rule reads is the same run, and a run with a read value
changed is another.  A topic whose rule lists no fields (its fields are
taken in order) keeps every field.  The run set's counts
(:mod:`.runset`) and the report's margins (report/margin_rows.py) count a
run once per identity.
"""
from __future__ import annotations

import hashlib
import json
import math
from decimal import Decimal
from pathlib import Path
from typing import IO, Any, Iterator, Mapping

from rclverify.traces.mapping import EVERY, TopicRule, parse_path
from rclverify.backends.monitors.canonical_fields import (canonical_json, field_names, flat, flat_message, is_stamp,
                                                          only_read, sorted_pairs)

#: The suffixes of a bag file (a directory is a ROS 2 bag too).
BAG_SUFFIXES = (".bag", ".mcap", ".db3")
#: Topic (no leading ``/``) -> the field paths its rule reads (each the path's field names up to its first
#: index: ``ranges[0]`` reads ``ranges``); a topic absent reads every field.
ReadFields = Mapping[str, tuple[str, ...]]


def read_fields(rules: Mapping[str, TopicRule] | None) -> dict[str, tuple[str, ...]]:
    """The fields a mapping's topic ``rules`` read (:data:`ReadFields`): per
    topic, the paths its rule lists, or, for a topic whose variables have
    rules of their own (``fields: {x: [...], y: [...]}``), the paths of
    those lists; each path cut at its first index (``ranges[0]`` and
    ``poses[*].position.x`` read ``ranges`` and ``poses``).  A topic whose
    rule lists no field, or a field that is no name (a position), is left
    out: every field of it is read.  ``None`` gives ``{}``."""
    if not rules:
        return {}
    lists: dict[str, list[tuple[str, ...]]] = {}
    for (topic, _), rule in getattr(rules, "by_var", {}).items():
        lists.setdefault(str(topic).lstrip("/"), []).append(rule.fields)
    for topic, rule in rules.items():
        if str(topic).lstrip("/") not in lists:
            lists[str(topic).lstrip("/")] = [rule.fields]
    out: dict[str, tuple[str, ...]] = {}
    for topic, field_lists in lists.items():
        cut = [_read_path(f) for fields in field_lists for f in fields]
        if all(field_lists) and cut and all(cut):
            out[topic] = tuple(sorted(set(cut)))
    return out


def _read_path(field: str) -> str:
    """The field names of a rule's path up to its first index (``""``: not a path)."""
    steps = parse_path(field)
    names: list[str] = []
    for s in steps or ():
        if not isinstance(s, str) or s == EVERY:
            break
        names.append(s)
    return ".".join(names)


def run_digest(root: Path, trace: str, read: ReadFields | None = None) -> str:
    """The run's identity (docs/statistics.md, "A run's identity"): a hex
    sha256 over the sorted multiset of its messages' canonical records, so
    one run is one identity whatever its form.

    ``trace`` is read from ``root`` by the monitors' own readers (a
    ROSMonitoring log by :func:`~rclverify.traces.jsonl.read_lines`, a bag
    opened by :func:`~rclverify.traces.bag.open_bag` and each message
    decoded by its type store, as :func:`~rclverify.traces.bag.bag_event`
    decodes it, less the type's constants), each message becoming
    ``[topic, time, fields]`` (:func:`_record`, :func:`_relative`): the
    topic without its leading ``/``; the time the message's header stamp
    when it has one (its source time, in integer nanoseconds after the run's
    first stamp), else its time (a bag's recording time ``ns / 1e9``, a
    log's ``time``) as the exact decimal difference from the run's first
    such time; the fields flattened to dotted paths, sorted, a number by its
    value, the header stamp left out when it is the time; with ``read``
    (:func:`read_fields` of the entry's mapping), only the fields it names
    for the message's topic.  So a run written as a log, an sqlite3 bag and
    an MCAP bag, reformatted, reordered, with its topics written with or
    without ``/``, with fields added that no rule reads, or with every time
    shifted by one offset, is one run; a changed read value, a changed time
    between two messages, or a changed message makes another.

    Left out, because a log and a bag hold them in different forms: the
    lines of rclverify's own topics (``rclverify/verdict``,
    ``rclverify/run``, ``rclverify/call``, ...), a log's lines that are no
    message (no string ``topic`` or no numeric ``time``), and a bag's
    service and action call topics (``.../_service_event``,
    ``.../_action/...``) and ``rclverify/call_decisions``.  A run with no
    message beside those is identified by its call lines (a log) or call
    messages (a bag), then, with none either, by its bytes, as is a file
    neither reader takes (a bag directory's files by their names).  Never
    raises for an unreadable run: its bytes identify it (or, unreadable
    too, ``unread:<trace>``); the check reports why it is unreadable."""
    p = root / trace
    try:
        found = _bag_identity(p, read or {}) if p.is_dir() or p.suffix in BAG_SUFFIXES else _log_identity(p, read or {})
    except Exception:  # noqa: BLE001 - unreadable as a run: identified by its bytes; the check reports why
        found = None
    if found is not None:
        return found
    h = hashlib.sha256()
    try:
        files = sorted(f for f in p.rglob("*") if f.is_file()) if p.is_dir() else [p]
        for f in files:
            if p.is_dir():
                h.update(f.relative_to(p).as_posix().encode() + b"\0")
            with f.open("rb") as fh:
                for block in iter(lambda: fh.read(1 << 20), b""):
                    h.update(block)
    except OSError:
        return f"unread:{trace}"
    return h.hexdigest()


#: The topics of rclverify's own lines and messages (verdicts, the run's origin, its calls as the live call
#: book wrote them, blocked messages, the call decisions of a bag): no message of the robot.
_OWN = "rclverify/"
#: Top-level fields a ROSMonitoring log cannot hold beside its own ``topic`` and ``time``.
_LOG_KEYS = frozenset(("topic", "time"))


def _is_call_topic(topic: str) -> bool:
    """A bag topic that holds service or action calls (backends/monitors/bag_calls.py), or the call decisions."""
    return topic.endswith("/_service_event") or "/_action/" in topic or topic.startswith(_OWN)


#: A record before its time is made relative: ``(topic, stamp_ns, time, payload)``, ``stamp_ns`` the
#: header stamp in integer nanoseconds (``None``: no stamp), ``time`` the receipt time (s) otherwise,
#: ``payload`` the sorted read fields' pairs, or ``[type, sha256]`` of a bag message that does not decode
#: (``raw`` true).
Pending = tuple[str, "int | None", float, Any, bool]


def _relative(pending: list[Pending]) -> list[bytes]:
    """Each pending record's canonical record's sha256, its time made relative to the run's first
    (docs/statistics.md, "A run's identity"): a header stamp as integer nanoseconds after the run's
    first stamp, a receipt time as the exact decimal difference of its double and the run's first
    receipt time's (each by its shortest repr), so a copy with every time shifted by one offset gives
    the same records."""
    stamps = [p[1] for p in pending if p[1] is not None]
    times = [_decimal(p[2]) for p in pending if p[1] is None]
    s0 = min(stamps) if stamps else 0
    t0 = min(times) if times else Decimal(0)
    sha, out = hashlib.sha256, []
    for topic, ns, t, payload, raw in pending:
        when: list[Any] = ["stamp", ns - s0] if ns is not None else ["time", str((_decimal(t) - t0).normalize())]
        out.append(sha(canonical_json([topic, when, *payload] if raw else [topic, when, payload])).digest())
    return out


def _decimal(t: float) -> Decimal:
    """The double ``t`` as the decimal its shortest repr writes (a NaN or an infinity as 0: no time)."""
    return Decimal(repr(float(t))) if math.isfinite(t) else Decimal(0)


def _identity(messages: list[Pending], calls: list[Pending]) -> str | None:
    """The hex sha256 of the sorted multiset of ``messages``' records (each its own sha256,
    :func:`_relative`), else of ``calls``' (marked so it never equals a run's messages), else ``None``
    (no record: the caller hashes the bytes)."""
    kind, pending = (b"messages", messages) if messages else (b"calls", calls)
    if not pending:
        return None
    records = _relative(pending)
    records.sort()
    h = hashlib.sha256(b"rclverify run identity 2: " + kind + b"\n")
    for r in records:
        h.update(r)
    return h.hexdigest()


def _log_identity(path: Path, read: ReadFields) -> str | None:
    """:func:`run_digest` of a ROSMonitoring log; raises what its reader raises for a line that is
    neither a message nor a JSON object without ``topic`` or ``time`` (a line that is no message)."""
    from rclverify.traces.jsonl import read_lines  # deferred: start-up (only where a run is counted)
    from rclverify.traces.events import TraceError  # deferred: start-up (only where a run is counted)
    messages: list[Pending] = []
    calls: list[Pending] = []
    record = _record
    last = [b""]

    def lines(fh: IO[bytes]) -> Iterator[bytes]:
        for raw in fh:
            last[0] = raw
            yield raw
    end = [0, 0]
    with path.open("rb") as fh:
        chunks = lines(fh)
        while True:
            try:
                for ev in read_lines(path, chunks, end[0], end[1], end):
                    topic = ev.topic
                    if not topic.startswith(_OWN):
                        messages.append(record(topic, _stamp_ns(ev), ev.time, ev.fields, read))
                    elif topic == "rclverify/call":
                        calls.append(record(topic, _stamp_ns(ev), ev.time, ev.fields))
                break
            except TraceError:
                if not _no_message(last[0]):
                    raise
                # a line that is no message (the ROS 1 service proxy's verdict and summary lines): the next one
    return _identity(messages, calls)


def _stamp_ns(ev: Any) -> int | None:
    """A log event's header stamp in integer nanoseconds (``None``: the event has none), exactly as its
    ``sec``/``nanosec`` integers give it (:func:`~rclverify.traces.events.header_stamp_ns`)."""
    if ev.stamp is None:
        return None
    from rclverify.traces.events import header_stamp_ns, to_ns  # deferred: start-up
    ns = header_stamp_ns(ev.fields)
    return to_ns(ev.stamp) if ns is None else ns


def _no_message(raw: bytes) -> bool:
    """Whether ``raw`` is a JSON object without a string ``topic`` or without a numeric ``time``."""
    try:
        obj = json.loads(raw)
    except (ValueError, RecursionError):
        return False
    if not isinstance(obj, dict):
        return False
    t = obj.get("time")
    return not isinstance(obj.get("topic"), str) or isinstance(t, bool) or not isinstance(t, (int, float))


def _bag_identity(path: Path, read: ReadFields) -> str | None:
    """:func:`run_digest` of a bag.  A message its type store cannot decode (a type the bag does not
    define) is recorded by its topic, time, type and serialized bytes, as every form of the bag holds them."""
    from rclverify.traces.bag import open_bag, typestore  # deferred: start-up (loads rosbags only when called)
    from rclverify.traces.events import header_stamp  # deferred: start-up (only where a run is counted)
    reader = open_bag(path, typestore([]))
    messages: list[Pending] = []
    held: list[tuple[Any, int, bytes]] = []  # the call topics' messages, decoded only for a run without others
    names = field_names(reader.typestore)

    def one(index: int, conn: Any, stamp: int, raw: bytes) -> Pending:
        try:
            msg = reader.deserialize(raw, conn.msgtype)
        except Exception:  # noqa: BLE001 - a type the bag does not define: the message as every form stores it
            return (conn.topic.lstrip("/"), None, stamp / 1e9, [conn.msgtype, hashlib.sha256(raw).hexdigest()], True)
        pairs: list[tuple[str, Any]] = []
        flat_message("", msg, names, pairs)
        t: Any = getattr(getattr(msg, "header", None), "stamp", None)
        # as bag_event: its header's stamp, when it has one, is its source time
        own = header_stamp({"header": {"stamp": {"sec": t.sec, "nanosec": t.nanosec}}}) \
            if hasattr(t, "sec") and hasattr(t, "nanosec") else None
        name = conn.topic.lstrip("/")
        kept = [kv for kv in pairs if kv[0] not in _LOG_KEYS and (own is None or not is_stamp(kv[0]))]
        return (name, None if own is None else int(t.sec) * 1_000_000_000 + int(t.nanosec), stamp / 1e9,
                sorted_pairs(only_read(kept, read.get(name))), False)
    try:
        for index, (conn, stamp, raw) in enumerate(reader.messages()):
            if _is_call_topic(conn.topic.lstrip("/")):
                held.append((conn, stamp, bytes(raw)))
            else:
                messages.append(one(index, conn, stamp, raw))
        calls = [] if messages else [one(i, c, s, r) for i, (c, s, r) in enumerate(held)]
    finally:
        reader.close()
    return _identity(messages, calls)


def _record(topic: str, stamp_ns: int | None, time: float, fields: Any, read: ReadFields | None = None) -> Pending:
    """One message's pending record (:data:`Pending`): the topic without its leading ``/``, its header
    stamp ``stamp_ns`` or else its ``time``, its fields flattened (:func:`flat`; a top-level ``topic``
    or ``time``, which a log cannot hold beside its own, left out, and the header stamp, which is its
    time, left out when it has one; with ``read``, the fields it names for the topic only) and sorted by
    path (:func:`run_digest`)."""
    pairs: list[tuple[str, Any]] = []
    flat("", fields, pairs)
    if "topic" in fields or "time" in fields:
        pairs = [kv for kv in pairs if kv[0] not in _LOG_KEYS]
    if stamp_ns is not None:
        pairs = [kv for kv in pairs if not is_stamp(kv[0])]
    name = topic.lstrip("/")
    if read:
        pairs = only_read(pairs, read.get(name))
    return (name, stamp_ns, time, sorted_pairs(pairs), False)


__all__ = ["BAG_SUFFIXES", "ReadFields", "read_fields", "run_digest"]
