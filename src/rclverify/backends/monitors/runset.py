"""Monitored runs counted, and a plan's statistical target judged on them (docs/statistics.md).

* :func:`run_counts` - what one run's evidence saw (``details["statistics"]``
  of every monitors record): the run's digest, how it was recorded
  (``live``: a log ``rclverify monitor --live`` wrote, with its verdict
  lines; ``bag``; ``log``: any other ROSMonitoring log), the entry's
  ``environment`` and ``origin``, judged answers, violations, inconclusive
  answers, the seconds observed and the violations per guarantee;
* :func:`runset_obligations` - with a ``target:`` the entry exports one more
  obligation, "the runs of the entry bound the violation probability under
  its environment", whose inputs are all of its traces;
* :func:`run_runset` - that obligation's evidence: every trace checked as
  its own obligation is (the same verdicts), each distinct digest counted
  once, and the target decided (:func:`rclverify.records.statistics.decide`).
  Runs of ``origin: harness`` are listed and never counted.

A run's own record stays what it was: a violation fails it (counter-evidence
for the guarantee, docs/confidence.md C0), while the run set's record judges
the separate, quantified claim.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
from pathlib import Path
from typing import IO, Any, Callable, Iterator

from rclverify.records.records import Evidence, Obligation, SourceRef, make_obligation_id
from rclverify.records.statistics import count_runs, decide
from rclverify.model.plan.targets import entry_environment, entry_origin, entry_target
from rclverify.backends.base import NodeTarget, Stopwatch, make_evidence
from rclverify.backends.monitors.verdicts import NodeResult
from rclverify.backends.monitors.shapes import RunCounts
from rclverify.backends.monitors.margin_target import of_margin

#: The suffixes of a bag file (a directory is a ROS 2 bag too).
BAG_SUFFIXES = (".bag", ".mcap", ".db3")
#: The topic of a live log's verdict lines (live.VERDICT_LOG_TOPIC; not imported: live.py pulls the engine in).
_LIVE_MARK = b'"rclverify/verdict"'


def recorded_as(root: Path, trace: str) -> str:
    """``bag``, ``live`` or ``log`` (module docstring)."""
    p = root / trace
    if p.is_dir() or p.suffix in BAG_SUFFIXES:
        return "bag"
    try:
        with p.open("rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                if _LIVE_MARK in block:
                    return "live"
    except OSError:
        return "log"
    return "log"


def run_digest(root: Path, trace: str) -> str:
    """The run's identity (docs/statistics.md, "A run's identity"): a hex
    sha256 over the sorted multiset of its messages' canonical records, so
    one run is one identity whatever its form.

    ``trace`` is read from ``root`` by the monitors' own readers (a
    ROSMonitoring log by :func:`~rclverify.traces.jsonl.read_lines`, a bag
    opened by :func:`~rclverify.traces.bag.open_bag` and each message
    decoded by its type store, as :func:`~rclverify.traces.bag.bag_event`
    decodes it, less the type's constants), each message becoming
    ``[topic, time, fields]`` (:func:`_record`): the topic without its
    leading ``/``; the time the message's header stamp when it has one (its
    source time, :attr:`~rclverify.traces.events.Event.stamped`), else its
    time (a bag's recording time ``ns / 1e9``, a log's ``time``); the
    fields flattened to dotted paths, sorted, a number by its value.  So a
    run written as a log, an sqlite3 bag and an MCAP bag, reformatted,
    reordered, or with its topics written with or without ``/``, is one
    run; a changed value, time or message makes another.

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
        found = _bag_identity(p) if p.is_dir() or p.suffix in BAG_SUFFIXES else _log_identity(p)
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
#: The member rosidl gives a message without fields (rosbags decodes it; the live monitor leaves it out).
_EMPTY_MEMBER = "structure_needs_at_least_one_member"
#: Top-level fields a ROSMonitoring log cannot hold beside its own ``topic`` and ``time``.
_LOG_KEYS = frozenset(("topic", "time"))


def _is_call_topic(topic: str) -> bool:
    """A bag topic that holds service or action calls (backends/monitors/bag_calls.py), or the call decisions."""
    return topic.endswith("/_service_event") or "/_action/" in topic or topic.startswith(_OWN)


