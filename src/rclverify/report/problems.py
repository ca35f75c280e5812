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

import bisect
import re
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from rclverify.records.records import SEVERITY
from rclverify.report import problems_causes as pc
from rclverify.report import problems_mc as mc
from rclverify.report import problems_shared as ps
from rclverify.report.problems_shared import producer_first
from rclverify.report import problems_units as pu
from rclverify.report.textfmt import natural_sorted

#: Key prefix of a group of outstanding evidence on a node's whole contract from one backend (rule 5).
OUTSTANDING_WHOLE = "outstanding-contract:"

_SOURCE = re.compile(r"^(.*?):(\d+)(?::(\d+))?$")
#: Diagnosis kinds whose victim guarantee is a defect of the contract itself.
_CONTRACT_DEFECTS = ("vacuity", "inconsistency")
#: Diagnosis kinds whose sentence names the cause rather than the symptom, most telling first: a
#: contract defect names the guarantees that exclude each other, a side condition producer and
#: consumer, a Hoare refutation the constants; a test or a monitor names only the guarantee broken.
_TELLING = {"unit": 0, "vacuity": 0, "inconsistency": 0, "unsatisfiable-assumption": 0, "side-condition": 1, "hoare": 1,
            "deadline": 1, "refinement": 2, "monitor": 3}
#: Rank of every other kind (a property test, other evidence, a requirement, an attention item).
_LEAST_TELLING = 4
#: Requirement verdicts that are problems (report/build.py lists them too).
BAD_VERDICTS = ("refuted", "proved from an inconsistency", "proved vacuously")
#: Status words of diagnosis records and health findings as evidence statuses.
_AS_EVIDENCE = {"problem": "failed", "refuted": "failed", "unknown": "inconclusive", "warning": "pending"}


#: Group key prefix of an end-to-end deadline's row (rule 5).
DEADLINE_PREFIX = "deadline:"


def _by_deadline(q: Mapping[str, Any]) -> bool:
    """Is requirement row ``q`` not met only because of its end-to-end
    deadline (refuted or undecided), its own statement not refuted?"""
    row = q.get("deadline") or {}
    own = (q.get("without_deadline") or {}).get("verdict")
    return row.get("verdict") in ("refuted", "inconclusive") and own not in BAD_VERDICTS


def _severity(status: str) -> int:
    return SEVERITY.get(_AS_EVIDENCE.get(status, status), SEVERITY["error"])


class _Places:
    """Source locations of the contract members of ``report["nodes"]``."""

    def __init__(self, report: Mapping[str, Any]) -> None:
        self.by_file: dict[str, list[tuple[int, str, dict[str, Any]]]] = {}
        for n in report["nodes"]:
            name = str(n["name"])
            self._add(n.get("source", ""), f"contract:{name}",
                      {"what": f"the contract of {name}", "source": n.get("source", ""), "anchor": ("node", name)})
            for k, a in enumerate(n.get("assumptions", []), 1):
                self._add(a.get("source", ""), f"assumption:{name}:{k}",
                          {"what": f"assumption {k} of {name}", "source": a.get("source", ""),
                           "anchor": ("node", name)})
            for g in n.get("guarantees", []):
                self._add(g.get("source", ""), f"guarantee:{name}:{g['index']}",
                          {"what": f"guarantee {g['index']} of {name}", "source": g.get("source", ""),
                           "anchor": ("g", name, g["index"])})
        for rows in self.by_file.values():
            rows.sort(key=lambda r: r[0])
        self.info: dict[str, dict[str, Any]] = {rid: info for rows in self.by_file.values() for _, rid, info in rows}

    def _add(self, source: str, rid: str, info: dict[str, Any]) -> None:
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
            self.info.setdefault(rid, {"what": "", "source": f"{file}:{line}", "anchor": None})
            return rid
        i = bisect.bisect_right([r[0] for r in rows], line) - 1
        return rows[i][1] if i >= 0 else None


def _join_requirements_to_side_conditions(members: list[tuple[dict[str, Any], list[str]]]) -> None:
    """A refuted requirement whose culprits are all culprits of one failed
    side condition has that side condition's root cause: both rows read one
    problem, with one first repair (issue 48: a service answering up to 64
    waypoints to a client whose buffer holds ``RouteBuffer = 50`` gave a
    side-condition row and a requirement row with two different first
    repairs).  Changes ``members`` (``(member, roots)``) in place."""
    sides = [set(r) for m, r in members if m["kind"] == "side-condition" and r]
    for i, (m, roots) in enumerate(members):
        if m["kind"] != "requirement" or not roots:
            continue
        home = next((s for s in sides if set(roots) <= s), None)
        if home is not None:
            members[i] = (m, sorted(home))


