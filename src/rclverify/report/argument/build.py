"""Build the GSN goal structure from the assurance report.

The argument is built from the :class:`~rclverify.records.report_record.AssuranceReport`
of :func:`rclverify.report.build.build_report` (the same data the report shows, read
by attribute), so it needs no other artifact and works
with any backend and any evidence kind: a solution is one evidence record,
whatever produced it.  Structure (docs/argument.md)::

    G-system  the system meets REQ1..REQn            in context of C-plan
      S-requirements  argument over each requirement
        G-<REQ>  the requirement's text
          S-<REQ>  argument over the composition calculus (rules R1-R4,
                   paper lines 556-768)              in context of A-persist,
                   the loop rule's assumption, J-calculus
            G-<Node>.g<k>   each supporting guarantee
            G-<Node>.sc<k>  each side condition of a supporting node
      S-contracts  argument over the node contracts (the rules' premises)
        G-<Node>  the node meets its contract        in context of C-<Node>,
                                                     its environment assumptions
          G-<Node>.g<k>, G-<Node>.sc<k>
    G-<Node>.g<k>   supported by one solution per evidence record of an
                    obligation on it (guarantee k, or 0 = the whole contract),
                    one per contract health finding on it, and an undeveloped
                    goal per obligation without a record, or when no
                    obligation was exported at all
    G-<Node>.sc<k>  supported by the Z3 query's solution
    G-<REQ>.deadline  a requirement's end-to-end deadline, under its goal
                    (:mod:`.deadlines`: Z3's decision, the chain's timed
                    guarantees, the monitors' evidence)

Statuses then propagate upward (:func:`.model.propagate`): with the
report's own roll-up rules this gives every requirement, guarantee and node
goal the status the report shows for it.
"""
from __future__ import annotations

import hashlib

import re
from typing import Any, Iterable, Mapping, TypeVar

import msgspec

from rclverify.records.derived_rows import EnvironmentAssumptionRow
from rclverify.records.findings import FindingRow
from rclverify.records.node_rows import NodeRow
from rclverify.records.obligations import ObligationRow
from rclverify.records.report_record import AssuranceReport
from rclverify.records.requirement_check import DeclarationRow, RequirementCheckRow
from rclverify.records.requirement_rows import RequirementRow
from rclverify.records.side_condition_rows import SideConditionRow
from rclverify.report.argument.deadlines import own_check, with_deadline
from rclverify.report.argument.statistics import with_statistics
from rclverify.report.argument.model import Argument, Element, propagate
from rclverify.report.textfmt import natural_key
from rclverify.report.argument.defeaters import add_defeaters
from rclverify.report.argument.standards import add_standard_links
from rclverify.report.argument.accepted import add_accepted_risks
from rclverify.report.argument.claim_points import add_claim_points

#: A report row that names its node.
_Row = TypeVar("_Row", ObligationRow, SideConditionRow, EnvironmentAssumptionRow)

_FINDING_AS = {"ok": "discharged", "problem": "failed", "inconclusive": "inconclusive", "stale": "stale"}
_ID_BAD = re.compile(r"[^A-Za-z0-9_.\-]+")

PERSIST = ("Outputs persist once produced, so the inputs a node receives from several producers are "
           "available together (the calculus's simplifying assumption for R3, paper lines 658-660; "
           "the user must ensure it).")
CALCULUS = ("Rules R1 (sequence), R2 (branch), R3 (join) and R4 (loop) of the composition calculus "
            "(paper lines 556-768): when each node meets its contract and every side condition is "
            "discharged, each node's guarantee eventually holds in the composed system.")
IN_CONTEXT = ("Side conditions in context (docs/calculus.md): a conjunct of a node's assumption that its producers' "
              "guarantees alone do not entail is entailed by the guarantees of its upstream cone, each taken only "
              "where its own node's assumption holds (the stream semantics, paper lines 462-495), with the "
              "environment assumptions and facts of the cone; loops are opened as rule R4 composes them (paper "
              "lines 717-768), so no guarantee discharges its own premise.")


def ident(prefix: str, *parts: Any) -> str:
    """A GSN id ``<prefix>-<parts joined by '.'>`` with unsafe characters replaced by ``_``."""
    return prefix + "-" + _ID_BAD.sub("_", ".".join(str(p) for p in parts))


