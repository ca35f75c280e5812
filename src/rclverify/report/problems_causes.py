"""Problems that follow from another problem, in its row (one row
per cause, its consequences listed under it; docs/reading-the-report.md).

Helpers of :func:`rclverify.report.problems.group_problems`, each changing
its ``members`` (``[(member, root culprit ids)]``) in place:

* :func:`join_consequences`: a requirement whose diagnosis is
  ``consequence_of`` failed side conditions takes their root culprits;
* :func:`join_implementation_findings`: a property test or run naming only
  its guarantee joins a finding of the same guarantee that names lines of
  the implementation (a generated node's handler);
* :func:`assumption_violations`: a recorded run whose first assumption
  violation is a failed side condition's conjunct, blamed on that side
  condition's producer, is listed in that side condition's row.
"""
from __future__ import annotations

from collections.abc import Callable, Mapping

from rclverify.records.monitored_run import MonitoredRun
from rclverify.records.problem_rows import DiagnosisRow
from rclverify.records.report_record import AssuranceReport
from rclverify.records.side_condition_rows import SideConditionRow
from rclverify.report.problems_places import Member, Rooted


def join_consequences(members: list[Rooted], by_id: Mapping[str, DiagnosisRow]) -> None:
    """A problem whose diagnosis is ``consequence_of`` other problems (a
    requirement refuted only because a side condition fails, Z3 proving it
    once that side condition is discharged: diagnosis/requirement.py) takes
    their root culprits and is marked ``consequence_of`` (one row
    per cause, its consequences listed under it).  Changes ``members``
    (``(member, roots)``) in place; a cause that is not a member changes
    nothing."""
    roots_of = {m.id: roots for m, roots in members}
    for i, (m, roots) in enumerate(members):
        d = by_id.get(m.id)
        causes = [c for c in (d.consequence_of or () if d is not None else ()) if c in roots_of]
        if causes and m.diagnosis:
            m.consequence_of = causes
            members[i] = (m, list(dict.fromkeys(r for c in causes for r in roots_of[c])) or roots)


def join_implementation_findings(members: list[Rooted], by_id: Mapping[str, DiagnosisRow]) -> None:
    """A property test or run that names only the guarantee it found
    violated joins the row of another such finding of the same guarantee
    that names implementation lines (``line:...``: the handler of a
    generated node's logic.py that published the message): one
    implementation defect, found by a test and by a run, is one row.
    Changes ``members`` in place."""
    def victim(mid: str) -> tuple[str | None, int | None]:
        d = by_id.get(mid)
        return (d.node, d.guarantee) if d is not None else (None, None)
    placed = {victim(m.id): roots for m, roots in members if m.kind in ("monitor", "property-test")
              and roots and all(r.startswith("line:") for r in roots) and victim(m.id)[1]}
    for i, (m, roots) in enumerate(members):
        node, k = victim(m.id)
        if m.kind in ("monitor", "property-test") and (node, k) in placed and roots == [f"guarantee:{node}:{k}"]:
            members[i] = (m, list(placed[(node, k)]))


def _producers(sc: SideConditionRow) -> set[str]:
    """The producer nodes of a side condition's links (``P.out.x -> C.in.y (via ...)``)."""
    return {link.split(".", 1)[0] for link in sc.links if ".out." in link}


def assumption_violations(report: AssuranceReport, members: list[Rooted], anchor: Callable[..., str]) -> None:
    """A recorded run of a node whose first assumption violation is a failed
    side condition of that node -- the violated assumption contains the
    side condition's conjunct, the monitor blames the producer the side
    condition names -- is a consequence of that side condition: the run's
    member (added when the run is not a problem of its own, e.g. pending)
    takes the side condition's root culprits and is marked
    ``consequence_of``.  Changes ``members`` in place."""
    roots_of = {m.id: roots for m, roots in members}
    failed = [sc for sc in report.side_conditions if sc.status == "failed" and sc.id in roots_of]
    nodes = {o.id: o.node for o in report.obligations}
    at = {m.id: i for i, (m, _) in enumerate(members)}
    for e in report.evidence:
        first = MonitoredRun.of(e.monitoring).first_assumption_violation if e.status != "discharged" else None
        if first is None:
            continue
        ob, text, blame = e.obligation, first.assumption, first.blame or ""
        causes = [sc for sc in failed if sc.node == nodes.get(ob) and sc.conjunct in text
                  and any(p in blame for p in _producers(sc))]
        if not causes:
            continue
        ids = [sc.id for sc in causes]
        roots = list(dict.fromkeys(r for c in ids for r in roots_of[c]))
        if ob in at:
            i = at[ob]
            members[i][0].consequence_of = ids
            members[i] = (members[i][0], roots)
        else:
            members.append((Member(id=ob, kind="evidence", status=e.status, anchor=anchor("ev", ob), diagnosis=False,
                                   sentence=(f"{ob}: the assumption `{text}` is violated at {'?' if first.where is None else first.where} "
                                             f"(t = {'?' if first.time is None else first.time} s), blamed on the {blame}: the failed "
                                             f"side condition {', '.join(ids)} lets such values through."),
                                   consequence_of=ids), roots))
