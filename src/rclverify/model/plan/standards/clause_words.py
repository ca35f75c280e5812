"""The words of a clause row (docs/standards.md): why it has its status, what the safety case must add,
who checked what covers it.  Pure functions of the clause's scope items and evidence rows
(:mod:`.mapping` builds them); nothing raises."""
from __future__ import annotations

from collections import Counter
from typing import Iterable, Mapping, Sequence

from rclverify.model.plan.standards.profiles import Item
from rclverify.model.plan.standards.report_view import EvidenceView
from rclverify.model.plan.standards.reviews import review_as_stated, review_identity
from rclverify.records.standards_rows import ClauseEvidence, ScopeItem

#: The states of an item not covered, worst first (what the clause's ``why`` counts).
WORST: tuple[str, ...] = ("failed", "problem", "error", "stale", "inconclusive", "pending", "unverified",
                          "not counted", "no evidence")
#: What an empty scope lacks, by ``about``.
NOTHING: Mapping[str, str] = {
    "guarantees": "guarantees", "interfaces": "connections between nodes", "requirements": "requirements",
    "system": "nodes", "field-data": "target decided over runs whose plan entry states origin: operation",
    "trials": "target decided over runs or trials"}


def why(status: str, scope: Sequence[ScopeItem], evidence: Sequence[ClauseEvidence], item: Item) -> str:
    """Why a clause has ``status`` over its ``scope`` and ``evidence`` (the module docstring)."""
    if status == "not recommended":
        return "not recommended at this level: the evidence is listed, nothing is asked"
    if not scope:
        return f"nothing in scope: the workspace has no {NOTHING.get(item.about, item.about)}"
    n, done = len(scope), sum(1 for s in scope if s.covered)
    if status == "covered":
        return f"all {n} item{'s' if n != 1 else ''} in scope covered"
    left = Counter(s.state for s in scope if not s.covered)
    if not left:  # every item covered, the clause asking more than the tool holds (adds says what)
        return f"{status}: {done} of {n} in scope covered"
    head = ", ".join(f"{left[st]} {st}" for st in sorted(left, key=lambda x: WORST.index(x) if x in WORST else 0))
    shown = [e for e in evidence if not e.counts]
    extra = f"; {len(shown)} record{'s' if len(shown) != 1 else ''} shown, not counted ({shown[0].note})" if shown else ""
    return f"{status}: {done} of {n} in scope covered; {head}{extra}"


def adds(item: Item) -> str:
    """What a clause the tool never covers alone (its item's ``safety_case_adds``) leaves to the safety case."""
    if not item.safety_case_adds:
        return ""
    return f"; never covered by the tool alone: the safety case must add {item.safety_case_adds}"


def checked_by(scope: Sequence[ScopeItem], evidence: Iterable[EvidenceView]) -> list[str]:
    """Who checked what covers the clause's covered items: each backend with its tool and version, each
    review's reviewer and author, Z3 for side conditions and requirement checks; ``evidence``: the report's
    evidence rows."""
    rows = {e.obligation: e for e in evidence}
    out: list[str] = []
    for s in scope:
        if not s.covered:
            continue
        for ob in s.evidence:
            r = rows.get(ob)
            if r is None:
                who = f"Z3 ({s.kind} check)"
            elif r.kind == "review":
                reviewer, author, _ = review_identity(r)
                stated = review_as_stated(r)
                who = (f"review by {reviewer or 'an unnamed reviewer'} (author: {author or 'not named'}"
                       + (f"; {stated})" if stated else ")"))
            else:
                tool, version = r.tool, r.tool_version
                who = f"{r.backend} ({version if version.startswith(tool) else f'{tool} {version}'.strip()})"
            if who not in out:
                out.append(who)
    return out


__all__ = ["NOTHING", "WORST", "adds", "checked_by", "why"]
