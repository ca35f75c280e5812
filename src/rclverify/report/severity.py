"""One severity per finding, the same in every output (docs/ci.md, "One
severity per finding").

Every item the report lists has one severity, decided here from its kind
and status and read by every output:

============  ==============================================  =========  ==================  ===========
severity      what                                            SARIF      JUnit               --strict
============  ==============================================  =========  ==================  ===========
``error``     shown not to hold, or its record not believed   error      failure (error for  fails
              (failed, refuted, a health problem, error)                 a status error)
``warning``   not established (inconclusive, stale,           warning    failure, or         fails
              pending, unverified, proved with evidence                  skipped when
              outstanding, a deadline not decided) or a                  undecided or not
              slip in the text (a redundant conjunct, a lint             run yet
              warning)
``note``      nothing can decide it: an informal requirement  note       skipped             passes
============  ==============================================  =========  ==================  ===========

The terminal and the HTML report show the status word of the item (its
severity in the colour of the badge); ``--strict`` fails exactly on the
items of severity ``error`` or ``warning`` (the ``-Werror`` reading of a
strict mode: a warning is not a pass), and names them
(:func:`blocking`).  ROS grounding findings keep the rule of docs/ros.md:
their errors fail ``--strict``, their warnings (software the contracts
need not describe: a graph node without a contract) do not; NoDL findings
likewise (report/nodl.py: an endpoint a document declares and the contract
does not constrain is a warning).

Kinds: ``obligation``, ``guarantee`` (one no obligation covers),
``side-condition``, ``health``, ``requirement`` (by verdict), ``deadline``
(by verdict), ``lint`` (by its severity word), ``acknowledgement`` (a plan
entry answering a warning: ``stale`` is a warning, ``error`` an error),
``near-miss`` (a guarantee held by less than the plan's ``near_miss``
threshold, report/near_misses.py: a warning; the plan asked to be told).

A health or lint warning that a plan acknowledgement answers
(model/plan/acknowledged.py) keeps its severity in every output (SARIF marks it
suppressed, with the reason as justification) but does not fail
``--strict`` (:func:`acknowledged`).
"""
from __future__ import annotations

from typing import Any, Mapping

import msgspec

from rclverify.records.report_record import AssuranceReport
from rclverify.records.statuses import SEVERITIES

#: The three severities (the vocabulary's set, records/statuses.py).
ERROR, WARNING, NOTE = SEVERITIES
#: Severities that fail ``--strict``.
GATING = (ERROR, WARNING)

_HOLDS = {"discharged", "ok", "met", "proved"}
_ERROR_WORDS = {"failed", "error", "problem", "refuted", "proved from an inconsistency", "proved vacuously"}
#: Statuses of something not decided or not run yet (JUnit ``<skipped>``).
UNDECIDED = {"inconclusive", "pending", "unknown", "informal", "proved, evidence outstanding"}


def of(kind: str, status: str) -> str | None:
    """The severity of an item of ``kind`` with ``status`` (for a
    requirement or a deadline: its verdict; for lint: its severity word),
    ``None`` when the item holds (it is no finding).  A word this table does
    not know is an ``error``: the report cannot vouch for what it does not
    understand."""
    s = str(status)
    if s in _HOLDS:
        return None
    if kind == "requirement" and s == "informal":
        return NOTE
    if kind == "lint":
        return ERROR if s.lower() == "error" else WARNING
    if s in _ERROR_WORDS:
        return ERROR
    if s in ("stale", "inconclusive", "pending", "unverified", "unknown", "warning", "proved, evidence outstanding"):
        return WARNING
    return ERROR


def gates(severity: str | None) -> bool:
    """Does an item of ``severity`` fail ``--strict``?"""
    return severity in GATING


def junit_outcome(kind: str, status: str) -> str:
    """``pass`` / ``skipped`` / ``failure`` / ``error``: how JUnit shows an
    item (module table).  ``status`` as for :func:`of`."""
    sev = of(kind, status)
    if sev is None:
        return "pass"
    if str(status) == "error":
        return "error"
    if sev == NOTE or str(status) in UNDECIDED:
        return "skipped"
    return "failure"


