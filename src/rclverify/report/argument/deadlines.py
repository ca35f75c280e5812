"""A requirement's end-to-end deadline in the assurance argument
(docs/argument.md, "End-to-end deadlines").

Under the goal of a requirement with a ``deadline:`` (its row's
:class:`~rclverify.records.deadline_rows.DeadlineRow`, :mod:`rclverify.report.deadlines`)::

    G-<REQ>           the requirement
      ...             its own argument (formal entailment), or, for an
                      informal one, G-<REQ>.text (undeveloped: its text is
                      not checked)
      G-<REQ>.deadline  the last output along the path follows the first
                        trigger within the bound
        S-<REQ>.deadline  argument by rule D3: the deadlines of the chain's
                          timed guarantees add up     in context of J-deadlines
          Sn-deadline.<REQ>   Z3's decision (artifacts/deadlines/<REQ>.smt2)
          G-<Node>.g<k>       each timed guarantee of the chain (its evidence)
          Sn-ev.<obligation>  each monitor record that checked a hop's
                              deadline against message stamps

Statuses propagate worst-child (:func:`.model.propagate`): a refuted
deadline fails its requirement's goal; a hop whose evidence is pending
leaves it pending.
"""
from __future__ import annotations

import re
from typing import Any, Mapping, MutableMapping

import msgspec

from rclverify.records.requirement_rows import RequirementRow
from rclverify.report.argument.model import Element

_ID_BAD = re.compile(r"[^A-Za-z0-9_.\-]+")

D3 = ("Rule D3 (docs/requirements.md, \"End-to-end deadlines\"): when each node of the path meets its timed "
      "guarantee (its output follows its trigger within its deadline) and each hop's trigger is fed by the output "
      "of the hop before, the path's last output follows its first trigger within the sum of the deadlines; Z3 "
      "compares the sum with the requirement's bound in exact arithmetic.  Stamps come from one clock "
      "(docs/monitors.md).")
#: A deadline verdict as the status of Z3's solution.
_STATUS = {"proved": "discharged", "refuted": "failed", "inconclusive": "inconclusive", "pending": "pending",
           "stale": "stale", "error": "error"}


def _id(prefix: str, *parts: Any) -> str:
    return prefix + "-" + _ID_BAD.sub("_", ".".join(str(p) for p in parts))


def _clip(text: str, n: int = 400) -> str:
    text = " ".join(str(text).split())
    return text if len(text) <= n else text[: n - 3] + "..."


def own_check(r: RequirementRow) -> RequirementRow:
    """The requirement row ``r`` as its own check left it, before its
    deadline was rolled in (:func:`rclverify.report.deadlines.fold_into`
    keeps that as ``without_deadline``: its verdict, status and note): its own argument is built from it."""
    before = r.without_deadline
    if before is None:
        return r
    return msgspec.structs.replace(r, verdict=before.verdict, status=before.status, note=before.note)


def with_deadline(els: MutableMapping[str, Element], goal: str, r: RequirementRow,
                  guarantee_goal: Mapping[tuple[str, int], str]) -> str:
    """Add the deadline goal of requirement row ``r`` under its goal ``goal``
    in ``els`` (module docstring); returns ``goal``.  Unchanged when ``r``
    has no deadline.  The chain's guarantee goals and the monitors' evidence
    solutions must already be in ``els``."""
    d = r.deadline
    if d is None:
        return goal
    rid = r.id
    j = _id("J", "deadlines")
    if j not in els:
        els[j] = Element(j, "justification", D3)
    sn = _id("Sn", "deadline", rid)
    reason = "" if d.reason is msgspec.UNSET else d.reason
    els[sn] = Element(sn, "solution", _clip(f"Z3 decision of {rid}'s end-to-end deadline ({d.smt2 or 'no query'})"
                                            f": {d.verdict}. {reason}"),
                      status=_STATUS.get(d.verdict, "error"), ref=rid, url=d.smt2 or "")
    kids = [sn]
    chain = d.chain or []
    for h in chain:
        g = guarantee_goal.get((h.node, h.guarantee))
        if g is not None:
            kids.append(g)
        for m in h.monitors or []:  # the monitor's record of the hop (backends/monitors' shape)
            ev = _id("Sn", "ev", m["obligation"])
            if ev in els:
                kids.append(ev)
    hops = " + ".join(f"{h.node} g{h.guarantee} {h.within}" for h in chain) or "no chain"
    s = _id("S", rid, "deadline")
    els[s] = Element(s, "strategy", _clip(f"Argument by rule D3 over the chain {hops} (sum {d.total or 'none'}, "
                                          f"bound {d.within})"),
                     supported_by=tuple(dict.fromkeys(kids)), in_context_of=(j,), ref=rid)
    g = _id("G", rid, "deadline")
    els[g] = Element(g, "goal", _clip(f"{rid}: along {' -> '.join(d.path)} the last output follows the first "
                                      f"trigger within {d.within} ({d.source})"), supported_by=(s,), ref=rid)
    top = els[goal]
    if top.undeveloped:  # an informal requirement: its text stays undeveloped beside the deadline
        text = _id("G", rid, "text")
        els[text] = Element(text, "goal", _clip(f"{rid}'s text holds: {r.text} (informal: no formal statement)"),
                            undeveloped=True, ref=rid)
        els[goal] = Element(goal, "goal", top.text, supported_by=(text, g), in_context_of=top.in_context_of,
                            ref=top.ref, url=top.url)
    else:
        els[goal] = Element(goal, "goal", top.text, supported_by=top.supported_by + (g,),
                            in_context_of=top.in_context_of, ref=top.ref, url=top.url)
    return goal
