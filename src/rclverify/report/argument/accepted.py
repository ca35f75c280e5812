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
from typing import Any, Mapping

from rclverify.report.argument.model import Element


def _target(row: Mapping[str, Any], kind: str, report: Mapping[str, Any], ident: Any) -> str:
    if kind == "health":
        g = row.get("guarantee")
        return str(ident("G", row["node"], f"g{g}") if g else ident("G", row["node"]))
    file, _, rest = str(row.get("location", "")).partition(":")
    line = int(rest.split(":")[0]) if rest.split(":")[0].isdigit() else 0
    best, at = "", 0
    for n in report.get("nodes", []):  # the last node of the file that starts at or before the line
        f, _, r = str(n.get("source", "")).partition(":")
        start = int(r.split(":")[0]) if r.split(":")[0].isdigit() else 0
        if f == file and at <= start <= line:
            best, at = ident("G", n["name"]), start
    return best


def add_accepted_risks(els: dict[str, Element], report: Mapping[str, Any], ident: Any, top: str) -> None:
    """Add one assumption per acknowledged warning of ``report`` to ``els``
    (changed in place), in the context of the goal it bears on (``top``
    when that goal is not shown); ``ident`` makes element ids."""
    rows = [("health", f) for f in report.get("findings") or ()] + [("lint", x) for x in report.get("lint") or ()]
    k = 0
    for kind, row in rows:
        ack = row.get("acknowledged")
        if not ack:
            continue
        k += 1
        target = _target(row, kind, report, ident)
        target = target if target in els else top
        what = row["id"] if kind == "health" else f"{row.get('code', '')} at {row.get('location', '')}"
        aid = ident("A", "accepted", k)
        els[aid] = Element(aid, "assumption", f"Accepted risk: the warning {what} is acknowledged "
                           f"({ack['reason']}; plan {ack['at']})", ref=str(what))
        if target in els:
            els[target] = replace(els[target], in_context_of=(*els[target].in_context_of, aid))
