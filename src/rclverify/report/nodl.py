"""The NoDL documents in the report (docs/nodl.md, "In the report").

The ``nodl`` stage (:mod:`rclverify.stages.nodl`) checks a workspace's NoDL
documents against its contracts and each other; here its sealed record
becomes the report's ``nodl`` (``null`` when the workspace has no document),
its problems, the ``--strict`` clause and the SARIF results.  NoDL findings
keep the rule of the ROS grounding (docs/ros.md; report/severity.py): they
change no proof's verdict; an error, a stale record or an altered one fails
``--strict``; a warning (an endpoint the contract does not constrain, a part
no document includes) is shown and does not.

Each finding is located at every place it involves (the contract's entry and
the document's, or the two documents of a topic's writer and reader): in
SARIF the first is the result's location and the others its related
locations, so a code-scanning view marks both files' lines.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import Callable

from rclverify.records.nodl_rows import NodlPlaceRow, NodlRow
from rclverify.records.report_record import AssuranceReport
from rclverify.records.sarif import SarifLocation, SarifResult
from rclverify.report.shapes import GroundingBrief
from rclverify.stages.workspace import Workspace
from rclverify.report.junit_suite import FindingSuite

#: SARIF rule of every NoDL finding: ``(id, name, level, text)`` (report/sarif.py ``Rule``).
SARIF_RULES = (
    ("RCL-NODL", "NodlFinding", "error",
     "A NoDL document disagrees with its node's contract or with a connected node's document: a missing, extra "
     "or differently typed endpoint, incompatible QoS, a parameter outside its declared constraints "
     "(docs/nodl.md; the finding's code names which)."),
)


def nodl_row(ws: Workspace) -> NodlRow | None:
    """The report's ``nodl``: the stage's record as :func:`rclverify.stages.nodl.read_nodl` reads
    it (stale or altered said) decoded into :class:`~rclverify.records.nodl_rows.NodlRow`; ``None`` when the workspace has no NoDL document.  Raises
    :class:`msgspec.ValidationError` for a record of another shape (a bug: the stage seals what it
    writes)."""
    from rclverify.stages.nodl import read_nodl  # deferred: start-up (loads jsonschema and yaml only when called)
    record = read_nodl(ws)
    return None if record is None else NodlRow.of(record)


def nodl_inputs(ws: Workspace, row: NodlRow | None) -> dict[str, object] | None:
    """What ``meta.inputs_sha256`` takes of the NoDL check (:func:`rclverify.report.records.inputs_sha256`):
    the sha256 the record was made from (``made_from``) and those of the same files and the current
    documents now (``now``), so a report built before a document changed is not the one built after;
    ``None`` for a workspace without a document."""
    if row is None:
        return None
    from rclverify.records.records import hash_inputs  # deferred: start-up (loads rclverify.records only when called)
    from rclverify.stages.nodl import documents  # deferred: start-up (loads jsonschema and yaml only when called)
    made = dict(row.inputs)
    return {"made_from": made, "now": hash_inputs(ws.root, sorted(set(made) | set(documents(ws.root))))}


def _at(place: NodlPlaceRow) -> str:
    return f"{place.file}:{place.line}:{place.col}"


def nodl_problems(row: NodlRow | None) -> list[str]:
    """The report's problem sentences of ``row``: a stale or altered record, each NoDL error."""
    if row is None:
        return []
    out = [f"NoDL check is stale: {row.stale}"] if row.stale else []
    for f in row.findings:
        if f.severity == "error":
            at = f" at {', '.join(_at(p) for p in f.places)}" if f.places else ""
            out.append(f"NoDL {f.code}{at}: {f.message}")
    return out


def blocks_strict(row: NodlRow | None) -> bool:
    """Whether ``row`` fails ``--strict``: a NoDL error, or a record stale or altered."""
    return row is not None and bool(row.counts.get("error") or row.stale)


def strict_reason(row: NodlRow | None) -> list[str]:
    """The clause ``verify --strict`` names for the NoDL check ``row`` (the report's ``nodl``, decoded;
    ``[]`` when it passes)."""
    if row is None:
        return []
    n = int(row.counts.get("error", 0))
    out = [f"{n} NoDL error{'s' if n != 1 else ''} (`rclverify nodl check`)"] if n else []
    return out + (["the NoDL check is stale"] if row.stale else [])


