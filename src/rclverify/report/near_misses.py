"""Near misses: guarantees the runs satisfied with a margin below the plan's
threshold (docs/monitors.md, "Near misses"; docs/semantics.md, "Margins").

A monitors entry's ``near_miss: {value, time}``
(:mod:`rclverify.backends.monitors.near_miss`) names the margins too small
to pass in silence.  For every obligation of that entry whose record is not
``failed`` (a violated run is named as a violation, not as a near miss),
each guarantee's smallest space margin on the run
(``details.monitoring.margins``) that is finite, at least 0 and below
``value``, and each timed guarantee's smallest time margin
(``details.deadlines.time_margins``) at least 0 and below ``time``, is one
row of the report's ``near_misses`` (:func:`near_miss_rows`), a SARIF
result ``RCL-NEAR-MISS`` at its severity, ``warning``, at the guarantee's
line (:func:`sarif_results`), a failing test case of the JUnit
``near_misses`` suite (:func:`junit_suite`), and a line of the summary
``verify`` ends with (:func:`summary_lines`).  A near miss changes no
status (the guarantee held on every run) but, a warning like every other
(report/severity.py), fails ``--strict`` (:func:`strict_reason`): the plan
stated the threshold to be told.
"""
from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from typing import Any, Callable, Literal, Mapping, Sequence

from rclverify.backends.monitors.payload import monitors_payload
from rclverify.records.margin_rows import NearMissRow
from rclverify.records.report_record import AssuranceReport
from rclverify.records.row import decode_rows
from rclverify.records.obligations import ObligationRow
from rclverify.records.sarif import SarifResult
from rclverify.records.store import EvidenceStore
from rclverify.stages.workspace import Workspace
from rclverify.report.junit_suite import closed

#: SARIF rule of a near miss (``id``, ``name``, ``level``, ``text``), listed by report/sarif.py.
SARIF_RULES = (
    ("RCL-NEAR-MISS", "NearMiss", "warning",
     "A guarantee held on every recorded run, but its smallest margin (how far the values, or an answer's "
     "stamp, came from violating it) is below the near-miss threshold the plan states for its monitors entry."),
)


def _entries(ws: Workspace, node: str) -> list[tuple[Any, Any, str]]:
    """``[(entry, threshold, plan place)]``: ``node``'s monitors entries with a ``near_miss``."""
    from rclverify.backends.monitors.near_miss import parse_near_miss  # deferred: start-up (loads rclverify.lang.timing only when called)
    out = []
    for e in ws.plan.evidence.get(node, ()):
        if e.backend != "monitors" or e.config.get("near_miss") is None:
            continue
        t = parse_near_miss(e.config.get("near_miss"))  # checked at load (backends/entry_checks.py)
        l = ws.plan.locs.get(("nodes", node, "evidence", e.index, "near_miss"), e.loc)
        out.append((e, t, f"{l.file}:{l.line}:{l.col}"))
    return out


def _entry_of(entries: Sequence[tuple[Any, Any, str]], trace: str, n_monitors: int) -> tuple[Any, Any, str] | None:
    """The entry whose ``traces`` name ``trace`` (the only monitors entry of the node, when one)."""
    for e in entries:
        if trace in [str(t).rstrip("/") for t in e[0].config.get("traces") or ()]:
            return e
    return entries[0] if entries and n_monitors == 1 else None


def _guarantee_place(ws: Workspace, node: str, k: int) -> str:
    cn = ws.checked.nodes.get(node)
    if cn is None or not 1 <= k <= len(cn.node.guarantees):
        return ""
    l = cn.node.guarantees[k - 1].loc
    return f"{l.file}:{l.line}:{l.col}"


def near_miss_rows(ws: Workspace, ob_rows: Sequence[ObligationRow]) -> list[NearMissRow]:
    """The report's ``near_misses`` (module docstring), in obligation order,
    space margins before time margins, guarantees in order, each a
    :class:`~rclverify.records.margin_rows.NearMissRow`."""
    rows: list[NearMissRow] = []
    nodes = {o.node for o in ob_rows if o.backend == "monitors"}
    wanted = {n: _entries(ws, n) for n in nodes}
    if not any(wanted.values()):
        return rows
    store = EvidenceStore(ws.root)
    for o in ob_rows:
        node = o.node
        if o.backend != "monitors" or not wanted.get(node) or o.status in ("failed", "error"):
            continue
        ev, problem = store.read(o.id)
        payload = monitors_payload(ev.backend, ev.details) if ev is not None and not problem else None
        if payload is None:  # no record, an altered one, or one whose payload does not decode (shown as error)
            continue
        mon = payload.monitoring
        trace = mon.trace if mon is not None else ""
        n_monitors = sum(1 for e in ws.plan.evidence.get(node, ()) if e.backend == "monitors")
        hit = _entry_of(wanted[node], trace, n_monitors)
        if hit is None:
            continue
        t, plan_place = hit[1], hit[2]

        def row(k: int, kind: Literal["value", "time"], margin: float, threshold: float, unit: str,
                atom: str, where: str, at: float | None, node: str = node, o: ObligationRow = o, trace: str = trace,
                plan_place: str = plan_place) -> NearMissRow:
            return NearMissRow(node=node, guarantee=k, kind=kind, margin=margin, threshold=threshold, unit=unit,
                               atom=atom, where=where, time=None if at is None else float(at),
                               trace=trace, obligation=o.id, source=_guarantee_place(ws, node, k),
                               threshold_source=plan_place)
        if t.value is not None and mon is not None:
            for m in mon.margins:
                v = m.margin
                limit = t.value_in(m.unit)  # in the margin's unit (0.1 mm on a margin in m: 0.0001)
                if limit is not None and v is not None and math.isfinite(v) and 0 <= v < limit:
                    rows.append(row(m.guarantee, "value", float(v), limit, m.unit, m.atom, m.where, m.time))
        if t.time_ns is not None and payload.deadlines is not None:
            for tm in payload.deadlines.time_margins:
                ns = tm.margin_ns
                if ns is not None and 0 <= ns < t.time_ns:
                    rows.append(row(tm.guarantee, "time", ns / 1e9, t.time_ns / 1e9, "s", "", tm.answer_where,
                                    tm.answer))
    return rows