def _identity(messages: list[bytes], calls: list[bytes]) -> str | None:
    """The hex sha256 of the sorted multiset ``messages`` (each a record's own sha256), else of ``calls``
    (marked so it never equals a run's messages), else ``None`` (no record: the caller hashes the bytes)."""
    kind, records = (b"messages", messages) if messages else (b"calls", calls)
    if not records:
        return None
    records.sort()
    h = hashlib.sha256(b"rclverify run identity 1: " + kind + b"\n")
    for r in records:
        h.update(r)
    return h.hexdigest()


def _log_identity(path: Path) -> str | None:
    """:func:`run_digest` of a ROSMonitoring log; raises what its reader raises for a line that is
    neither a message nor a JSON object without ``topic`` or ``time`` (a line that is no message)."""
    from rclverify.traces.jsonl import read_lines  # deferred: start-up (only where a run is counted)
    from rclverify.traces.events import TraceError  # deferred: start-up (only where a run is counted)
    messages: list[bytes] = []
    calls: list[bytes] = []
    record, sha = _record, hashlib.sha256
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
                        messages.append(sha(record(topic, ev.stamped, ev.fields)).digest())
                    elif topic == "rclverify/call":
                        calls.append(sha(record(topic, ev.stamped, ev.fields)).digest())
                break
            except TraceError:
                if not _no_message(last[0]):
                    raise
                # a line that is no message (the ROS 1 service proxy's verdict and summary lines): the next one
    return _identity(messages, calls)


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


def _bag_identity(path: Path) -> str | None:
    """:func:`run_digest` of a bag.  A message its type store cannot decode (a type the bag does not
    define) is recorded by its topic, time, type and serialized bytes, as every form of the bag holds them."""
    from rclverify.traces.bag import open_bag, typestore  # deferred: start-up (loads rosbags only when called)
    from rclverify.traces.events import header_stamp  # deferred: start-up (only where a run is counted)
    reader = open_bag(path, typestore([]))
    messages: list[bytes] = []
    held: list[tuple[Any, int, bytes]] = []  # the call topics' messages, decoded only for a run without others
    sha, names = hashlib.sha256, _field_names(reader.typestore)

    def one(index: int, conn: Any, stamp: int, raw: bytes) -> bytes:
        try:
            msg = reader.deserialize(raw, conn.msgtype)
        except Exception:  # noqa: BLE001 - a type the bag does not define: the message as every form stores it
            return sha(_raw_record(conn.topic.lstrip("/"), stamp / 1e9, conn.msgtype, raw)).digest()
        pairs: list[tuple[str, Any]] = []
        _flat_message("", msg, names, pairs)
        t: Any = getattr(getattr(msg, "header", None), "stamp", None)
        # as bag_event: its header's stamp, when it has one, is its source time
        own = header_stamp({"header": {"stamp": {"sec": t.sec, "nanosec": t.nanosec}}}) \
            if hasattr(t, "sec") and hasattr(t, "nanosec") else None
        return sha(_ENCODE([conn.topic.lstrip("/"), _value(stamp / 1e9 if own is None else own),
                            _sorted([kv for kv in pairs if kv[0] not in _LOG_KEYS])])).digest()
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


def _flat_message(prefix: str, msg: Any, names: Callable[[Any], tuple[str, ...]],
                  out: list[tuple[str, Any]]) -> None:
    """A decoded bag message's fields into ``out`` as :func:`_flat` puts the same message's fields
    read from a log (``names``: a message's field names): rosbags' message classes also hold the
    type's constants and name as dataclass fields, which are not the message's, and the live
    monitor's log, decoded with other classes, does not hold them."""
    for n in names(msg):
        if n == _EMPTY_MEMBER:
            continue
        x = getattr(msg, n)
        p = prefix + n
        t = type(x)
        if t is float:
            out.append((p, int(x) if x.is_integer() else x if -_INF < x < _INF else repr(x)))
        elif t is int or t is str or t is bool:
            out.append((p, x))
        elif hasattr(x, "__dataclass_fields__"):
            k = len(out)
            _flat_message(p + ".", x, names, out)
            if len(out) == k:
                out.append((p, {}))
        else:
            out.append((p, _message_value(x, names)))


