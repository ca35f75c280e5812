"""An end-to-end deadline diagnosed as a deadline (docs/diagnosis.md,
"End-to-end deadlines").

A deadline that rule D3 refutes (:mod:`rclverify.calculus.deadlines`) is
over its budget because the deadlines of its chain's hops add up past it;
its diagnosis names the chain, each hop's bound and the budget, and its
repairs split the budget: which hop must become how fast.

* ``tighten-hop``: one hop answers faster by the excess (``Planner``:
  100 ms becomes 50 ms), for every hop whose bound is larger than the
  excess; the smallest relative cut first (it asks least of one node).
* ``split-budget``: every hop of the chain scaled by ``budget / sum``,
  rounded down in the unit it is written in, when the hops are in one file.

Each is returned only when Z3, deciding rule D3 again on the edited
contracts, proves the deadline; its ``cost`` is every other deadline of
the plan whose verdict changes.  What Z3 does not show: that the node can
answer that fast; its evidence (the monitors' deadline verdicts on its
recorded runs) must.  A deadline that is not decided (no chain of timed
guarantees along its path) names the node where the path breaks.
"""
from __future__ import annotations

from fractions import Fraction
from typing import Any, Mapping, Sequence

import msgspec

from rclverify.calculus.deadlines import chains, decide, show_seconds
from rclverify.lang.timing import UNITS
from rclverify.diagnosis import recheck
from rclverify.diagnosis.bounds import number_text
from rclverify.diagnosis.shapes import ReportRows
from rclverify.records.deadline_rows import DeadlineHop, DeadlineRow
from rclverify.diagnosis.record import diagnosis_record
from rclverify.records.problem_rows import DiagnosisRow
from rclverify.records.stage_records import CexRow, Culprit, Repair
from rclverify.records.statuses import AnyStatus
from rclverify.diagnosis.edits import Edit
from rclverify.diagnosis.repairs import _record

#: Units tried, largest first, to write a new deadline as a whole number.
_SMALLER = ("min", "s", "ms", "us", "ns")


def _spec(ws: Any, req: str) -> Any:
    return next((d for d in ws.plan.deadlines if d.requirement == req), None)


