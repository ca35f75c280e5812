"""Evidence strength and confidence on the report's rows.

What :func:`confidence_part` gives the rows of the report
:func:`rclverify.report.build.build_report` makes (report/assemble.py puts
it in):

* every evidence row and side condition gets ``strength``
  (:mod:`rclverify.report.argument.strength`);
* every node gets ``confidence`` (rule C3) and every derived property
  ``confidence`` (C4, over its cone, loops by a fixpoint);
* every requirement gets ``confidence`` (C5) and ``limited_by``: the
  premise with the largest doubt and a sentence naming it;
* ``summary.confidence``: the least confidence of the formal requirements.

The rules and their sources: :mod:`rclverify.report.argument.confidence`, docs/confidence.md.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping, cast

import msgspec

from rclverify.records.report_record import AssuranceReport
from rclverify.records.requirement_check import RequirementCheckRow
from rclverify.records.requirement_rows import RequirementRow, StrengthKind
from rclverify.records.strength_rows import LimitedBy, Strength
from rclverify.report.shapes import Confidence, RequirementConfidence
from rclverify.report.argument.confidence import (Claim, Premise, derived_claims, guarantee_premise, node_claims,
                                                  requirement_claim)
from rclverify.report.argument.strength import DOUBT, KINDS, evidence_strength, side_condition_strength
from rclverify.calculus.requirements.rollup import MET, OUTSTANDING

#: Requirement verdicts whose Z3 proof holds (the evidence it rests on may not be all discharged).
_PROVED = (MET, OUTSTANDING)

_WORDS = {"proof": "a proof", "bounded": "bounded evidence", "statistical": "statistical evidence",
          "tested": "tested-only evidence", "observed": "observed-only evidence", "reviewed": "reviewed-only evidence",
          "assumed": "an assumed premise"}


def limit_sentence(req_id: str, p: Premise) -> str:
    """"REQ2 rests on tested-only evidence for Navigation guarantee 1" (with the doubt)."""
    if p.doubt >= 1.0:
        return f"{req_id} rests on {p.label}, which nothing discharges"
    return f"{req_id} rests on {_WORDS.get(p.kind, p.kind)} for {p.label} (doubt {p.doubt:g})"


@dataclass
class ConfidencePart:
    """What the confidence pass adds to the report's rows (module docstring),
    by row: ``evidence``/``side_conditions``: one ``strength`` per row, in
    the report's order; ``guarantees``: node -> one ``strength`` per
    guarantee; ``nodes``/``derived``/``requirements``: name or id -> the fields the row
    gains (``confidence``, ``limited_by``; a requirement also
    ``required_strength`` and ``strength_shortfall``); ``problems``: one
    sentence per requirement short of its required strength; ``confidence``:
    the least confidence of the formal requirements (``None``: none);
    ``ok``: no requirement is short of its required strength."""
    evidence: list[Strength] = field(default_factory=list)
    side_conditions: list[Strength] = field(default_factory=list)
    guarantees: dict[str, list[Strength]] = field(default_factory=dict)
    nodes: dict[str, Confidence] = field(default_factory=dict)
    derived: dict[str, Confidence] = field(default_factory=dict)
    requirements: dict[str, RequirementConfidence] = field(default_factory=dict)
    problems: list[str] = field(default_factory=list)
    confidence: float | None = None
    ok: bool = True


def confidence_part(report: AssuranceReport, links: list[tuple[str, str]],
                    required: dict[str, str] | None = None) -> ConfidencePart:
    """The strength and confidence of ``report``'s rows (module docstring),
    as a part: the report is read, not changed (report/assemble.py puts the
    part in).  ``links``: ``(producer node, consumer node)`` of the system
    model; ``required``: requirement id -> the least strength the plan asks
    of the guarantees its proof uses; a requirement short of it makes
    ``ok`` false (then ``--strict`` fails) and is one of ``problems``."""
    part = ConfidencePart()
    by_ob: dict[str, list[Strength]] = {}
    for e in report.evidence:
        part.evidence.append(evidence_strength(e))
        by_ob.setdefault(e.obligation, []).append(part.evidence[-1])
    status = {o.id: str(o.status) for o in report.obligations}
    sc_premises: dict[str, list[Premise]] = {}
    for sc in report.side_conditions:
        part.side_conditions.append(side_condition_strength(sc))
        sc_premises.setdefault(sc.node, []).append(
            Premise(f"side condition {sc.id}", "proof", part.side_conditions[-1].doubt))
    own: dict[str, list[Premise]] = {}
    guarantee: dict[tuple[str, int], Premise] = {}
    for n in report.nodes:
        name, ps = n.name, []
        for g in n.guarantees:
            p = guarantee_premise(f"{name} guarantee {g.index}", _legs(g.obligations, by_ob, status))
            guarantee[(name, g.index)] = p
            part.guarantees.setdefault(name, []).append(Strength(kind=p.kind, doubt=p.doubt))
            ps.append(p)
        own[name] = ps + sc_premises.get(name, [])
    producers: dict[str, set[str]] = {n: set() for n in own}
    for a, b in links:
        if b in producers and a in own:
            producers[b].add(a)
    claims = node_claims(own)
    part.nodes = {n.name: _put(claims[n.name]) for n in report.nodes}
    derived = derived_claims(own, producers)
    part.derived = {d.node: _put(derived[d.node]) for d in report.derived_properties if d.node in derived}
    lows = [_requirement(rq, check, guarantee, sc_premises, (required or {}).get(rq.id), part)
            for rq in report.requirements if (check := RequirementCheckRow.of(rq.check)).formal]
    if lows:
        part.confidence = min(lows)
    return part


def _requirement(rq: RequirementRow, check: RequirementCheckRow, guarantee: Mapping[tuple[str, int], Premise],
                 sc_premises: Mapping[str, list[Premise]], need: str | None, part: ConfidencePart) -> float:
    """Put a formal requirement's confidence (C5) and its shortfall of ``need`` into ``part``; its confidence.
    ``check``: its check record, decoded."""
    two = check.solvers is not None and check.solvers.agreement == "two solvers"
    proof = Premise(f"the proof of {rq.id}", "proof", DOUBT["proof2" if two else "proof"])
    used: list[Premise] = []
    rests: list[Premise] = []  # the guarantees the proof used
    for p in check.used:
        if p.kind == "guarantee" and p.node is not None and (p.node, p.index) in guarantee:
            rests.append(guarantee[(p.node, p.index)])
            used.append(rests[-1])
            used.extend(sc_premises.get(p.node, []))
        else:
            used.append(Premise(p.label, "assumed", DOUBT["assumed"]))
    c = requirement_claim(rq.verdict in _PROVED, proof, used)
    required: StrengthKind | None = None
    shortfall: list[str] = []
    if need in KINDS:
        short = [g for g in rests if g.doubt >= 1.0 or g.kind not in KINDS or KINDS.index(g.kind) > KINDS.index(need)]
        required = cast(StrengthKind, need)
        shortfall = [f"{g.label} ({g.kind if g.doubt < 1.0 else 'nothing discharged'})" for g in short]
        if short:
            part.ok = False
            part.problems.append(f"Requirement {rq.id} requires {need} evidence; " + ", ".join(
                f"{g.label} rests on {g.kind if g.doubt < 1.0 else 'no discharged'} evidence" for g in short))
    if c.limits is not None and rq.verdict not in _PROVED:  # a claim always has its proof as a premise
        conf = _put(c, f"{rq.id} is {rq.verdict}: no confidence rests on it")
    else:
        conf = _put(c, None if c.limits is None else limit_sentence(rq.id, c.limits))
    part.requirements[rq.id] = RequirementConfidence(conf.confidence, conf.limited_by, required, shortfall)
    return float(c.confidence)


#: Obligation statuses that are counter-evidence: the guarantee is defeated (docs/confidence.md, C0).
_DEFEATING = ("failed", "error")


def _legs(obligations: list[str], by_ob: dict[str, list[Strength]],
          status: dict[str, str]) -> list[tuple[str, float]]:
    """A guarantee's legs (C1): its obligations grouped by evidence entry (the
    obligation id up to its entry, ``Node.g1.hoare.prog``), each leg's doubt
    the C2 sum over its obligations (conjuncts and instances are all needed).
    One failed obligation defeats the guarantee (C0): a single leg of doubt 1."""
    if any(status.get(o) in _DEFEATING for o in obligations):
        return [("defeated", 1.0)]
    legs: dict[str, list[tuple[str, float]]] = {}
    for o in obligations:
        parts = o.split(".")
        leg = ".".join(parts[:4])
        strengths: list[Strength] = by_ob.get(o) or [Strength(kind="assumed", doubt=1.0)]
        legs.setdefault(leg, []).extend((s.kind, s.doubt) for s in strengths)
    return [(ps[0][0], min(1.0, sum(d for _, d in ps))) for ps in legs.values()]


def _put(c: Claim, sentence: str | None = None) -> Confidence:
    """A claim's ``confidence`` and ``limited_by`` (the premise with the largest doubt, named in
    ``sentence`` when given: a requirement's), the row fields they set."""
    lim = c.limits
    return Confidence(c.confidence, None if lim is None else LimitedBy(
        label=lim.label, kind=lim.kind, doubt=lim.doubt, sentence=msgspec.UNSET if sentence is None else sentence))