def _message_value(v: Any, names: Callable[[Any], tuple[str, ...]]) -> Any:
    """A decoded field's value that is no scalar and no message, as :func:`_value` gives it from a log:
    an array as a list, a message in a sequence as its sorted flattened pairs."""
    if hasattr(v, "tolist"):
        return _value(v.tolist())
    if isinstance(v, (list, tuple)):
        out = []
        for x in v:
            if hasattr(x, "__dataclass_fields__"):
                pairs: list[tuple[str, Any]] = []
                _flat_message("", x, names, pairs)
                out.append(_sorted(pairs))
            else:
                out.append(_message_value(x, names))
        return out
    return _value(v)


def _field_names(store: Any) -> Callable[[Any], tuple[str, ...]]:
    """A decoded message's field names, as its type's definition in ``store`` (a rosbags type store)
    lists them (not its constants), each type's looked up once."""
    known: dict[str, tuple[str, ...]] = {}

    def names(msg: Any) -> tuple[str, ...]:
        t = getattr(msg, "__msgtype__", "")
        got = known.get(t)
        if got is None:
            defs = store.fielddefs.get(t)
            got = known[t] = (tuple(f[0] for f in defs[1]) if defs is not None else
                              tuple(f.name for f in dataclasses.fields(msg) if f.default is dataclasses.MISSING))
        return got
    return names


def _record(topic: str, time: float, fields: Any) -> bytes:
    """One message's canonical record: JSON ``[topic, time, [[path, value], ...]]``, the topic without
    its leading ``/``, the fields flattened (:func:`_flat`; a top-level ``topic`` or ``time``, which a
    log cannot hold beside its own, left out) and sorted by path (:func:`run_digest`)."""
    pairs: list[tuple[str, Any]] = []
    _flat("", fields, pairs)
    if "topic" in fields or "time" in fields:
        pairs = [kv for kv in pairs if kv[0] not in _LOG_KEYS]
    return _ENCODE([topic.lstrip("/"), _value(time), _sorted(pairs)])


def _raw_record(topic: str, time: float, msgtype: str, raw: bytes) -> bytes:
    """The record of a bag message that does not decode: its topic, time, type and bytes' sha256."""
    return _ENCODE([topic, _value(time), msgtype, hashlib.sha256(raw).hexdigest()])


def _flat(prefix: str, fields: Any, out: list[tuple[str, Any]]) -> None:
    """The fields of mapping ``fields`` into ``out`` as ``(path, value)``: a field's path is
    ``prefix.name`` (``name`` at the top), a nested mapping's fields are flattened (an empty one, or
    one holding rosidl's placeholder member alone, is ``{}`` at its path), any other value is
    :func:`_value`'s."""
    for k, x in fields.items():
        if k == _EMPTY_MEMBER:
            continue
        p = f"{prefix}.{k}" if prefix else str(k)
        t = type(x)
        if t is float:
            out.append((p, int(x) if x.is_integer() else x if -_INF < x < _INF else repr(x)))
        elif t is int or t is str or t is bool:
            out.append((p, x))
        elif isinstance(x, dict):
            n = len(out)
            _flat(p, x, out)
            if len(out) == n:
                out.append((p, {}))
        else:
            out.append((p, _value(x)))


def _value(v: Any) -> Any:
    """``v`` canonical: a float that is an integer as that integer, a NaN or an infinity as the text the
    live monitor writes for it (``"nan"``, ``"inf"``, ``"-inf"``), bytes and arrays as lists, a mapping
    as its sorted flattened pairs; booleans, integers, other floats and text as they are."""
    t = type(v)
    if t is float:
        if v.is_integer():
            return int(v)
        return v if -_INF < v < _INF else repr(v)
    if t is list or t is tuple:
        return [_value(x) for x in v]
    if isinstance(v, dict):
        pairs: list[tuple[str, Any]] = []
        _flat("", v, pairs)
        return _sorted(pairs)
    if isinstance(v, (bytes, bytearray)):
        return list(v)
    if hasattr(v, "tolist"):  # an array, or a numpy scalar
        return _value(v.tolist())
    return v


