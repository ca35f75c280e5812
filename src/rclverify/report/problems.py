"""The report's problems grouped by root cause: one row per problem.

The same defect is often found by several techniques: the Agent's guarantee
3 makes guarantees 1 and 2 vacuous (contract health), the requirement REQ1
that rests on guarantee 2 is proved only vacuously (the requirements
check), a monitor and a property test see guarantee 3 violated.  This
module puts every problem the report lists into the group of its *root
cause*, so the report shows one row per root cause with the list of
findings behind it (docs/reading-the-report.md, "What needs attention").

The root-cause key of a problem is the set of its *root culprits*, read from
its diagnosis record (:mod:`rclverify.diagnosis.build`, ``culprits``):

1. every culprit is placed by its source location: a location inside a
   node's contract is that node's guarantee, assumption or contract header
   (the last one starting at or before that line of the file); a location in
   another file (a program line) is that line; an environment fact of the
   plan and an event of a trace are context and evidence, not culprits
   (kept only when nothing else is named);
2. the problem's own guarantee (the *victim*: the guarantee a Hoare triple or
   a property test checks) is left out when something else is named (for a
   refuted Hoare triple the program's constants remain);
3. a culprit guarantee that is itself the victim of a vacuity or
   inconsistency problem of contract health stands for that problem's root
   culprits (except for a failed side condition, whose culprits are the
   ones Z3 showed for it: it is its own root unless those name another): the contract defect explains what is found on top of it (the
   property test of a vacuous guarantee, a requirement proved vacuously
   because of it); when any culprit is explained so, the explained ones make
   the key.

4. the guarantees of one node that no obligation covers (``unverified``,
   :mod:`rclverify.report.unverified`) are one group of their own, keyed
   ``unverified:<Node>``, each guarantee a finding and a culprit at its
   location; a contract defect never absorbs them.
5. outstanding evidence (inconclusive or pending, without a diagnosis) on a
   node's whole contract from one backend, e.g. the recorded runs one
   ``monitors`` entry checks, is one group, keyed
   ``outstanding-contract:<backend>:<Node>`` (one cause, one row: each run is a
   finding of it).

5. an end-to-end deadline that is refuted or not decided
   (:mod:`rclverify.diagnosis.deadline`) is one group of its own, keyed
   ``deadline:<REQ>``, its culprits the hops of its chain with their bounds
   (or the node where its path breaks); the requirement it makes not met
   (when its own statement is not refuted) is a finding of that group.  A
   hop's guarantee found wanting elsewhere (a monitor, a vacuity) is
   another problem: a deadline is about time, not about what is answered.

Failed side conditions whose first repair is the same edit (one producer
too loose for several consumers) are one group, keyed by the union of their
culprits (:mod:`.problems_shared`).

The culprits a diagnosis record names are the ones Z3 showed
(:mod:`rclverify.diagnosis.blame`): strengthening each alone removes the
counterexample, so unrelated bugs that only mention the same variable do
not share a key.  Findings are named fully (a derived property is
``<Node>.derived``).  Problems with the same key are one group; a problem with no culprit at all
(a refinement that fails, a lint error) is its own group.  A derived
property that is not derived joins the group of the side conditions of its
cone that are not discharged (the reason it is not derived).  Requirements
refuted, proved vacuously or from an inconsistency take their culprits from
the check's core (``vacuity_core``, ``inconsistent_core``,
``failed_to_prevent``); attention items without a diagnosis record
(inconclusive or stale evidence, undecided side conditions, derived
properties, lint errors) take the guarantee their obligation belongs to.
"""
from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import msgspec

from rclverify.records.problem_rows import DiagnosisRow, ProblemRow
from rclverify.records.repair_rows import CexTableRow
from rclverify.records.report_record import AssuranceReport
from rclverify.records.requirement_check import RequirementCheckRow
from rclverify.report.shapes import AttentionItem
from rclverify.report import problems_causes as pc
from rclverify.report import problems_mc as mc
from rclverify.report import problems_places as pp
from rclverify.report import problems_shared as ps
from rclverify.report import problems_units as pu
from rclverify.report.problems_places import (BAD_VERDICTS, DEADLINE_PREFIX, OUTSTANDING_WHOLE, SENTENCE_CHARS,
                                              Member, Rooted, first_sentence)
