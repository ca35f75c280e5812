"""End-to-end deadlines in the report (rule D3; docs/requirements.md,
"End-to-end deadlines"; docs/reading-the-report.md).

The ``deadlines`` stage (:mod:`rclverify.stages.deadlines`) decides
each requirement's ``deadline:`` with Z3.  Here its sealed record becomes
one row per deadline of the current plan (:func:`deadline_rows`):

* ``verdict``: ``proved`` / ``refuted`` / ``inconclusive`` as decided;
  ``status``: a refuted one ``failed``, a proved one the worst evidence
  status of its chain's guarantees (``discharged`` only when all are:
  proved from premises not yet established is no green tick);
  ``pending`` before the stage ran (or when the record is about another
  path or bound than the plan's now); ``stale`` when made from another
  text of the contracts or plan; ``error`` when its seal does not hold
  (never what it claims);
* ``chain``: the hops node by node, each guarantee's deadline, location,
  evidence status and the deadline verdicts the monitors recorded for its
  node (``true`` / ``currently_false`` / ``false`` counts, the first
  ``false`` with its stamps);
* ``time_margin``/``time_margin_ns``: the chain's measured margin, the
  bound less every hop's worst measured latency summed
  (:func:`.chain_margins.chain_margin`; ``None`` unless every hop has one);
* ``total`` (the sum), ``within`` (the requirement's bound), ``reason``
  (the chain named), ``stamps`` (a late run, for a refuted one), ``smt2``.

:func:`fold_into` rolls a row into its requirement: a requirement whose
deadline is refuted is ``refuted`` (status ``failed``), never met; a met
one whose deadline is proved from a chain with outstanding evidence is
``proved, evidence outstanding``; one
whose deadline is not decided (inconclusive, pending) is at best
``inconclusive``; stale and error carry over.  A proved deadline leaves
the requirement's own verdict (an informal requirement stays informal:
its text is not checked).  ``--strict`` fails unless every deadline is
proved from a chain whose evidence is discharged, each hop's deadline
measured on a run (a hop whose guarantee only a property test or a proof
covers is ``pending``: they check its formula, not its time)
(:func:`strict_ok`, :func:`strict_reason`).  SARIF
(``RCL-DEADLINE-REFUTED``, ``RCL-DEADLINE-INCONCLUSIVE``) and JUnit (a
``deadlines`` test suite) are laid out here too.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import Any, Callable, Mapping, NamedTuple, Sequence, cast

import msgspec
from msgspec.structs import replace

from rclverify.backends.monitors.payload import DeadlineBlock, monitors_payload
from rclverify.records.deadline_rows import DeadlineHop, DeadlineRow
from rclverify.records.report_record import AssuranceReport
from rclverify.records.obligations import ObligationRow
from rclverify.records.requirement_rows import RequirementRow, WithoutDeadline
from rclverify.records.solvers_rows import Solvers
from rclverify.records.statuses import DeadlineVerdict, EvidenceStatus
from rclverify.records.sarif import SarifResult
from rclverify.records.records import worst
from rclverify.records.statuses import DEADLINE_STATUS
from rclverify.stages.workspace import Workspace
from rclverify.records.store import EvidenceStore
from rclverify.report.chain_margins import chain_margin, hop_margin
from rclverify.report.junit_suite import closed

#: A deadline verdict as an evidence status (the report's badges and roll-up).
STATUS_OF = {"proved": "discharged", **DEADLINE_STATUS}  # records/statuses.py, "Verdict and status"
#: Requirement verdicts a deadline that is not proved never improves.
_WORSE = ("refuted", "proved from an inconsistency", "proved vacuously", "error")


def _spec_of(rec: Mapping[str, Any], spec: Any) -> bool:
    """Whether the record ``rec`` was decided for the plan's ``spec`` (same path and bound)."""
    from fractions import Fraction  # deferred: start-up (loads fractions only when called)
    try:
        within = Fraction(str(rec.get("within_s")))
    except (ValueError, ZeroDivisionError):
        return False
    return list(rec.get("path") or []) == list(spec.path) and within == spec.within


