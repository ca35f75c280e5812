"""Every backend's evidence payload is a Struct tagged by ``backend`` (backends/<backend>/payload.py; the ``ajpf``
backend's in backends/model_checking/payload.py), decoded once by the report's evidence pass
(backends/payloads.py ``payload_of``, report/evidence_rows.py): a record's ``details`` decodes into the one
its backend names, a key that payload does not declare makes the record ``error`` in one sentence (the
control: the same record without it is shown), and a backend no payload is declared for is not decoded.
In-process: evidence records written to a temporary workspace, no pipeline.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import msgspec
import pytest

from rclverify.backends.hoare.payload import HoarePayload
from rclverify.backends.payloads import TYPED, payload_of
from rclverify.backends.property_tests.payload import PropertyTestsPayload
from rclverify.records.records import Evidence, Obligation, SourceRef, hash_inputs
from rclverify.records.store import EvidenceStore
from rclverify.report.evidence_rows import evidence_part
from rclverify.stages.crosscheck.apply import SecondSolver
from rclverify.stages.workspace import Workspace

_RUN = PropertyTestsPayload(examples={"run": 100, "valid": 90, "rejected": 10, "failures": 0, "inconclusive": 0},
                            seed=7, max_examples=100, implementation="impl.py:step", replay="replay-command",
                            facts=["in.x >= 0 (plan.yaml:3:5)"])


def test_a_payload_round_trips_through_its_details_and_its_tag() -> None:
    assert TYPED == {"hoare", "property_tests", "monitors", "experiment", "review", "dafny", "ajpf"}
    hoare = HoarePayload(vcs={"main": "valid"}, program="prog.imp", triple={"pre": "true", "post": "y > 0"})
    for backend, payload in (("hoare", hoare), ("property_tests", _RUN)):
        details = payload.details()
        assert "backend" not in details  # the record names its backend itself
        assert payload_of(backend, details) == payload
    # a field at its default is left out of the record; a run cut short holds only what cut it
    assert PropertyTestsPayload(timeout_s=0.05).details() == {"timeout_s": 0.05}
    assert "deadline_ms" not in _RUN.details() and _RUN.details()["seed"] == 7
    # a backend no payload is declared for (none of rclverify's) is not decoded here
    assert payload_of("a_plugin", {"figures_table": [["runs", "3"]]}) is None
    # a key the backend's payload does not declare, or a value of another type, is refused
    with pytest.raises(msgspec.ValidationError, match="margin_added_here"):
        payload_of("hoare", {**hoare.details(), "margin_added_here": "0.5 m"})
    with pytest.raises(msgspec.ValidationError, match="seed"):
        payload_of("property_tests", {**_RUN.details(), "seed": "seven"})


def _evidence(root: Path, oid: str, backend: str, details: dict[str, Any]) -> Evidence:
    return Evidence(obligation=oid, backend=backend, kind="testing", status="discharged", tool="hypothesis",
                    tool_version="6", started="2026-01-01T00:00:00+00:00", duration_s=0.5,
                    input_hashes=hash_inputs(root, ["impl.py"]), details=details)


def _obligation(oid: str, backend: str) -> Obligation:
    return Obligation(id=oid, node="N", guarantee=1, backend=backend, kind="testing", statement="out.y > 0",
                      source=SourceRef("a.rcl", 3, 4))


def test_the_evidence_pass_decodes_each_payload_once_and_refuses_an_undeclared_key(tmp_path: Path) -> None:
    (tmp_path / "impl.py").write_text("def step(x): return x\n")
    store = EvidenceStore(tmp_path)
    good, bad = "N.g1.property_tests.ok", "N.g1.property_tests.bad"
    store.put(_evidence(tmp_path, good, "property_tests", _RUN.details()))
    store.put(_evidence(tmp_path, bad, "property_tests", {**_RUN.details(), "margin_added_here": "0.5 m"}))
    part = evidence_part(Workspace(tmp_path), [_obligation(good, "property_tests"),
                                               _obligation(bad, "property_tests")], {}, {}, SecondSolver({}))
    # the control: the record whose payload decodes is shown, its examples from the decoded payload
    assert part.status == {good: "discharged", bad: "error"}
    [row] = part.evidence
    assert row.obligation == good and row.examples["seed"] == 7 and row.examples["replay"] == "replay-command"
    assert row.examples["facts"] == ["in.x >= 0 (plan.yaml:3:5)"] and row.examples["valid"] == 90
    # the other is error, in one sentence naming the key
    [said] = part.altered
    assert said.startswith(f"Evidence {bad} is error: its property_tests details are not that backend's payload")
    assert "margin_added_here" in said


def test_a_monitored_runs_row_is_encoded_from_its_payload_and_an_undeclared_key_is_error(tmp_path: Path) -> None:
    """The monitors' record: the row's ``monitoring`` and ``statistics`` are the decoded payload's parts
    encoded (the keys the record has, an unset one absent); a margin with a key its Struct does not declare
    makes the record error (the control: the same record without it is shown)."""
    (tmp_path / "impl.py").write_text("def step(x): return x\n")
    store = EvidenceStore(tmp_path)
    run: dict[str, Any] = {"monitoring": {"trace": "runs/a.jsonl", "counts": {"satisfied": 3},
                                          "margins": [{"guarantee": 1, "margin": 0.25, "answers": 3,
                                                       "lowest": [0.25]}]},
                           "statistics": {"trace": "runs/a.jsonl", "sha256": "ab" * 32, "answers": 3, "violations": 0}}
    good, bad = "N.g0.monitors.ok", "N.g0.monitors.bad"
    store.put(_evidence(tmp_path, good, "monitors", run))
    margin = {**run["monitoring"]["margins"][0], "margin_added_here": 1}
    store.put(_evidence(tmp_path, bad, "monitors", {**run, "monitoring": {**run["monitoring"], "margins": [margin]}}))
    part = evidence_part(Workspace(tmp_path), [_obligation(good, "monitors"), _obligation(bad, "monitors")], {}, {},
                         SecondSolver({}))
    assert part.status == {good: "discharged", bad: "error"}
    [row] = part.evidence
    assert row.monitoring["trace"] == "runs/a.jsonl" and row.monitoring["margins"][0]["lowest"] == [0.25]
    assert "trace" not in row.monitoring["margins"][0]  # unset in the record: absent in the row
    assert row.statistics == run["statistics"]
    [said] = part.altered
    assert said.startswith(f"Evidence {bad} is error: its monitors details are not that backend's payload")
    assert "margin_added_here" in said


#: each backend's details as its producer writes them (backends/experiment/backend.py and target.py,
#: backends/review/backend.py, backends/dafny/verdict.py and backend.py, backends/model_checking/backend.py
#: and ajpf/backend.py), with a key only some records hold
_WRITTEN: dict[str, dict[str, Any]] = {
    "experiment": {"criterion": "worst <= tolerance", "file": "runs.csv",
                   "figures": {"worst": {"as_written": "12 cm", "base_value": "0.12", "dimension": "length"}},
                   "constants": {"tolerance": "25 cm"}, "criterion_holds": True, "flags": [], "per_trial": False,
                   "failing_trials": [], "figures_table": [["worst", "0.12 m"]], "plot": None},
    "review": {"reviewer": "R", "author": "", "independence": "", "date": "2026-01-01", "scope": "impl",
               "files": [{"path": "impl.py", "sha256": "ab" * 32}], "verdict": "pass",
               "checklist": [{"id": "q1", "question": "Is it so?", "location": "a.rcl:3:4", "answer": "yes",
                              "note": ""}],
               "record": "reviews/N.yaml", "figures_table": [["reviewer", "R"]]},
    "dafny": {"verified": 3, "errors": [], "error_count": 0, "timeouts": 0, "other_outcomes": 0, "warnings": [],
              "exit_code": 0, "parse_errors": 0, "resolution_errors": 0, "prover_messages": [], "cli": "verify",
              "guarantees": {"1": "verified"}, "refining_modules": [{"module": "StepImpl", "line": 1}],
              "unsound_constructs": [], "command": "dafny verify stub.dfy impl.dfy"},
    "ajpf": {"model_checker": "spin", "claim": "p1", "psl": "[] (B(a, x) -> D(a, y))", "states": 12, "transitions": 20,
             "complete": True, "cut": "", "depth": 5, "max_states": 100000, "max_depth": 10000, "timeout_s": 60,
             "explore_s": 0.01, "identifiers": "", "spin_verdict": "holds", "spin_states_stored": None,
             "build_s": 0.5, "pan_s": 0.01, "promela": "spin/model.pml", "propositions": {"p0": "B(a, x)"},
             "antecedents": [{"antecedent": "B(a, x)", "holds_in_state": 3}]},
}


@pytest.mark.parametrize("backend", sorted(_WRITTEN))
def test_each_backends_written_details_decode_and_an_undeclared_key_is_refused(backend: str) -> None:
    """The details each producer writes decode into its backend's payload (``checked`` gives them back
    unchanged, so the record's JSON is what the producer built); a key the payload does not declare is
    refused, by the producer's check and by the reader's decode alike."""
    written = _WRITTEN[backend]
    payload = payload_of(backend, written)
    assert payload is not None and payload.__struct_config__.tag == backend
    cls = type(payload)
    assert cls.checked(written) is written
    with pytest.raises(msgspec.ValidationError, match="added_here"):
        cls.checked({**written, "added_here": 1})
    with pytest.raises(msgspec.ValidationError, match="added_here"):
        payload_of(backend, {**written, "added_here": 1})


def test_an_experiments_and_a_reviews_rows_are_read_from_their_decoded_payloads(tmp_path: Path) -> None:
    """The rows an experiment and a review ask the report to show (``figures``), an experiment target's
    statistics and its plot are read from the decoded payload; a review record with a key its payload does
    not declare is error in one sentence (the control: the same record without it is shown)."""
    (tmp_path / "impl.py").write_text("def step(x): return x\n")
    (tmp_path / "plot.svg").write_text('<?xml version="1.0"?>\n<svg xmlns="http://www.w3.org/2000/svg"></svg>\n')
    store = EvidenceStore(tmp_path)
    stats = {"environment": "lab", "origin": "operation", "target": {"rate": "0.1"}, "counts": {"runs": 3},
             "file_sha256": "cd" * 32, "decision": {"status": "discharged"}, "failing_trials": []}
    exp, tgt, good, bad = "N.g1.experiment.e0", "N.g1.experiment.t0", "N.g1.review.ok", "N.g1.review.bad"
    store.put(_evidence(tmp_path, exp, "experiment", {**_WRITTEN["experiment"], "plot": "plot.svg"}))
    store.put(_evidence(tmp_path, tgt, "experiment", {"statistics": stats}))
    store.put(_evidence(tmp_path, good, "review", _WRITTEN["review"]))
    store.put(_evidence(tmp_path, bad, "review", {**_WRITTEN["review"], "reviewer_added_here": "S"}))
    part = evidence_part(Workspace(tmp_path), [_obligation(o, o.split(".")[2]) for o in (exp, tgt, good, bad)],
                         {}, {}, SecondSolver({}))
    assert part.status == {exp: "discharged", tgt: "discharged", good: "discharged", bad: "error"}
    rows = {r.obligation: r for r in part.evidence}
    assert rows[exp].figures == [["worst", "0.12 m"]] and rows[exp].plot_svg.startswith("<svg")
    assert rows[tgt].statistics == stats and rows[tgt].figures == [] and rows[tgt].plot_svg == ""
    assert rows[good].figures == [["reviewer", "R"]] and rows[good].plot_svg == ""
    [said] = part.altered
    assert said.startswith(f"Evidence {bad} is error: its review details are not that backend's payload")
    assert "reviewer_added_here" in said
