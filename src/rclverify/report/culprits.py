"""Which nodes the problems blame (the first screen names the culprit, not its victims).

A problem by root cause (:mod:`.problems`) names its culprits by id: ``guarantee:Node:k``,
``contract:Node``, ``assumption:Node:k``, a program line.  The nodes whose guarantee or contract is a
culprit are where the repair goes; the dashboard of the HTML report and the terminal table mark them.
"""
from __future__ import annotations

from typing import Any, Iterable, Iterator, Mapping, Sequence, TypeVar, cast

from msgspec.structs import replace

from rclverify.records.node_rows import CulpritOf, GuaranteeRow, NodeRow
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


def _blamed(problems: Iterable[ProblemRow]) -> Iterator[tuple[str, str, str, CulpritOf]]:
    """``(kind, node, guarantee index or '', the problem as a culprit_of entry)`` for each culprit a problem
    row blames."""
    for g in problems:
        st = _status(g.status)
        if st is None or st == "discharged" or (g.key or [""])[0].startswith("unverified:"):
            continue  # an unverified guarantee's row: the guarantee reads "unverified" already
        for c in g.culprits:  # a culprit (free-form: report/problems_causes.py)
            kind, _, rest = str(c.get("id", "")).partition(":")
            name, _, k = rest.partition(":")
            if kind == "line":  # a line of a node's code: the node, no guarantee (problems.py)
                kind, name = "contract", str(c.get("node") or "")
            if kind in ("guarantee", "contract"):
                yield kind, name, k, CulpritOf(status=st, sentence=g.sentence)


R = TypeVar("R", NodeRow, GuaranteeRow)


def _marked(row: R, blame: CulpritOf) -> R:
    """``row`` (a node or guarantee) with the status of the problem ``blame`` and the problem in ``culprit_of``."""
    seen = list(row.culprit_of or [])
    if blame not in seen:
        seen.append(blame)
    return replace(row, status=worst([row.status, blame.status]), culprit_of=seen)


def marked_nodes(nodes: Sequence[NodeRow], problems: Iterable[ProblemRow]) -> list[NodeRow]:
    """``nodes`` (the report's node rows) with every node and guarantee a
    problem blames given the status of that problem (a culprit
    never reads "discharged"; its own evidence may all hold, the problem it
    causes does not).  For each row of ``problems``
    (:func:`rclverify.report.problems.group_problems`) and each culprit
    ``guarantee:Node:k`` or ``contract:Node`` of it (or a program line with
    its ``node``), the node's ``status`` (and the guarantee's) becomes the
    worse of its own and the row's, and ``culprit_of`` lists the
    :class:`~rclverify.records.node_rows.CulpritOf` of the rows that name it.  New rows: ``nodes`` is left as
    it is; a row without culprits, or naming a node not in ``nodes``,
    changes nothing."""
    out = {n.name: n for n in nodes}
    for kind, name, k, blame in _blamed(problems):
        n = out.get(name)
        if n is None:
            continue
        n = _marked(n, blame)
        if kind == "guarantee":
            n = replace(n, guarantees=[_marked(x, blame) if str(x.index) == k else x for x in n.guarantees])
        out[name] = n
    return list(out.values())


__all__ = ["culprit_nodes", "marked_nodes"]
