"""A requirement's recorded runs as quantified support in the assurance
argument (docs/statistics.md, docs/argument.md).

Under the goal of a requirement whose recorded runs the report counted
(its row's ``statistics``, :class:`~rclverify.records.statistics_rows.RequirementRuns`
each, :mod:`rclverify.report.statistics`),
one row per environment tag:

    G-<REQ>                      the requirement
      G-<REQ>.target.<env>       with a ``target``: a run under <env>
                                 violates it with probability at most the
                                 target, at the target's level
                                 in context of J-statistics
        Sn-runs.<REQ>.<env>      the runs counted: n, violating, the
                                 Clopper-Pearson bound, the runs still
                                 needed and the SPRT state
      C-runs.<REQ>.<env>         without a target: the runs and their 95 %
                                 bound, as context (no claim is made of them)

A goal is never drawn across two tags; the target goal's status is the
target's decision (pending until the bound meets it), so the requirement's
goal is pending while a tag's runs fall short.
"""
from __future__ import annotations

import re
from typing import Any, MutableMapping

from rclverify.records.requirement_rows import RequirementRow
from rclverify.records.statistics_rows import RequirementRuns
from rclverify.report.argument.model import Element

_ID_BAD = re.compile(r"[^A-Za-z0-9_.\-]+")

JUSTIFICATION = ("Clopper and Pearson (1934): with k violating runs among n, the level-quantile of Beta(k+1, n-k) "
                 "bounds the probability that a run violates the requirement from above at that confidence; zero "
                 "violations in n runs give 1 - (1 - level)^(1/n), about 3/n at 95 % (the rule of three).  It "
                 "assumes the runs independent and representative of the operating conditions they are tagged "
                 "with; runs of two tags are never pooled, and runs a test harness drove count toward no bound.")


def _id(prefix: str, *parts: Any) -> str:
    return prefix + "-" + _ID_BAD.sub("_", ".".join(str(p) for p in parts))


def _counts(row: RequirementRuns) -> str:
    c = row.counts
    b = f"; one-sided {float(row.level or 0.95) * 100:g} % upper bound {row.bound:.3g}"
    return f"{c.get('runs', 0)} run(s) under {row.environment} ({row.origin}), " \
           f"{c.get('violating_runs', 0)} violating, {c.get('undecided_runs', 0)} undecided{b}"


def with_statistics(els: MutableMapping[str, Element], goal: str, r: RequirementRow) -> str:
    """Add requirement row ``r``'s run statistics under its goal ``goal``
    in ``els`` (module docstring); returns ``goal``."""
    rows = r.statistics
    if not rows or goal not in els:
        return goal
    rid = r.id
    kids: list[str] = []
    ctx: list[str] = []
    for row in rows:
        env = row.environment
        if not row.target:
            c = _id("C", "runs", rid, env)
            els[c] = Element(c, "context", f"Recorded runs of {rid}: {_counts(row)}", ref=rid)
            ctx.append(c)
            continue
        j = _id("J", "statistics")
        if j not in els:
            els[j] = Element(j, "justification", JUSTIFICATION)
        sn = _id("Sn", "runs", rid, env)
        needed = (f"; {row.runs_needed} further clean run(s) needed" if row.status != "discharged"
                  and row.runs_needed is not None else "")
        els[sn] = Element(sn, "solution", f"Recorded runs of {rid}: {_counts(row)}{needed}; SPRT {row.sprt}",
                          status=row.status or "pending", ref=rid)
        g = _id("G", rid, "target", env)
        els[g] = Element(g, "goal", f"{rid}: under {env}, {row.target}", supported_by=(sn,),
                         in_context_of=(j,), ref=rid)
        kids.append(g)
    top = els[goal]
    els[goal] = Element(goal, "goal", top.text, supported_by=top.supported_by + tuple(kids),
                        in_context_of=top.in_context_of + tuple(ctx), undeveloped=top.undeveloped and not kids,
                        ref=top.ref, url=top.url)
    return goal


__all__ = ["JUSTIFICATION", "with_statistics"]
