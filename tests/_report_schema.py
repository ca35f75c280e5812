"""Checking an assurance report against its published schema and the status vocabulary.

Shared by tests/report/test_report_schema.py and the tests that verify a whole
workspace (tests/report/test_pipeline_e2e.py, the examples' tests): each hands the
reports it already built to :func:`check_report`, so no workspace is verified
twice for this check.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Iterator

from jsonschema import Draft202012Validator

from rclverify.records.statuses import VOCABULARY, contradictions

SCHEMA_PATH = Path(__file__).resolve().parents[1] / "docs" / "assurance.schema.json"
SCHEMA: dict[str, Any] = json.loads(SCHEMA_PATH.read_text(encoding="utf-8"))
VALIDATOR = Draft202012Validator(SCHEMA)

#: Every status word of a report by where it sits (``[]``: each element of a list) and its set of
#: :data:`rclverify.records.statuses.VOCABULARY`; ``*`` accepts a word of any set but the
#: agreements, lint severities and evidence kinds (a problem row's member keeps its item's own word).
STATUS_FIELDS: tuple[tuple[str, str], ...] = (
    ("summary.status", "evidence_status"),
    ("system.nodes[].status", "evidence_status"),
    ("requirements[].status", "evidence_status"),
    ("requirements[].verdict", "requirement_verdict"),
    ("requirements[].support[].status", "evidence_status"),
    ("requirements[].deadline.verdict", "deadline_verdict"),
    ("requirements[].deadline.status", "evidence_status"),
    ("requirements[].without_deadline.verdict", "requirement_verdict"),
    ("requirements[].without_deadline.status", "evidence_status"),
    ("nodes[].status", "evidence_status"),
    ("nodes[].guarantees[].status", "evidence_status"),
    ("side_conditions[].status", "evidence_status"),
    ("side_conditions[].verdict", "side_condition_verdict"),
    ("derived_properties[].status", "evidence_status"),
    ("derived_properties[].evidence_status", "evidence_status"),
    ("derived_properties[].derivation", "derivation"),
    ("findings[].status", "health_status"),
    ("obligations[].status", "evidence_status"),
    ("obligations[].kind", "evidence_kind"),
    ("evidence[].status", "evidence_status"),
    ("evidence[].kind", "evidence_kind"),
    ("lint[].severity", "lint_severity"),
    ("acknowledgements[].status", "acknowledgement_status"),
    ("unverified[].status", "evidence_status"),
    ("deadlines[].verdict", "deadline_verdict"),
    ("deadlines[].status", "evidence_status"),
    ("deadlines[].evidence_status", "evidence_status"),
    ("deadlines[].chain[].status", "evidence_status"),
    ("problems[].status", "evidence_status"),
    ("problems[].members[].status", "*"),
    ("diagnoses[].status", "*"),
)
_ANY = {w for name, words in VOCABULARY.items() if name not in ("agreement", "lint_severity", "evidence_kind")
        for w in words}


def _at(x: Any, parts: list[str], where: str) -> Iterator[tuple[str, Any]]:
    """The values at the dotted path ``parts`` under ``x``, each with its concrete path."""
    if not parts:
        yield where, x
        return
    head, rest = parts[0], parts[1:]
    many = head.endswith("[]")
    key = head[:-2] if many else head
    if not isinstance(x, dict) or key not in x or x[key] is None:
        return
    if many:
        for i, item in enumerate(x[key]):
            yield from _at(item, rest, f"{where}{key}[{i}].")
    else:
        yield from _at(x[key], rest, f"{where}{key}.")


def _agreements(x: Any, where: str = "") -> Iterator[tuple[str, Any]]:
    """Every ``agreement`` of a ``solvers`` record anywhere in ``x``."""
    if isinstance(x, dict):
        for k, v in x.items():
            if k.endswith("solvers") and isinstance(v, dict) and "agreement" in v:
                yield f"{where}{k}.agreement", v["agreement"]
            yield from _agreements(v, f"{where}{k}.")
    elif isinstance(x, list):
        for i, v in enumerate(x):
            yield from _agreements(v, f"{where}[{i}].")


def out_of_vocabulary(report: dict[str, Any]) -> list[str]:
    """``path: word`` for every status word of ``report`` outside its set (empty when all are in)."""
    bad = []
    for spec, name in STATUS_FIELDS:
        allowed = _ANY if name == "*" else set(VOCABULARY[name])
        for where, word in _at(report, spec.split("."), ""):
            if word not in allowed:
                bad.append(f"{where.rstrip('.')}: {word!r} is not in {name}")
    bad += [f"{w}: {a!r}" for w, a in _agreements(report) if a not in VOCABULARY["agreement"]]
    bad += [f"summary.counts: {k!r}" for k in report.get("summary", {}).get("counts", {})
            if k not in VOCABULARY["evidence_status"]]
    return bad


def schema_errors(report: dict[str, Any], limit: int = 10) -> list[str]:
    """The first ``limit`` violations of docs/assurance.schema.json, as ``path: message``."""
    out = []
    for e in VALIDATOR.iter_errors(report):
        out.append(f"{'/'.join(map(str, e.absolute_path)) or '(top)'}: {e.message[:300]}")
        if len(out) >= limit:
            break
    return out


def words_seen(report: dict[str, Any]) -> set[str]:
    """Every status word :data:`STATUS_FIELDS` finds in ``report``."""
    return {w for spec, _ in STATUS_FIELDS for _, w in _at(report, spec.split("."), "")}


def check_report(report: dict[str, Any], label: str = "") -> None:
    """Assert that ``report`` matches the schema, that each status word is in its set, and that each
    row's status follows from its verdict (records/statuses.py, "Verdict and status")."""
    assert not schema_errors(report), (label, schema_errors(report))
    assert not out_of_vocabulary(report), (label, out_of_vocabulary(report)[:10])
    assert not contradictions(report), (label, contradictions(report)[:10])
