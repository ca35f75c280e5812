"""Where the problems of the report are, and the words of a problem row: the shared parts of
report/problems.py (grouping the report's problems by root cause).

:class:`Places` locates a ``file:line:col`` in the contract member
(guarantee, assumption, contract header) that starts there or before it;
:func:`roots` gives a problem's root culprits from its diagnosis's culprits
(rules 1 and 2 of report/problems.py); :func:`culprit` lays a root out as
a row's culprit; :func:`first_sentence` cuts a row's sentence.
"""
from __future__ import annotations

import bisect
import re
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from rclverify.records.report_schema import Report
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


def by_deadline(q: Mapping[str, Any]) -> bool:
    """Is requirement row ``q`` not met only because of its end-to-end
    deadline (refuted or undecided), its own statement not refuted?"""
    row = q.get("deadline") or {}
    own = (q.get("without_deadline") or {}).get("verdict")
    return row.get("verdict") in ("refuted", "inconclusive") and own not in BAD_VERDICTS


def severity(status: str) -> int:
    return SEVERITY.get(AS_EVIDENCE.get(status, status), SEVERITY["error"])


class Places:
    """Source locations of the contract members of ``report["nodes"]``."""

    def __init__(self, report: Report) -> None:
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


def join_requirements_to_side_conditions(members: list[tuple[dict[str, Any], list[str]]]) -> None:
    """A refuted requirement whose culprits are all culprits of one failed
    side condition has that side condition's root cause: both rows read one
    problem, with one first repair (a service answering up to 64
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


def roots(culprits: Sequence[Mapping[str, Any]], places: Places, victim: str | None) -> list[str]:
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


def cone_side_conditions(report: Report, node: str) -> list[str]:
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


def sources(report: Report) -> dict[str, str]:
    """``{problem id: file:line:col}`` of the report's items: a side
    condition's conjunct, an obligation's clause, a health finding's
    guarantee (else its node), a requirement's statement, a derived
    property's node (``Node.derived``), a lint error's location."""
    out: dict[str, str] = {}
    node_src = {str(n["name"]): str(n.get("source", "")) for n in report.get("nodes", [])}
    g_src: dict[tuple[str, int | None], str] = {(str(n["name"]), g["index"]): str(g.get("source", ""))
                                                 for n in report.get("nodes", [])
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


def default_anchor(d: Mapping[str, Any], anchor: Callable[..., str]) -> str:
    if d["kind"] in ("side-condition",):
        return anchor("sc", d["id"])
    if d["kind"] in ("vacuity", "inconsistency", "unsatisfiable-assumption", "refinement"):
        return anchor("finding", d["id"])
    if d["kind"] == "requirement":  # a refuted requirement's diagnosis: its row in the requirements table
        return anchor("req", d["id"])
    if d["kind"] == "deadline":  # its row in the deadlines table
        return anchor("deadline", d.get("requirement", ""))
    return anchor("ev", d["id"])


def culprit(rid: str, places: Places, anchor: Callable[..., str]) -> dict[str, Any]:
    info = places.info[rid]
    a = info.get("anchor")
    m = _SOURCE.match(str(info["source"]))
    return {"id": rid, "what": info["what"], "source": info["source"], "file": m.group(1) if m else "",
            "anchor": anchor(*a) if a else ""}
