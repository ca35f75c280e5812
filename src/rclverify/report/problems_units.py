"""A unit mismatch's row of the problem list: the findings it explains join it.

A diagnosis record of kind ``unit`` (:mod:`rclverify.diagnosis.units`)
names in ``joins`` the findings that follow from one unit mismatch on a
connection: its lint error and the ``W-unit-missing`` warning (by their
``file:line:col``), the reader's side condition, the probable scale
mismatch on it, the recorded runs whose assumption violations are blamed
on the producer.  :func:`rclverify.report.problems.group_problems` keys each
of them, and the record itself, by the record's root culprits (the
producer's equation or declaration), so they are one row blaming the
producer; a joined finding that is no problem of its own (a lint warning, a
health warning, a run whose evidence holds) is listed in that row too.
"""
from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

from rclverify.records.report_schema import Report

#: The kind of a unit mismatch's diagnosis record.
KIND = "unit"


def joins(diagnoses: Sequence[Mapping[str, Any]]) -> dict[str, str]:
    """``{finding id: unit record id}`` of every unit record's ``joins``
    (the first record that names a finding keeps it)."""
    out: dict[str, str] = {}
    for d in diagnoses:
        if d.get("kind") == KIND:
            for j in d.get("joins") or ():
                out.setdefault(str(j), str(d["id"]))
    return out


def extra_members(report: Report, diagnoses: Sequence[Mapping[str, Any]], covered: set[str],
                  anchor: Callable[..., str]) -> list[tuple[dict[str, Any], str]]:
    """The joined findings not yet among the row's members, each
    ``(member, unit record id)``: a lint row (by location), a health
    finding, an evidence record; members as ``group_problems`` makes them
    (``id``, ``kind``, ``status``, ``sentence``, ``anchor``, ``diagnosis``)."""
    lint = {str(x["location"]): (k, x) for k, x in enumerate(report.get("lint") or ())}
    findings = {str(f["id"]): f for f in report.get("findings") or ()}
    evidence = {str(e["obligation"]): e for e in report.get("evidence") or ()}
    out: list[tuple[dict[str, Any], str]] = []
    for d in diagnoses:
        if d.get("kind") != KIND:
            continue
        for j in d.get("joins") or ():
            j = str(j)
            if j in covered:
                continue
            covered.add(j)
            if j in lint:
                k, x = lint[j]
                m = {"id": j, "kind": "lint", "status": str(x["severity"]).lower(),
                     "sentence": f"{x.get('code', '')}: {x['message']}", "anchor": anchor("lint", k + 1)}
            elif j in findings:
                f = findings[j]
                m = {"id": j, "kind": f"contract health: {f['check']}", "status": str(f["status"]),
                     "sentence": str(f["message"]), "anchor": anchor("finding", j)}
            elif j in evidence:
                e = evidence[j]
                first = (e.get("monitoring") or {}).get("first_assumption_violation") or {}
                m = {"id": j, "kind": "evidence", "status": str(e["status"]),
                     "sentence": (f"{j}: the assumption `{first.get('assumption', '')}` is violated at "
                                  f"{first.get('where', '?')} (t = {first.get('time', '?')} s), blamed on the "
                                  f"{first.get('blame', '?')}."),
                     "anchor": anchor("ev", j)}
            else:
                continue
            out.append(({**m, "diagnosis": False}, str(d["id"])))
    return out
