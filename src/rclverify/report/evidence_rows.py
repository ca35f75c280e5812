"""The obligations' and evidence records' rows of the report: the first pass of report/build.py.

Each obligation's status is its evidence's *current* status: ``stale`` when
an input's sha256 changed since the evidence was produced, ``pending`` when
there is no record, ``error`` when the record (or the node's obligation
list) was altered outside rclverify (records/store.py), and a proof the
second solver does not confirm is downgraded (stages/crosscheck/apply.py).
A record's ``details`` is decoded once into its backend's payload where the
backend declares one (backends/payloads.py ``payload_of``); a record whose
payload does not decode is ``error``, as an altered one.  The pass returns its part (:class:`EvidencePart`) and changes nothing it
was given.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping, Sequence, cast

import msgspec

from rclverify.backends.experiment.payload import ExperimentPayload
from rclverify.backends.monitors.payload import MonitorsPayload
from rclverify.backends.payloads import Payload, payload_of
from rclverify.backends.property_tests.payload import PropertyTestsPayload
from rclverify.backends.review.payload import ReviewPayload
from rclverify.records.records import Obligation
from rclverify.records.obligations import ObligationRow
from rclverify.records.evidence_rows import EvidenceRow
from rclverify.records.solvers_rows import Solvers
from rclverify.records.verdict_rows import PendingRow
from rclverify.records.statuses import EvidenceKind, EvidenceStatus
from rclverify.records.store import EvidenceStore
from rclverify.report.statistics import compact as compact_statistics
from rclverify.stages.crosscheck.apply import SecondSolver
from rclverify.stages.workspace import Workspace


@dataclass
class EvidencePart:
    """What the evidence pass gives the report and the later passes.

    ``obligations``/``evidence``/``pending``: the report's rows;
    ``status``: obligation id -> its current status; ``declared``: node ->
    ``(record status, declaration rows)`` per record that judged the node's
    declarations; ``altered``: one problem sentence per record
    that cannot be read as rclverify wrote it; ``inputs``: obligation id ->
    the input sha256s its evidence was made from (``None``: no record)."""
    obligations: list[ObligationRow] = field(default_factory=list)
    evidence: list[EvidenceRow] = field(default_factory=list)
    pending: list[PendingRow] = field(default_factory=list)
    status: dict[str, str] = field(default_factory=dict)
    declared: dict[str, list[tuple[str, Any]]] = field(default_factory=dict)
    altered: list[str] = field(default_factory=list)
    inputs: dict[str, object] = field(default_factory=dict)


def evidence_extras(ws: Workspace, payload: Payload | None) -> tuple[list[list[str]], str]:
    """``(figures, plot_svg)``: the rows a backend asks the report to show
    (``figures_table`` of an experiment's or a review's payload; ``[]`` when
    none) and the inline SVG of its plot (an experiment's ``plot``, an SVG
    artifact the backend drew with matplotlib; ``""`` when none or
    unreadable)."""
    rows = payload.figures_table if isinstance(payload, (ExperimentPayload, ReviewPayload)) else []
    figures = [[str(a), str(b)] for a, b in rows]
    plot = payload.plot if isinstance(payload, ExperimentPayload) else None
    svg = ""
    if plot is not None and plot.endswith(".svg"):
        try:
            text = ws.path(plot).read_text(encoding="utf-8")
            svg = text[text.index("<svg"):]
        except (OSError, ValueError):
            pass
    return figures, svg


def _explanation(ev: Any, status: str, altered: str, solvers: Solvers | None) -> str:
    """The record's explanation, prefixed with why the report does not show its recorded status."""
    expl = str(ev.explanation)
    if altered:
        expl = f"{altered[0].upper()}{altered[1:]}. The record's own text follows, not to be believed: " + expl
    if solvers is not None and status != ev.status:
        expl = f"Not discharged: {solvers.why} (second solver). Z3 alone: " + expl
    if status == "stale" and ev.status != "stale":
        expl = f"STALE: an input changed since this evidence was produced (recorded status {ev.status}). " + expl
    return expl


