"""The statistical targets in a ``field-data`` or ``trials`` clause's scope (docs/standards.md, "Scope").

A target is an evidence row that decided a stated target over counted runs
(docs/statistics.md: ``statistics.decision``), or a requirement's target
decided over its runs.  A clause about ``field-data`` takes run sets of the
``monitors`` backend whose plan entry *states* ``origin: operation`` (a run
set whose entry names no origin is read as operation by the statistics,
never as field data here: :func:`unstated_origins`); a ``trials`` clause
also takes ``simulation`` runs and an experiment's per-trial data.

A target in scope is covered when its decision is ``discharged`` (the
bound at the stated confidence meets the target) and it counts at least the
clause's ``min_runs`` independent runs (each run counted once by its
digest, docs/statistics.md "A run's identity").  Each item's detail shows
the figures an assessor checks: the runs counted, the violating runs, the
bound, its confidence, the target, the environment and the origin
(:func:`figures`).  Pure functions of the report's rows, read as
:class:`~.report_view.StatisticsView`; nothing raises on a report's rows.
"""
from __future__ import annotations

from typing import Any, Collection, Iterable, Mapping

from rclverify.model.plan.standards.report_view import (CountsView, DecisionView, ReportView, StatisticsView,
                                                        report_view, statistics_view)
from rclverify.records.standards_rows import ScopeItem


def figures(stats: StatisticsView | Mapping[str, Any]) -> dict[str, str]:
    """The figures of a target's ``statistics`` (an evidence row's, or a requirement's runs row; its JSON
    object or its :class:`~.report_view.StatisticsView`): ``n`` (runs counted), ``violations``, ``target``
    and ``confidence`` (percent), ``bound``, ``environment`` and ``origin``, each as text (``""`` for what
    it does not hold)."""
    s = statistics_view(stats)
    d = s.decision or DecisionView()
    counts = s.counts or CountsView()
    n = _first(d.n, counts.runs)
    k = _first(d.k, counts.violating_runs)
    bound = d.bound if d.bound is not None else s.bound
    level = d.level if d.level is not None else s.level
    limit = d.target.bound
    text = s.target if isinstance(s.target, str) else d.target.text

    def pct(x: float | None) -> str:
        return "" if x is None else f"{100 * float(x):.4g} %"
    return {"n": n, "violations": k,
            "target": (pct(limit) if limit is not None else str(text or "")),
            "confidence": pct(level), "bound": pct(bound), "environment": s.environment, "origin": s.origin}


def _first(decided: int | None, counted: int | None) -> str:
    """The decision's figure, else the counts' one, as text (``""`` when neither states it)."""
    x = decided if decided is not None else counted
    return "" if x is None else str(x)


def sentence(f: Mapping[str, str]) -> str:
    """The :func:`figures` of a target in one phrase."""
    return (f"{f['n']} independent run(s), {f['violations']} violating; bound {f['bound'] or 'none'} at "
            f"{f['confidence'] or '?'} confidence against the target {f['target'] or 'none stated'}; "
            f"environment {f['environment'] or 'unstated'}, origin {f['origin'] or 'unstated'}")


def _state(status: str, n: int | None, min_runs: int, stated: bool, field_data: bool) -> tuple[str, str]:
    """(state, why not covered) of a target whose decision is ``status`` over ``n`` runs."""
    if field_data and not stated:
        return "not counted", ("the plan entry states no origin: a run set counts as field data only when it "
                               "says origin: operation")
    if status != "discharged":
        return status, f"target {status}"
    if min_runs and (n is None or n < min_runs):
        return "not counted", f"{n} independent runs; the clause asks at least {min_runs}"
    return "covered", ""


def unstated_origins(entries: Iterable[Any]) -> frozenset[tuple[str, str]]:
    """The (node, environment tag) of each ``monitors`` plan entry (model/plan/model.py ``EvidenceEntry``:
    ``node``, ``backend``, ``config``) that states no ``origin:``; an entry without an ``environment:``
    is under the tag ``unstated`` (docs/statistics.md)."""
    from rclverify.model.plan.targets import entry_environment  # deferred: the plan's target reader imports the plan model
    return frozenset((str(e.node), entry_environment(e.config)) for e in entries
                     if e.backend == "monitors" and "origin" not in e.config)


def target_items(report: ReportView | Mapping[str, Any], about: str, min_runs: int,
                 unstated: Collection[tuple[str, str]] = ()) -> list[ScopeItem]:
    """The targets of ``report`` (its :class:`~.report_view.ReportView`, or its JSON object) in the scope of
    a clause about ``about`` (``field-data`` or ``trials``) that asks ``min_runs`` independent runs (0: no
    minimum), each a :class:`~rclverify.records.standards_rows.ScopeItem` with its state and figures (the
    module docstring); ``unstated``: the (node, environment) of the run sets whose plan entry states no
    origin (:func:`unstated_origins`)."""
    field_data = about == "field-data"
    origins = ("operation",) if field_data else ("operation", "simulation")
    out: list[ScopeItem] = []
    envs_unstated = {env for _, env in unstated}
    rep = report_view(report)
    for e in rep.evidence:
        s = e.statistics
        if s is None or s.decision is None:
            continue
        monitors = e.backend == "monitors"
        if not ((monitors and s.origin in origins) or (not field_data and e.backend == "experiment")):
            continue
        node = e.obligation.split(".", 1)[0]
        stated = not monitors or (node, s.environment) not in unstated
        state, why = _state(str(e.status), s.decision.n, min_runs, stated, field_data)
        out.append(_target(f"target {e.obligation}", state, why, figures(s), e.obligation))
    for rq in rep.requirements:
        for t in rq.statistics or ():
            if not (t.target and t.origin in origins):
                continue
            counts = t.counts or CountsView()
            stated = t.origin != "operation" or t.environment not in envs_unstated
            state, why = _state(t.status or "pending", counts.runs, min_runs, stated, field_data)
            out.append(_target(f"target of requirement {rq.id} ({t.environment}, {t.origin})",
                               state, why, figures(t), f"requirement {rq.id}"))
    return out


def _target(item: str, state: str, why: str, f: Mapping[str, str], evidence: str) -> ScopeItem:
    ok = state == "covered"
    return ScopeItem(item, "target", ok, state, sentence(f) if ok else f"{why}: {sentence(f)}",
                     [evidence] if ok else [])


__all__ = ["figures", "sentence", "target_items", "unstated_origins"]
