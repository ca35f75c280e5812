"""The monitors backend's evidence payload is a Struct tagged by ``backend`` (backends/monitors/payload.py):
the backend builds it and writes its details, which decode back into the same payload; a number the run
wrote as an int stays one; a key written on some records only is absent when unset; a record written before
a field existed (no ``lowest``, no run identity) still decodes; a key the payload does not declare is refused
(the control: the same details without it decode).  In-process: the bundled runs checked by the backend.
"""
from __future__ import annotations

import shutil
from pathlib import Path
from typing import Any

import msgspec
import pytest

from rclverify.backends.base import NodeTarget
from rclverify.backends.monitors.backend import MonitorsBackend, run_payload
from rclverify.backends.monitors.payload import MonitorsPayload, SpaceMargin, monitors_payload
from rclverify.backends.payloads import payload_of
from rclverify.core.atomic import dumps
from rclverify.diagnosis.monitor_repair import is_call_violation
from rclverify.lang.typecheck import load
from rclverify.report.margin_rows import figures

REPO = Path(__file__).resolve().parents[2]
RCL = "contracts/remote_inspection.rcl"


def _target(root: Path, traces: list[str], horizon: Any) -> NodeTarget:
    checked = load([root / RCL])
    config = {"backend": "monitors", "mapping": "backends/monitors/mapping.yaml", "horizon": horizon,
              "traces": [f"backends/monitors/traces/{t}" for t in traces]}
    return NodeTarget(root=root, checked=checked, node=checked.nodes["RadiationSensor"], config=config,
                      contract_files=(RCL,), plan_file="contracts/plan.yaml",
                      artifacts=root / "artifacts" / "monitors" / "RadiationSensor")


def test_a_monitored_run_writes_its_payload_and_it_decodes_back(tmp_path: Path) -> None:
    for rel in ("contracts", "backends"):
        shutil.copytree(REPO / rel, tmp_path / rel)
    t = _target(tmp_path, ["nominal.jsonl", "sensor_fault.jsonl"], 2.0)
    b = MonitorsBackend()
    evs = {o.instance: b.run(o, t) for o in b.export(t)}
    failed = evs["sensor_fault_jsonl"]
    assert failed.status == "failed"
    for ev in evs.values():
        payload = payload_of("monitors", ev.details)
        assert isinstance(payload, MonitorsPayload) and payload.monitoring is not None
        # decoded once, written again: the same JSON text
        assert dumps(payload.details()) == dumps(dict(ev.details))
        assert payload.statistics is not None and payload.statistics.trace == payload.monitoring.trace
        assert payload.not_judged is not None
    fv = payload_of("monitors", failed.details)
    assert isinstance(fv, MonitorsPayload) and fv.monitoring is not None and fv.monitoring.first_violation
    assert fv.monitoring.counts["violated"] > 0 and fv.statistics is not None and fv.statistics.violations == \
        fv.monitoring.counts["violated"]
    assert not is_call_violation(fv)  # a topic's violation: the repair search re-runs the topics (the control of
    # tests/backends/test_log_calls.py, where a served call's violation is told)


def test_only_the_keys_written_are_in_the_json_and_an_old_record_still_decodes() -> None:
    m = SpaceMargin(guarantee=1, formula="r < 0.5", margin=0.25, answers=3, lowest=[0.25, 0.3])
    out = msgspec.to_builtins(m)
    assert "trace" not in out and out["lowest"] == [0.25, 0.3]  # unset: left out, as the backend wrote it
    assert msgspec.to_builtins(msgspec.structs.replace(m, trace="run.jsonl"))["trace"] == "run.jsonl"
    # a number the run wrote as an int stays one (a float field would write 3.0 for 3)
    stamped = msgspec.convert({"guarantee": 1, "time": 3, "margin": 1}, SpaceMargin)
    assert dumps(msgspec.to_builtins(stamped)).count('": 3,') == 1 and isinstance(stamped.margin, int)
    # a record that kept only the smallest margin and had no run identity (written before either existed)
    old = {"monitoring": {"trace": "old.jsonl", "margins": [{"guarantee": 1, "margin": 0.5, "answers": 4}]},
           "statistics": {"environment": "lab", "origin": "operation"}}
    p = monitors_payload("monitors", old)
    assert p is not None and p.monitoring is not None and p.statistics is not None
    [margin] = p.monitoring.margins
    assert margin.lowest is msgspec.UNSET and p.statistics.sha256 is msgspec.UNSET
    assert figures([margin])[:2] == (4, 1)  # its one kept margin; the other three unknown, at least 0.5
    assert p.details()["statistics"] == old["statistics"]  # only the keys it had


def test_an_undeclared_key_is_refused_and_the_same_details_without_it_decode() -> None:
    details: dict[str, Any] = {"monitoring": {"trace": "t.jsonl", "margins": []}, "not_judged": []}
    assert isinstance(monitors_payload("monitors", details), MonitorsPayload)  # the control
    bad = {**details, "monitoring": {**details["monitoring"], "margin_added_here": 0.5}}
    with pytest.raises(msgspec.ValidationError, match="margin_added_here"):
        payload_of("monitors", bad)
    assert monitors_payload("monitors", bad) is None  # a reader skips it; the evidence pass shows it as error
    assert monitors_payload("hoare", details) is None  # another backend's record is not read as the monitors'
    # the backend refuses to write a part its payload does not declare, instead of dropping it
    with pytest.raises(msgspec.ValidationError, match="window"):
        run_payload({"trace": "t.jsonl"}, {"trace": "t.jsonl"}, {"window": {}})
    d = run_payload({"trace": "t.jsonl"}, {"trace": "t.jsonl"}, {"not_judged": []}).details()
    assert d["statistics"] == {"trace": "t.jsonl"} and d["not_judged"] == []
    assert msgspec.convert(d["monitoring"], dict)["trace"] == "t.jsonl"
    assert "deadlines" not in d and "calls" not in d  # a part the run did not produce is left out
