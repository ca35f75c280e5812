"""Where the problems of the report are, and the words of a problem row: the shared parts of
report/problems.py (grouping the report's problems by root cause).

:class:`Places` locates a ``file:line:col`` in the contract member
(guarantee, assumption, contract header) that starts there or before it;
:func:`roots` gives a problem's root culprits from its diagnosis's culprits
(rules 1 and 2 of report/problems.py); :func:`culprit` lays a root out as
a row's culprit; :func:`first_sentence` cuts a row's sentence.  A problem
found on the way is a :class:`Member` (a
:class:`~rclverify.records.problem_rows.ProblemMember` while its row is
being made); the report is read decoded
(:class:`~rclverify.records.report_record.AssuranceReport`).
"""
from __future__ import annotations

import bisect
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from rclverify.records.node_rows import NodeRow
from rclverify.records.problem_rows import DiagnosisRow
from rclverify.records.report_record import AssuranceReport
from rclverify.records.requirement_rows import RequirementRow
from rclverify.report.diagnosis_text import whole_first_sentence
from rclverify.records.records import SEVERITY

#: Key prefix of a group of outstanding evidence on a node's whole contract from one backend (rule 5).
OUTSTANDING_WHOLE = "outstanding-contract:"

_SOURCE = re.compile(r"^(.*?):(\d+)(?::(\d+))?$")
#: Diagnosis kinds whose victim guarantee is a defect of the contract itself.
CONTRACT_DEFECTS = ("vacuity", "inconsistency")
#: Diagnosis kinds whose sentence names the cause rather than the symptom, most telling first: a
#: contract defect names the guarantees that exclude each other, a side condition producer and
#: consumer, a Hoare refutation the constants; a test or a monitor names only the guarantee broken.
TELLING = {"unit": 0, "vacuity": 0, "inconsistency": 0, "unsatisfiable-assumption": 0, "side-condition": 1, "hoare": 1,
            "deadline": 1, "refinement": 2, "monitor": 3}
#: Rank of every other kind (a property test, other evidence, a requirement, an attention item).
LEAST_TELLING = 4
#: Requirement verdicts that are problems (report/build.py lists them too).
BAD_VERDICTS = ("refuted", "proved from an inconsistency", "proved vacuously")
#: Status words of diagnosis records and health findings as evidence statuses.
AS_EVIDENCE = {"problem": "failed", "refuted": "failed", "unknown": "inconclusive", "warning": "pending"}


#: Group key prefix of an end-to-end deadline's row (rule 5).
DEADLINE_PREFIX = "deadline:"


@dataclass
class Member:
    """A problem of the report as a member of its row (the fields of
    :class:`~rclverify.records.problem_rows.ProblemMember`): the grouping
    marks it a consequence of other members (``consequence_of``) on the way."""
    id: str
    kind: str
    status: str
    sentence: str
    anchor: str
    diagnosis: bool
    consequence_of: list[str] | None = None

    def to_json(self) -> dict[str, Any]:
        """The member as its JSON object (``consequence_of`` only on a consequence)."""
        out: dict[str, Any] = {"id": self.id, "kind": self.kind, "status": self.status, "sentence": self.sentence,
                               "anchor": self.anchor, "diagnosis": self.diagnosis}
        if self.consequence_of is not None:
            out["consequence_of"] = self.consequence_of
        return out


#: A member and its root culprit ids, as the grouping collects them.
Rooted = tuple[Member, list[str]]


@dataclass
class Place:
    """What a root culprit is (``what``), where (``source``, ``file:line:col``) and its anchor's parts
    (``None``: no anchor in the report)."""
    what: str
    source: str
    anchor: tuple[Any, ...] | None


def by_deadline(q: RequirementRow) -> bool:
    """Is requirement row ``q`` not met only because of its end-to-end
    deadline (refuted or undecided), its own statement not refuted?"""
    own = q.without_deadline.verdict if q.without_deadline is not None else None
    return q.deadline is not None and q.deadline.verdict in ("refuted", "inconclusive") and own not in BAD_VERDICTS


def severity(status: str) -> int:
    return SEVERITY.get(AS_EVIDENCE.get(status, status), SEVERITY["error"])


class Places:
    """Source locations of the contract members of ``nodes`` (the report's, decoded)."""

    def __init__(self, nodes: Sequence[NodeRow]) -> None:
        self.by_file: dict[str, list[tuple[int, str, Place]]] = {}
        for n in nodes:
            self._add(n.source, f"contract:{n.name}", Place(f"the contract of {n.name}", n.source, ("node", n.name)))
            for k, a in enumerate(n.assumptions, 1):
                self._add(a.source, f"assumption:{n.name}:{k}",
                          Place(f"assumption {k} of {n.name}", a.source, ("node", n.name)))
            for g in n.guarantees:
                self._add(g.source, f"guarantee:{n.name}:{g.index}",
                          Place(f"guarantee {g.index} of {n.name}", g.source, ("g", n.name, g.index)))
        for rows in self.by_file.values():
            rows.sort(key=lambda r: r[0])
        self.info: dict[str, Place] = {rid: info for rows in self.by_file.values() for _, rid, info in rows}

    def _add(self, source: str, rid: str, info: Place) -> None:
        m = _SOURCE.match(str(source))
        if m:
            self.by_file.setdefault(m.group(1), []).append((int(m.group(2)), rid, info))

    def locate(self, source: str) -> str | None:
        """The id of the contract member at ``source`` (``file:line[:col]``),
        ``line:file:line`` for a line of another file, ``None`` for no location."""
        m = _SOURCE.match(str(source))
        if not m:
            return None
        file, line = m.group(1), int(m.group(2))
        rows = self.by_file.get(file)
        if rows is None:
            rid = f"line:{file}:{line}"
            self.info.setdefault(rid, Place("", f"{file}:{line}", None))
            return rid
        i = bisect.bisect_right([r[0] for r in rows], line) - 1
        return rows[i][1] if i >= 0 else None


