"""The non-vacuity check of contract health (:mod:`.checks`): for each
guarantee ``forall v | P -> Q``, can the premise ``P`` hold together with
the assumption, every guarantee and the facts?  With an instance range the
premise is examined instance by instance where the general query cannot
decide (:func:`non_vacuity`).
"""
from __future__ import annotations

from msgspec.structs import replace
from typing import Sequence


from rclverify.semantics.query import QueryResult
from rclverify.calculus.health.finding import Finding
from rclverify.calculus.health.node_health import NodeHealth, extended_witness, noted, table_witness

#: Timeout of one per-instance premise query, and how many undecided
#: instances in a row (with no vacuous one found) end the scan.
INSTANCE_TIMEOUT_MS = 2_000
GIVE_UP_AFTER = 3
#: With an instance range, the first budgets of the general non-vacuity query
#: and of each instance ("decide first with what decides"; see
#: :func:`non_vacuity`).  The case study's instances each take about 25,000
#: Z3 steps (0.2 of :data:`INSTANCE_FIRST_MS`); its guarantee 1's general
#: query takes its whole budget and decides nothing.
SCAN_FIRST_MS = 250
INSTANCE_FIRST_MS = 100


def non_vacuity(h: NodeHealth, n: str, k: int) -> Finding | None:
    prem = h.premise(k)
    if prem is None:
        return None  # not forall ... (premise -> conclusion): no premise to examine
    extra, ptext = prem
    comment = f"health {n}: can the premise of guarantee {k} hold? {ptext}"
    if not (h.instances and h.natural_vars(k)):
        r = h.sat(extra, comment=comment, retry=True)
        return noted(replace(_premise_finding(h, n, k, r, ptext), smt2=r.smt2), r)
    # With an instance range the scan decides where the general query cannot; the retries of
    # semantics/retry.py are not tried (the Agent's guarantee 1: 4 CPU s of retries that all give up).
    # Decide first with what decides: the general query with a small budget (what it decides
    # there, its whole budget decides the same way), then each instance with a small budget; the general
    # query gets its whole budget only when no instance was found vacuous.
    r = h.sat(extra, comment=comment, retry=False, timeout_ms=min(h.timeout, SCAN_FIRST_MS))
    if r.status == "inconclusive":
        quick = _scan(h, n, k, min(h.timeout, INSTANCE_FIRST_MS))
        if not any(x.status == "unsat" for x in quick.values()):
            # no instance shown vacuous: the consistency witness extended, else a finite-table witness of
            # the general query (either's sat is the general query's), else the general query with its
            # whole budget
            r = (extended_witness(h, comment, extra) or table_witness(h, comment, extra)
                 or h.sat(extra, comment=comment, retry=False))
        if r.status == "inconclusive":
            return replace(_scan_finding(h, n, k, r, ptext, quick), smt2=r.smt2)
    return noted(replace(_premise_finding(h, n, k, r, ptext), smt2=r.smt2), r)


def _scan(h: NodeHealth, n: str, k: int, budget_ms: int,
          known: dict[int, QueryResult] | None = None, *, witness_first: bool = False) -> dict[int, QueryResult]:
    """Guarantee ``k``'s premise asked at each instance ``lo..hi`` of its
    first NATURAL variable, in order, with ``budget_ms`` each (an instance
    ``known`` decided is not asked again), until :data:`GIVE_UP_AFTER`
    instances in a row are undecided with none found vacuous before.
    ``witness_first``: an instance still undecided is first given to the
    witnesses of that instance's premise alone (the consistency witness
    extended, then a finite-table witness within ``budget_ms``: either's
    ``sat`` is a model of the instance's query, so the instance can fire);
    only what they leave open is asked with ``budget_ms``.  The case
    study's Agent, guarantee 1 at ``i = 12``: a witness in 0.3 s where the
    general query gives up after 2 s."""
    assert h.instances is not None
    v = h.natural_vars(k)[0]
    lo, hi = h.instances
    out: dict[int, QueryResult] = {}
    streak = 0
    for x in range(lo, hi + 1):
        got = (known or {}).get(x)
        if got is None or got.status == "inconclusive":
            pe = h.premise(k, {v: x})
            assert pe is not None
            comment = f"health {n}: premise of guarantee {k} at {v}={x}"
            got = ((extended_witness(h, comment, pe[0]) or table_witness(h, comment, pe[0], budget_ms=budget_ms))
                   if witness_first else None) or h.sat(pe[0], comment=comment, timeout_ms=budget_ms)
        out[x] = got
        streak = streak + 1 if got.status == "inconclusive" else 0
        if streak >= GIVE_UP_AFTER and not any(y.status == "unsat" for y in out.values()):
            break
    return out