def _sorted(pairs: list[tuple[str, Any]]) -> list[list[Any]]:
    """``pairs`` sorted by path; two of one path (a log naming ``a.b`` and ``a: {b}``) by their JSON."""
    pairs.sort(key=_first)
    if len({p for p, _ in pairs}) != len(pairs):
        pairs.sort(key=lambda kv: (kv[0], _ENCODE(kv[1])))
    return [[p, x] for p, x in pairs]


def _first(kv: tuple[str, Any]) -> str:
    return kv[0]


_INF = float("inf")


def _encode(v: Any) -> bytes:
    """Compact JSON of a canonical record (msgspec: floats by their shortest repr, integers exact)."""
    global _ENCODE
    import msgspec  # deferred: start-up (only where a run is counted)
    _ENCODE = msgspec.json.Encoder(order="sorted").encode
    return _ENCODE(v)


_ENCODE: Callable[[Any], bytes] = _encode


def run_counts(root: Path, config: Any, trace: str, sha: str, res: NodeResult, status: str,
               seconds: float | None) -> RunCounts:
    """One run's counts (module docstring).  A run that failed or stayed
    inconclusive on its deadlines, periods or calls alone counts one
    violation or one undecided answer, so the run's verdict and its counts
    never disagree."""
    c = res.counts
    violations = int(c.get("violated", 0))
    unsure = int(c.get("inconclusive", 0)) + int(c.get("open", 0))
    if status == "failed" and not violations:
        violations = 1
    if status == "inconclusive" and not unsure and not violations:
        unsure = 1
    per_guarantee: dict[str, int] = {}
    for v in res.violations:
        key = str(v.get("guarantee") or 0)
        per_guarantee[key] = per_guarantee.get(key, 0) + 1
    return {"trace": trace, "sha256": run_digest(root, trace), "files_sha256": sha, "recorded": recorded_as(root, trace),
            "environment": entry_environment(config), "origin": entry_origin(config), "status": status,
            "answers": int(c.get("satisfied", 0)) + int(c.get("violated", 0)), "violations": violations,
            "inconclusive": unsure, "seconds": seconds or 0.0, "violations_per_guarantee": per_guarantee,
            "per_guarantee_complete": not res.violations_dropped}


def of_guarantee(row: dict[str, Any], k: int) -> dict[str, Any]:
    """A run's counts for guarantee ``k`` alone: its violations of ``k``; a
    violation the run did not attribute to one guarantee (a missed deadline
    or period, a failed call, or one beyond the violations the record kept)
    is an undecided answer of ``k``, never a clean one."""
    per = row.get("violations_per_guarantee") or {}
    attributed = sum(int(v) for v in per.values())
    unattributed = max(0, int(row.get("violations") or 0) - attributed)
    return {**row, "violations": int(per.get(str(k), 0)),
            "inconclusive": int(row.get("inconclusive") or 0) + unattributed}


def runset_obligations(target: NodeTarget, traces: list[str], per_trace: list[Obligation]) -> list[Obligation]:
    """The run-set obligation of an entry with a ``target:`` (``[]`` without one or without traces)."""
    t = entry_target(target.config)
    if t is None:
        return []
    env = entry_environment(target.config)
    k = t.guarantee  # 0: the whole contract
    oid = make_obligation_id(target.node.name, k, "monitors", f"runs_{env}_e{target.index}")
    what = f"guarantee {k}" if k else "its contract"
    statement = (f"the runs of {target.node.name} recorded under {env} bound the probability that a "
                 f"{t.per} violates {what}: {t.words()}" if t.margin is None else
                 f"the runs of {target.node.name} recorded under {env} bound the probability that a {t.per} "
                 f"keeps less than {t.margin:g} of guarantee {k}'s margin: {t.words()}")
    data = {"trace": "", "run_set": list(traces), "target": t.to_json(), "environment": env}
    if not per_trace:  # a target and no run: pending, never silently dropped
        loc = target.node.node.guarantees[k - 1].loc if k else target.node.node.loc
        f = Path(loc.file)
        if f.is_absolute() and f.resolve().is_relative_to(target.root.resolve()):
            f = f.resolve().relative_to(target.root.resolve())
        return [Obligation(id=oid, node=target.node.name, guarantee=k, backend="monitors", kind="monitoring",
                           statement=statement, source=SourceRef(f.as_posix(), loc.line, loc.col),
                           instance=f"runs_{env}_e{target.index}",
                           inputs=tuple(sorted({*target.contract_files, target.plan_file})), data=data)]
    first = per_trace[0]
    inputs = sorted({i for o in per_trace for i in o.inputs})
    source = first.source
    if k:
        g = target.node.node.guarantees[k - 1].loc
        source = SourceRef(first.source.file, g.line, g.col)
    return [dataclasses.replace(first, id=oid, guarantee=k, source=source, statement=statement,
                                instance=f"runs_{env}_e{target.index}", inputs=tuple(inputs),
                                data={**first.data, **data})]


