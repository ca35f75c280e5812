"""Failed side conditions of several consumers with one first repair are one problem.

A producer whose guarantee is too loose for every node that reads its
output (the MissionPlanner's ``out.dest_id <= 501`` read by a Navigator and
a LockerController that both assume ``in.dest_id <= 500``) fails one side
condition per consumer.  Each is keyed by its own culprits (the consumer's
assumption and the producer's guarantee, :mod:`.problems` rule 1), so the
report showed one row per *victim*, each with the same first repair: two
rows for one root cause.  The cause is the edit that removes them: when the
first repair of two failed side conditions is the same edit of the same
text (the same diff, :mod:`rclverify.diagnosis.repairs`), they are one
problem, keyed by the union of their culprits, and that edit is its one
first repair.  A side condition with no repair, or one whose first repair
differs, keeps its own key.

A row's culprits name the producer first (:func:`producer_first`): its
guarantee is where the first repair goes; the consumers' assumptions follow.

The rule is applied to the side-condition members only, before the
requirements and derived properties take their keys from them, so a derived
property behind both joins the same row.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence

from rclverify.records.problem_rows import DiagnosisRow
from rclverify.report.problems_places import Rooted


def first_diff(diagnosis: DiagnosisRow | None) -> str | None:
    """The unified diff of the first repair of ``diagnosis``, ``None`` when it has none."""
    reps = diagnosis.repairs if diagnosis is not None else []
    return reps[0].diff or None if reps else None


def join_by_first_repair(members: list[Rooted], by_id: Mapping[str, DiagnosisRow]) -> None:
    """Give the failed side conditions of ``members`` that share a first
    repair one key: the union of their roots (module docstring).

    ``members`` is the grouping's list of ``(member, roots)`` (roots the
    root-culprit ids), changed in place; ``by_id`` maps a diagnosis id to
    its record.  Members of other kinds, and side conditions whose first
    repair no other shares, are left as they are."""
    by_diff: dict[str, list[int]] = {}
    for i, (m, roots) in enumerate(members):
        if m.kind != "side-condition" or not roots or m.status != "failed":
            continue
        diff = first_diff(by_id.get(m.id))
        if diff is not None:
            by_diff.setdefault(diff, []).append(i)
    for idx in by_diff.values():
        if len(idx) < 2:
            continue
        union: list[str] = sorted({r for i in idx for r in members[i][1]})
        for i in idx:
            members[i] = (members[i][0], list(union))


def producer_first(roots: Sequence[str]) -> list[str]:
    """``roots`` (root-culprit ids in their display order) with the
    consumers' assumptions (``assumption:Node:k``) after everything else,
    each part in its order: a failed side condition's row names the
    producer's guarantee, the place of its first repair, before the
    assumptions of the victims it fails (the first screen blamed
    the victims)."""
    return [r for r in roots if not r.startswith("assumption:")] + [r for r in roots if r.startswith("assumption:")]