def _premise_finding(h: NodeHealth, n: str, k: int, r: QueryResult, ptext: str) -> Finding:
    """The finding of a general non-vacuity query that decided, or of one
    that did not when there is no instance range to scan."""
    fid, check = f"{n}.g{k}.non-vacuous", "non-vacuous"
    if r.status == "sat":
        return Finding(fid, n, check, k, "ok", f"The premise of guarantee {k} of {n} can hold: the guarantee can fire.",
                       f"Premise: {ptext}. Z3 found a situation where it holds together with the assumption, every "
                       "guarantee and the environment facts (witness below).", r.model, duration_s=r.duration_s)
    if r.status == "unsat":
        return Finding(fid, n, check, k, "problem",
                       f"Guarantee {k} of {n} is vacuous: its premise can never hold together with the node's other "
                       "guarantees and the environment facts, so it promises nothing.",
                       f"Premise: {ptext}. The unsat core names the clauses that exclude it.", None, list(r.core or []),
                       r.duration_s)
    return Finding(fid, n, check, k, "inconclusive", f"Z3 could not decide whether guarantee {k} of {n} can fire ({r.reason}).",
                   f"Premise: {ptext}. Give the plan an 'instances' range for {n} to examine it instance by instance.",
                   duration_s=r.duration_s)


def _scan_finding(h: NodeHealth, n: str, k: int, r: QueryResult, ptext: str,
                  quick: dict[int, QueryResult]) -> Finding:
    """The finding of guarantee ``k`` examined instance by instance, the
    general query ``r`` undecided: each instance the ``quick`` look did not
    decide is asked with :data:`INSTANCE_TIMEOUT_MS` (the scan of
    :func:`_scan`, in order, with its give-up rule)."""
    fid, check = f"{n}.g{k}.non-vacuous", "non-vacuous"
    assert h.instances is not None
    v = h.natural_vars(k)[0]
    lo, hi = h.instances
    full = _scan(h, n, k, min(h.timeout, INSTANCE_TIMEOUT_MS), quick, witness_first=True)
    per: dict[str, str] = {}
    cores: dict[str, list[str]] = {}
    total = r.duration_s + sum(x.duration_s for x in quick.values()) + sum(
        x.duration_s for y, x in full.items() if x is not quick.get(y))
    for x, ri in full.items():
        per[str(x)] = {"sat": "can fire", "unsat": "vacuous", "inconclusive": "inconclusive"}[ri.status]
        if ri.status == "unsat":
            cores[str(x)] = list(ri.core or [])
    if len(full) < hi - lo + 1:  # the scan gave up
        per.update({str(y): "not examined" for y in range(lo + len(full), hi + 1)})
    vac = [x for x, st in per.items() if st == "vacuous"]
    fires = [x for x, st in per.items() if st == "can fire"]
    unk = [x for x, st in per.items() if st in ("inconclusive", "not examined")]
    if vac:
        sample = cores[vac[0]]
        msg = (f"Guarantee {k} of {n} is vacuous for {v} in {_ranges(vac)}: its premise contradicts the node's other "
               f"guarantees and the environment facts there" + (f"; it can fire only for {v} in {_ranges(fires)}" if fires else "")
               + (f"; undecided for {v} in {_ranges(unk)}" if unk else "") + ".")
        return Finding(fid, n, check, k, "problem", msg,
                       f"Premise: {ptext}. Unsat core at {v}={vac[0]} below. Z3 could not decide the general case "
                       f"({r.reason}), so each instance {v}={lo}..{hi} was checked.", None, sample, round(total, 4), per)
    if fires and not unk:
        return Finding(fid, n, check, k, "ok", f"Guarantee {k} of {n} can fire for every {v} in {lo}..{hi}.",
                       f"Premise: {ptext}.", None, None, round(total, 4), per)
    return Finding(fid, n, check, k, "inconclusive", f"Z3 could not decide whether guarantee {k} of {n} can fire"
                   + (f" for {v} in {_ranges(unk)}" if unk else "") + ".",
                   f"Premise: {ptext}.", None, None, round(total, 4), per)


def _ranges(xs: Sequence[str]) -> str:
    """Whole numbers (as text) as ranges: ``["1", "2", "3", "7"]`` -> ``"{1..3, 7}"``."""
    nums = sorted(int(x) for x in xs)
    parts, start = [], None
    for i, x in enumerate(nums):
        if start is None:
            start = x
        if i + 1 == len(nums) or nums[i + 1] != x + 1:
            parts.append(f"{start}" if start == x else f"{start}..{x}")
            start = None
    return "{" + ", ".join(parts) + "}"