def deadline_rows(ws: Workspace, current: Mapping[str, str], g_status: Callable[[str, int], str],
                  ob_rows: Sequence[ObligationRow], second: Any = None) -> list[DeadlineRow]:
    """One row per ``deadline:`` of ``ws``'s plan, in plan order (module
    docstring), each a :class:`~rclverify.records.deadline_rows.DeadlineRow`.  ``current``: path -> sha256 of the current snapshots and
    model (:func:`rclverify.stages.provenance.current_snapshot_hashes`);
    ``g_status(node, k)``: a guarantee's evidence status; ``ob_rows``: the
    report's obligation rows (``id``, ``node``, ``backend``, ``status``).
    ``second``: the second solver's verdicts (:class:`rclverify.stages.crosscheck.apply.SecondSolver`),
    which make a proved deadline they do not agree on inconclusive.
    Returns ``[]`` for a plan without deadlines."""
    from rclverify.stages.deadlines import INDEX, read_deadlines  # deferred: start-up (loads yaml, z3 and more only when called)
    from rclverify.calculus.deadlines import show_seconds as _show  # deferred: start-up (loads yaml, z3 and more only when called)
    specs = list(ws.plan.deadlines)
    if not specs:
        return []
    records, why = read_deadlines(ws, current)
    by_req = {str(r.get("requirement")): r for r in records or []}
    monitors = _monitor_verdicts(ws, ob_rows, {n for s in specs for n in s.path})
    rows: list[DeadlineRow] = []
    for spec in specs:
        rec = by_req.get(spec.requirement)
        rec = rec if not why and rec is not None and _spec_of(rec, spec) else None  # None: no decision shown
        if rec is not None and second is not None:
            rec = second.deadline(rec)
        verdict, reason = _verdict(rec, why, INDEX)
        chain = [_hop(h, g_status(str(h["node"]), int(h["guarantee"])), monitors.get(str(h["node"]), []))
                 for h in (rec or {}).get("chain") or []]
        measured = chain_margin(spec.within, chain)
        # the timed guarantees the decision rests on: their evidence (the monitors check the stamps)
        evidence_status = cast(EvidenceStatus, worst([str(h.status) for h in chain], empty="pending"))
        rows.append(DeadlineRow(
            requirement=spec.requirement, path=list(spec.path), within=_show(spec.within),
            source=f"{spec.loc.file}:{spec.loc.line}:{spec.loc.col}", verdict=verdict,
            # proved is a green tick only when every hop's guarantee is discharged (as a requirement's "met")
            status=evidence_status if verdict == "proved" else STATUS_OF[verdict],
            evidence_status=evidence_status, reason=reason, chain=chain, total=(rec or {}).get("total"),
            time_margin=None if measured is None else f"{measured / 1e6:.3f} ms", time_margin_ns=measured,
            stamps=list((rec or {}).get("stamps") or []), smt2=str((rec or {}).get("smt2") or ""),
            solvers=msgspec.UNSET if rec is None else _solvers(rec.get("solvers"))))
    return rows


def _verdict(rec: Mapping[str, Any] | None, why: str, index: str) -> tuple[DeadlineVerdict, str]:
    """``(verdict, reason)`` of a deadline from its stage record ``rec`` (``None``: none decided for the plan's
    path and bound now, or none believed); ``why``: why the stage's record is not believed (``""`` when it
    is); ``index``: the record's path."""
    if why:
        return "error", f"error: {why}; the recorded verdict is not shown"
    if rec is None:
        return "pending", f"not decided yet for this path and bound ({index}): run `doit verify`"
    verdict = str(rec.get("status"))
    reason = str(rec.get("reason", ""))
    if verdict == "stale":
        reason = f"STALE: {reason}; recorded verdict {rec.get('recorded_status')}"
    return cast(DeadlineVerdict, verdict if verdict in STATUS_OF else "error"), reason


