"""One diagnosis record per problem of the report.

:func:`diagnose` reads the report without diagnoses
(:func:`rclverify.report.build.undiagnosed_report`) and the workspace and
returns ``[record, ...]``, each (the diagnosis stage seals them into
``artifacts/diagnosis/index.json``, :mod:`rclverify.stages.diagnoses`, and
the report reads them from there)::

    {"id": problem id (finding, side condition or obligation id),
     "kind": "vacuity" | "inconsistency" | "unsatisfiable-assumption" | "refinement"
             | "side-condition" | "hoare" | "monitor" | "property-test" | "evidence"
             | "requirement" (a refuted one: diagnosis/requirement.py)
             | "deadline" (a refuted or undecided end-to-end deadline: diagnosis/deadline.py)
             | "unit" (a unit mismatch on a connection, blaming the producer: diagnosis/units.py;
                       with "joins", the ids of the findings it explains, and "lint"),
     "node": str, "status": str,
     "sentence": one sentence naming the culprit by source location,
     "culprits": [{"what": str, "source": "file:line:col", "text": str}],
     "counterexample": [{"node", "variable", "value", "table"}]  (diagnosis.table),
     "repairs": [repair, ...]  (diagnosis.repairs; each checked by Z3, cheapest for the user first),
     "not_offered": [sentences]  (repairs Z3 showed do not work, e.g. a strengthening that
                                  leaves the node unimplementable; side conditions only),
     "related": [ids of other problems of the same node and guarantee]}

Repairs cost Z3 queries, so they are kept between runs
(:mod:`.repair_cache`); the records of failed evidence are
:mod:`.evidence_records`', each record made by :mod:`.record`.
"""
from __future__ import annotations

import re
from functools import partial
from typing import Any, Callable, Mapping

import msgspec

from rclverify.diagnosis import blame, repairs as rep
from rclverify.diagnosis.deadline import budget_repairs, deadline_record
from rclverify.diagnosis.evidence_records import evidence_record
from rclverify.diagnosis.record import diagnosis_record, entry, guarantee_source
from rclverify.diagnosis.repair_cache import RepairCache, one_at_a_time
from rclverify.diagnosis.requirement import requirement_record
from rclverify.diagnosis.sidecond import side_condition_repairs
from rclverify.diagnosis.culprits import culprits, parse_core, plan_facts
from rclverify.records.links import link_pairs
from rclverify.diagnosis.table import counterexample_table
from rclverify.diagnosis.units import unit_records
from rclverify.diagnosis.shapes import ProducerCulprits, ReportRows
from rclverify.records.findings import FindingRow
from rclverify.records.problem_rows import DiagnosisRow
from rclverify.records.side_condition_rows import SideConditionRow
from rclverify.records.stage_records import Culprit, DiagnosisEntry, Repair


def diagnose(ws: Any, report: ReportRows) -> list[DiagnosisEntry]:
    """The diagnosis records of every problem of ``report`` (see the module
    docstring), in the order of the report's problems list: health
    findings, side conditions, evidence.  ``report`` is the report's
    :class:`~rclverify.diagnosis.shapes.ReportRows`
    (:func:`~rclverify.diagnosis.shapes.report_rows` decodes a report or its JSON object
    into them).  One process at a time per workspace (:func:`one_at_a_time`), so parallel
    report tasks compute each repair once."""
    with one_at_a_time(ws):
        return _diagnose(ws, report)