def _roots(culprits: Sequence[Mapping[str, Any]], places: _Places, victim: str | None) -> list[str]:
    """Root culprit ids of one problem (rules 1 and 2 of the module docstring)."""
    roots: list[str] = []
    context: list[str] = []
    for c in culprits:
        what = str(c.get("what", ""))
        rid = places.locate(str(c.get("source", "")))
        if rid is None:
            continue
        if what.startswith(("environment fact", "event ")):
            places.info[rid] = {**places.info.get(rid, {}), "what": what.split(" `")[0], "anchor": None}
            context.append(rid)
        elif rid not in roots:
            roots.append(rid)
    if victim is not None and len([r for r in roots if r != victim]) > 0:
        roots = [r for r in roots if r != victim]
    return roots or context


def group_problems(report: Mapping[str, Any], items: Sequence[Mapping[str, Any]],
                   anchor: Callable[..., str]) -> list[dict[str, Any]]:
    """The problems of ``report`` grouped by root cause (module docstring).

    ``items`` are the report's attention problems (``render.problem_items``:
    dicts with ``status``, ``kind``, ``ref``, ``anchor``, ``message``);
    ``anchor`` builds a fragment id from parts (``render.anchor``).  Returns
    ``[group]``, worst status first and then in the order of the report's
    problems, each::

        {"key": [root culprit ids], "status": worst member status,
         "sentence": the first sentence (first_sentence) of the diagnosis of a member with
                     the worst status: the most telling kind (_TELLING), then the shortest,
         "culprits": [{"id", "what", "source", "file", "anchor" (fragment id or ""),
                       "node" (a program line's: the node of every finding of the row, when one)}],
         "where": file:line:col of the first member that has one (shown when no culprit is named),
         "members": [{"id", "kind", "status", "sentence", "anchor", "diagnosis": bool,
                      "consequence_of": [ids of the members it follows from] (only on a consequence)}],
         "repairs": [{"diagnosis": id, "index": n}]  (distinct diffs, each checked by Z3)}

    Raises ``KeyError`` for a report dict without ``nodes``.
    """
    places = _Places(report)
    diagnoses = list(report.get("diagnoses") or [])
    by_id = {str(d["id"]): d for d in diagnoses}
    item_anchor = {str(it["ref"]): str(it["anchor"]) for it in items}
    members: list[tuple[dict[str, Any], list[str]]] = []

    def victim_of(node: Any, k: Any) -> str | None:
        return f"guarantee:{node}:{k}" if node and k else None

    explains: dict[str, list[str]] = {}
    mc_obl = mc.mc_obligations(report)
    direct: set[str] = set()  # model-checking evidence: grouped only by the culprits it names (problems_mc)
    unit_of, unit_roots = pu.joins(diagnoses), {}  # a unit mismatch's row takes what it explains (problems_units)
    for d in diagnoses:
        roots = _roots(d.get("culprits", []), places, victim_of(d.get("node"), d.get("guarantee")))
        if d["kind"] == pu.KIND:
            unit_roots[str(d["id"])] = roots = roots or [f"problem:{d['id']}"]
            item_anchor.setdefault(str(d["id"]), item_anchor.get(str(d.get("lint")), ""))
        if d["kind"] == pu.KIND or unit_of.get(str(d["id"])) in unit_roots:
            roots = unit_roots[str(d["id"]) if d["kind"] == pu.KIND else unit_of[str(d["id"])]]
            direct.add(str(d["id"]))
        if d["kind"] == "deadline":  # its own row, whatever else its hops' guarantees are found in (rule 5)
            roots = [f"{DEADLINE_PREFIX}{d.get('requirement')}"]
        if str(d["id"]) in mc_obl:
            direct.add(str(d["id"]))
            roots = ([r for r in roots if r != victim_of(d.get("node"), d.get("guarantee"))]
                     or [mc.mc_key(mc_obl[str(d["id"])], str(d["status"]))])
        m: dict[str, Any] = {"id": str(d["id"]), "kind": str(d["kind"]), "status": str(d["status"]), "sentence": str(d["sentence"]),
             "anchor": item_anchor.get(str(d["id"])) or _default_anchor(d, anchor), "diagnosis": True}
        members.append((m, roots))
        victim = victim_of(d.get("node"), d.get("guarantee"))
        if d["kind"] in _CONTRACT_DEFECTS and victim and roots and victim not in roots:
            explains.setdefault(victim, [])
            explains[victim] += [r for r in roots if r not in explains[victim]]
    ps.join_by_first_repair(members, by_id)  # several consumers, one too loose producer: one row (issue 48)
    pc.join_consequences(members, by_id)  # refuted only because of another problem: that problem's row (issue 64)
    pc.join_implementation_findings(members, by_id)  # a test and a run of one guarantee: the handler's row (issue 64)
    diagnosed = {str(d["id"]) for d in diagnoses}
    for q in report.get("requirements", []):
        if q.get("verdict") not in BAD_VERDICTS or str(q["id"]) in diagnosed:
            continue
        check = q.get("check") or {}
        core = [*(check.get("vacuity_core") or []), *(check.get("inconsistent_core") or []),
                *(check.get("failed_to_prevent") or [])]
        roots = _roots([{"what": str(p.get("label", "")), "source": p.get("source", "")} for p in core], places, None)
        if _by_deadline(q):  # not met because of its end-to-end deadline only: the deadline's row (rule 5)
            roots = [f"{DEADLINE_PREFIX}{q['id']}"]
        note = str(q.get("note") or "")
        members.append(({"id": str(q["id"]), "kind": "requirement", "status": str(q["status"]),
                         "sentence": f"Requirement {q['id']} is {q['verdict']}" + (f": {note}" if note else "") + ".",
                         "anchor": anchor("req", q["id"]), "diagnosis": False}, roots))
    _join_requirements_to_side_conditions(members)
    covered = {m["id"] for m, _ in members}
    obligation = {str(o["id"]): o for o in report.get("obligations", [])}
    unverified = {str(u["id"]): u for u in report.get("unverified") or ()}
    roots_of = {m["id"]: roots for m, roots in members}
    for it in items:
        ref = str(it["ref"])
        if ref in covered:
            continue
        if it["kind"] == "guarantee":  # unverified: no obligation covers it (rule 4 of the module docstring)
            u = unverified.get(ref)
            members.append(({"id": ref, "kind": "unverified guarantee", "status": str(it["status"]),
                             "sentence": f"Guarantee {ref} is unverified: {u['reason'] if u else it['message']}.",
                             "anchor": str(it["anchor"]), "diagnosis": False},
                            [f"unverified:{u['node'] if u else ref}"]))
            covered.add(ref)
            continue
        o = obligation.get(ref)
        roots = [f"guarantee:{o['node']}:{o['guarantee']}"] if o is not None and o.get("guarantee") else []
        roots = [r for r in roots if r in places.info]
        if ref in mc_obl:  # model-checking evidence without a diagnosis (inconclusive): outstanding, by guarantee
            direct.add(ref)
            roots = [mc.mc_key(mc_obl[ref], str(it["status"]))]
        elif o is not None and not o.get("guarantee") and str(it["status"]) in ("inconclusive", "pending"):
            roots = [f"{OUTSTANDING_WHOLE}{o.get('backend')}:{o.get('node')}"]  # rule 5
            direct.add(ref)
        if unit_of.get(ref) in unit_roots:  # explained by a unit mismatch: its row (problems_units)
            roots = unit_roots[unit_of[ref]]
            direct.add(ref)
        if it["kind"] == "derived property":
            ref = f"{ref}.derived"  # named fully: the derived property of the node, never the bare node name
            # not derived because a side condition of its cone is not discharged: that side condition's cause
            for sc in _cone_side_conditions(report, str(it["ref"])):
                roots += [r for r in (roots_of.get(sc) or [f"problem:{sc}"]) if r not in roots]
        roots_of[ref] = roots
        members.append(({"id": ref, "kind": str(it["kind"]), "status": str(it["status"]),
                         "sentence": str(it["message"]) + (f" `{it['formula']}`" if it.get("formula") else ""),
                         "anchor": str(it["anchor"]), "diagnosis": False}, roots))
        covered.add(ref)
    pc.assumption_violations(report, members, anchor)  # a run's assumption violation a failed side condition explains
    for m, uid in pu.extra_members(report, diagnoses, covered, anchor):  # a lint warning, a health warning, a run
        if uid in unit_roots:
            direct.add(m["id"])
            members.append((m, unit_roots[uid]))

    groups: dict[tuple[str, ...], dict[str, Any]] = {}
    for m, roots in members:
        # an unverified guarantee stays a row of its own, even when a contract defect explains the guarantee;
        # so does a failed side condition: its culprits are the ones Z3 showed for it (diagnosis/blame.py)
        explained = ([] if m["kind"] in ("unverified guarantee", "side-condition") or m["id"] in direct
                     or any(r.startswith(DEADLINE_PREFIX) for r in roots)
                     else [e for r in roots for e in explains.get(r, [])])
        if explained:
            roots = list(dict.fromkeys(explained))
        key = tuple(sorted(roots)) if roots else (f"problem:{m['id']}",)
        g = groups.get(key)
        if g is None:
            g = groups[key] = {"key": list(key), "status": m["status"], "sentence": first_sentence(m["sentence"]),
                               # in natural order: a program's line 9 before its line 13 (issue 48); what
                               # to repair before the assumptions it fails (the producer, then its victims)
                               "culprits": [_culprit(r, places, anchor) for r in producer_first(natural_sorted(key))
                                            if r in places.info],
                               "members": [], "repairs": []}
        g["members"].append(m)
        if _severity(m["status"]) > _severity(g["status"]):
            g["status"] = m["status"]
    for key, g in groups.items():  # a node's unverified guarantees: each one a culprit at its location
        if key[0].startswith("unverified:"):
            node = key[0].split(":", 1)[1]
            ids = [m["id"] for m in g["members"]]
            g["culprits"] = [_culprit(f"guarantee:{u['node']}:{u['guarantee']}", places, anchor)
                             for u in (unverified.get(i) for i in ids) if u is not None
                             and f"guarantee:{u['node']}:{u['guarantee']}" in places.info]
            first = unverified.get(ids[0])
            if len(ids) > 1 and first is not None:
                g["sentence"] = first_sentence(f"{len(ids)} guarantees of {node} are unverified "
                                               f"({', '.join(ids)}): {first['reason'].replace('covers it', 'covers them')}.")
    for key, g in groups.items():  # a deadline's row: the hops of its chain, each with its bound (rule 5)
        if key[0].startswith(DEADLINE_PREFIX):
            d = next((by_id[m["id"]] for m in g["members"] if m["id"] in by_id and by_id[m["id"]]["kind"] == "deadline"),
                     None)
            g["culprits"] = []
            for c in (d or {}).get("culprits") or ():
                rid = places.locate(str(c.get("source", "")))
                if rid is not None and rid in places.info:
                    g["culprits"].append({**_culprit(rid, places, anchor), "what": str(c["what"])})
    for key, g in groups.items():  # model-checking rows: the Gwendolen lines the counterexamples pass through
        if key[0].startswith(mc.FAILED_PREFIX):
            lines = [places.locate(src) for m in g["members"] for src in mc.trail_sources(by_id.get(m["id"]))]
            g["culprits"] = [_culprit(r, places, anchor) for r in dict.fromkeys(lines) if r is not None]
    for g in groups.values():  # a program line (a handler, an assignment) is the code of its findings' node
        owners = {str((by_id.get(m["id"]) or {}).get("node") or "") for m in g["members"]}
        if len(owners) == 1 and "" not in owners:
            for c in g["culprits"]:
                if str(c["id"]).startswith("line:"):
                    c["node"] = next(iter(owners))
    where = _sources(report)
    for g in groups.values():  # where the problem is, for a row that names no culprit
        g["where"] = next((where[m["id"]] for m in g["members"] if where.get(m["id"])), "")
    for g in groups.values():
        if g["key"][0].startswith("unverified:"):
            continue
        # the row's sentence: from the diagnosis that says most about the cause (_TELLING), the shortest
        worst = [m for m in g["members"] if _severity(m["status"]) == _severity(g["status"])]
        told = [m for m in worst if m["diagnosis"]] or worst
        best = min(told, key=lambda m: (_TELLING.get(m["kind"], _LEAST_TELLING), len(first_sentence(m["sentence"]))))
        g["sentence"] = first_sentence(best["sentence"])
        diffs: set[str] = set()
        for m in g["members"]:
            for k, rep in enumerate((by_id.get(m["id"]) or {}).get("repairs", []) if m["diagnosis"] else []):
                if rep.get("diff") not in diffs:
                    diffs.add(rep.get("diff"))
                    g["repairs"].append({"diagnosis": m["id"], "index": k})
        if g["key"][0].startswith(OUTSTANDING_WHOLE) and len(g["members"]) > 1:
            _, backend, node = g["key"][0].split(":", 2)
            g["sentence"] = first_sentence(f"{len(g['members'])} {backend} obligations on the contract of {node} are "
                                           f"{g['status']} (evidence outstanding): {g['sentence']}",
                                           SENTENCE_CHARS // 2)  # a summary: each finding holds its whole text
        if g["key"][0].startswith((mc.FAILED_PREFIX, mc.OUTSTANDING_PREFIX)):
            cex = next((str(r.get("value", "")) for m in g["members"]
                        for r in (by_id.get(m["id"]) or {}).get("counterexample") or [] if r.get("variable") == "lasso"), "")
            g["sentence"] = first_sentence(mc.row_sentence(g["key"][0], g["members"], first_sentence(g["members"][0]["sentence"]), cex))
    out = list(groups.values())
    out.sort(key=lambda g: -_severity(g["status"]))  # stable: report order within a status
    return out


_SENTENCE_END = re.compile(r"(?<=[.;])\s+(?=[A-Z])")
#: Longest sentence a group's row shows (characters); the whole text is in its findings.
SENTENCE_CHARS = 400


def first_sentence(text: str, limit: int = SENTENCE_CHARS) -> str:
    """The first sentence of ``text`` (up to a ``.`` or ``;`` followed by a
    capital letter), cut at a word boundary to ``limit`` characters with
    ``...`` when longer."""
    s = _SENTENCE_END.split(str(text).strip(), 1)[0]
    if len(s) > limit:
        s = s[:limit].rsplit(" ", 1)[0] + " ..."
    return s


def _cone_side_conditions(report: Mapping[str, Any], node: str) -> list[str]:
    """The ids of the side conditions not discharged in the cone of ``node``:
    of the node and every node upstream of it along the system's
    connections (the cone a derived property rests on, paper section 4)."""
    upstream: dict[str, set[str]] = {}
    for c in report.get("system", {}).get("connections", []):
        upstream.setdefault(str(c["to_node"]), set()).add(str(c["from_node"]))
    cone, todo = {node}, [node]
    while todo:
        for u in upstream.get(todo.pop(), ()):
            if u not in cone:
                cone.add(u)
                todo.append(u)
    return [str(sc["id"]) for sc in report.get("side_conditions", [])
            if str(sc["node"]) in cone and sc["status"] != "discharged"]


def _sources(report: Mapping[str, Any]) -> dict[str, str]:
    """``{problem id: file:line:col}`` of the report's items: a side
    condition's conjunct, an obligation's clause, a health finding's
    guarantee (else its node), a requirement's statement, a derived
    property's node (``Node.derived``), a lint error's location."""
    out: dict[str, str] = {}
    node_src = {str(n["name"]): str(n.get("source", "")) for n in report.get("nodes", [])}
    g_src = {(str(n["name"]), g["index"]): str(g.get("source", "")) for n in report.get("nodes", [])
             for g in n.get("guarantees", [])}
    for sc in report.get("side_conditions", []):
        out[str(sc["id"])] = str(sc.get("source", ""))
    for o in report.get("obligations", []):
        out[str(o["id"])] = str(o.get("source", ""))
    for f in report.get("findings", []):
        out[str(f["id"])] = g_src.get((str(f["node"]), f.get("guarantee")), node_src.get(str(f["node"]), ""))
    for q in report.get("requirements", []):
        out[str(q["id"])] = str((q.get("check") or {}).get("source") or "")
    for d in report.get("derived_properties", []):
        out[f"{d['node']}.derived"] = node_src.get(str(d["node"]), "")
    for x in report.get("lint", []):
        out[str(x["location"])] = str(x["location"])
    for u in report.get("unverified") or ():
        out[str(u["id"])] = str(u["source"])
    return out


def _default_anchor(d: Mapping[str, Any], anchor: Callable[..., str]) -> str:
    if d["kind"] in ("side-condition",):
        return anchor("sc", d["id"])
    if d["kind"] in ("vacuity", "inconsistency", "unsatisfiable-assumption", "refinement"):
        return anchor("finding", d["id"])
    if d["kind"] == "requirement":  # a refuted requirement's diagnosis: its row in the requirements table
        return anchor("req", d["id"])
    if d["kind"] == "deadline":  # its row in the deadlines table
        return anchor("deadline", d.get("requirement", ""))
    return anchor("ev", d["id"])


def _culprit(rid: str, places: _Places, anchor: Callable[..., str]) -> dict[str, Any]:
    info = places.info[rid]
    a = info.get("anchor")
    m = _SOURCE.match(str(info["source"]))
    return {"id": rid, "what": info["what"], "source": info["source"], "file": m.group(1) if m else "",
            "anchor": anchor(*a) if a else ""}
