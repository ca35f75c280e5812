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

from typing import Any, Mapping, Sequence

from rclverify.model.plan.expected import VERDICTS
from rclverify.model.plan.load import Plan
from rclverify.records.report_schema import ObligationJson


def _loc(plan: Plan, node: str, index: int, k: int) -> str:
    l = plan.locs.get(("nodes", node, "evidence", index, "expected", k))
    if l is None:
        e = plan.evidence[node][index]
        l = e.loc
    return f"{l.file}:{l.line}:{l.col}"


def expected_rows(plan: Plan, ob_rows: Sequence[ObligationJson]) -> list[dict[str, Any]]:
    """One row per (expectation, matching obligation) of every evidence entry:
    ``{"node", "backend", "guarantee", "instance", "expected", "actual",
    "obligation", "outcome", "reason", "source"}``; ``actual``/``obligation``
    are ``None`` when nothing matches or the expectation is malformed
    (``outcome`` then says why)."""
    rows: list[dict[str, Any]] = []
    for node, entries in plan.evidence.items():
        for e in entries:
            exp = e.config.get("expected")
            if exp is None:
                continue
            items = exp if isinstance(exp, list) else [exp]
            for k, item in enumerate(items):
                src = _loc(plan, node, e.index, k)
                base: dict[str, Any] = {"node": node, "backend": e.backend, "source": src, "obligation": None,
                                        "actual": None}
                if not (isinstance(item, Mapping) and isinstance(item.get("guarantee"), int)
                        and item.get("verdict") in VERDICTS):
                    rows.append({**base, "guarantee": None, "instance": None, "expected": None, "reason": "",
                                 "outcome": "invalid expectation: give guarantee (a number) and verdict "
                                            "(discharged or failed)"})
                    continue
                g, verdict = int(item["guarantee"]), str(item["verdict"])
                inst = item.get("instance")
                base.update({"guarantee": g, "instance": inst, "expected": verdict,
                             "reason": str(item.get("reason", ""))})
                matches = [o for o in ob_rows if o["node"] == node and o["backend"] == e.backend
                           and o["guarantee"] == g and (inst is None or o["instance"] == inst)]
                if not matches:
                    rows.append({**base, "outcome": "no obligation matches"})
                for o in matches:
                    actual = str(o["status"])
                    outcome = ("as expected" if actual == verdict
                               else "MISMATCH" if actual in VERDICTS else "not yet decided")
                    rows.append({**base, "obligation": o["id"], "actual": actual, "outcome": outcome})
    return rows
