"""Monitored runs counted, and a plan's statistical target judged on them (docs/statistics.md).

* :func:`run_counts` - what one run's evidence saw (``details["statistics"]``
  of every monitors record): the run's identity
  (:func:`.run_identity.run_digest` over the fields the entry's mapping
  reads), how it was recorded (``live``: a log ``rclverify monitor --live``
  wrote, with its verdict lines; ``bag``; ``log``: any other ROSMonitoring
  log), the entry's ``environment`` and ``origin``, judged answers,
  violations, inconclusive answers, the seconds observed and the violations
  per guarantee.  The answers are every judged answer of the run: those
  judged on its topics and its service calls and action goals (judged from
  a live log's call lines or a bag's call topics), each judged on one of
  the two paths and counted once;
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
from pathlib import Path
from typing import Any, Callable, Mapping

import msgspec

from rclverify.records.records import Evidence, Obligation, SourceRef, make_obligation_id
from rclverify.records.statistics import count_runs, decide
from rclverify.model.plan.targets import entry_environment, entry_origin, entry_target
from rclverify.backends.base import NodeTarget, Stopwatch, make_evidence
from rclverify.backends.monitors.verdicts import NodeResult
from rclverify.backends.monitors.shapes import RunCounts
from rclverify.backends.monitors.margin_target import of_margin
from rclverify.backends.monitors.payload import MonitorsPayload, RunStatistics, monitors_payload
from rclverify.backends.monitors.run_identity import BAG_SUFFIXES, read_fields, run_digest
from rclverify.traces.mapping import TopicRule

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




def run_counts(root: Path, config: Any, trace: str, sha: str, res: NodeResult, status: str,
               seconds: float | None, calls: Mapping[str, Any] | None = None,
               rules: Mapping[str, TopicRule] | None = None) -> RunCounts:
    """One run's counts (module docstring): ``res`` the verdicts on the
    run's topics, ``calls`` the record's ``details["calls"]`` (the node's
    calls and goals judged, :func:`.backend.with_calls`; ``None``: none),
    ``rules`` the entry's topic rules (the fields the run's identity
    reads; ``None``: every field).  A run that failed or stayed
    inconclusive on its deadlines, periods or declarations alone counts one
    violation or one undecided answer, so the run's verdict and its counts
    never disagree."""
    own = _call_result(calls)
    both = (res.counts, own.get("counts") or {})
    violations = sum(int(c.get("violated", 0)) for c in both)
    unsure = sum(int(c.get("inconclusive", 0)) + int(c.get("open", 0)) for c in both)
    answers = sum(int(c.get("satisfied", 0)) + int(c.get("violated", 0)) for c in both)
    if status == "failed" and not violations:
        violations = 1
    if status == "inconclusive" and not unsure and not violations:
        unsure = 1
    per_guarantee: dict[str, int] = {}
    for v in [*res.violations, *(own.get("violations") or ())]:
        key = str(v.get("guarantee") or 0)
        per_guarantee[key] = per_guarantee.get(key, 0) + 1
    return {"trace": trace, "sha256": run_digest(root, trace, read_fields(rules)), "files_sha256": sha,
            "recorded": recorded_as(root, trace), "environment": entry_environment(config),
            "origin": entry_origin(config), "status": status, "answers": answers, "violations": violations,
            "inconclusive": unsure, "seconds": seconds or 0.0, "violations_per_guarantee": per_guarantee,
            "per_guarantee_complete": not res.violations_dropped and not own.get("violations_dropped")}


def _call_result(calls: Mapping[str, Any] | None) -> Mapping[str, Any]:
    """The node's own call result in a record's ``details["calls"]`` (its
    ``counts`` by verdict and ``violations``), ``{}`` when the run judged
    none of its calls (``calls`` then holds the log's counts alone)."""
    if not isinstance(calls, Mapping) or "status" not in calls or not isinstance(calls.get("counts"), Mapping):
        return {}
    return calls


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
        payload = monitors_payload(ev.backend, ev.details)  # the run's record, decoded once
        seen = payload.statistics if payload is not None else None
        stats = msgspec.to_builtins(seen) if seen is not None else None
        if t.margin is not None and stats is not None and payload is not None:  # a margin target: the answers below
            margins = payload.monitoring.margins if payload.monitoring is not None else []
            stats = of_margin(stats, margins, t.guarantee, t.margin, t.per)
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
    stats = msgspec.convert({"environment": env, "origin": origin, "target": t.to_json(), "counts": counts,
                             "decision": verdict, "runs": rows}, RunStatistics)
    return evidence(status, explanation, details=MonitorsPayload(statistics=stats).details(), log=explanation)


__all__ = ["BAG_SUFFIXES", "recorded_as", "run_counts", "run_digest", "run_runset", "runset_obligations"]