def _diagnose(ws: Any, report: ReportRows) -> list[DiagnosisEntry]:
    cache = RepairCache(ws)
    out: list[DiagnosisRow] = []
    health_by_node: dict[str, dict[str, str]] = {}
    findings = report.findings
    for f in findings:
        health_by_node.setdefault(f.node, {})[f.id] = f.status
    # which guarantees of a node each culprit guarantee makes vacuous (one guard repair for all of them)
    victims: dict[tuple[str, int], list[tuple[int, int | None]]] = {}
    for f in findings:
        fk = f.guarantee
        if f.status == "problem" and f.check == "non-vacuous" and fk is not None:  # a guarantee's check
            vac = sorted(int(x) for x, st in (f.instances or {}).items() if st == "vacuous")
            victim = (fk, vac[0] if vac else None)  # where it was vacuous
            for m in culprits(parse_core(f.core), fk):
                if m.kind == "guarantee" and victim not in victims.setdefault((f.node, m.index), []):
                    victims[(f.node, m.index)].append(victim)

    def guard(node: str, c: int) -> Repair | None:
        vs = sorted(victims.get((node, c), []), key=lambda v: v[0])
        found: Repair | None = cache.get(["guard", node, c, vs, health_by_node.get(node, {})],
                                                 lambda: rep.guard_repair(ws, node, c, vs,
                                                                          health_by_node.get(node, {})))
        return found

    # a unit mismatch on a connection first: it explains the side condition and the runs that follow from it
    out += unit_records(ws, report, cache.get)
    for f in findings:
        if f.status != "problem":
            continue
        out.append(_finding(ws, report, f, guard))
    sc_before = {sc.id: sc.status for sc in report.side_conditions}
    for sc in report.side_conditions:
        if sc.status in ("failed", "inconclusive"):
            out.append(_side_condition(ws, report, sc, cache, sc_before))
    for q in report.requirements:
        # a requirement refuted only by its end-to-end deadline is the deadline's problem (below), not its formula's
        own = q.without_deadline.verdict if q.deadline and q.without_deadline else q.verdict
        if q.verdict == "refuted" and own == "refuted":
            out.append(requirement_record(ws, report, q, cache, guarantee_source))
    for row in report.deadlines:
        if row.verdict in ("refuted", "inconclusive"):
            chain = row.chain if row.chain is not msgspec.UNSET else None
            key = ["deadline", row.requirement, row.path, row.within,
                   [[h.node, h.guarantee, h.within_s] for h in chain] if chain else chain]
            reps: list[Repair] = ((cache.get(key, partial(budget_repairs, ws, row)) or [])
                                  if row.verdict == "refuted" else [])
            out.append(deadline_record(ws, report, row, reps))
    obligations = {o.id: o for o in report.obligations}
    for e in report.evidence:
        if e.status in ("failed", "error"):
            out.append(evidence_record(ws, report, e, obligations.get(e.obligation), cache))
    # the same node and guarantee found by several techniques: each record names the others
    by_key: dict[tuple[str, int | None], list[str]] = {}
    for d in out:
        by_key.setdefault((d.node, d.guarantee), []).append(d.id)
    cache.save()
    return [entry(msgspec.structs.replace(d, related=[x for x in by_key[(d.node, d.guarantee)] if x != d.id]
                                          if d.guarantee else [])) for d in out]


def _finding(ws: Any, report: ReportRows, f: FindingRow, guard: Callable[[str, int], Repair | None]) -> DiagnosisRow:
    node, k = f.node, f.guarantee
    facts = plan_facts(ws, node)
    members = parse_core(f.core, facts)
    table = counterexample_table(f.model, node)
    if f.check == "non-vacuous":
        text, src = guarantee_source(report, node, k)
        cs = culprits(members, k)
        names = [m.name() for m in cs]
        sentence = (f"Guarantee {k} of {node} ({src}) can never fire"
                    + (f" for {_after(f.message, ' is vacuous for ', ':')}" if " is vacuous for " in f.message else "")
                    + ": " + (_and(names) + (" exclude" if len(names) > 1 else " excludes") + " its premise"
                              if names else "its premise contradicts the node's contract") + ".")
        reps = [guard(node, m.index) for m in cs if m.kind == "guarantee"]
        kind = "vacuity"
    elif f.check in ("contract-consistent", "assumption-satisfiable"):
        names = [m.name() for m in members]
        kind = "inconsistency" if f.check == "contract-consistent" else "unsatisfiable-assumption"
        what = "contract" if kind == "inconsistency" else "assumption"
        sentence = (f"The {what} of {node} cannot hold: " + (_and(names) + " contradict each other" if names
                                                               else "Z3 found no way to satisfy it") + ".")
        cs = members
        reps = [guard(node, m.index) for m in members if m.kind == "guarantee"] if kind == "inconsistency" else []
    else:
        cs, reps, kind = [], [], "refinement" if f.check == "replacement-refines" else f.check
        sentence = f.message + (" " + f.explanation if f.explanation else "")
    return diagnosis_record(f.id, kind, node, "failed", sentence,
                   culprits=[{"what": m.name(), "source": m.source, "text": m.text} for m in cs],
                   counterexample=table, repairs=[r for r in reps if r], guarantee=k)


