"""Assurance claim points: where the argument's confidence is
argued, marked in the form of the GSN Community Standard v3's confidence
argument extension as gsn2x reads it (jonasthewolf/gsn2x,
doc/src/ext_confidence.md): an element's ``acp`` maps an ACP name to the
element's own id or to elements it is directly related to (its
``supportedBy`` or ``inContextOf`` targets; gsn2x check V09 rejects any
other reference).

Where the points are, and what each states (the computed confidence and
the rule of docs/confidence.md that gives it):

============================================  =====================================  ======
claim point                                   on                                      rule
============================================  =====================================  ======
``ACP-<REQ>``                                 the requirement goal's link to its      C5
                                              strategy (itself when undeveloped)
``ACP-<REQ>.limit``                           the strategy's link to the premise      C5
                                              that limits the requirement
``ACP-<Node>``                                the node goal's link to the premise     C3, C4
                                              that limits it (itself without one)
``ACP-<claim>.challenged``                    a claim a defeater challenges (itself)  C0, C1,
                                                                                      C5
============================================  =====================================  ======

gsn2x has no text for a claim point, so each point's statement is appended
to its element's text, ``[ACP-REQ1: confidence 0.9965 by rule C5; ...]``,
as the defeaters' reasons are.
"""
from __future__ import annotations

import re
from dataclasses import replace
from typing import Any, Callable

import msgspec

from rclverify.records.report_record import AssuranceReport
from rclverify.records.strength_rows import LimitedBy
from rclverify.report.argument.model import Element

_GUARANTEE = re.compile(r"^(?P<node>\S+) guarantee (?P<k>\d+)$")


def _premise_element(label: str, rid: str, ident: Callable[..., str]) -> str:
    """The element standing for a premise of the confidence calculus, by its
    label (report/confidence_rows.py): ``"Navigation guarantee 1"``,
    ``"side condition Planner.sc1"``, ``"the proof of REQ1"``; '' for a
    premise the argument draws no element for (a declared fact)."""
    m = _GUARANTEE.match(label)
    if m:
        return ident("G", m["node"], f"g{m['k']}")
    if label.startswith("side condition "):
        return ident("G", "sc", label[len("side condition "):])
    if label == f"the proof of {rid}":
        return ident("Sn", "req", rid)
    return ""


def _conf(value: Any) -> str:
    return f"{float(value):.4g}"


def _mark(els: dict[str, Element], eid: str, name: str, refs: tuple[str, ...], statement: str) -> None:
    """Give element ``eid`` the claim point ``name`` over ``refs`` and append its statement to the text."""
    e = els[eid]
    if any(n == name for n, _ in e.acp):
        return
    els[eid] = replace(e, text=f"{e.text} [{name}: {statement}]", acp=e.acp + ((name, refs),))


def _linked(e: Element, target: str) -> bool:
    return target in e.supported_by or target in e.in_context_of


def _limit(lim: LimitedBy) -> str:
    """The weakest premise's kind and doubt, as a claim point states them."""
    return f"{lim.kind}, doubt {lim.doubt:g}"


def add_claim_points(els: dict[str, Element], report: AssuranceReport, ident: Callable[..., str]) -> None:
    """Mark the assurance claim points of ``report``'s argument in ``els``
    (element id -> element, changed in place; the module docstring says
    where).  ``ident`` makes element ids (:func:`.build.ident`).  Every
    reference is the element itself or one of its ``supportedBy`` /
    ``inContextOf`` targets (gsn2x V09); claims the argument does not show
    are skipped.  Call after the defeaters are added."""
    for r in report.requirements:
        rid = r.id
        gid = ident("G", rid)
        if gid not in els:
            continue
        goal, name = els[gid], ident("ACP", rid)
        conf, lim = r.confidence, r.limited_by
        if conf is None:
            why = ("informal: no formal statement to compute a confidence for" if r.verdict == "informal"
                   else "no confidence computed: the calculus's requirements are argued by their guarantees' goals")
            _mark(els, gid, name, (gid,), why)
            continue
        strategy = ident("S", rid)
        sentence = lim.sentence if lim is not None and lim.sentence is not msgspec.UNSET else ""
        _mark(els, gid, name, (strategy,) if _linked(goal, strategy) else (gid,),
              f"confidence {_conf(conf)} by rule C5" + (f"; {sentence}" if sentence else ""))
        limit = _premise_element(lim.label, rid, ident) if lim is not None else ""
        if lim is not None and strategy in els and limit and _linked(els[strategy], limit):
            _mark(els, strategy, ident("ACP", rid, "limit"), (limit,), f"{lim.label} limits {rid} ({_limit(lim)}; rule C5)")
    derived = {d.node: d.confidence for d in report.derived_properties if d.confidence is not msgspec.UNSET}
    for n in report.nodes:
        name = n.name
        gid = ident("G", name)
        if gid not in els or n.confidence is msgspec.UNSET:
            continue
        node_lim = n.limited_by or None
        limit = _premise_element(node_lim.label, "", ident) if node_lim is not None else ""
        refs = (limit,) if limit and _linked(els[gid], limit) else (gid,)
        text = f"confidence {_conf(n.confidence)} by rule C3"
        if node_lim is not None:
            text += f", limited by {node_lim.label} ({_limit(node_lim)})"
        d = derived.get(name)
        if d is not None:
            text += f"; its derived property (rules R1-R4): confidence {_conf(d)} by rule C4"
        _mark(els, gid, ident("ACP", name), refs, text)
    _challenged(els, report, ident)


def _challenged(els: dict[str, Element], report: AssuranceReport, ident: Callable[..., str]) -> None:
    """A claim point on every claim a counter solution challenges (on the
    claim itself), with the confidence the calculus gives that claim."""
    confidence: dict[str, tuple[float, str]] = {}  # goal id -> (confidence, rule)
    for n in report.nodes:
        for g in n.guarantees:
            s = g.strength
            if s is not msgspec.UNSET:
                confidence[ident("G", n.name, f"g{g.index}")] = (1.0 - s.doubt, "C0" if s.kind == "defeated" else "C1")
    for sc in report.side_conditions:
        if sc.strength is not msgspec.UNSET:
            doubt = sc.strength.doubt
            confidence[ident("G", "sc", sc.id)] = (1.0 - doubt, "C0" if doubt >= 1.0 else "strength")
    for r in report.requirements:
        if r.confidence is not None:
            confidence[ident("G", r.id)] = (r.confidence, "C5")
    challengers: dict[str, list[str]] = {}
    for cs in els.values():
        if cs.type == "counter_solution":
            for target in cs.challenges:
                if target in els:
                    challengers.setdefault(target, []).append(cs.id)
    for target, by in challengers.items():
        conf, rule = confidence.get(target, (0.0 if els[target].defeated else None, "C0"))
        what = ("no confidence computed" if conf is None else
                f"confidence {_conf(conf)} by rule {rule}" if rule != "strength"
                else f"confidence {_conf(conf)} from its proof's strength")
        _mark(els, target, f"ACP-{target[2:]}.challenged", (target,),
              f"challenged by {', '.join(by)}{' (defeated)' if els[target].defeated else ''}: {what}")