def _clip(text: str, n: int = 400) -> str:
    text = " ".join(str(text).split())
    return text if len(text) <= n else text[: n - 3] + "..."


ENTAILMENT = ("Z3 decides the requirement from the guarantees of the nodes it mentions and of every node upstream "
              "of them, the environment assumptions and facts of those nodes and the requirement's own assumptions "
              "(docs/requirements.md); the proof is only as good as the evidence of the guarantees it used and the "
              "consistency of its premises.")
_PROOF_STATUS = {"met": "discharged", "proved, evidence outstanding": "discharged",
                 "proved from an inconsistency": "failed", "proved vacuously": "failed", "refuted": "failed", "inconclusive": "inconclusive",
                 "stale": "stale", "error": "error"}


def _requirement_goal(b: "_Builder", r: RequirementRow, guarantee_goal: Mapping[tuple[str, int], str],
                      sides: Mapping[str, list[SideConditionRow]], j_calc: str) -> str:
    """The goal of a requirement the report's requirement check decided
    (its ``verdict``): an informal one is an undeveloped goal; a formal one is
    supported by a formal-entailment strategy whose children are the Z3
    proof (a solution with the check's verdict) and the goals of the
    guarantees the proof used, with the side conditions of their nodes."""
    rid = r.id
    if r.verdict == "informal":
        traced = ", ".join(f"{s.node} guarantee {s.guarantee}" for s in r.support) or "no guarantee"
        return b.add(Element(ident("G", rid), "goal",
                             _clip(f"{rid}: {r.text} (informal: no formal statement; traced to {traced})"),
                             undeveloped=True, ref=rid))
    c = RequirementCheckRow.of(r.check)  # the requirements stage's check record, decoded
    sn = b.add(Element(ident("Sn", "req", rid), "solution",
                       _clip(f"Z3 {('proof' if r.verdict in ('met', 'proved, evidence outstanding') else 'check')} "
                             f"of {rid} ({c.smt2 or _temporal_what(c.temporal) or 'not checked yet'}): {r.verdict}. "
                             f"{r.note}"),
                       status=_PROOF_STATUS.get(r.verdict, "pending"), ref=rid, url=c.smt2 or ""))
    kids = [sn]
    nodes_used: list[str] = []
    for p in c.used:
        if p.kind == "guarantee" and (str(p.node), p.index) in guarantee_goal:
            kids.append(guarantee_goal[(str(p.node), p.index)])
            if p.node not in nodes_used:
                nodes_used.append(str(p.node))
    for name in nodes_used:
        kids += [ident("G", "sc", sc.id) for sc in sides.get(name, [])]
    kids += [_declaration_goal(b, d) for d in c.declarations]
    ctx = [j_calc] + [b.add(Element(ident("A", rid, "assuming", k), "assumption",
                                    _clip(f"{rid} assumes: {a}"), ref=rid))
                      for k, a in enumerate(c.assuming, 1)]
    strategy = b.add(Element(
        ident("S", rid), "strategy",
        _clip(f"Argument by formal entailment: {c.formal} follows from the premises Z3 used"
              + (f" ({', '.join(p.label for p in c.used)})" if c.used else "")
              + ". " + ENTAILMENT),
        supported_by=tuple(dict.fromkeys(kids)), in_context_of=tuple(ctx), ref=rid))
    # its confidence is stated at its assurance claim point (.claim_points)
    return b.add(Element(ident("G", rid), "goal", _clip(f"{rid}: {r.text}"), supported_by=(strategy,), ref=rid))


def _declaration_goal(b: "_Builder", d: DeclarationRow) -> str:
    """The goal that a declaration a proof used holds of its node's
    implementation, supported by its evidence as the roll-up
    reads it (requirements/rollup.declaration_evidence): the monitors' runs,
    the property tests, or the declarations it follows from."""
    label = d.label
    sn = b.add(Element(ident("Sn", "decl", label), "solution",
                       _clip(f"Evidence of {label} ({d.source}): {d.status} ({d.words})"),
                       status=d.status, ref=label))
    return b.add(Element(ident("G", "decl", label), "goal",
                         _clip(f"{d.node} keeps its declaration {d.text}".rstrip()),
                         supported_by=(sn,), ref=label))