def _solvers(s: Any) -> Solvers | None | msgspec.UnsetType:
    """A deadline record's ``solvers`` (stages/crosscheck/apply.py) as the row holds it: absent when the
    record has none."""
    return Solvers.of(s) if isinstance(s, Mapping) else None if s is None else msgspec.UNSET


class HopRun(NamedTuple):
    """A monitored run of a hop's node: its ``obligation``, that obligation's ``status`` in the report and its
    evidence's deadline record (the monitors' payload ``deadlines``)."""

    obligation: str
    status: str
    deadlines: DeadlineBlock

    def to_json(self) -> dict[str, Any]:
        """The run as the hop's row holds it (records/deadline_rows.py ``DeadlineHop.monitors``)."""
        d = self.deadlines
        return {"obligation": self.obligation, "status": self.status, "counts": dict(d.counts),
                "first_false": d.first_false, "time_margins": [msgspec.to_builtins(t) for t in d.time_margins]}


def _hop(h: Mapping[str, Any], status: str, monitors: list[HopRun]) -> DeadlineHop:
    """The stage's hop ``h`` (records/stage_records.py ``DeadlineHop``) as the report's row: its guarantee's
    evidence ``status``, its node's monitored runs ``monitors``, whether a run timed it
    (:func:`_timing_measured`) and its smallest time margin on the runs (:func:`.chain_margins.hop_margin`)."""
    status, timing = _timing_measured(status, monitors, str(h.get("within", "")))
    return DeadlineHop(node=str(h["node"]), guarantee=int(h["guarantee"]), trigger=str(h["trigger"]),
                       outputs=[str(o) for o in h["outputs"]], within_s=str(h["within_s"]), within=str(h["within"]),
                       loc=str(h["loc"]), status=cast(EvidenceStatus, status), timing=timing,
                       monitors=[m.to_json() for m in monitors],
                       time_margin=hop_margin(int(h["guarantee"]),
                                              [(m.obligation, m.deadlines.time_margins) for m in monitors]))


def _timing_measured(status: str, monitors: Sequence[HopRun], within: str) -> tuple[str, str | msgspec.UnsetType]:
    """``(status, timing)`` of a hop whose guarantee's evidence status is
    ``status``: one discharged by evidence that checks only its formula (a
    property test, a proof: backends/timing_scope.py) while no run timed it
    (no monitors' deadline record of its node, of ``monitors``, with a
    ``true`` verdict and no ``false`` one) is ``pending``: the deadline
    ``within`` the sum rests on was measured by nothing (a proved deadline
    is no green tick on an unmeasured hop); ``timing`` says so, ``UNSET``
    otherwise."""
    if status != "discharged":
        return status, msgspec.UNSET
    timed = [m for m in monitors if m.status == "discharged" and m.deadlines.counts.get("true", 0) > 0]
    if timed:
        return status, msgspec.UNSET
    return "pending", (f"its {within} deadline is measured by no run: its evidence checks the "
                       "guarantee's formula only (a monitors entry on a recorded or live run times it)")


def _monitor_verdicts(ws: Workspace, ob_rows: Sequence[ObligationRow], nodes: set[str]) -> dict[str, list[HopRun]]:
    """node -> its monitored runs with their deadline records (``details["deadlines"]``,
    backends/monitors/deadlines.py), decoded."""
    store = EvidenceStore(ws.root)
    out: dict[str, list[HopRun]] = {}
    for o in ob_rows:
        if o.backend != "monitors" or o.node not in nodes:
            continue
        ev, problem = store.read(o.id)
        payload = monitors_payload(ev.backend, ev.details) if ev is not None and not problem else None
        d = payload.deadlines if payload is not None else None
        if d is not None:
            out.setdefault(o.node, []).append(HopRun(o.id, o.status, d))
    return out


