"""Counter-evidence in the argument: defeaters as the GSN
Community Standard v3's dialectic extension draws them (a counter solution
``CSn`` that ``challenges`` a claim; the claim marked ``defeated`` where the
counter-evidence refutes it), in the form gsn2x reads.

What undermines a claim, and what it challenges:

==============================================  ===============================  ========
counter-evidence                                 challenges                       defeats
==============================================  ===============================  ========
failed evidence (a monitor violation, a test     the guarantee's goal             yes
counterexample, a refuted triple)
stale evidence                                   the guarantee's goal             no
partial coverage (a mapping covering part of a   the guarantee's goal             no
guarantee)
a solver disagreement                            the side condition's or          yes
                                                 requirement's goal
a vacuous or inconsistent proof                  the requirement's goal           yes
a problem's culprit, failed or error             the guarantee's or the node's    if failed
(report/culprits.py)                             goal
==============================================  ===============================  ========

A defeated claim is never better than what defeats it
(:func:`.model.propagate`): a culprit guarantee whose own evidence holds
reads the status of the problem it causes.
"""
from __future__ import annotations

from dataclasses import replace
from typing import Any

import msgspec

from rclverify.records.report_record import AssuranceReport
from rclverify.records.requirement_check import RequirementCheckRow
from rclverify.report.argument.model import Element


def _clip(text: str, n: int = 300) -> str:
    return text if len(text) <= n else text[:n - 3] + "..."


def add_defeaters(els: dict[str, Element], report: AssuranceReport, ident: Any) -> None:
    """Add a counter solution per piece of counter-evidence of ``report`` to
    ``els`` (element id -> element, changed in place) and mark the claims
    it defeats; ``ident`` makes element ids (:func:`.build.ident`).  A
    target not in ``els`` (a claim the argument does not show) is skipped."""
    def challenge(cid: str, target: str, text: str, status: str, defeats: bool, url: str = "") -> None:
        if target not in els or cid in els:
            return
        els[cid] = Element(cid, "counter_solution", _clip(text), status=status, challenges=(target,), url=url)
        if defeats:
            els[target] = replace(els[target], defeated=True)

    for ev in report.evidence:
        oid, st = ev.obligation, ev.status
        parts = oid.split(".")
        target = ident("G", parts[0], parts[1]) if len(parts) > 1 and parts[1][1:].isdigit() else ""
        url = f"artifacts/evidence/{oid}.json"
        if st == "failed":
            challenge(ident("CSn", "ev", oid), target, f"Counter-evidence {oid} ({ev.backend}): "
                      f"{ev.explanation}", "failed", True, url)
        elif st == "stale":
            challenge(ident("CSn", "ev", oid), target, f"Stale evidence {oid}: an input changed since it was produced",
                      "stale", False, url)
        elif "PARTIAL COVERAGE" in ev.explanation:
            challenge(ident("CSn", "ev", oid), target, f"Partial coverage {oid}: {ev.explanation}",
                      st, False, url)
    for sc in report.side_conditions:
        s = sc.solvers
        if s and s.agreement in ("disagree", "inconclusive"):
            challenge(ident("CSn", "solvers", sc.id), ident("G", "sc", sc.id),
                      f"The second solver does not confirm {sc.id}: {s.why}", "inconclusive", True,
                      "" if s.smt2 is msgspec.UNSET else s.smt2)
    for n in report.nodes:  # a problem's culprit: its goal is never "discharged"
        name = n.name
        for index, culprit_of in [*((g.index, g.culprit_of or []) for g in n.guarantees),
                                  (None, n.culprit_of or [])]:  # the guarantees, then the contract
            target = ident("G", name, f"g{index}") if index is not None else ident("G", name)
            for k, row in enumerate(culprit_of, 1):
                if row.status not in ("failed", "error"):
                    continue  # outstanding evidence is no counter-evidence: the goal reads it already
                what = f"guarantee {index} of {name}" if index is not None else f"the contract of {name}"
                challenge(ident("CSn", "culprit", target, k), target,
                          f"Problem caused by {what}: {row.sentence}", row.status, row.status == "failed")
    for r in report.requirements:
        rid, verdict = r.id, r.verdict
        checked = RequirementCheckRow.of(r.check).solvers  # the second solver (stages/crosscheck/apply.py)
        if checked is not None and checked.agreement in ("disagree", "inconclusive"):
            challenge(ident("CSn", "solvers", rid), ident("G", rid),
                      f"The second solver does not confirm {rid}: {checked.why}", "inconclusive", True)
        if verdict in ("proved vacuously", "proved from an inconsistency"):
            challenge(ident("CSn", "vacuous", rid), ident("G", rid), f"{rid} is {verdict}: {r.note}",
                      "failed", True)