def run_runset(check_one: Callable[[Obligation, NodeTarget], Evidence], obligation: Obligation,
               target: NodeTarget, versions: str) -> Evidence:
    """The run-set obligation's evidence (module docstring); ``check_one``
    is the backend's per-trace ``run``."""
    clock = Stopwatch()
    t = entry_target(target.config)
    env, origin = entry_environment(target.config), entry_origin(target.config)

    def evidence(status: str, explanation: str, **kw: Any) -> Evidence:
        return make_evidence(target, obligation, status, tool="rclverify monitor", tool_version=versions,
                             clock=clock, explanation=explanation, **kw)
    if t is None:
        return evidence("error", "the plan entry no longer states a target that reads")
    rows = []
    own = {k: v for k, v in obligation.data.items() if k not in ("run_set", "target", "environment")}
    for trace in dict.fromkeys(str(x) for x in obligation.data.get("run_set", ())):
        # its record is read for its verdict and counts only: no input hashed (the run set's record hashes them all)
        # and its entry seen with this trace only (the entry's check of every trace is done once, at export)
        one = dataclasses.replace(target, config={**target.config, "traces": [trace]})
        ev = check_one(dataclasses.replace(obligation, data={**own, "trace": trace}, inputs=()), one)
        stats = (ev.details or {}).get("statistics")
        if t.margin is not None and isinstance(stats, dict):  # a margin target: the answers below its margin
            mon = (ev.details or {}).get("monitoring") or {}
            stats = of_margin(stats, mon.get("margins") or (), t.guarantee, t.margin, t.per)
        rows.append(stats if isinstance(stats, dict) else
                    {"trace": trace, "sha256": f"unread:{trace}", "status": ev.status, "answers": 0,
                     "violations": 0, "inconclusive": 0, "seconds": 0.0, "reason": ev.explanation})
    counted = ([] if origin == "harness" else rows if t.margin is not None
               else [of_guarantee(r, t.guarantee) for r in rows] if t.guarantee else rows)
    counts = count_runs(counted)
    verdict = decide(counts, t)
    status, explanation = verdict["status"], f"under {env}: {verdict['explanation']}"
    if origin == "harness":
        status, explanation = "pending", (f"the {len(rows)} run(s) under {env} were driven by a test harness "
                                          f"(origin: harness): they are not operation and count toward no bound")
    errors = [r for r in rows if r.get("status") == "error"]
    if errors and status == "discharged":  # an unreadable run may have violated: no bound without it
        status = "inconclusive"
        explanation += (f"; but {len(errors)} run(s) could not be checked (first: {errors[0].get('trace')}): "
                        f"the bound holds only if they were clean")
    if counts["duplicates"]:
        explanation += f"; {counts['duplicates']} run file(s) repeat a run already counted (same sha256)"
    if origin == "simulation":
        explanation += "; the runs are simulated (origin: simulation): the bound holds for the simulator's runs"
    details = {"statistics": {"environment": env, "origin": origin, "target": t.to_json(), "counts": counts,
                              "decision": verdict, "runs": rows}}
    return evidence(status, explanation, details=details, log=explanation)


__all__ = ["BAG_SUFFIXES", "recorded_as", "run_counts", "run_runset", "runset_obligations"]