def _decoded(report: AssuranceReport | Mapping[str, Any]) -> AssuranceReport:
    """``report``, or its JSON object decoded (report/view.py ``decoded_parts``: a stored report of an
    earlier version reads the parts it lacks as empty)."""
    if isinstance(report, AssuranceReport):
        return report
    from rclverify.report.view import decoded_parts  # deferred: view reads the passes that read this table
    return decoded_parts(report)


def items(report: AssuranceReport | Mapping[str, Any]) -> list[tuple[str, str, str, str]]:
    """Every finding of ``report`` (decoded on entry) as ``(kind, id, status, severity)``, in
    the report's order (obligations, guarantees no obligation covers, side
    conditions, health checks, requirements, deadlines, lint,
    acknowledgements, near misses); items that hold are left out."""
    r = _decoded(report)
    out: list[tuple[str, str, str, str]] = []

    def add(kind: str, ident: str, status: str) -> None:
        sev = of(kind, status)
        if sev is not None:
            out.append((kind, ident, status, sev))
    for o in r.obligations:
        add("obligation", o.id, o.status)
    for u in r.unverified:
        add("guarantee", u.id, "unverified")
    for sc in r.side_conditions:
        add("side-condition", sc.id, sc.status)
    for f in r.findings:
        add("health", f.id, f.status)
    for rq in r.requirements:
        add("requirement", rq.id, rq.verdict)
    for d in r.deadlines:  # proved from a chain whose evidence is outstanding: not a pass
        open_ = d.verdict == "proved" and d.status not in (msgspec.UNSET, "discharged")
        add("deadline", f"{d.requirement}.deadline", "proved, evidence outstanding" if open_ else str(d.verdict))
    for x in r.lint:
        add("lint", f"{x.location}:{x.code}", x.severity)
    for a in r.acknowledgements:  # a stale or refused acknowledgement (model/plan/acknowledged.py)
        add("acknowledgement", f"{a.at}:{a.warning}", a.status)
    for n in r.near_misses:  # held by less than the plan's threshold (report/near_misses.py)
        add("near-miss", f"{n.obligation}:g{n.guarantee}:{n.kind}", "warning")
    return out


def acknowledged(report: AssuranceReport | Mapping[str, Any]) -> set[tuple[str, str]]:
    """The ``(kind, id)`` of :func:`items` that a plan acknowledgement
    answers (a warning accepted as a risk with a reason, docs/plan.md): they
    keep their severity in every output but do not fail ``--strict``."""
    r = _decoded(report)
    out = {("health", f.id) for f in r.findings if f.acknowledged}
    return out | {("lint", f"{x.location}:{x.code}") for x in r.lint if x.acknowledged}


def blocking(report: AssuranceReport | Mapping[str, Any]) -> list[tuple[str, str, str, str]]:
    """The findings that fail ``--strict`` (severity ``error`` or
    ``warning``), as :func:`items` gives them, plus the ROS grounding
    errors (``("grounding", code, "error", "error")``) and a stale grounding, and likewise the NoDL
    errors (``("nodl", code, "error", "error")``) and a stale or altered NoDL record."""
    r = _decoded(report)
    answered = acknowledged(r)
    out = [x for x in items(r) if gates(x[3]) and not (x[3] == WARNING and (x[0], x[1]) in answered)]
    g = r.grounding
    if g is not None:
        for f in g.findings:  # a grounding finding (free-form: ros/check.py)
            if f.get("severity") == "error":
                out.append(("grounding", str(f.get("code", "")), "error", ERROR))
        if g.stale:
            out.append(("grounding", "stale", "stale", WARNING))
    nodl = r.nodl
    if nodl is not None:
        out += [("nodl", f.code, "error", ERROR) for f in nodl.findings if f.severity == "error"]
        if nodl.stale:
            out.append(("nodl", "stale", "stale", WARNING))
    return out
