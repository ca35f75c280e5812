"""Recorded runs as evidence for a temporal requirement (docs/plan.md, "Traces of a temporal requirement").

Which runs: the traces of the plan's ``monitors`` entries of the nodes the
statement reads, each with its entry's mapping file (the one the plan names
for the entry, :func:`~rclverify.model.plan.mapping_file.plan_mapping`; no new plan key: a run the
plan records for a node is a run of the system those nodes are part of).
A trace named by several entries is checked once, with the first entry's
mapping.

Each trace gives one row of the requirement record's ``traces`` list
(:func:`trace_rows`), ``{"trace", "sha256", "mapping", "status",
"verdict": TraceVerdict.to_json()}`` with the evidence status:

==================  =============  ===============================================
trace verdict       status         meaning for the requirement
==================  =============  ===============================================
``false``           ``failed``     the run refutes it: never ``met``
``true``            ``discharged`` the run satisfies it (for ``always``: on this
                                   run only, evidence, never a proof)
``currently_false`` ``inconclusive``  not reached when the run ended
``inconclusive``    ``inconclusive``  undecided operand or too short a run
(unreadable trace)  ``error``      the located message
==================  =============  ===============================================

The rows live in the requirement's sealed record (stages/requirements.py), so
they are sealed with it; the record's ``inputs`` hold each trace's sha256
under ``trace:<path>`` (:func:`trace_hashes`), and its fingerprint holds
them too: an edited trace re-checks the requirement in the stage and shows
the record ``stale`` in ``rclverify report`` before that.
"""
from __future__ import annotations

from pathlib import Path

from rclverify.model.plan.mapping_file import plan_mapping
from rclverify.model.plan.model import Plan, Requirement
from rclverify.model.plan.state import state_types
from rclverify.model.plan.temporal import Temporal, operands, parse_temporal
from rclverify.lang.errors import RclError
from rclverify.lang.types import Checked
from rclverify.traces import TraceError, read_trace
from rclverify.traces.files import trace_sha256
from rclverify.backends.monitors.config import ConfigError, load_mapping
from rclverify.backends.monitors.temporal_trace import check_temporal_trace
from rclverify.records.stage_records import TraceFailure, TraceRow, TraceVerdictJson
import hashlib
import json

STATUS = {"false": "failed", "true": "discharged", "currently_false": "inconclusive", "inconclusive": "inconclusive"}


def requirement_traces(req: Requirement, checked: Checked, plan: Plan) -> list[tuple[str, str | None]]:
    """``[(trace, mapping)]`` of a temporal requirement (module docstring);
    ``[]`` for a state requirement or a statement that does not parse."""
    if req.formal is None:
        return []
    try:
        t = parse_temporal(req.formal, checked, req.id, state_types(plan.states, checked))
    except RclError:
        return []
    if not isinstance(t, Temporal):
        return []
    nodes = {n for f in operands(t) for n in f.nodes}
    out: dict[str, str | None] = {}
    for n in checked.nodes:
        if n not in nodes:
            continue
        for e in plan.evidence.get(n, ()):
            if e.backend == "monitors":
                for tr in e.config.get("traces", ()) or ():
                    out.setdefault(str(tr), plan_mapping(plan, n, e.config))
    return list(out.items())


def trace_key(trace: str) -> str:
    """The key of a trace's sha256 in a requirement record's ``inputs``."""
    return f"trace:{trace}"


def trace_hashes(root: Path, traces: list[tuple[str, str | None]]) -> dict[str, str]:
    """``{trace:<path>: sha256}`` of ``traces`` (a missing one: ``"missing"``)."""
    out = {}
    for tr, _ in traces:
        try:
            out[trace_key(tr)] = trace_sha256(root, tr)
        except OSError:
            out[trace_key(tr)] = "missing"
    return out


def fingerprint_text(root: Path, traces: list[tuple[str, str | None]]) -> str:
    """What a requirement's fingerprint adds for its recorded runs: each
    trace's sha256 and its mapping file's (the mapping decides the values)."""
    out = []
    for tr, mapping in traces:
        m = root / mapping if mapping else None
        msha = hashlib.sha256(m.read_bytes()).hexdigest() if m is not None and m.is_file() else ""
        out.append([tr, trace_hashes(root, [(tr, mapping)])[trace_key(tr)], mapping, msha])
    return json.dumps(out)


def trace_rows(req: Requirement, checked: Checked, plan: Plan, root: Path) -> list[TraceRow]:
    """One row per trace of ``req`` (module table); never raises for a
    user-caused problem (an unreadable trace or mapping is an ``error`` row)."""
    rows: list[TraceRow] = []
    traces = requirement_traces(req, checked, plan)
    if not traces:
        return rows
    t = parse_temporal(req.formal, checked, req.id, state_types(plan.states, checked))  # type: ignore[arg-type]
    assert isinstance(t, Temporal)
    for tr, mapping in traces:
        sha = trace_hashes(root, [(tr, mapping)])[trace_key(tr)]
        verdict: TraceVerdictJson | TraceFailure
        try:
            cfg = load_mapping(root, mapping)
            v = check_temporal_trace(t, checked, plan.states,
                                     read_trace(root / tr, [root / d for d in cfg.msg_dirs]), cfg.rules)
            status, verdict = STATUS[v.verdict], v.to_json()
        except (TraceError, ConfigError, OSError, RclError) as exc:
            status, verdict = "error", {"verdict": "error", "reason": str(exc)}
        rows.append({"trace": tr, "mapping": mapping, "sha256": sha, "status": status, "verdict": verdict})
    return rows


__all__ = ["STATUS", "fingerprint_text", "requirement_traces", "trace_hashes", "trace_key", "trace_rows"]