from rclverify.report.problems_shared import producer_first
from rclverify.report.textfmt import natural_sorted


@dataclass
class _Row:
    """A problem row while it is made (the fields of :class:`~rclverify.records.problem_rows.ProblemRow`)."""
    key: list[str]
    status: str
    sentence: str
    culprits: list[dict[str, Any]]
    members: list[Member] = field(default_factory=list)
    repairs: list[dict[str, Any]] = field(default_factory=list)
    where: str = ""

    def record(self) -> ProblemRow:
        """The row checked by decoding it into :class:`~rclverify.records.problem_rows.ProblemRow` (raises
        :class:`msgspec.ValidationError` for a row the class does not admit)."""
        return ProblemRow.of({"key": self.key, "status": self.status, "sentence": self.sentence,
                              "culprits": self.culprits, "members": [m.to_json() for m in self.members],
                              "repairs": self.repairs, "where": self.where})


def group_problems(report: AssuranceReport | Mapping[str, Any], items: Sequence[AttentionItem],
                   anchor: Callable[..., str]) -> list[ProblemRow]:
    """The problems of ``report`` (the report, or its JSON object, which may lack ``problems``:
    decoded here once into :class:`~rclverify.records.report_record.AssuranceReport`; the problems
    it has are not read) grouped by root cause (module docstring), each a
    :class:`~rclverify.records.problem_rows.ProblemRow`.

    ``items`` are the report's attention problems (``render.problem_items``:
    dicts with ``status``, ``kind``, ``ref``, ``anchor``, ``message``);
    ``anchor`` builds a fragment id from parts (``render.anchor``).  Returns
    ``[group]``, worst status first and then in the order of the report's
    problems, each::

        {"key": [root culprit ids], "status": worst member status,
         "sentence": the first sentence (first_sentence) of the diagnosis of a member with
                     the worst status: the most telling kind (TELLING), then the shortest,
         "culprits": [{"id", "what", "source", "file", "anchor" (fragment id or ""),
                       "node" (a program line's: the node of every finding of the row, when one)}],
         "where": file:line:col of the first member that has one (shown when no culprit is named),
         "members": [{"id", "kind", "status", "sentence", "anchor", "diagnosis": bool,
                      "consequence_of": [ids of the members it follows from] (only on a consequence)}],
         "repairs": [{"diagnosis": id, "index": n}]  (distinct diffs, each checked by Z3)}

    Raises :class:`msgspec.ValidationError` for a report of another shape, or a row the class does
    not decode (a bug of the grouping).
    """
    typed = report if isinstance(report, AssuranceReport) else AssuranceReport.of({"problems": [], **report})
    g = _Grouping(typed, items, anchor)
    g.diagnosis_members()
    g.requirement_members()
    g.item_members()
    groups = g.groups()
    g.unverified_rows(groups)
    g.deadline_rows(groups)
    g.model_checking_rows(groups)
    g.line_owners(groups)
    where = pp.sources(typed)
    for row in groups.values():  # where the problem is, for a row that names no culprit
        row.where = next((where[m.id] for m in row.members if where.get(m.id)), "")
    for row in groups.values():
        if not row.key[0].startswith("unverified:"):
            g.sentence_and_repairs(row)
    out = list(groups.values())
    out.sort(key=lambda row: -pp.severity(row.status))  # stable: report order within a status
    return [row.record() for row in out]


def _set(value: str | msgspec.UnsetType) -> str | None:
    """An optional text field of a diagnosis: ``None`` when it is not set."""
    return None if isinstance(value, msgspec.UnsetType) else value


def _victim_of(node: object, k: object) -> str | None:
    return f"guarantee:{node}:{k}" if node and k else None


