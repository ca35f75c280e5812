"""The checked code repairs of a monitor's violation, as the diagnosis of a report asks them
(docs/diagnosis.md, "Monitor violations: a node re-run on its recorded run").

A ``monitors`` evidence entry that names its ``implementation`` (``<file>.py:<function>``, the function
that, called without arguments, makes the robot's rclpy nodes; docs/plan.md) gives the diagnosis of a
failed run what :func:`rclverify.diagnosis.run_repair.run_repairs` needs: the file, the factory, the run
(the obligation's trace), the mapping the backend judged it with, and whether the violation is of the
node's served calls or of its topics.  :func:`monitor_repairs` searches them in the ROS 2 Python
(:func:`rclverify.runtime.rclpy_source.python.ros2_python`) and says, in one sentence, why none is
offered when the search cannot run (no entry naming the code, no ROS 2 Python, a run that is not a
JSON-lines log) or found none.  :func:`report_repairs` is that search as the diagnosis stage asks it, kept
in the diagnosis cache; :func:`rejudged_applied` the check ``rclverify repair --apply`` runs again once a
repair is written.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Mapping

from rclverify.records.problem_rows import DiagnosisRow
from rclverify.records.repair_rows import RepairRow
from rclverify.records.stage_records import Repair

if TYPE_CHECKING:  # a type only: the monitors' payload is imported by whoever decoded it
    from rclverify.backends.monitors.payload import MonitorsPayload


@dataclass
class MonitorRepairs:
    """What :func:`monitor_repairs` found: the checked ``repairs`` (best first, as JSON), the ``line``
    (``file:line``) the diagnosis names (the first repair's, else the callback's first line; ``""`` when the
    node was not re-run), and ``why`` none is offered (``""`` when one is, or when the entry names no
    implementation: nothing was asked)."""

    repairs: list[Repair] = field(default_factory=list)
    line: str = ""
    why: str = ""


def entry_of(ws: Any, node: str, data: Mapping[str, Any]) -> Any:
    """The plan's ``monitors`` evidence entry of ``node`` the obligation ``data`` (its record's ``data``:
    ``entry``, ``trace``) was exported from, ``None`` when the plan no longer has it."""
    entries = list(ws.plan.evidence.get(node, ()))
    k = data.get("entry")
    if isinstance(k, int) and 0 <= k < len(entries) and entries[k].backend == "monitors":
        return entries[k]
    return next((x for x in entries if x.backend == "monitors" and data.get("trace") in (x.config.get("traces") or ())),
                None)


def is_call_violation(payload: MonitorsPayload) -> bool:
    """Whether the run's first violation (the evidence payload's ``monitoring.first_violation``) is one of
    the node's served calls (a service's response, an action's feedback or result: the payload's ``calls``
    part names the same one) rather than of its topics."""
    fv = payload.monitoring.first_violation if payload.monitoring is not None else None
    return fv is not None and payload.calls is not None and payload.calls.get("first_violation") == fv


def monitor_repairs(ws: Any, node: str, data: Mapping[str, Any], payload: MonitorsPayload,
                    python: Path | None) -> MonitorRepairs:
    """The checked repairs of ``node``'s violation on the run of the obligation whose record's ``data`` is
    ``data`` (``trace``, ``mapping``, ``implementation``), its evidence's ``payload``, re-run in the
    ROS 2 Python ``python`` (``None``: there is none).  Nothing is asked, and ``why`` is ``""``, when the
    obligation names no implementation.  Never raises for the user's code or run (each cause is ``why``)."""
    impl = str(data.get("implementation") or "")
    if not impl:
        return MonitorRepairs()
    source, _, factory = impl.rpartition(":")
    if python is None:
        return MonitorRepairs(why=f"no repair is searched: re-running {impl} needs a Python with rclpy (source "
                              "ROS 2's setup.bash, or name one with RCLVERIFY_ROS2_PYTHON)")
    trace = str(data.get("trace") or "")
    if not trace.endswith(".jsonl"):
        return MonitorRepairs(why=f"no repair is searched: {trace} is not a JSON-lines log (the re-run reads a "
                              "live monitor's log: `rclverify monitor --live --log`)")
    from rclverify.backends.monitors.config import ConfigError, load_mapping  # deferred: start-up (the monitors)
    from rclverify.diagnosis.run_repair import run_repairs  # deferred: start-up (the property tests' search)
    entry = entry_of(ws, node, data)
    c = entry.config if entry is not None else {}
    try:
        cfg = load_mapping(ws.root, data.get("mapping"), c.get("horizon"), c.get("traces", ()), c.get("tolerance"))
    except ConfigError as exc:
        return MonitorRepairs(why=f"no repair is searched: the mapping does not load: {exc}")
    got = run_repairs(Path(ws.root), ws.checked, cfg, ws.path(trace), node, is_call_violation(payload),
                      source, factory, [], python)
    if got.repairs:
        return MonitorRepairs(list(got.repairs), got.line)
    return MonitorRepairs(why=f"{impl} re-run on {trace}: {got.why}", line=got.line)


