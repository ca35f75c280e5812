"""Typed evidence strength (docs/confidence.md).

Every evidence record and side condition of the report carries a
``strength``: a :class:`~rclverify.records.strength_rows.Strength` (``kind``,
``detail``, ``doubt``; a side condition's also ``solvers``).

=============  ==========================================================
kind           what it rests on
=============  ==========================================================
``proof``      unbounded and decided by a solver or verifier (``solvers``: 2
               when cvc5 agreed, 1 otherwise)
``bounded``    exhaustive to a stated bound: SPIN or AJPF over an
               abstraction or a partial mapping
``statistical`` experiments: the sample size and the one-sided 95 % bound
               the data give for the criterion; a target's record (a run set
               or an experiment's trials): its Clopper-Pearson bound
``tested``     property tests: examples run against the assumption, and
               their coverage of the assumption's ranges per input
``observed``   monitored runs: messages judged, events read, the run's
               duration in trace time; the doubt is the 95 % bound over the
               runs of its node and environment where the report counted them
``reviewed``   a signed review record
``assumed``    stated, not verified (environment assumptions, declared
               progress and initial values)
=============  ==========================================================

``doubt`` is the probability, by convention, that a claim resting on this
evidence alone is false (the complement of its confidence; the convention of
conservative claims, Bishop, Bloomfield, Littlewood et al., IEEE TSE 37(5),
2011): :data:`DOUBT`.  Only evidence whose status is ``discharged`` gives
confidence; any other status has doubt 1.
"""
from __future__ import annotations

import math
from typing import Any, Mapping

import msgspec

from rclverify.model.plan.declarations import DECLARATIONS, STRENGTHS
from rclverify.records.evidence_rows import EvidenceRow
from rclverify.records.monitored_run import MonitoredRun
from rclverify.records.side_condition_rows import SideConditionRow
from rclverify.records.strength_rows import Strength

#: The kinds, strongest first (the report orders and compares by this).
KINDS = STRENGTHS

#: Doubt of a discharged claim per kind (docs/confidence.md gives the reasons).  ``proof`` is split by
#: how many independent solvers decided it; ``statistical`` uses its data's bound where there is one.
DOUBT: Mapping[str, float] = {"proof2": 1e-4, "proof": 1e-3, "bounded": 1e-2, "statistical": 5e-2,
                              "tested": 5e-2, "observed": 1e-1, "reviewed": 1e-1, "assumed": 2e-1}

#: The strength of each backend's evidence, as its ``declaration.yaml`` states it.
BACKEND_KIND: Mapping[str, str] = {n: d.strength for n, d in DECLARATIONS.items()}


def one_sided_bound(n: int, level: float = 0.95) -> float:
    """The one-sided upper confidence bound, at ``level``, on the rate of
    trials missing a criterion when ``n`` trials all met it: the exact
    Clopper-Pearson bound for zero failures, ``1 - (1 - level) ** (1 / n)``
    (about 3/n, the "rule of three").  ``1.0`` for ``n <= 0``."""
    return 1.0 if n <= 0 else 1.0 - (1.0 - level) ** (1.0 / n)


def _figure(row: EvidenceRow, name: str) -> str | None:
    for pair in row.figures:
        if len(pair) == 2 and pair[0] == name:
            return pair[1]
    return None


def evidence_strength(row: EvidenceRow) -> Strength:
    """The strength of one evidence row of the report (an
    :class:`~rclverify.records.evidence_rows.EvidenceRow`: ``backend``, ``status``, and the
    backend's figures: ``examples``, ``monitoring``, ``figures``, ``statistics``): a
    :class:`~rclverify.records.strength_rows.Strength` with its ``kind``, ``detail`` and
    ``doubt``; an unknown backend is ``assumed``."""
    backend = row.backend
    kind = BACKEND_KIND.get(backend, "assumed")
    detail, doubt = "", DOUBT[kind]
    stats = row.statistics or None  # the run counts a backend's payload carries (its own shape)
    if stats is not None and "decision" in stats:  # a target's record: its bound is the doubt
        return target_strength(row, stats)
    if backend == "hoare":
        two = row.solvers is not None and row.solvers.agreement == "two solvers"
        detail = f"Z3{' and cvc5' if two else ' (one solver)'} on the verification conditions"
        doubt = DOUBT["proof2" if two else "proof"]
    elif backend in DECLARATIONS and DECLARATIONS[backend].strength_detail:
        detail = str(DECLARATIONS[backend].strength_detail)
    elif kind == "bounded":
        partial = "PARTIAL COVERAGE" in row.explanation
        detail = f"{row.tool or backend} over an abstraction" + ("; partial coverage" if partial else "")
    elif kind == "statistical":
        n = _figure(row, "count")
        k = int(n) if n and n.isdigit() else 0
        bound = one_sided_bound(k)
        detail = ("sample size not stated" if not k else f"{k} trials" if row.status != "discharged" else
                  f"{k} trials, all within the criterion: a one-sided 95 % bound of {bound:.1%} on the rate of trials "
                  "missing it")
        doubt = max(DOUBT["statistical"], bound) if k else 1.0
    elif kind == "tested":
        ex = row.examples  # the property tests' payload (backends/property_tests, its own shape)
        detail = f"{ex.get('valid', 0)} examples within the assumption (of {ex.get('run', 0)} run)"
        cov = coverage_text(ex.get("coverage") or {})
        detail += f"; coverage of the assumption's ranges: {cov}" if cov else ""
    elif kind == "observed":
        m = MonitoredRun.of(row.monitoring)  # the monitors' run (docs/monitors.md), decoded
        answered = m.counts.get("satisfied", 0) + m.counts.get("violated", 0)
        detail = f"{answered} verdicts on messages (satisfied or violated), {m.events_read} events read"
        if m.duration_s is not None:
            detail += f" over {m.duration_s:g} s of trace time"
        group = stats.get("group") if stats is not None else None
        if stats is not None and isinstance(group, Mapping) and isinstance(group.get("bound"), (int, float)):
            # the runs of its node and environment, counted: their bound replaces the convention
            doubt = float(group["bound"])
            detail += (f"; {group.get('runs')} run(s) under {stats.get('environment')}: a one-sided "
                       f"{float(group.get('level', 0.95)) * 100:g} % bound of {doubt:.3g} on the probability "
                       f"that a run violates the contract")
    elif kind == "reviewed":
        who = (_figure(row, "reviewer") or "").split(";")[0].strip()
        detail = f"review by {who[:60] or 'an unnamed reviewer'}"
    if row.status != "discharged":
        doubt = 1.0
    return Strength(kind=kind, detail=detail, doubt=doubt)


