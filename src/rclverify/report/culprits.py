"""Which nodes the problems blame (the first screen names the culprit, not its victims).

A problem by root cause (:mod:`.problems`) names its culprits by id: ``guarantee:Node:k``,
``contract:Node``, ``assumption:Node:k``, a program line.  The nodes whose guarantee or contract is a
culprit are where the repair goes; the dashboard of the HTML report and the terminal table mark them.
"""
from __future__ import annotations

from typing import Any, Iterable, Iterator, Mapping, Sequence, cast

from rclverify.records.node_rows import CulpritOf
from rclverify.records.problem_rows import ProblemRow
from rclverify.records.records import SEVERITY, worst
from rclverify.records.statuses import EvidenceStatus


def culprit_nodes(groups: Iterable[Any]) -> set[str]:
    """The nodes a problem's culprit (``groups``: the problems by root cause)
    is a guarantee, the contract or a line of the code of (``guarantee:Node:k``,
    ``contract:Node``, a ``line:`` with its ``node``: the dashboard marks them, so that the first
    screen blames the culprit, not its victims)."""
    out = set()
    for g in groups:
        if isinstance(g, ProblemRow):
            culprits: Iterable[Any] = g.culprits
        elif isinstance(g, Mapping):
            culprits = g.get("culprits") or ()
        else:
            continue  # a summary's problems are sentences, not groups
        for c in culprits:
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


def _status(word: Any) -> EvidenceStatus | None:
    s = _AS_EVIDENCE.get(str(word), str(word))
    return cast(EvidenceStatus, s) if s in SEVERITY else None  # SEVERITY ranks the evidence statuses


def _blamed(problems: Iterable[Mapping[str, Any]]) -> Iterator[tuple[str, str, str, dict[str, Any]]]:
    """``(kind, node, guarantee index or '', {"status", "sentence"})`` for each culprit a problem row blames
    (the last a :class:`~rclverify.records.node_rows.CulpritOf`'s JSON object)."""
    for g in problems:
        st = _status(g.get("status"))
        if st is None or st == "discharged" or str((g.get("key") or [""])[0]).startswith("unverified:"):
            continue  # an unverified guarantee's row: the guarantee reads "unverified" already
        for c in g.get("culprits") or ():
            kind, _, rest = str(c.get("id", "")).partition(":")
            name, _, k = rest.partition(":")
            if kind == "line":  # a line of a node's code: the node, no guarantee (problems.py)
                kind, name = "contract", str(c.get("node") or "")
            if kind in ("guarantee", "contract"):
                yield kind, name, k, CulpritOf(status=st, sentence=str(g.get("sentence", ""))).to_json()


def _marked(row: Mapping[str, Any], blame: Mapping[str, Any]) -> dict[str, Any]:
    """``row`` (a node or guarantee) with the status of the problem ``blame`` and the problem in ``culprit_of``."""
    seen = list(row.get("culprit_of") or [])
    if blame not in seen:
        seen.append(dict(blame))
    return {**row, "status": worst([str(row.get("status") or "discharged"), blame["status"]]), "culprit_of": seen}


def marked_nodes(nodes: Sequence[Mapping[str, Any]], problems: Iterable[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """``nodes`` (the report's node rows) with every node and guarantee a
    problem blames given the status of that problem (a culprit
    never reads "discharged"; its own evidence may all hold, the problem it
    causes does not).  For each row of ``problems``
    (:func:`rclverify.report.problems.group_problems`) and each culprit
    ``guarantee:Node:k`` or ``contract:Node`` of it (or a program line with
    its ``node``), the node's ``status`` (and the guarantee's) becomes the
    worse of its own and the row's, and ``culprit_of`` lists ``{"status",
    "sentence"}`` of the rows that name it.  New rows: ``nodes`` is left as
    it is; a row without culprits, or naming a node not in ``nodes``,
    changes nothing."""
    out = {str(n["name"]): dict(n) for n in nodes}
    for kind, name, k, blame in _blamed(problems):
        n = out.get(name)
        if n is None:
            continue
        out[name] = n = _marked(n, blame)
        if kind == "guarantee":
            n["guarantees"] = [_marked(x, blame) if str(x.get("index")) == k else x for x in n.get("guarantees") or ()]
    return list(out.values())


__all__ = ["culprit_nodes", "marked_nodes"]