def fold_into(requirements: Sequence[RequirementRow], rows: Sequence[DeadlineRow]) -> list[RequirementRow]:
    """``requirements`` with each deadline row of ``rows`` rolled into its
    requirement row (module docstring): a new row with the requirement's
    ``deadline`` (the row), ``without_deadline`` (its own verdict, status
    and note) and, unless the deadline is proved from discharged evidence,
    its ``verdict``, ``status`` and ``note``.  The rows given are left as
    they are; a requirement without a deadline is returned as it is."""
    by_req = {r.requirement: r for r in rows}
    return [_with_deadline(rq, by_req[rq.id]) if rq.id in by_req else rq for rq in requirements]


def _with_deadline(own: RequirementRow, row: DeadlineRow) -> RequirementRow:
    """The requirement row ``own`` with the deadline ``row`` rolled in (:func:`fold_into`)."""
    # the requirement as its own check left it: its own argument is built from it (report/argument/deadlines.py)
    rq = replace(own, deadline=row, without_deadline=WithoutDeadline(own.verdict, own.status, own.note))
    v, st = row.verdict, "discharged" if row.status is msgspec.UNSET else row.status
    if v == "proved":
        if st != "discharged":  # the chain's evidence is outstanding: not met yet
            open_steps = [f"{c.node} guarantee {c.guarantee} ({c.status})"
                          for c in row.chain or () if c.status != "discharged"]
            rq = replace(rq, verdict="proved, evidence outstanding" if own.verdict == "met" else own.verdict,
                         status=worst([own.status, st]),
                         note=(f"end-to-end deadline proved, evidence of its chain {st}"
                               + (f": {', '.join(open_steps)}" if open_steps else "")
                               + (f"; without the deadline: {own.note}" if own.note else "")))
        return rq
    said = f"end-to-end deadline {row.within} along {' -> '.join(row.path)} {v}: {row.reason}"
    old, verdict = own.verdict, own.verdict
    if v == "refuted" and old != "error":
        verdict = "refuted"
    elif v in ("stale", "error") and old not in _WORSE:
        verdict = v
    elif v in ("inconclusive", "pending") and old not in _WORSE and old != "stale":
        verdict = "inconclusive"
    return replace(rq, verdict=verdict, status=worst([own.status, st]),
                   note=said + (f"; {own.note}" if own.note and old != "informal" else ""))


def strict_ok(rows: Sequence[DeadlineRow]) -> bool:
    """``--strict`` holds for the deadlines: every one is proved, and every
    hop of its chain discharged with its deadline measured on a run
    (:func:`_timing_measured`)."""
    return all(r.verdict == "proved" and r.status in (msgspec.UNSET, "discharged") for r in rows)


def strict_reason(rows: Sequence[DeadlineRow]) -> list[str]:
    """The clause ``verify --strict`` names for the deadlines ``rows`` (the
    report's ``deadlines``, decoded) that are not proved (``[]`` when every
    one is): "1 end-to-end deadline is refuted (STOP)"."""
    bad = [r for r in rows if r.verdict != "proved"]
    out = []
    if bad:
        verdicts = sorted({r.verdict for r in bad})
        out.append(f"{len(bad)} end-to-end deadline{'s are' if len(bad) != 1 else ' is'} {' or '.join(verdicts)} ("
                   + ", ".join(r.requirement for r in bad[:4]) + (", ..." if len(bad) > 4 else "") + ")")
    open_ = [r for r in rows if r.verdict == "proved" and r.status not in (msgspec.UNSET, "discharged")]
    if open_:
        out.append(f"{len(open_)} end-to-end deadline{'s are' if len(open_) != 1 else ' is'} proved from a chain "
                   "whose evidence is outstanding (a hop unverified, or its deadline measured by no run: "
                   + ", ".join(r.requirement for r in open_[:4]) + (", ..." if len(open_) > 4 else "") + ")")
    return out


def _chain(row: DeadlineRow) -> list[DeadlineHop]:
    return [] if row.chain is msgspec.UNSET else row.chain


def _chain_text(row: DeadlineRow) -> str:
    return " -> ".join(f"{h.node} guarantee {h.guarantee} ({h.trigger} -> {', '.join(h.outputs)} "
                       f"within {h.within}, {h.loc})" for h in _chain(row)) or "no chain"