def terminal_brief(row: NodlRow | None) -> GroundingBrief | None:
    """The NoDL check ``row`` (the report's ``nodl``, decoded) as the summary ``verify`` prints shows
    it, in the shape of the ROS grounding's (report/summary.py): ``{"error": n, "warning": m,
    "errors": ["file:line:col: message [code] (also at file:line:col, ...)", ...]}``, a stale record
    one more line; ``None`` for a workspace without a document."""
    if row is None:
        return None
    errors: list[str] = []
    for f in row.findings:
        if f.severity == "error":
            places = [_at(p) for p in f.places]
            also = f" (also at {', '.join(places[1:])})" if len(places) > 1 else ""
            errors.append(f"{places[0] + ': ' if places else ''}{f.message} [{f.code}]{also}")
    if row.stale:
        errors.append(f"the NoDL check is stale: {row.stale}")
    return {"error": int(row.counts.get("error", 0)), "warning": int(row.counts.get("warning", 0)),
            "errors": errors}


def junit_suite(report: AssuranceReport, case: Callable[..., ET.Element],
                outcome: Callable[..., str]) -> tuple[ET.Element, dict[str, int], float] | None:
    """The ``nodl`` ``<testsuite>`` (docs/nodl.md, "In doit verify's report"): one failing
    ``<testcase>`` per NoDL error (``classname`` ``nodl``, name its code and first place, at that
    place, the other places in the failure's text; the record not believed, ``nodl-record``, an
    ``<error>``), one failing ``stale`` case for a record made from other files; a check with
    neither is one passing case, its warnings (which do not fail ``--strict``) in its
    ``<system-out>``.  ``case`` and ``outcome`` are report/junit.py's.  ``None`` for a workspace
    without a document."""
    row = report.nodl
    if row is None:
        return None
    found = FindingSuite("nodl", outcome, "nodl")
    suite, add = found.suite, found.add
    for f in row.findings:
        if f.severity != "error":
            continue
        places = [_at(p) for p in f.places]
        first = places[0] if places else ""
        add(case(suite, "nodl", f"{f.code} {first}".strip(), first, 0.0),
            "error" if f.code == "nodl-record" else "failed", f"{f.message} [{f.code}]",
            "\n".join(f"{p}: error: {f.message}" for p in places))
    if row.stale:
        add(case(suite, "nodl", "nodl-stale", "", 0.0), "stale", f"the NoDL check is stale: {row.stale}",
            "`doit verify` checks the current documents")
    if not found.counts["tests"]:
        n = len(row.documents)
        c = case(suite, "nodl", f"nodl check of {n} document{'s' if n != 1 else ''}", "", 0.0)
        add(c, "ok", "", "")
        warned = [f"{_at(f.places[0]) + ': ' if f.places else ''}warning: {f.message} [{f.code}]"
                  for f in row.findings if f.severity == "warning"]
        if warned:
            ET.SubElement(c, "system-out").text = "\n".join(warned)
    return found.closed()


def sarif_results(report: AssuranceReport, result: Callable[..., SarifResult],
                  location: Callable[[str], list[SarifLocation]]) -> list[SarifResult]:
    """One SARIF result per NoDL finding, at its first place, the others as related locations;
    ``result(rule, level, text, where, key, props)`` and ``location(where)`` are report/sarif.py's."""
    row = report.nodl
    if row is None:
        return []
    out = []
    for k, f in enumerate(row.findings):
        places = [_at(p) for p in f.places]
        res = result("RCL-NODL", "error" if f.severity == "error" else "warning", f"{f.message} [{f.code}]",
                     places[0] if places else "", f"nodl:{f.code}:{':'.join(places)}:{k}", {"code": f.code})
        related = [loc for p in places[1:] for loc in location(p)]
        for i, loc in enumerate(related):
            loc["id"] = i
            loc["message"] = {"text": "the other place of this finding"}
        if related:
            res["relatedLocations"] = related
        out.append(res)
    return out


__all__ = ["SARIF_RULES", "blocks_strict", "junit_suite", "nodl_inputs", "nodl_problems", "nodl_row", "sarif_results",
           "strict_reason", "terminal_brief"]