def report_repairs(ws: Any, oid: str, node: str, data: Mapping[str, Any], payload: MonitorsPayload,
                   cache: Any) -> MonitorRepairs:
    """:func:`monitor_repairs` as the report's diagnosis asks it, for the failed obligation ``oid`` of ``node``
    (``data``: its record's ``data``; ``payload``: its evidence record's); none (nothing asked) when the
    obligation names no implementation.  Kept in ``cache`` (the diagnosis cache: ``get(key, make, extra_file)``), keyed by
    the run's and the implementation's sha256 and the run's verdict counts, unless no ROS 2 Python was found
    (nothing is asked then, and the answer is the environment's)."""
    from rclverify.core.cache import file_digest  # deferred: start-up (the cache layer)
    from rclverify.runtime.rclpy_source.python import ros2_python  # deferred: start-up (only for a named implementation)
    impl = str(data.get("implementation") or "")
    if not impl:
        return MonitorRepairs()
    python = ros2_python()
    if python is None:
        return monitor_repairs(ws, node, data, payload, None)
    trace = str(data.get("trace") or "")
    digest = file_digest(ws.path(trace)) if trace and ws.path(trace).is_file() else ""
    counts = dict(payload.monitoring.counts) if payload.monitoring is not None else None
    key = ["run", oid, node, impl, trace, digest, counts, data.get("mapping")]
    got = cache.get(key, lambda: asdict(monitor_repairs(ws, node, data, payload, python)), impl.rpartition(":")[0])
    return MonitorRepairs(**got) if isinstance(got, dict) else MonitorRepairs()  # kept as JSON: its fields


def rejudged_applied(ws: Any, diagnosis: DiagnosisRow, repair: RepairRow,
                     python: Path | None) -> list[tuple[str, str]]:
    """After a repair of a monitored violation was written (``rclverify repair --apply``): the run of
    ``diagnosis`` (a ``monitor`` record, its obligation's id; ``repair`` the one written, whose ``cost`` says
    whether the node's calls or its topics failed) judged again with the node re-run from its
    implementation file as it now reads, as the repair was checked (:func:`rclverify.diagnosis.run_repair.rejudged`):
    ``[(obligation id, the node's status on the re-judged run)]``; ``[]`` when the obligation names no
    implementation or there is no ROS 2 Python ``python``.  The evidence itself is the recorded run's until the
    run is recorded again.  Raises :class:`rclverify.diagnosis.rerun.RerunError` when the file no longer answers
    the run's questions, ``OSError`` when it cannot be read."""
    from rclverify.backends.monitors.config import load_mapping  # deferred: start-up (the monitors)
    from rclverify.diagnosis.run_repair import rejudged  # deferred: start-up (the property tests' search)
    from rclverify.records.sealed import obligation_list  # deferred: start-up (the records)
    oid, node = diagnosis.id, diagnosis.node
    records, _ = obligation_list(ws.path(ws.obligations(node)))
    data = next((dict(o.get("data") or {}) for o in records or [] if isinstance(o, dict) and o.get("id") == oid), {})
    impl = str(data.get("implementation") or "")
    if not impl or python is None:
        return []
    source, _, factory = impl.rpartition(":")
    entry = entry_of(ws, node, data)
    c = entry.config if entry is not None else {}
    cfg = load_mapping(ws.root, data.get("mapping"), c.get("horizon"), c.get("traces", ()), c.get("tolerance"))
    text = ws.path(source).read_text(encoding="utf-8")
    calls = any(c.check == f"{node} calls" and c.before == "failed" for c in repair.cost)
    got = rejudged(Path(ws.root), ws.checked, cfg, ws.path(str(data.get("trace"))), node, calls, source, text,
                   factory, [], python)
    mine = [v for k, v in got.items() if k == node or k.startswith(node + " ")]
    bad = any(v[0] == "failed" or dict(v[1]).get("false", 0) > 0 for v in mine)
    return [(oid, "failed" if bad else got[f"{node} calls" if calls else node][0])] if mine else []


__all__ = ["MonitorRepairs", "entry_of", "is_call_violation", "monitor_repairs", "rejudged_applied", "report_repairs"]
