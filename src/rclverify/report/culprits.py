"""Which nodes the problems blame (issue 48: the first screen names the culprit, not its victims).

A problem by root cause (:mod:`.problems`) names its culprits by id: ``guarantee:Node:k``,
``contract:Node``, ``assumption:Node:k``, a program line.  The nodes whose guarantee or contract is a
culprit are where the repair goes; the dashboard of the HTML report and the terminal table mark them.
"""
from __future__ import annotations

from typing import Any, Iterable, Mapping

from rclverify.records.records import SEVERITY, worst


def culprit_nodes(groups: Iterable[Any]) -> set[str]:
    """The nodes a problem's culprit (``groups``: the problems by root cause)
    is a guarantee, the contract or a line of the code of (``guarantee:Node:k``,
    ``contract:Node``, a ``line:`` with its ``node``; issue 48: the dashboard marks them, so that the first
    screen blames the culprit, not its victims)."""
    out = set()
    for g in groups:
        if not isinstance(g, Mapping):
            continue  # a summary's problems are sentences, not groups
        for c in g.get("culprits") or ():
            if not isinstance(c, Mapping):
                continue
            kind, _, rest = str(c.get("id", "")).partition(":")
            if kind in ("guarantee", "contract") and rest:
                out.add(rest.split(":", 1)[0])
            elif kind == "line" and c.get("node"):  # a line of the node's code (problems.py)
                out.add(str(c["node"]))
    return out


#: Status words of the problem rows that are not evidence statuses, as evidence statuses (report/problems.py).
_AS_EVIDENCE = {"problem": "failed", "refuted": "failed", "unknown": "inconclusive", "warning": "pending"}


def _status(word: Any) -> str | None:
    s = _AS_EVIDENCE.get(str(word), str(word))
    return s if s in SEVERITY else None


def mark_culprits(report: dict[str, Any]) -> None:
    """Give every node and guarantee a problem blames the status of that
    problem (issue 64: a culprit never reads "discharged"; its own evidence
    may all hold, the problem it causes does not).  For each row of
    ``report["problems"]`` (:func:`rclverify.report.problems.group_problems`)
    and each culprit ``guarantee:Node:k`` or ``contract:Node`` of it (or a
    program line with its ``node``), the
    node's ``status`` (and the guarantee's) becomes the worse of its own and
    the row's, and ``culprit_of`` lists ``{"status", "sentence"}`` of the rows
    that name it.  Changes ``report`` in place; a row without culprits, or
    naming a node the report does not have, changes nothing."""
    nodes = {str(n["name"]): n for n in report.get("nodes") or ()}
    for g in report.get("problems") or ():
        st = _status(g.get("status"))
        if st is None or st == "discharged" or str((g.get("key") or [""])[0]).startswith("unverified:"):
            continue  # an unverified guarantee's row: the guarantee reads "unverified" already
        for c in g.get("culprits") or ():
            kind, _, rest = str(c.get("id", "")).partition(":")
            name, _, k = rest.partition(":")
            if kind == "line":  # a line of a node's code: the node, no guarantee (problems.py)
                kind, name = "contract", str(c.get("node") or "")
            n = nodes.get(name)
            if kind not in ("guarantee", "contract") or n is None:
                continue
            targets = [n] + [x for x in n.get("guarantees") or () if kind == "guarantee" and str(x.get("index")) == k]
            for t in targets:
                t["status"] = worst([str(t.get("status") or "discharged"), st])
                seen = t.setdefault("culprit_of", [])
                row = {"status": st, "sentence": str(g.get("sentence", ""))}
                if row not in seen:
                    seen.append(row)


__all__ = ["culprit_nodes", "mark_culprits"]
