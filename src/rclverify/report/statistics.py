"""Statistical guarantees in the report (docs/statistics.md).

* :func:`compact` - an evidence record's ``details["statistics"]`` as the
  report row carries it (the run set's list of runs left in the record);
* :func:`statistics_part` - the report's ``statistics`` table: the
  monitored runs grouped by node, environment tag and origin (each run
  counted once, by its content digest; never a bound across two tags),
  with the one-sided 95 % Clopper-Pearson bound on the probability that a
  run violates the node's contract (a stale or altered record's counts
  are left out); beside them every target's row (the
  run sets' and the experiments' records); and each requirement's runs
  grouped by the tags of the entries that recorded them, decided against
  its ``target`` when it states one.  Each per-run evidence row gets its
  group's bound (``statistics.group``), which the confidence uses as the
  doubt of that run evidence (:mod:`rclverify.report.argument.strength`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping

import msgspec

from rclverify.records.evidence_rows import EvidenceRow
from rclverify.records.report_record import AssuranceReport
from rclverify.records.requirement_check import RequirementCheckRow
from rclverify.records.requirement_rows import RequirementRow
from rclverify.records.statistics_rows import RequirementRuns, StatisticsRow
from rclverify.report.shapes import RunGroupBound

from rclverify.records.statistics import count_runs, decide, trivial_or_exact
from rclverify.model.plan.model import Plan
from rclverify.model.plan.targets import UNSTATED, entry_environment, entry_origin

#: The level of a bound drawn where the plan states no target.
LEVEL = 0.95
#: Report statuses whose record's counts are not believed: made from other inputs, or altered (docs/integrity.md).
_UNBELIEVED = ("stale", "error")


def compact(stats: Mapping[str, Any]) -> dict[str, Any]:
    """The report's copy of a record's statistics: the run list summarised
    (how many runs were recorded live, from bags, as other logs)."""
    out = {k: v for k, v in stats.items() if k != "runs"}
    if isinstance(stats.get("counts"), Mapping):
        out["counts"] = {k: v for k, v in stats["counts"].items() if k != "digests"}
    runs = stats.get("runs")
    if isinstance(runs, list):
        recorded: dict[str, int] = {}
        for r in runs:
            if isinstance(r, Mapping):
                recorded[str(r.get("recorded", "unknown"))] = recorded.get(str(r.get("recorded", "unknown")), 0) + 1
        out["recorded"] = recorded
    return out


def _node(obligation: str) -> str:
    return obligation.split(".", 1)[0]


def _group_row(node: str, env: str, origin: str, rows: list[dict[str, Any]]) -> StatisticsRow:
    counts = count_runs(rows)
    recorded: dict[str, int] = {}
    for r in rows:
        recorded[str(r.get("recorded", "unknown"))] = recorded.get(str(r.get("recorded", "unknown")), 0) + 1
    n, k = counts["runs"], counts["violating_runs"] + counts["undecided_runs"]
    counted = origin != "harness" and n > 0
    bound, why = trivial_or_exact(k, n, LEVEL) if counted else (None, "")
    return StatisticsRow.of({
        "node": node, "environment": env, "origin": origin, "kind": "runs",
        "counts": {key: v for key, v in counts.items() if key != "digests"}, "recorded": recorded,
        "level": LEVEL, "bound": bound,
        "note": why if counted else ("driven by a test harness: not operation, no bound" if origin == "harness"
                                     else "no judged run: no bound")})


def _target_row(e: EvidenceRow) -> StatisticsRow:
    s = e.statistics  # the record's statistics (free-form: backends/monitors/runset.py, backends/experiment/)
    d = s.get("decision") or {}
    return StatisticsRow.of({
        "node": _node(e.obligation), "environment": s.get("environment", UNSTATED),
        "origin": s.get("origin", "operation"), "kind": "target", "obligation": e.obligation,
        "backend": e.backend, "status": e.status, "target": (s.get("target") or {}).get("text"),
        "counts": s.get("counts"), "recorded": s.get("recorded", {}), "level": d.get("level"),
        "bound": d.get("bound"), "runs_needed": d.get("runs_needed"),
        "sprt": (d.get("sprt") or {}).get("decision")})


def _trace_environments(plan: Plan) -> dict[str, tuple[str, str]]:
    """Each monitored trace of the plan -> (environment, origin) of the first entry naming it."""
    out: dict[str, tuple[str, str]] = {}
    for entries in plan.evidence.values():
        for e in entries:
            if e.backend == "monitors":
                for tr in e.config.get("traces", ()) or ():
                    out.setdefault(str(tr), (entry_environment(e.config), entry_origin(e.config)))
    return out


def requirement_statistics(req: RequirementRow, target: Any, where: Mapping[str, tuple[str, str]]) -> list[RequirementRuns]:
    """A requirement's runs (its record's ``traces``) grouped by environment
    tag: one row each with the counts, the bound (at the target's level, else
    95 %) and, with a ``target``, its decision."""
    groups: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for t in RequirementCheckRow.of(req.check).traces:
        env, origin = where.get(str(t.trace), (UNSTATED, "operation"))
        status = str(t.status)
        groups.setdefault((env, origin), []).append({
            "sha256": t.sha256, "status": status, "violations": int(status == "failed"),
            "inconclusive": int(status == "inconclusive"), "answers": 1})
    out: list[RequirementRuns] = []
    for (env, origin), rows in sorted(groups.items()):
        counts = count_runs([] if origin == "harness" else rows)
        level = target.level if target is not None else LEVEL
        bound, why = trivial_or_exact(counts["violating_runs"] + counts["undecided_runs"], counts["runs"], level)
        row: dict[str, Any] = {"environment": env, "origin": origin,
                               "counts": {k: v for k, v in counts.items() if k != "digests"}, "bound": bound,
                               "level": level, "note": why}
        if target is not None:
            d = decide(counts, target)
            row["target"], row["status"] = target.text, d["status"]
            row["explanation"] = f"under {env}: {d['explanation']}"
            row["runs_needed"], row["sprt"] = d["runs_needed"], d["sprt"]["decision"]
        out.append(msgspec.convert(row, RequirementRuns))
    return out


@dataclass
class StatisticsPart:
    """The statistics pass's part: the report's ``statistics`` table;
    ``groups``: index of a per-run evidence row -> its ``statistics.group``;
    ``requirements``: requirement id -> its ``statistics`` rows."""
    table: list[StatisticsRow]
    groups: dict[int, RunGroupBound] = field(default_factory=dict)
    requirements: dict[str, list[RequirementRuns]] = field(default_factory=dict)


def _per_run(e: EvidenceRow) -> bool:
    """``e`` (an evidence row) is a believed monitored run of a run set (not a target's decision)."""
    s = e.statistics
    return bool(s) and "decision" not in s and e.backend == "monitors" and "sha256" in s \
        and e.status not in _UNBELIEVED


def _group_key(e: EvidenceRow) -> tuple[str, str, str]:
    s = e.statistics
    return _node(e.obligation), str(s.get("environment", UNSTATED)), str(s.get("origin", "operation"))


def _requirement_row(rid: str, runs: RequirementRuns) -> StatisticsRow:
    """``runs`` as a row of the ``statistics`` table, with its requirement ``rid``."""
    return StatisticsRow.of({"requirement": rid, "kind": "requirement", **runs.to_json()})


def statistics_part(report: AssuranceReport, plan: Plan, targets: Mapping[str, Any]) -> StatisticsPart:
    """The report's ``statistics`` table (module docstring), each per-run
    evidence row's group bound and each requirement's runs, as a part: the
    report is read, not changed (report/assemble.py puts the part in).
    ``targets``: requirement id -> its
    :class:`~rclverify.records.statistics.Target` (or ``None``)."""
    groups: dict[tuple[str, str, str], list[dict[str, Any]]] = {}
    decisions: list[StatisticsRow] = []
    for e in report.evidence:
        if "decision" in e.statistics:
            decisions.append(_target_row(e))
        elif _per_run(e):
            groups.setdefault(_group_key(e), []).append(e.statistics)
    by_key = {key: _group_row(*key, rows) for key, rows in groups.items()}
    part = StatisticsPart([by_key[k] for k in sorted(by_key)] + decisions)
    for i, e in enumerate(report.evidence):
        if _per_run(e):
            g = by_key[_group_key(e)]
            part.groups[i] = {"runs": int((g.counts or {})["runs"]), "bound": g.bound, "level": LEVEL}
    where = _trace_environments(plan)
    for rq in report.requirements:
        rows = requirement_statistics(rq, targets.get(rq.id), where)
        if rows:
            part.requirements[rq.id] = rows
            part.table.extend(_requirement_row(rq.id, r) for r in rows)
    return part


__all__ = ["LEVEL", "StatisticsPart", "statistics_part", "compact", "requirement_statistics"]