def _amount(seconds: Fraction, unit: str, floor: bool) -> tuple[str, str] | None:
    """``seconds`` written in ``unit`` or a smaller one as ``(amount, unit)``:
    the first unit in which it is a whole number (``floor``: rounded down to
    one, in ``unit`` itself unless that gives 0), ``None`` when it is not
    positive."""
    if seconds <= 0:
        return None
    start = _SMALLER.index(unit) if unit in _SMALLER else 2
    for u in _SMALLER[start:]:
        x = seconds / UNITS[u]
        if floor and x >= 1:
            return str(x.numerator // x.denominator), u
        if x.denominator == 1:
            return str(x.numerator), u
    text = number_text(seconds / UNITS["ns"])
    return (text, "ns") if text else None


def _hop_clause(ws: Any, hop: DeadlineHop) -> Any:
    return ws.checked.nodes[hop.node].node.guarantees[hop.guarantee - 1]


def _decide_all(ws: Any, checked: Any, model: Any) -> dict[str, str]:
    return {f"{d.requirement}.deadline": decide(checked, model, d.requirement, d.path, d.within, d.loc).status
            for d in ws.plan.deadlines}


def budget_repairs(ws: Any, row: DeadlineRow) -> list[Repair]:
    """The repairs of the refuted deadline ``row`` (the report's record of
    :func:`rclverify.report.deadlines.deadline_rows`), each checked by Z3
    (module docstring), in the order shown."""
    spec = _spec(ws, row.requirement)
    hops = _hops(row)
    if spec is None or not hops:
        return []
    bounds = [Fraction(h.within_s) for h in hops]
    total, budget = sum(bounds, Fraction(0)), spec.within
    excess = total - budget
    if excess <= 0:
        return []
    req = row.requirement
    before = _decide_all(ws, ws.checked, ws.model)
    out: list[Repair] = []
    single: list[tuple[Fraction, Repair]] = []
    for h, b in zip(hops, bounds):
        if b <= excess:
            continue  # this hop alone cannot absorb the excess
        cl = _hop_clause(ws, h)
        if cl.deadline is None or not cl.deadline.loc.end_line:
            continue
        amount = _amount(b - excess, cl.deadline.unit or "ms", floor=True)
        if amount is None:
            continue
        loc = cl.deadline.loc
        edit = Edit(loc.file, loc.line, loc.col, loc.end_line, loc.end_col, f"within {amount[0]} {amount[1]}")
        rec = _checked(ws, req, edit, before, budget)
        if rec is None:
            continue
        new = Fraction(amount[0]) * UNITS[amount[1]]
        summary = (f"Make {h.node} answer within {show_seconds(new)} instead of {h.within}: guarantee "
                   f"{h.guarantee} of {h.node} ({h.loc}) `{edit.deleted(recheck.source_text(ws, loc.file))}` "
                   f"becomes `{edit.text}`; the chain then sums to {show_seconds(total - b + new)}, within the "
                   f"{show_seconds(budget)} of {req}.")
        single.append((excess / b, _record(
            "tighten-hop", summary, edit, recheck.source_text(ws, loc.file), rec[0], rec[1],
            proves=f"the end-to-end deadline of {req} follows from the chain (rule D3)",
            not_shown=(f"that {h.node} can answer within {show_seconds(new)}: its evidence (the monitors' "
                       "deadline verdicts on its recorded runs) must show it"))))
    out += [r for _, r in sorted(single, key=lambda x: x[0])]
    split = _split(ws, req, hops, bounds, total, budget, before)
    if split is not None and len(hops) > 1:
        out.append(split)
    return out


def _split(ws: Any, req: str, hops: Sequence[DeadlineHop], bounds: Sequence[Fraction], total: Fraction,
           budget: Fraction, before: Mapping[str, str]) -> Repair | None:
    """Every hop scaled by ``budget / total``, rounded down (module docstring)."""
    clauses = [_hop_clause(ws, h) for h in hops]
    if any(c.deadline is None or not c.deadline.loc.end_line for c in clauses):
        return None
    files = {c.deadline.loc.file for c in clauses}
    if len(files) != 1:
        return None
    rel = files.pop()
    source = recheck.source_text(ws, rel)
    new_texts: list[tuple[Any, str, Fraction]] = []
    for c, b in zip(clauses, bounds):
        amount = _amount(b * budget / total, c.deadline.unit or "ms", floor=True)
        if amount is None:
            return None
        new_texts.append((c.deadline.loc, f"within {amount[0]} {amount[1]}", Fraction(amount[0]) * UNITS[amount[1]]))
    ordered = sorted(new_texts, key=lambda t: (t[0].line, t[0].col))
    lo, hi = ordered[0][0], ordered[-1][0]
    region = Edit(rel, lo.line, lo.col, hi.end_line, hi.end_col, "").deleted(source)
    # replace from the last to the first, positions relative to the region's start
    for loc, text, _ in reversed(ordered):
        line = loc.line - lo.line + 1
        col = loc.col - (lo.col - 1 if loc.line == lo.line else 0)
        end_col = loc.end_col - (lo.col - 1 if loc.end_line == lo.line else 0)
        region = Edit("", line, col, loc.end_line - lo.line + 1, end_col, text).apply(region)
    edit = Edit(rel, lo.line, lo.col, hi.end_line, hi.end_col, region)
    rec = _checked(ws, req, edit, before, budget)
    if rec is None:
        return None
    said = ", ".join(f"{h.node} {h.within} -> {show_seconds(n)}" for h, (_, _, n) in zip(hops, new_texts))
    new_total = sum((n for _, _, n in new_texts), Fraction(0))
    return _record(
        "split-budget",
        f"Split the {show_seconds(budget)} of {req} over its chain in proportion to each hop's deadline now: {said}; "
        f"the chain then sums to {show_seconds(new_total)}.",
        edit, source, rec[0], rec[1],
        proves=f"the end-to-end deadline of {req} follows from the chain (rule D3)",
        not_shown=("that each node can answer that fast: each hop's evidence (the monitors' deadline verdicts on "
                   "its recorded runs) must show it"))


def _checked(ws: Any, req: str, edit: Edit, before: Mapping[str, str],
             budget: Fraction) -> tuple[list[dict[str, str]], list[dict[str, str]]] | None:
    """``(checks, cost)`` when Z3, deciding rule D3 on the contracts with
    ``edit`` made, proves the deadline of ``req``; ``None`` otherwise."""
    system = recheck.edited_system(ws, edit)
    if system is None:
        return None
    after = _decide_all(ws, *system)
    if after.get(f"{req}.deadline") != "proved":
        return None
    return ([{"check": f"{req}.deadline", "status": f"proved (Z3: unsat: no run later than {show_seconds(budget)})"}],
            recheck.changes(before, after))


def break_node(ws: Any, path: Sequence[str]) -> str | None:
    """The node of ``path`` where the chain of timed guarantees breaks (the
    first node no chain reaches), ``None`` when there is a chain."""
    for i in range(1, len(path) + 1):
        found, _ = chains(ws.checked, ws.model, path[:i])
        if not found:
            return str(path[i - 1])
    return None


def deadline_record(ws: Any, report: ReportRows, row: DeadlineRow,
                    repairs: Sequence[Repair]) -> DiagnosisRow:
    """The diagnosis record (:mod:`rclverify.diagnosis.build`) of the
    refuted or inconclusive deadline ``row``: id ``<REQ>.deadline``, kind
    ``deadline``; the sentence names the chain, each hop's bound and the
    budget; the culprits are the hops' guarantees (or, with no chain, the
    node where the path breaks); the counterexample is the late run's
    stamps; ``repairs`` from :func:`budget_repairs`."""
    req = row.requirement
    path = " -> ".join(row.path)
    head = f"The end-to-end deadline of {req} ({row.within} along {path}, {row.source})"
    g_text = {(n.name, g.index): g.text for n in report.nodes for g in n.guarantees}
    hops = _hops(row)
    culprits: list[Culprit] = [{"what": f"guarantee {h.guarantee} of {h.node}: within {h.within}", "source": h.loc,
                 "text": g_text.get((h.node, h.guarantee), "")} for h in hops]
    if row.verdict == "refuted":
        spec = _spec(ws, req)
        total = sum((Fraction(h.within_s) for h in hops), Fraction(0))
        over = f", {show_seconds(total - spec.within)} over the budget" if spec is not None and total > spec.within else ""
        chain = " -> ".join(f"{h.node} guarantee {h.guarantee} within {h.within} ({h.loc})" for h in hops)
        sentence = (f"{head} is refuted: its chain {chain} sums to {row.total}{over}; a hop must answer faster "
                    f"or the budget be larger.")
        status: AnyStatus = "failed"
    else:
        broken = break_node(ws, row.path)
        if broken is not None:
            src = next((n.source for n in report.nodes if n.name == broken), "")
            culprits = [{"what": f"the contract of {broken}", "source": src, "text": ""}]
        sentence = f"{head} is not decided: {row.reason}."
        status = "inconclusive"
    stamps: list[CexRow] = [{"node": str(s["event"]).split(".", 1)[0], "variable": str(s["event"]).split(".", 1)[-1],
               "value": f"t0 + {_seconds_text(s['t_s'])} s", "table": None} for s in _stamps(row)]
    return diagnosis_record(f"{req}.deadline", "deadline", "", status, sentence, culprits=culprits,
                            counterexample=stamps, repairs=repairs, requirement=req)


def _hops(row: DeadlineRow) -> list[DeadlineHop]:
    """The hops of ``row``'s chain, ``[]`` without one."""
    return list(row.chain) if row.chain is not msgspec.UNSET else []


def _stamps(row: DeadlineRow) -> list[Any]:
    """The late run's stamps of ``row`` (``{"event", "t_s"}`` each, calculus/deadlines.py), ``[]`` without them."""
    return list(row.stamps) if row.stamps is not msgspec.UNSET else []


def _seconds_text(t: Any) -> str:
    try:
        x = Fraction(str(t))
    except (ValueError, ZeroDivisionError):
        return str(t)
    return number_text(x) or f"{float(x):g}"