def evidence_row(ws: Workspace, ev: Any, status: str, altered: str, solvers: Solvers | None,
                 payload: Payload | None = None) -> EvidenceRow:
    """The report's row of the evidence record ``ev`` shown with ``status``
    (``altered``: why the record is not believed, '' when it is;
    ``solvers``: the second solver's agreement, ``None`` without one;
    ``payload``: its ``details`` decoded by :func:`~rclverify.backends.payloads.payload_of`, decoded
    here when not given), an :class:`~rclverify.records.evidence_rows.EvidenceRow`.  Raises
    :class:`msgspec.ValidationError` for details that are not the backend's payload."""
    if payload is None:
        payload = payload_of(ev.backend, ev.details if isinstance(ev.details, dict) else {})
    figures, svg = evidence_extras(ws, payload)
    examples: dict[str, Any] = {}
    if isinstance(payload, PropertyTestsPayload) and payload.examples:  # example counts, seed, replay
        examples = {**payload.examples, "seed": payload.seed, "replay": payload.replay, "facts": payload.facts,
                    "coverage": payload.coverage}
    # the row holds the monitors' run and its statistics as JSON objects (records/evidence_rows.py): the payload's
    # parts encoded, the keys the record has; an experiment target's statistics likewise
    monitoring: dict[str, Any] = {}
    stats: Mapping[str, Any] | None = None
    if isinstance(payload, MonitorsPayload):
        if payload.monitoring is not None:
            monitoring = msgspec.to_builtins(payload.monitoring)
        if payload.statistics is not None:
            stats = msgspec.to_builtins(payload.statistics)
    elif isinstance(payload, ExperimentPayload) and payload.statistics is not None:
        stats = msgspec.to_builtins(payload.statistics)
    return EvidenceRow(
        obligation=ev.obligation, backend=ev.backend, kind=ev.kind, status=cast(EvidenceStatus, status),
        tool=ev.tool, tool_version=ev.tool_version, started=ev.started, duration_s=ev.duration_s,
        explanation=_explanation(ev, status, altered, solvers), counterexample=ev.counterexample,
        artifacts=list(ev.artifacts), log_excerpt=ev.log[-2000:], figures=figures, plot_svg=svg, solvers=solvers,
        examples=examples, monitoring=monitoring, statistics=compact_statistics(stats) if stats is not None else {},
    )


def _declarations(payload: Payload | None) -> list[Any] | None:
    """The node's declarations the record judged (each a row of backends/shapes.py ``DeclarationRow``):
    the property tests' and the monitors' payloads hold them; ``None`` when the record judged none."""
    if isinstance(payload, (PropertyTestsPayload, MonitorsPayload)) and payload.declarations is not None:
        return list(payload.declarations)
    return None


def evidence_part(ws: Workspace, obligations: Sequence[Obligation], altered_lists: Mapping[str, str],
                  hashes: dict[str, str], second: SecondSolver) -> EvidencePart:
    """The rows of ``obligations`` and of their evidence records (module
    docstring).  ``altered_lists``: placeholder obligation id -> why its
    node's obligation list is not believed; ``hashes``: the current input
    sha256s (stages/workspace.py), a memo the store adds the sha256s of
    the records' other inputs to (records/store.py: taken once per file,
    the files do not change while the report is built); ``second``: the
    second solver's verdicts."""
    store = EvidenceStore(ws.root)
    part = EvidencePart()
    for o in obligations:
        ev, altered = (None, altered_lists[o.id]) if o.id in altered_lists else store.read(o.id)
        payload: Payload | None = None
        if ev is not None:
            try:  # its backend's payload decoded once; one that does not decode is not believed
                payload = payload_of(ev.backend, ev.details)
            except ValueError as exc:
                altered = f"its {ev.backend} details are not that backend's payload: {exc}"
                ev = None
        part.inputs[o.id] = dict(ev.input_hashes) if ev is not None else None
        status = "error" if altered else (store.current_status(ev, hashes) if ev else "pending")
        status, agreement = second.evidence(o.id, o.backend, status)
        solvers = None if agreement is None else Solvers.of(agreement)  # stages/crosscheck/apply.py builds it
        part.status[o.id] = status
        part.obligations.append(ObligationRow(
            id=o.id, node=o.node, guarantee=o.guarantee, backend=o.backend, kind=cast(EvidenceKind, o.kind),
            instance=o.instance, statement=o.statement, source=str(o.source), artifact=o.artifact,
            status=cast(EvidenceStatus, status)))  # the record's words: the vocabulary's (records/statuses.py)
        if ev is None:
            if altered:
                part.altered.append(f"Evidence {o.id} is error: {altered}")
            else:
                part.pending.append(PendingRow(o.id, o.backend, "no evidence record yet: run `doit verify`"))
            continue
        declared = _declarations(payload)
        if declared is not None:  # a node's declarations judged
            part.declared.setdefault(o.node, []).append((status, declared))
        part.evidence.append(evidence_row(ws, ev, status, altered, solvers, payload))
        if status == "pending":
            part.pending.append(PendingRow(o.id, o.backend, ev.explanation))
    return part
