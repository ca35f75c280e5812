"""Guarantees no obligation covers: ``unverified``, each a problem of its own.

A guarantee is established only by evidence of an obligation exported for
it (or for the whole contract, guarantee index 0).  When the plan lists no
evidence entry for its node, or none of the node's entries exports an
obligation for it (a Hoare binding that does not cover the guarantee's
outputs still exports one, which stays ``pending``), nothing will ever
vouch for it: the report says so for every such guarantee instead of
counting only the obligations that exist ("5 obligations: 5 discharged"
while five guarantees had none).  Status order:
:data:`rclverify.records.records.SEVERITY` (pending < unverified <
inconclusive); docs/reading-the-report.md, "Unverified guarantees".
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Literal

from rclverify.records.node_rows import NodeRow, UnverifiedRow

#: The status of a guarantee without any obligation.
UNVERIFIED: Literal["unverified"] = "unverified"


def guarantee_id(node: str, k: int) -> str:
    """The item id of guarantee ``k`` (1-based) of ``node``: ``Node.g<k>``."""
    return f"{node}.g{k}"


def unverified_guarantees(plan: Any, nodes: Sequence[NodeRow]) -> list[UnverifiedRow]:
    """One row per guarantee of ``nodes`` (the report's node rows) that no obligation covers, in report
    order, each an :class:`~rclverify.records.node_rows.UnverifiedRow`::

        {"id": "Node.g<k>", "node", "guarantee": k, "text", "source" (file:line:col),
         "status": "unverified", "reason", "message"}

    ``reason`` says why there is none: the plan lists no evidence for the
    node, or it does but none of its entries (named by backend) exports an
    obligation for this guarantee.  ``message`` is the one-line problem
    (summary ``problems``).  ``plan.evidence`` maps node names to their
    entries (:class:`rclverify.model.plan.model.EvidenceEntry`)."""
    out: list[UnverifiedRow] = []
    for n in nodes:
        name = n.name
        entries = tuple(getattr(plan, "evidence", {}).get(name, ()))
        backends = sorted({str(e.backend) for e in entries})
        for g in n.guarantees:
            if g.obligations:
                continue
            k = g.index
            if not entries:
                reason = f"the plan lists no evidence for {name} (nodes.{name}.evidence), so no obligation covers it"
            else:
                reason = (f"none of the plan's evidence entries for {name} ({', '.join(backends)}) "
                          "exports an obligation for it")
            gid = guarantee_id(name, k)
            out.append(UnverifiedRow(id=gid, node=name, guarantee=k, text=g.text, source=g.source,
                                     status=UNVERIFIED, reason=reason,
                                     message=f"Guarantee {gid} ({g.source}) is unverified: {reason}."))
    return out


def strict_sentence(ids: Sequence[str], limit: int = 10) -> str:
    """The part of the ``--strict`` failure naming the unverified guarantees:
    ``"5 guarantees are unverified (no obligation covers them): A.g1, ..."``,
    at most ``limit`` named; ``""`` for none."""
    if not ids:
        return ""
    named = ", ".join(ids[:limit]) + (f" and {len(ids) - limit} more" if len(ids) > limit else "")
    one = len(ids) == 1
    return (f"{len(ids)} guarantee{'' if one else 's'} {'is' if one else 'are'} unverified "
            f"(no obligation covers {'it' if one else 'them'}): {named}")
