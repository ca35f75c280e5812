"""Expected verdicts: the plan says what a check should find, the report compares.

An evidence entry of the plan may list the verdicts it expects, e.g. a
property known to be false of the agent::

    - backend: ajpf
      ...
      expected:
        - {guarantee: 3, instance: "i=12", verdict: failed,
           reason: "guarantee 3 as published demands a move to waypoint 0 at every step"}

``guarantee`` (1-based) and ``verdict`` (``discharged`` or ``failed``) are
required; ``instance`` (the obligation's instance label, e.g. ``i=12``)
narrows the match; ``reason`` is shown.  Every obligation of that node and
backend with that guarantee (and instance) is compared with its current
status: ``as expected``, ``MISMATCH`` (decided, and not the expected way: the
report lists it under "What needs attention"), or ``not yet decided``
(pending, inconclusive, stale, error).  An expectation no obligation matches
is shown as such, never dropped.
"""
from __future__ import annotations

from typing import Mapping, Sequence

from rclverify.model.plan.expected import VERDICTS
from rclverify.model.plan.load import Plan
from rclverify.records.obligations import ObligationRow
from rclverify.records.verdict_rows import ExpectedVerdictRow


def _loc(plan: Plan, node: str, index: int, k: int) -> str:
    l = plan.locs.get(("nodes", node, "evidence", index, "expected", k))
    if l is None:
        e = plan.evidence[node][index]
        l = e.loc
    return f"{l.file}:{l.line}:{l.col}"


def expected_rows(plan: Plan, ob_rows: Sequence[ObligationRow]) -> list[ExpectedVerdictRow]:
    """One :class:`~rclverify.records.verdict_rows.ExpectedVerdictRow` per (expectation, matching
    obligation) of every evidence entry; ``actual``/``obligation`` are ``None`` when
    nothing matches or the expectation is malformed (``outcome`` then says why)."""
    rows: list[ExpectedVerdictRow] = []
    for node, entries in plan.evidence.items():
        for e in entries:
            exp = e.config.get("expected")
            if exp is None:
                continue
            items = exp if isinstance(exp, list) else [exp]
            for k, item in enumerate(items):
                src = _loc(plan, node, e.index, k)
                if not (isinstance(item, Mapping) and isinstance(item.get("guarantee"), int)
                        and item.get("verdict") in VERDICTS):
                    rows.append(ExpectedVerdictRow(
                        node, e.backend, src, None, None, None, None, None, "",
                        "invalid expectation: give guarantee (a number) and verdict (discharged or failed)"))
                    continue
                g, verdict = int(item["guarantee"]), str(item["verdict"])
                inst = item.get("instance")
                reason = str(item.get("reason", ""))
                matches = [o for o in ob_rows if o.node == node and o.backend == e.backend
                           and o.guarantee == g and (inst is None or o.instance == inst)]
                if not matches:
                    rows.append(ExpectedVerdictRow(node, e.backend, src, None, None, g, inst, verdict, reason,
                                                   "no obligation matches"))
                for o in matches:
                    actual = o.status
                    outcome = ("as expected" if actual == verdict
                               else "MISMATCH" if actual in VERDICTS else "not yet decided")
                    rows.append(ExpectedVerdictRow(node, e.backend, src, o.id, actual, g, inst, verdict, reason,
                                                   outcome))
    return rows
