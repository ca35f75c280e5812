"""An experiment entry's statistical target (docs/statistics.md).

With ``target: violation probability <= 5e-2 at 95 %`` an experiment entry
exports a second obligation beside its criterion's: "the trials bound the
probability that a trial misses the criterion".  Each row of the per-trial
data file is one trial (one run and one answer: ``per run`` and ``per
answer`` count the same); a trial missing the criterion is a violation.
Its evidence counts the trials (each identified by the data file's sha256
and its row, so one file named twice is counted once) and decides the
target with :func:`rclverify.records.statistics.decide`.  A criterion over
summary statistics only says nothing of each trial: the target stays
``pending`` and says so.  The criterion's own obligation is unchanged: a
trial that misses it still fails it.
"""
from __future__ import annotations

import dataclasses
import hashlib
from typing import Any

from rclverify.records.records import Evidence, Obligation, make_obligation_id
from rclverify.records.statistics import count_runs, decide
from rclverify.model.plan.targets import entry_environment, entry_target
from rclverify.backends.base import NodeTarget, Stopwatch, make_evidence
from rclverify.backends.experiment.payload import ExperimentPayload


def target_obligations(target: NodeTarget, criterion: Obligation) -> list[Obligation]:
    """The target's obligation beside ``criterion`` (``[]`` without a target)."""
    t = entry_target(target.config)
    if t is None:
        return []
    env = entry_environment(target.config)
    oid = make_obligation_id(target.node.name, criterion.guarantee, "experiment", f"e{target.index}_target")
    statement = (f"the trials in {criterion.data.get('file')} under {env} bound the probability that a trial misses "
                 f"the criterion {criterion.data.get('criterion')}: {t.words()}")
    return [dataclasses.replace(criterion, id=oid, statement=statement, instance=f"e{target.index}_target",
                                data={**criterion.data, "target": t.to_json(), "environment": env})]


def run_target(obligation: Obligation, target: NodeTarget, cfg: Any, verdict: Any, tool: str,
               version: str) -> Evidence:
    """The target obligation's evidence from the criterion's ``verdict`` on ``cfg``'s trials."""
    clock = Stopwatch()
    t = entry_target(target.config)
    env = entry_environment(target.config)

    def evidence(status: str, explanation: str, **kw: Any) -> Evidence:
        return make_evidence(target, obligation, status, tool=tool, tool_version=version, clock=clock,
                             explanation=explanation, **kw)
    if t is None:
        return evidence("error", "the plan entry no longer states a target that reads")
    if not verdict.per_trial:
        return evidence("pending", f"the criterion {cfg.criterion_text} is over summary statistics: it says nothing "
                                   f"of each trial, so no trial counts toward {t.words()} (give per-trial data: "
                                   f"data: and column:)")
    sha = hashlib.sha256((target.root / cfg.file).read_bytes()).hexdigest()
    failing = set(verdict.failing)
    rows = [{"sha256": f"{sha}:{i}", "status": "failed" if i in failing else "discharged", "answers": 1,
             "violations": int(i in failing), "inconclusive": 0, "seconds": 0.0}
            for i in range(1, len(cfg.figures.trials) + 1)]
    counts = count_runs(rows)
    d = decide(counts, t)
    status, explanation = d["status"], f"under {env}: {d['explanation']} (trials of {cfg.file})"
    if verdict.holds is None:
        status, explanation = "inconclusive", (f"Z3 could not decide the criterion on some trials of {cfg.file}: "
                                               f"they cannot be counted as clean or as missing it")
    details = {"statistics": {"environment": env, "origin": "operation", "target": t.to_json(),
                              "counts": {k: v for k, v in counts.items() if k != "digests"}, "file_sha256": sha,
                              "decision": d, "failing_trials": sorted(failing)[:20]}}
    return evidence(status, explanation, details=ExperimentPayload.checked(details), log=explanation)


__all__ = ["run_target", "target_obligations"]