def _said(value: Any, empty: Any = None) -> Any:
    """A row's field as its JSON object holds it, ``empty`` for one the row leaves unset."""
    return empty if value is msgspec.UNSET else value


#: SARIF rules of the deadlines (``id``, ``name``, ``level``, ``text``), listed by report/sarif.py.
SARIF_RULES = (
    ("RCL-DEADLINE-REFUTED", "DeadlineRefuted", "error",
     "A requirement's end-to-end deadline is refuted: the deadlines of the timed guarantees along its path sum "
     "past its bound (rule D3); the chain is named."),
    ("RCL-DEADLINE-INCONCLUSIVE", "DeadlineInconclusive", "warning",
     "A requirement's end-to-end deadline is not decided: no chain of timed guarantees along its path, not "
     "decided yet, made from other inputs (stale) or its record altered (then at level error)."),
)


def sarif_results(report: AssuranceReport, result: Callable[..., SarifResult]) -> list[SarifResult]:
    """One SARIF result per deadline that is not proved, at the plan's
    ``deadline:`` entry; ``result(rule, level, text, where, key, props)``
    is report/sarif.py's result maker."""
    out = []
    for r in report.deadlines:
        if r.verdict == "proved":
            continue
        from rclverify.report.severity import of  # deferred: optional or conditional (inside a block)
        rule = "RCL-DEADLINE-REFUTED" if r.verdict == "refuted" else "RCL-DEADLINE-INCONCLUSIVE"
        level = of("deadline", r.verdict) or "note"  # one severity in every output (report/severity.py)
        words = [f"End-to-end deadline of {r.requirement} ({r.within} along {' -> '.join(r.path)}) is "
                 f"{r.verdict}: {_said(r.reason, '')}."]
        if _chain(r):
            words.append(f"Chain: {_chain_text(r)}; sum {_said(r.total)}.")
        stamps = _said(r.stamps, [])  # each a late run's event and its time from the run's start (timing stage)
        if stamps:
            words.append("A late run: " + ", ".join(f"{s['event']} at t0 + {float_text(s['t_s'])} s"
                                                   for s in stamps) + ".")
        props = {"requirement": r.requirement, "verdict": r.verdict, "within": r.within,
                 "total": _said(r.total), "chain": [f"{h.node}.g{h.guarantee}" for h in _chain(r)]}
        out.append(result(rule, level, " ".join(words), r.source, f"deadline:{r.requirement}", props))
    return out


def float_text(fraction: Any) -> str:
    """An exact fraction of seconds as text (``"1/4"``) in decimal (``0.25``)."""
    from fractions import Fraction  # deferred: start-up (loads fractions only when called)
    try:
        return f"{float(Fraction(str(fraction))):g}"
    except (ValueError, ZeroDivisionError):
        return str(fraction)


def junit_suite(report: AssuranceReport, case: Callable[..., ET.Element],
                outcome: Callable[..., str]) -> tuple[ET.Element, dict[str, int], float] | None:
    """The ``deadlines`` ``<testsuite>``: one ``<testcase>`` per deadline
    (``classname`` ``deadline``, name the requirement id, at the plan's
    entry), passing only when proved; ``case`` and ``outcome`` are
    report/junit.py's.  ``None`` without deadlines."""
    rows = report.deadlines
    if not rows:
        return None
    suite = ET.Element("testsuite", {"name": "deadlines"})
    counts = {"tests": 0, "failures": 0, "errors": 0, "skipped": 0}
    for r in rows:
        c = case(suite, "deadline", r.requirement, r.source, 0.0)
        counts["tests"] += 1
        bumped = outcome(c, _said(r.status, ""), f"{r.verdict}: {_said(r.reason, '')}",
                         "\n".join([f"deadline {r.within} along {' -> '.join(r.path)}",
                                    f"chain: {_chain_text(r)}", f"sum: {_said(r.total)}", f"verdict: {r.verdict}"]))
        if bumped:
            counts[bumped] += 1
    return closed(suite, counts)