class _Builder:
    def __init__(self) -> None:
        self.els: dict[str, Element] = {}

    def add(self, e: Element) -> str:
        if e.id not in self.els:
            self.els[e.id] = e
        return e.id


def build_argument(report: AssuranceReport) -> Argument:
    """The goal structure of ``report`` (the decoded report, read by attribute), statuses propagated.

    Returns an :class:`Argument` whose element order is deterministic
    (requirements and nodes in report order, obligations in natural order
    of their ids: ``p1_i0 < p2_i1 < p10_i9``).
    Raises :class:`.model.ArgumentError` if the result were malformed.
    """
    g = _Goals(report)
    top, top_ctx = ident("G", "system"), g.top_context()
    g.loop_assumptions()
    g.j_calc = g.b.add(Element(ident("J", "calculus"), "justification", CALCULUS))
    if any(sc.verdict == "discharged in context" for scs in g.sides.values() for sc in scs):
        g.b.add(Element(g.j_context, "justification", IN_CONTEXT))
    contract_goals = [g.contract_goal(n) for n in report.nodes]
    req_goals = [g.requirement_goal(r) for r in report.requirements]
    b = g.b
    s_reqs = b.add(Element(ident("S", "requirements"), "strategy", "Argument over each requirement of the plan",
                           supported_by=tuple(req_goals), undeveloped=not req_goals))
    s_contracts = b.add(Element(ident("S", "contracts"), "strategy",
                                "Argument over the node contracts: every node meets its contract (the premises of rules R1-R4)",
                                supported_by=tuple(contract_goals), in_context_of=(g.a_persist, *g.loop_ids.values())))
    ids = ", ".join(r.id for r in report.requirements) or "no requirement listed"
    b.els = {top: Element(top, "goal", f"The system {g.meta.workspace} meets its requirements ({ids})",
                          supported_by=(s_reqs, s_contracts), in_context_of=top_ctx), **b.els}
    add_defeaters(b.els, report, ident)
    add_accepted_risks(b.els, report, ident, top)
    add_claim_points(b.els, report, ident)
    add_standard_links(b.els, report, ident)  # strategies -> the standard clauses they address
    return propagate(Argument(top, b.els))


def _by_node(rows: Iterable[_Row]) -> dict[str, list[_Row]]:
    out: dict[str, list[_Row]] = {}
    for r in rows:
        out.setdefault(r.node, []).append(r)
    return out