def _after(text: str, start: str, stop: str) -> str:
    return text.split(start, 1)[1].split(stop, 1)[0]


def _and(items: list[str]) -> str:
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


def _side_condition(ws: Any, report: ReportRows, sc: SideConditionRow, cache: RepairCache,
                    sc_before: Mapping[str, str]) -> DiagnosisRow:
    pairs = link_pairs(sc)
    cul: list[Culprit] = [{"what": f"assumption of {sc.node}: `{sc.conjunct}`", "source": sc.source, "text": sc.conjunct}]
    said = []
    # a producer guarantee is named only when strengthening it discharges the side condition (blame.py)
    def find() -> ProducerCulprits:
        found, undecided = blame.side_condition_culprits(ws, sc)
        return {"culprits": [list(x) for x in found], "undecided": undecided}
    got: ProducerCulprits | None = \
        cache.get(["sc-culprits", sc.id, sc.conjunct], find) if sc.status == "failed" else None
    shown: ProducerCulprits = got or {"culprits": [], "undecided": 1}
    blamed = {(str(p), int(k)) for p, k in shown["culprits"]}
    for p, ov, _, _ in pairs:
        for n in report.nodes:
            if n.name != p:
                continue
            for g in n.guarantees:
                if not re.search(rf"out\.{re.escape(ov)}(?!\w)", g.text):
                    continue
                if sc.status == "failed" and (p, g.index) not in blamed:
                    continue
                if any(c["source"] == g.source for c in cul):
                    continue
                cul.append({"what": f"guarantee {g.index} of {p}: `{g.text}`", "source": g.source,
                            "text": g.text})
                said.append(f"{p}'s guarantee {g.index} ({g.source}) `{g.text}`")
    involved = {sc.node} | {p for p, _, _, _ in pairs}
    table = [r for r in counterexample_table(sc.model, sc.node) if r["node"] in involved]
    cex = ", ".join(f"{r['node']}.{r['variable']} = {r['value']}" for r in table)
    together = ("its producers' guarantees (Z3 could not show which)" if shown["undecided"]
                else "its producers' guarantees (together: strengthening any one of them alone does not discharge it)")
    sentence = (f"{sc.node} assumes `{sc.conjunct}` ({sc.source}), but "
                + (_and(said) if said else together)
                + (" allows" if len(said) == 1 else " allow") + " values outside it"
                + (f": Z3's counterexample {cex}" if cex else "") + ".")
    if sc.status == "inconclusive":
        sentence = f"Z3 could not decide whether {sc.node}'s assumption `{sc.conjunct}` ({sc.source}) follows from " \
                   + (_and(said) if said else "its producers' guarantees") + "."
    # what a weakened assumption of the consumer invalidates: its evidence, established under the old one
    evidence = [f"{o.id} ({o.status})" for o in report.obligations if o.node == sc.node]
    found = (cache.get(["side-condition", sc.id, sc.conjunct, dict(sc_before), evidence],
                       lambda: side_condition_repairs(ws, sc, sc_before, evidence)) or {}) if sc.status == "failed" else {}
    return diagnosis_record(sc.id, "side-condition", sc.node, sc.status, sentence, culprits=cul,
                            counterexample=table, repairs=list(found.get("repairs") or []),
                            not_offered=list(found.get("not_offered") or []))