def join_requirements_to_side_conditions(members: list[Rooted]) -> None:
    """A refuted requirement whose culprits are all culprits of one failed
    side condition has that side condition's root cause: both rows read one
    problem, with one first repair (a service answering up to 64
    waypoints to a client whose buffer holds ``RouteBuffer = 50`` gave a
    side-condition row and a requirement row with two different first
    repairs).  Changes ``members`` (``(member, roots)``) in place."""
    sides = [set(r) for m, r in members if m.kind == "side-condition" and r]
    for i, (m, roots) in enumerate(members):
        if m.kind != "requirement" or not roots:
            continue
        home = next((s for s in sides if set(roots) <= s), None)
        if home is not None:
            members[i] = (m, sorted(home))


def roots(culprits: Sequence[tuple[str, str]], places: Places, victim: str | None) -> list[str]:
    """Root culprit ids of one problem (rules 1 and 2 of the module docstring); ``culprits``: each
    ``(what, source)``, a culprit in words and its ``file:line:col``."""
    roots: list[str] = []
    context: list[str] = []
    for what, source in culprits:
        rid = places.locate(source)
        if rid is None:
            continue
        if what.startswith(("environment fact", "event ")):
            known = places.info.get(rid)
            places.info[rid] = Place(what.split(" `")[0], known.source if known is not None else "", None)
            context.append(rid)
        elif rid not in roots:
            roots.append(rid)
    if victim is not None and len([r for r in roots if r != victim]) > 0:
        roots = [r for r in roots if r != victim]
    return roots or context


#: Longest sentence a group's row shows (characters); the whole text is in its findings.
SENTENCE_CHARS = 400


def first_sentence(text: str, limit: int = SENTENCE_CHARS) -> str:
    """The first sentence of ``text``
    (:func:`rclverify.report.diagnosis_text.whole_first_sentence`), cut at a word
    boundary to ``limit`` characters with ``...`` when longer."""
    s = whole_first_sentence(text)
    if len(s) > limit:
        s = s[:limit].rsplit(" ", 1)[0] + " ..."
    return s


def cone_side_conditions(report: AssuranceReport, node: str) -> list[str]:
    """The ids of the side conditions not discharged in the cone of ``node``:
    of the node and every node upstream of it along the system's
    connections (the cone a derived property rests on, paper section 4)."""
    upstream: dict[str, set[str]] = {}
    for c in report.system.connections:
        upstream.setdefault(str(c["to_node"]), set()).add(str(c["from_node"]))
    cone, todo = {node}, [node]
    while todo:
        for u in upstream.get(todo.pop(), ()):
            if u not in cone:
                cone.add(u)
                todo.append(u)
    return [sc.id for sc in report.side_conditions if sc.node in cone and sc.status != "discharged"]


def sources(report: AssuranceReport) -> dict[str, str]:
    """``{problem id: file:line:col}`` of the report's items: a side
    condition's conjunct, an obligation's clause, a health finding's
    guarantee (else its node), a requirement's statement, a derived
    property's node (``Node.derived``), a lint error's location."""
    out: dict[str, str] = {}
    node_src = {n.name: n.source for n in report.nodes}
    g_src: dict[tuple[str, int | None], str] = {(n.name, g.index): g.source for n in report.nodes for g in n.guarantees}
    for sc in report.side_conditions:
        out[sc.id] = sc.source
    for o in report.obligations:
        out[o.id] = o.source
    for f in report.findings:
        out[f.id] = g_src.get((f.node, f.guarantee), node_src.get(f.node, ""))
    for q in report.requirements:
        out[q.id] = str(q.check.get("source") or "")
    for d in report.derived_properties:
        out[f"{d.node}.derived"] = node_src.get(d.node, "")
    for x in report.lint:
        out[x.location] = x.location
    for u in report.unverified:
        out[u.id] = u.source
    return out


def default_anchor(d: DiagnosisRow, anchor: Callable[..., str]) -> str:
    if d.kind in ("side-condition",):
        return anchor("sc", d.id)
    if d.kind in ("vacuity", "inconsistency", "unsatisfiable-assumption", "refinement"):
        return anchor("finding", d.id)
    if d.kind == "requirement":  # a refuted requirement's diagnosis: its row in the requirements table
        return anchor("req", d.id)
    if d.kind == "deadline":  # its row in the deadlines table
        return anchor("deadline", d.requirement or "")
    return anchor("ev", d.id)


def culprit(rid: str, places: Places, anchor: Callable[..., str]) -> dict[str, Any]:
    """The root ``rid`` as a row's culprit (:class:`~rclverify.records.problem_rows.ProblemRow`
    ``culprits``): ``{"id", "what", "source", "file", "anchor"}``."""
    info = places.info[rid]
    m = _SOURCE.match(info.source)
    return {"id": rid, "what": info.what, "source": info.source, "file": m.group(1) if m else "",
            "anchor": anchor(*info.anchor) if info.anchor else ""}