class _Goals:
    """The elements of one argument, added in a fixed order (the element
    order is the output's): the report's rows by node, and the ids of the
    context elements the goals refer to."""

    def __init__(self, report: AssuranceReport) -> None:
        self.report, self.b = report, _Builder()
        self.meta = report.meta
        self.ev_of = {e.obligation: e for e in report.evidence}
        # by node, still sorted by id: p1 < p2 < p10
        self.obligations_of = _by_node(sorted(report.obligations, key=lambda o: natural_key(o.id)))
        self.sides = _by_node(report.side_conditions)
        self.findings: dict[str, list[FindingRow]] = {}
        for f in report.findings:
            self.findings.setdefault(f.node, []).append(f)
        self.env = _by_node(report.environment_assumptions)
        self.loop_ids: dict[str, str] = {}  # R4's assumption text -> its element (one per loop)
        self.loop_of: dict[str, str] = {}
        self.guarantee_goal: dict[tuple[str, int], str] = {}
        self.a_persist = self.j_calc = ""
        self.j_context = ident("J", "context")

    def top_context(self) -> tuple[str, ...]:
        """The plan's context, the persistence assumption and the grounding's context (docs/ros.md:
        which software version the contracts were grounded in)."""
        b, meta = self.b, self.meta
        c_plan = b.add(Element(ident("C", "plan"), "context",
                               f"Verification plan {meta.plan} and contracts {', '.join(meta.contracts)} "
                               f"of {meta.workspace}", url=meta.plan))
        self.a_persist = b.add(Element(ident("A", "persist"), "assumption", PERSIST))
        grounding = self.report.grounding
        if not grounding:
            return (c_plan,)
        ctx = grounding.context  # stages/grounding's context record (its own shape): packages and files
        digest = hashlib.sha256("".join(f"{f['path']}\0{f['sha256']}\n" for f in ctx["files"]).encode()).hexdigest()
        return (c_plan, b.add(Element(ident("C", "ros"), "context", _clip(
            "Contracts grounded in the ROS software: "
            + ", ".join(f"{p['name']} {p['version']}" for p in ctx["packages"])
            + f"; {len(ctx['files'])} scanned files (sha256 of their sha256 list {digest[:16]}, each in "
              f"artifacts/ros/graph.json); {grounding.counts.error} grounding error(s), "
              f"{grounding.counts.warning} warning(s)"), url="artifacts/ros/graph.json")))

    def loop_assumptions(self) -> None:
        """One assumption element per loop of rule R4 (its derived properties' loop assumption)."""
        for d in self.report.derived_properties:
            text = d.loop_assumption
            if text:
                if text not in self.loop_ids:
                    self.loop_ids[text] = self.b.add(Element(ident("A", "loop", len(self.loop_ids) + 1), "assumption",
                                                             text))
                self.loop_of[d.node] = self.loop_ids[text]

    def _evidence(self, o: ObligationRow) -> str:
        """The solution of obligation ``o`` (its evidence record), or an undeveloped goal without one."""
        oid = o.id
        ev = self.ev_of.get(oid)
        if ev is None:
            return self.b.add(Element(ident("G", "ob", oid), "goal",
                                      f"Obligation {oid} ({o.backend}) is discharged: no evidence record yet",
                                      undeveloped=True, ref=oid))
        tool = f"{ev.tool} {ev.tool_version}".strip()
        strength = (f" [strength: {ev.strength.kind}; {'' if ev.strength.detail is msgspec.UNSET else ev.strength.detail}]"
                    if ev.strength else "")
        return self.b.add(Element(
            ident("Sn", "ev", oid), "solution",
            _clip(f"{ev.kind} evidence ({ev.backend}, {tool}) for {oid}: {ev.status}{strength}. {ev.explanation}"),
            status=ev.status, ref=oid, url=f"artifacts/evidence/{oid}.json"))

    def evidence_goals(self, node: str, k: int) -> list[str]:
        """Solutions and undeveloped goals under guarantee ``k`` of ``node``."""
        mine = [o for o in self.obligations_of.get(node, []) if o.node == node and o.guarantee in (k, 0)]
        kids = [self._evidence(o) for o in mine]
        if not mine:
            kids.append(self.b.add(Element(ident("G", node, f"g{k}", "evidence"), "goal",
                                           f"Evidence that {node} guarantee {k} holds: no obligation was exported for it",
                                           undeveloped=True, ref=f"{node}.g{k}", status="unverified")))
        for f in self.findings.get(node, []):
            if f.guarantee in (None, k):
                kids.append(self.b.add(Element(
                    ident("Sn", "health", f.id), "solution",
                    _clip(f"Contract health check {f.check} (Z3): {f.status}. {f.message}"),
                    status=_FINDING_AS.get(f.status, "error"), ref=f.id, url=f.smt2)))
        return kids

    def side_goal(self, sc: SideConditionRow) -> str:
        """The goal of side condition ``sc`` with its Z3 query as solution (in context: the weaker claim)."""
        b, sid = self.b, sc.id
        verdict = sc.verdict or sc.status
        sn = b.add(Element(ident("Sn", "sc", sid), "solution",
                           _clip(f"Z3 query {sc.smt2}: {verdict}"
                                 + (f" [{sc.solvers.agreement}]" if sc.solvers else "")
                                 + f". {sc.explanation}"),
                           status=sc.status, ref=sid, url=sc.smt2))
        if verdict == "discharged in context":  # the claim is the weaker one the proof supports (docs/calculus.md)
            ctx = sc.context or {}  # calculus/compose.py's record of the proof in context
            used = sorted({str(u).split(" ", 1)[0] for u in ctx.get("used_nodes") or []})
            return b.add(Element(ident("G", "sc", sid), "goal",
                                 _clip(f"Side condition {sid} ({sc.rule}, {sc.source}): the conjunct "
                                       f"{sc.conjunct} of {sc.node}'s assumption follows, in context, from the "
                                       f"guarantees of its upstream cone ({', '.join(used) or 'none'}), each under its "
                                       "own node's assumption, and the cone's environment assumptions and facts"),
                                 supported_by=(sn,), in_context_of=(self.j_context,), ref=sid))
        return b.add(Element(ident("G", "sc", sid), "goal",
                             _clip(f"Side condition {sid} ({sc.rule}, {sc.source}): the conjunct "
                                   f"{sc.conjunct} of {sc.node}'s assumption follows from its producers' guarantees"),
                             supported_by=(sn,), ref=sid))

    def contract_goal(self, n: NodeRow) -> str:
        """The goal that node ``n`` meets its contract: its guarantees' goals and its side conditions'."""
        b, name = self.b, n.name
        g_ids = []
        for g in n.guarantees:
            k = g.index
            gid = b.add(Element(ident("G", name, f"g{k}"), "goal",
                                _clip(f"{name} guarantee {k} holds ({g.source}): {g.text}"),
                                supported_by=tuple(self.evidence_goals(name, k)), ref=f"{name}.g{k}"))
            self.guarantee_goal[(name, k)] = gid
            g_ids.append(gid)
        sc_ids = [self.side_goal(sc) for sc in self.sides.get(name, [])]
        c_node = b.add(Element(ident("C", name), "context", f"Contract of {name} ({n.source})", ref=name))
        ctx = [c_node] + [b.add(Element(ident("A", "env", name, i), "assumption",
                                        _clip(f"Environment assumption of {name} ({a.source}): {a.text}"), ref=name))
                          for i, a in enumerate(self.env.get(name, []), 1)]
        return b.add(Element(
            ident("G", name), "goal",
            f"{name} meets its contract in the composed system: for every input satisfying its assumption, "
            f"eventually an output satisfying its guarantees (paper lines 462-495)",
            supported_by=tuple(g_ids + sc_ids), in_context_of=tuple(ctx), ref=name))

    def requirement_goal(self, r: RequirementRow) -> str:
        """The goal of requirement ``r``: Z3's entailment when it was checked (it has a check record),
        else the calculus over its support."""
        b, rid = self.b, r.id
        if r.check:  # checked by the requirements stage (docs/requirements.md): entailment, or undeveloped
            gid = _requirement_goal(b, own_check(r), self.guarantee_goal, self.sides, self.j_calc)
            # its deadline (rule D3) and its recorded runs' bounds and targets (statistics.py)
            return with_statistics(b.els, with_deadline(b.els, gid, r, self.guarantee_goal), r)
        kids: list[str] = []
        nodes_used: list[str] = []
        for s in r.support:
            kids.append(self.guarantee_goal[(s.node, s.guarantee)])
            if s.node not in nodes_used:
                nodes_used.append(s.node)
        for name in nodes_used:
            kids += [ident("G", "sc", sc.id) for sc in self.sides.get(name, [])]
        ctx = [self.a_persist] + sorted({self.loop_of[x] for x in nodes_used if x in self.loop_of}) + [self.j_calc]
        strategy = b.add(Element(
            ident("S", rid), "strategy",
            f"Argument over the composition calculus: {rid} follows from the guarantees of "
            f"{', '.join(nodes_used) or 'no node'} once the side conditions of their assumptions are discharged",
            supported_by=tuple(dict.fromkeys(kids)), in_context_of=tuple(ctx), ref=rid))
        if kids:
            return b.add(Element(ident("G", rid), "goal", _clip(f"{rid}: {r.text}"), supported_by=(strategy,), ref=rid))
        del b.els[strategy]  # no supporting guarantee listed: nothing argues for it
        return b.add(Element(ident("G", rid), "goal", _clip(f"{rid}: {r.text} (no supporting guarantee listed)"),
                             undeveloped=True, ref=rid))


def _temporal_what(t: Mapping[str, Any] | None) -> str:
    """How a temporal requirement was decided (its check's ``temporal`` record,
    calculus/requirements/temporal_check.py's own shape), for its solution's text."""
    if t is None:
        return ""
    steps = "no step checked" if t.get("bound") is None else f"{t['bound']} steps checked"
    return f"temporal, {t.get('method')}, {steps}"