def describe(r: NearMissRow) -> str:
    """One sentence: ``ScanGuard guarantee 1 held with margin 0.02 (r < 0.5), under the near-miss
    threshold 0.05, at robot: message 9 of runs/robot.jsonl``."""
    if r.kind == "time":
        what = (f"answered {r.margin * 1000:.3f} ms before its deadline, under the near-miss threshold "
                f"{r.threshold * 1000:g} ms")
    else:
        unit = f" {r.unit}" if r.unit else ""
        atom = f" ({r.atom})" if r.atom else ""
        what = f"held with margin {r.margin:g}{unit}{atom}, under the near-miss threshold {r.threshold:g}{unit}"
    return f"{r.node} guarantee {r.guarantee} {what}, at {r.where} of {r.trace}"


def sarif_results(report: AssuranceReport, result: Callable[..., SarifResult]) -> list[SarifResult]:
    """One SARIF result per near miss at its guarantee's line (level
    ``warning``); ``result(rule, level, text, where, key, props)`` is
    report/sarif.py's result maker."""
    from rclverify.report.severity import of  # deferred: start-up (one severity in every output)
    level = of("near-miss", "warning") or "note"
    out = []
    for r in report.near_misses:
        props = {"node": r.node, "guarantee": r.guarantee, "kind": r.kind, "margin": r.margin,
                 "threshold": r.threshold, "unit": r.unit, "obligation": r.obligation,
                 "threshold_source": r.threshold_source}
        out.append(result("RCL-NEAR-MISS", level, f"Near miss: {describe(r)}.", r.source or r.threshold_source,
                          f"near-miss:{r.obligation}:{r.guarantee}:{r.kind}", props))
    return out


def summary_lines(near_misses: Sequence[NearMissRow | Mapping[str, Any]], most: int = 5) -> list[str]:
    """The summary's lines: ``near misses: N ...`` and one line per near miss (at most ``most``);
    ``near_misses``: the report's rows, decoded here when given as JSON objects."""
    rows = decode_rows(NearMissRow, near_misses)
    if not rows:
        return []
    out = [f"near misses: {len(rows)} guarantee margin{'s' if len(rows) != 1 else ''} under the plan's threshold "
           "(held on every run, by little):"]
    out += [f"  {describe(r)} ({r.source})" for r in rows[:most]]
    if len(rows) > most:
        out.append(f"  ... and {len(rows) - most} more (reports/assurance.html)")
    return out


def junit_suite(report: AssuranceReport, case: Callable[..., ET.Element],
                outcome: Callable[..., str]) -> tuple[ET.Element, dict[str, int], float] | None:
    """The ``near_misses`` ``<testsuite>``: one failing ``<testcase>`` per
    near miss (``classname`` ``near_miss``, name ``<obligation>.g<k>.<kind>``,
    at the guarantee); ``case`` and ``outcome`` are report/junit.py's.
    ``None`` without near misses."""
    rows = report.near_misses
    if not rows:
        return None
    suite = ET.Element("testsuite", {"name": "near_misses"})
    counts = {"tests": 0, "failures": 0, "errors": 0, "skipped": 0}
    for r in rows:
        c = case(suite, "near_miss", f"{r.obligation}.g{r.guarantee}.{r.kind}", r.source, 0.0)
        counts["tests"] += 1
        bumped = outcome(c, "warning", f"near miss: {describe(r)}", f"threshold: {r.threshold_source}", "near-miss")
        if bumped:
            counts[bumped] += 1
    return closed(suite, counts)


def strict_reason(rows: Sequence[NearMissRow]) -> list[str]:
    """The clause a failed ``--strict`` names for the near misses ``rows`` (the report's, decoded;
    ``[]`` without)."""
    if not rows:
        return []
    names = list(dict.fromkeys(f"{r.node} guarantee {r.guarantee}" for r in rows))
    return [f"{len(rows)} near miss{'es' if len(rows) != 1 else ''}: a margin under the plan's near_miss threshold ("
            + ", ".join(names[:4]) + (", ..." if len(names) > 4 else "") + ")"]


__all__ = ["SARIF_RULES", "describe", "junit_suite", "near_miss_rows", "sarif_results", "strict_reason",
           "summary_lines"]