class _Grouping:
    """The state of one :func:`group_problems`: the members found so far
    (each with its roots), what a contract defect explains, the members
    grouped only by the culprits they name (``direct``), and the rows of
    unit mismatches; each method is one step of the module docstring's rules."""

    def __init__(self, report: AssuranceReport, items: Sequence[AttentionItem],
                 anchor: Callable[..., str]) -> None:
        self.report, self.items, self.anchor = report, items, anchor
        self.places = pp.Places(report.nodes)
        self.diagnoses = report.diagnoses
        self.by_id = {d.id: d for d in self.diagnoses}
        self.item_anchor = {str(it["ref"]): str(it["anchor"]) for it in items}
        self.members: list[Rooted] = []
        self.explains: dict[str, list[str]] = {}
        self.mc_obl = mc.mc_obligations(report)
        self.direct: set[str] = set()  # model-checking evidence: grouped only by the culprits it names (problems_mc)
        self.unit_of = pu.joins(self.diagnoses)  # a unit mismatch's row takes what it explains (problems_units)
        self.unit_roots: dict[str, list[str]] = {}
        self.unverified = {u.id: u for u in report.unverified}
        self.obligation = {o.id: o for o in report.obligations}

    def _diagnosis_roots(self, d: DiagnosisRow) -> list[str]:
        """The roots of the diagnosis ``d`` (rules 1, 2 and 5; a unit mismatch's, a model checker's)."""
        roots = pp.roots([(c.what, c.source) for c in d.culprits], self.places, _victim_of(d.node, d.guarantee))
        did = d.id
        if d.kind == pu.KIND:
            self.unit_roots[did] = roots = roots or [f"problem:{d.id}"]
            self.item_anchor.setdefault(did, self.item_anchor.get(str(_set(d.lint)), ""))
        if d.kind == pu.KIND or self.unit_of.get(did) in self.unit_roots:
            roots = self.unit_roots[did if d.kind == pu.KIND else self.unit_of[did]]
            self.direct.add(did)
        if d.kind == "deadline":  # its own row, whatever else its hops' guarantees are found in (rule 5)
            roots = [f"{DEADLINE_PREFIX}{_set(d.requirement)}"]
        if did in self.mc_obl:
            self.direct.add(did)
            roots = ([r for r in roots if r != _victim_of(d.node, d.guarantee)]
                     or [mc.mc_key(self.mc_obl[did], d.status)])
        return roots

    def diagnosis_members(self) -> None:
        """One member per diagnosis, then the joins of problems_shared and problems_causes."""
        for d in self.diagnoses:
            roots = self._diagnosis_roots(d)
            m = Member(id=d.id, kind=d.kind, status=d.status, sentence=d.sentence, diagnosis=True,
                       anchor=self.item_anchor.get(d.id) or pp.default_anchor(d, self.anchor))
            self.members.append((m, roots))
            victim = _victim_of(d.node, d.guarantee)
            if d.kind in pp.CONTRACT_DEFECTS and victim and roots and victim not in roots:
                self.explains.setdefault(victim, [])
                self.explains[victim] += [r for r in roots if r not in self.explains[victim]]
        ps.join_by_first_repair(self.members, self.by_id)  # several consumers, one too loose producer: one row
        pc.join_consequences(self.members, self.by_id)  # refuted only because of another problem: its row
        pc.join_implementation_findings(self.members, self.by_id)  # a test and a run of one guarantee: the handler's row

    def requirement_members(self) -> None:
        """One member per requirement not met that no diagnosis covers, its roots from its check's cores."""
        diagnosed = {d.id for d in self.diagnoses}
        for q in self.report.requirements:
            if q.verdict not in BAD_VERDICTS or q.id in diagnosed:
                continue
            check = RequirementCheckRow.of(q.check)
            core = [*check.vacuity_core, *check.inconsistent_core, *check.failed_to_prevent]
            roots = pp.roots([(p.label, p.source) for p in core], self.places, None)
            if pp.by_deadline(q):  # not met because of its end-to-end deadline only: the deadline's row (rule 5)
                roots = [f"{DEADLINE_PREFIX}{q.id}"]
            self.members.append((Member(id=q.id, kind="requirement", status=q.status,
                                        sentence=f"Requirement {q.id} is {q.verdict}" + (f": {q.note}" if q.note else "") + ".",
                                        anchor=self.anchor("req", q.id), diagnosis=False), roots))
        pp.join_requirements_to_side_conditions(self.members)

    def _item_roots(self, it: AttentionItem, ref: str, roots_of: Mapping[str, list[str]]) -> tuple[str, list[str]]:
        """``(member id, roots)`` of the attention item ``it`` no diagnosis covers (rules 4 and 5)."""
        o = self.obligation.get(ref)
        roots = [f"guarantee:{o.node}:{o.guarantee}"] if o is not None and o.guarantee else []
        roots = [r for r in roots if r in self.places.info]
        if ref in self.mc_obl:  # model-checking evidence without a diagnosis (inconclusive): outstanding, by guarantee
            self.direct.add(ref)
            roots = [mc.mc_key(self.mc_obl[ref], str(it["status"]))]
        elif o is not None and not o.guarantee and str(it["status"]) in ("inconclusive", "pending"):
            roots = [f"{OUTSTANDING_WHOLE}{o.backend}:{o.node}"]  # rule 5
            self.direct.add(ref)
        if self.unit_of.get(ref) in self.unit_roots:  # explained by a unit mismatch: its row (problems_units)
            roots = self.unit_roots[self.unit_of[ref]]
            self.direct.add(ref)
        if it["kind"] == "derived property":
            ref = f"{ref}.derived"  # named fully: the derived property of the node, never the bare node name
            # not derived because a side condition of its cone is not discharged: that side condition's cause
            for sc in pp.cone_side_conditions(self.report, str(it["ref"])):
                roots += [r for r in (roots_of.get(sc) or [f"problem:{sc}"]) if r not in roots]
        return ref, roots

    def item_members(self) -> None:
        """One member per attention item no diagnosis or requirement covers, then the assumption
        violations and the extra members of a unit mismatch (problems_causes, problems_units)."""
        covered = {m.id for m, _ in self.members}
        roots_of = {m.id: roots for m, roots in self.members}
        for it in self.items:
            ref = str(it["ref"])
            if ref in covered:
                continue
            if it["kind"] == "guarantee":  # unverified: no obligation covers it (rule 4 of the module docstring)
                u = self.unverified.get(ref)
                self.members.append((Member(id=ref, kind="unverified guarantee", status=str(it["status"]),
                                            sentence=f"Guarantee {ref} is unverified: {u.reason if u else it['message']}.",
                                            anchor=str(it["anchor"]), diagnosis=False),
                                     [f"unverified:{u.node if u else ref}"]))
                covered.add(ref)
                continue
            ref, roots = self._item_roots(it, ref, roots_of)
            roots_of[ref] = roots
            self.members.append((Member(id=ref, kind=str(it["kind"]), status=str(it["status"]),
                                        sentence=str(it["message"]) + (f" `{it['formula']}`" if it.get("formula") else ""),
                                        anchor=str(it["anchor"]), diagnosis=False), roots))
            covered.add(ref)
        pc.assumption_violations(self.report, self.members, self.anchor)  # a run's violation a failed side condition explains
        for m, uid in pu.extra_members(self.report, self.diagnoses, covered, self.anchor):  # a lint or health warning, a run
            if uid in self.unit_roots:
                self.direct.add(m.id)
                self.members.append((m, self.unit_roots[uid]))

    def groups(self) -> dict[tuple[str, ...], _Row]:
        """The members grouped by their roots (or by what a contract defect explains of them: rule 3)."""
        groups: dict[tuple[str, ...], _Row] = {}
        for m, roots in self.members:
            # an unverified guarantee stays a row of its own, even when a contract defect explains the guarantee;
            # so does a failed side condition: its culprits are the ones Z3 showed for it (diagnosis/blame.py)
            explained = ([] if m.kind in ("unverified guarantee", "side-condition") or m.id in self.direct
                         or any(r.startswith(DEADLINE_PREFIX) for r in roots)
                         else [e for r in roots for e in self.explains.get(r, [])])
            if explained:
                roots = list(dict.fromkeys(explained))
            key = tuple(sorted(roots)) if roots else (f"problem:{m.id}",)
            g = groups.get(key)
            if g is None:
                # in natural order: a program's line 9 before its line 13; what to repair before the
                # assumptions it fails (the producer, then its victims)
                g = groups[key] = _Row(list(key), m.status, first_sentence(m.sentence),
                                       [pp.culprit(r, self.places, self.anchor)
                                        for r in producer_first(natural_sorted(key)) if r in self.places.info])
            g.members.append(m)
            if pp.severity(m.status) > pp.severity(g.status):
                g.status = m.status
        return groups

    def unverified_rows(self, groups: Mapping[tuple[str, ...], _Row]) -> None:
        """A node's unverified guarantees: each one a culprit at its location, one sentence for them all."""
        for key, g in groups.items():
            if not key[0].startswith("unverified:"):
                continue
            node = key[0].split(":", 1)[1]
            ids = [m.id for m in g.members]
            g.culprits = [pp.culprit(f"guarantee:{u.node}:{u.guarantee}", self.places, self.anchor)
                          for u in (self.unverified.get(i) for i in ids) if u is not None
                          and f"guarantee:{u.node}:{u.guarantee}" in self.places.info]
            first = self.unverified.get(ids[0])
            if len(ids) > 1 and first is not None:
                g.sentence = first_sentence(f"{len(ids)} guarantees of {node} are unverified "
                                            f"({', '.join(ids)}): {first.reason.replace('covers it', 'covers them')}.")

    def deadline_rows(self, groups: Mapping[tuple[str, ...], _Row]) -> None:
        """A deadline's row: the hops of its chain, each with its bound (rule 5)."""
        for key, g in groups.items():
            if not key[0].startswith(DEADLINE_PREFIX):
                continue
            d = next((self.by_id[m.id] for m in g.members
                      if m.id in self.by_id and self.by_id[m.id].kind == "deadline"), None)
            g.culprits = []
            for c in (d.culprits if d is not None else ()):
                rid = self.places.locate(c.source)
                if rid is not None and rid in self.places.info:
                    g.culprits.append({**pp.culprit(rid, self.places, self.anchor), "what": c.what})

    def model_checking_rows(self, groups: Mapping[tuple[str, ...], _Row]) -> None:
        """Model-checking rows: the Gwendolen lines the counterexamples pass through."""
        for key, g in groups.items():
            if key[0].startswith(mc.FAILED_PREFIX):
                lines = [self.places.locate(src) for m in g.members for src in mc.trail_sources(self.by_id.get(m.id))]
                g.culprits = [pp.culprit(r, self.places, self.anchor) for r in dict.fromkeys(lines) if r is not None]

    def line_owners(self, groups: Mapping[tuple[str, ...], _Row]) -> None:
        """A program line (a handler, an assignment) is the code of its findings' node, when they have one."""
        for g in groups.values():
            owners = {self.by_id[m.id].node or "" if m.id in self.by_id else "" for m in g.members}
            if len(owners) == 1 and "" not in owners:
                for c in g.culprits:
                    if str(c["id"]).startswith("line:"):
                        c["node"] = next(iter(owners))

    def _counterexample(self, ident: str) -> list[CexTableRow]:
        """The counterexample rows of the diagnosis ``ident`` (``[]`` without one)."""
        d = self.by_id.get(ident)
        return d.counterexample if d is not None else []

    def sentence_and_repairs(self, g: _Row) -> None:
        """The row's sentence, from the diagnosis that says most about the cause (TELLING), the
        shortest; its distinct repairs; the summary sentence of an outstanding or model-checking row."""
        worst = [m for m in g.members if pp.severity(m.status) == pp.severity(g.status)]
        told = [m for m in worst if m.diagnosis] or worst
        best = min(told, key=lambda m: (pp.TELLING.get(m.kind, pp.LEAST_TELLING), len(first_sentence(m.sentence))))
        g.sentence = first_sentence(best.sentence)
        diffs: set[object] = set()
        for m in g.members:
            dg = self.by_id.get(m.id)
            for k, rep in enumerate(dg.repairs if dg is not None and m.diagnosis else []):
                if rep.diff not in diffs:
                    diffs.add(rep.diff)
                    g.repairs.append({"diagnosis": m.id, "index": k})
        if g.key[0].startswith(OUTSTANDING_WHOLE) and len(g.members) > 1:
            _, backend, node = g.key[0].split(":", 2)
            g.sentence = first_sentence(f"{len(g.members)} {backend} obligations on the contract of {node} are "
                                        f"{g.status} (evidence outstanding): {g.sentence}",
                                        SENTENCE_CHARS // 2)  # a summary: each finding holds its whole text
        if g.key[0].startswith((mc.FAILED_PREFIX, mc.OUTSTANDING_PREFIX)):
            cex = next((r.value for m in g.members for r in self._counterexample(m.id) if r.variable == "lasso"), "")
            g.sentence = first_sentence(mc.row_sentence(g.key[0], g.members, first_sentence(g.members[0].sentence), cex))


__all__ = ["BAD_VERDICTS", "DEADLINE_PREFIX", "OUTSTANDING_WHOLE", "SENTENCE_CHARS", "first_sentence", "group_problems"]