def target_strength(row: EvidenceRow, stats: Mapping[str, Any]) -> Strength:
    """The strength of a target's record (a run set's or an experiment's,
    docs/statistics.md): ``statistical``, its detail the counts and the
    bound at the target's level, its doubt that bound when ``discharged``
    (1 otherwise)."""
    d = stats.get("decision") or {}
    t = stats.get("target") or {}
    bound = d.get("bound")
    per = t.get("per", "run")
    detail = (f"{d.get('n', 0)} {per}(s) under {stats.get('environment')}, {d.get('k', 0)} violating"
              + (f", {d['undecided']} undecided" if d.get("undecided") else "")
              + (f": a one-sided {float(d.get('level', 0.95)) * 100:g} % bound of {bound:.3g} on the probability "
                 f"that a {per} violates it" if isinstance(bound, (int, float)) else ""))
    doubt = float(bound) if row.status == "discharged" and isinstance(bound, (int, float)) else 1.0
    return Strength(kind="statistical", detail=detail, doubt=doubt)


def coverage_text(cov: Mapping[str, Any]) -> str:
    """The property tests' coverage (backends/property_tests/coverage.py) in
    one line: ``in.x 80% of [0, 100] (drawn 0..97)`` per measured input,
    ``in.y drawn -3..41 of [-inf, inf] (unbounded)`` for an unbounded one;
    inputs not measured (tables, sequences) are left out.  '' without any."""
    parts = []
    for key, c in cov.items():
        if not isinstance(c, Mapping):
            continue
        narrowed = f", the plan's bounds; the assumption admits {c['admitted']}" if c.get("admitted") else ""
        if isinstance(c.get("fraction"), (int, float)):
            parts.append(f"{key} {c['fraction']:.0%} of {c.get('range')} (drawn {c.get('drawn')}{narrowed})")
        elif c.get("buckets") is None and c.get("drawn") and "not measured" not in str(c.get("range")):
            parts.append(f"{key} drawn {c['drawn']} of {c.get('range')} (unbounded)")
    return "; ".join(parts)


def side_condition_strength(sc: SideConditionRow) -> Strength:
    """The strength of a side-condition row (a
    :class:`~rclverify.records.side_condition_rows.SideConditionRow`): a ``proof`` by one or two
    solvers (its ``solvers.agreement``), doubt 1 unless ``discharged``.  One
    discharged from its producers' cone summaries (``context.summaries``,
    calculus/summary.py) is one solver's: cvc5 decides the last query only,
    the summaries were each proved implied by their cone by Z3 alone."""
    two = sc.solvers is not msgspec.UNSET and sc.solvers.agreement == "two solvers"
    detail = "Z3 and cvc5" if two else "Z3 (one solver)"
    if two and ((sc.context or {}).get("summaries")):  # calculus/compose.py's record of the proof in context
        # cvc5 decided the query over the cone summaries; each summary's own proof (implied by its cone) is Z3's
        two, detail = False, "Z3 and cvc5 on the query over the cone summaries, the summaries by Z3 alone"
    doubt = DOUBT["proof2" if two else "proof"] if sc.status == "discharged" else 1.0
    return Strength(kind="proof", detail=detail, solvers=2 if two else 1, doubt=doubt)


def stronger(a: str, b: str) -> str:
    """The stronger of two kinds (:data:`KINDS` order)."""
    return a if KINDS.index(a) <= KINDS.index(b) else b


def confidence(doubt: float) -> float:
    """The confidence of a doubt, ``1 - doubt`` clipped to ``[0, 1]``, rounded to 6 places."""
    return round(min(1.0, max(0.0, 1.0 - doubt)), 6) if not math.isnan(doubt) else 0.0
