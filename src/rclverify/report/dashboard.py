"""The report's dashboard: the matrix of nodes (rows) against techniques
(columns), each cell the worst status of the node's items of that technique
(docs/reading-the-report.md), read off the decoded
:class:`~rclverify.records.report_record.AssuranceReport`.  Part of the view
model of :mod:`rclverify.report.view`; nothing here verifies.
"""
from __future__ import annotations

from collections import defaultdict
from typing import Mapping, Sequence

from rclverify.model.plan.declarations import BACKEND_NAMES
from rclverify.records.report_record import AssuranceReport
from rclverify.report.culprits import culprit_nodes
from rclverify.report.shapes import Dashboard, DashboardCell, DashboardRow
from rclverify.report.templating import anchor, rank


#: The techniques of the dashboard's columns, in order: contract health, the
#: calculus' side conditions, then the backends (docs/reading-the-report.md).
#: A backend outside this list gets a column after them when it has evidence.
TECHNIQUES: tuple[str, ...] = ("health", "side conditions", *BACKEND_NAMES)


#: A contract health status as the evidence status the dashboard ranks it by.
#: A warning stays ``warning`` (ranked with pending): it changes no node's
#: status (report/build.py) but it is no pass either; it fails ``--strict``
#: as in every other output (report/severity.py).
_HEALTH_AS: Mapping[str, str] = {"ok": "discharged", "problem": "failed", "unknown": "inconclusive"}


def dashboard(report: AssuranceReport, evidence_of: Mapping[str, Sequence[tuple[str, object]]]) -> Dashboard:
    """The dashboard's matrix of nodes (rows) against techniques (columns).

    Each cell is the WORST status of the node's items of that technique
    (evidence severity: failed > error > stale > inconclusive > pending >
    discharged, :data:`rclverify.records.records.SEVERITY`): for a backend,
    the statuses of the node's obligations of that backend (an obligation's
    status is that of its evidence, pending when it has none); for
    ``no evidence`` (only when there is one), the node's guarantees no
    obligation covers (``unverified``); for
    ``health``, the node's contract health checks (ok counts as
    discharged, a problem as failed, unknown as inconclusive); for ``side
    conditions``, the side conditions the node's assumptions give rise to.
    A cell is ``None`` when the node has no item of that technique, else
    ``{"status", "worst" (how many items have it), "total", "counts"
    ([(status, n)] worst first), "anchor"}``: ``anchor`` is the fragment id
    of the first item with the worst status (its first evidence record,
    else its obligation row; the health finding; the side condition).
    Returns ``{"columns": [technique], "rows": [{"node", "status",
    "cells": [cell], "culprit" (a problem's culprit is its guarantee or
    contract, :func:`culprit_nodes`)}]}``."""
    items: dict[tuple[str, str], list[tuple[str, str]]] = defaultdict(list)
    for o in report.obligations:
        evs = evidence_of.get(o.id, [])
        items[(o.node, o.backend)].append((o.status, evs[0][0] if evs else anchor("ob", o.id)))
    for f in report.findings:
        items[(f.node, "health")].append((_HEALTH_AS.get(f.status, f.status), anchor("finding", f.id)))
    for sc in report.side_conditions:
        items[(sc.node, "side conditions")].append((sc.status, anchor("sc", sc.id)))
    for u in report.unverified:  # no obligation at all: a column of its own, after the techniques
        items[(u.node, "no evidence")].append((u.status, anchor("g", u.node, u.guarantee)))
    culprits = culprit_nodes(report.problems)
    extra = sorted({b for _, b in items} - set(TECHNIQUES) - {"no evidence"})
    extra += ["no evidence"] if any(b == "no evidence" for _, b in items) else []
    columns = [*TECHNIQUES, *extra]
    rows: list[DashboardRow] = []
    for n in report.nodes:
        name = n.name
        cells: list[DashboardCell | None] = []
        for col in columns:
            got = items.get((name, col))
            if not got:
                cells.append(None)
                continue
            worst_rank = max(rank(st) for st, _ in got)
            first = next((st, a) for st, a in got if rank(st) == worst_rank)
            tally: dict[str, int] = defaultdict(int)
            for st, _ in got:
                tally[st] += 1
            counts = sorted(tally.items(), key=lambda kv: (-rank(kv[0]), kv[0]))
            cells.append({"status": first[0], "worst": tally[first[0]], "total": len(got), "counts": counts,
                          "anchor": first[1]})
        rows.append({"node": name, "status": n.status, "cells": cells, "culprit": name in culprits})
    return {"columns": columns, "rows": rows}
