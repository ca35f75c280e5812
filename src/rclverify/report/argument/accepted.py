"""Accepted risks in the argument: a warning the plan
acknowledges with a reason (model/plan/acknowledged.py) stands beside the claim it
bears on as a GSN *assumption* (``A``), in the context of that claim.

A health warning bears on the goal of its guarantee (``<Node>.g<k>...``) or
of its node; a lint warning on the goal of the node whose contract holds its
location (else on the top goal).  The assumption's text names the warning,
its reason and the plan entry, so a reader of the argument sees what was
accepted and why; it changes no status (an acknowledged warning is no
counter-evidence).
"""
from __future__ import annotations

from dataclasses import replace
from typing import Any

from rclverify.records.findings import FindingRow
from rclverify.records.lint_rows import LintRow
from rclverify.records.report_record import AssuranceReport
from rclverify.report.argument.model import Element


def _target(row: FindingRow | LintRow, report: AssuranceReport, ident: Any) -> str:
    if isinstance(row, FindingRow):
        g = row.guarantee
        return str(ident("G", row.node, f"g{g}") if g else ident("G", row.node))
    file, _, rest = row.location.partition(":")
    line = int(rest.split(":")[0]) if rest.split(":")[0].isdigit() else 0
    best, at = "", 0
    for n in report.nodes:  # the last node of the file that starts at or before the line
        f, _, r = n.source.partition(":")
        start = int(r.split(":")[0]) if r.split(":")[0].isdigit() else 0
        if f == file and at <= start <= line:
            best, at = ident("G", n.name), start
    return best


def add_accepted_risks(els: dict[str, Element], report: AssuranceReport, ident: Any, top: str) -> None:
    """Add one assumption per acknowledged warning of ``report`` to ``els``
    (changed in place), in the context of the goal it bears on (``top``
    when that goal is not shown); ``ident`` makes element ids."""
    rows: list[FindingRow | LintRow] = [*report.findings, *report.lint]
    k = 0
    for row in rows:
        ack = row.acknowledged
        if not ack:
            continue
        k += 1
        target = _target(row, report, ident)
        target = target if target in els else top
        what = row.id if isinstance(row, FindingRow) else f"{row.code} at {row.location}"
        aid = ident("A", "accepted", k)
        els[aid] = Element(aid, "assumption", f"Accepted risk: the warning {what} is acknowledged "
                           f"({ack.reason}; plan {ack.at})", ref=what)
        if target in els:
            els[target] = replace(els[target], in_context_of=(*els[target].in_context_of, aid))
