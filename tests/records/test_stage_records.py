"""Every sealed record the stages write is its TypedDict (records/stage_records.py, records/composition_records.py,
records/crosscheck_records.py), key by key.

The case study's stages run once on a copy of the repository root's workspace (contracts, backends'
inputs, the robot's code): check, compose, health, export per node, deadlines, requirements, the second
solver, the ROS grounding and the diagnosis; the deadlines on a copy of examples/safety_stop (the rover has none).  Each record a stage returned, and each record it sealed on disk, is walked
against its TypedDict: no key the type does not declare, every required key present, each value of its
JSON type (nested TypedDicts, lists, dicts and unions walked).  A contract-health finding is no TypedDict
but its one definition, records/findings.py, and an obligation records/records.py ``Obligation``: the
stages return instances of them and their sealed records decode into them.
"""
# No ``from __future__ import annotations``: the test's own TypedDicts need ``NotRequired`` evaluated.
import dataclasses
import shutil
import types
import typing
from pathlib import Path
from typing import Any, Iterator, NotRequired, TypedDict

import msgspec
import pytest

from rclverify.records import composition_records as cr, crosscheck_records as xr, stage_records as sr
from rclverify.records.findings import HealthFinding
from rclverify.records.records import Obligation
from rclverify.records.sealed import read_sealed

ROOT = Path(__file__).resolve().parent.parent.parent


def _problems(value: Any, tp: Any, where: str) -> Iterator[str]:
    """What in the JSON ``value`` does not fit the type ``tp``, as ``where: why`` lines."""
    if tp is Any:
        return
    origin = typing.get_origin(tp)
    if origin in (typing.Union, types.UnionType):
        branches = [list(_problems(value, t, where)) for t in typing.get_args(tp)]
        if all(branches):
            yield f"{where}: {value!r:.60} fits no branch of {tp}: {branches}"
        return
    if typing.is_typeddict(tp):
        yield from _typeddict_problems(value, tp, where)
    elif origin is list:
        if not isinstance(value, list):
            yield f"{where}: {type(value).__name__}, not a list"
            return
        for i, v in enumerate(value):
            yield from _problems(v, typing.get_args(tp)[0], f"{where}[{i}]")
    elif origin is dict:
        if not isinstance(value, dict):
            yield f"{where}: {type(value).__name__}, not an object"
            return
        for k, v in value.items():
            if not isinstance(k, str):
                yield f"{where}: key {k!r} is not a string"
            yield from _problems(v, typing.get_args(tp)[1], f"{where}.{k}")
    elif tp is type(None):
        if value is not None:
            yield f"{where}: {value!r:.60} is not null"
    elif tp is float:  # a JSON number: an integer is a number too, a boolean is not
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            yield f"{where}: {value!r:.60} is not a number"
    elif tp in (str, int, bool):
        if not isinstance(value, tp) or (tp is int and isinstance(value, bool)):
            yield f"{where}: {value!r:.60} is not {tp.__name__}"
    else:
        raise AssertionError(f"{where}: the checker does not know the type {tp}")


def _typeddict_problems(value: Any, tp: Any, where: str) -> Iterator[str]:
    if not isinstance(value, dict):
        yield f"{where}: {type(value).__name__}, not an object ({tp.__name__})"
        return
    hints = typing.get_type_hints(tp)
    for k in sorted(set(value) - set(hints)):
        yield f"{where}: key {k!r} is not declared in {tp.__name__}"
    for k in sorted(tp.__required_keys__ - set(value)):
        yield f"{where}: required key {k!r} of {tp.__name__} is missing"
    for k, v in value.items():
        if k in hints:
            yield from _problems(v, hints[k], f"{where}.{k}")


def _check(value: Any, tp: Any, where: str) -> None:
    problems = list(_problems(value, tp, where))
    assert problems == [], "\n".join(problems)


# Two requirements more, so that the records of the informal and the refuted branches are walked too.
EXTRA = """\
  - id: EXTRA-INFORMAL
    text: The rover is pleasant to work with.
    supported_by:
      - {node: Agent, guarantees: [1]}
  - id: EXTRA-REFUTED
    text: With the radiation red, the agent commands the inspection of waypoint 0 (REQ3 says it leaves).
    formal: >-
      Agent.in.radiationStatus == red -> Agent.out.command == inspect(0)
    supported_by:
      - {node: Agent, guarantees: [1]}
"""


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Any]]:
    """The case study's stages run once on a copy: ``(root, {stage: what it returned})``."""
    from rclverify.app import pipeline
    from rclverify.app.ros_stage import stage_ground
    from rclverify.stages.crosscheck.stage import stage_crosscheck
    from rclverify.stages.workspace import Workspace
    root = tmp_path_factory.mktemp("rover")
    for d in ("contracts", "backends", "ros"):
        shutil.copytree(ROOT / d, root / d, ignore=shutil.ignore_patterns("__pycache__"))
    plan = root / "contracts" / "plan.yaml"
    text = plan.read_text(encoding="utf-8")
    assert text.count("\nrequirements:\n") == 1
    plan.write_text(text.replace("\nrequirements:\n", "\nrequirements:\n" + EXTRA, 1), encoding="utf-8")
    ws = Workspace(root)
    out: dict[str, Any] = {"check": pipeline.stage_check(ws)}
    nodes = list(ws.checked.nodes)
    out["compose"] = {n: pipeline.stage_compose(ws, n) for n in nodes}
    out["health"] = {n: pipeline.stage_health(ws, n) for n in nodes}
    out["export"] = {n: pipeline.stage_export(ws, n) for n in nodes}
    out["deadlines"] = pipeline.stage_deadlines(ws)
    out["requirements"] = [rec for rec, _ in pipeline.stage_requirements(ws)]
    out["crosscheck"] = stage_crosscheck(root, nodes)
    out["ground"] = stage_ground(ws)
    out["diagnosis"] = pipeline.stage_diagnosis(ws)  # the report's problems, from every record above
    return root, out


def _sealed(root: Path, rel: str) -> Any:
    data, why = read_sealed(root / rel, rel)
    assert not why and data is not None, (rel, why)
    return data


def test_the_returned_records_are_their_types(run: tuple[Path, dict[str, Any]]) -> None:
    _, out = run
    assert len(out["compose"]) == 4 and all(out["export"].values()) and out["requirements"]
    assert out["crosscheck"]["items"] and out["ground"]["findings"] is not None
    verdicts = {r["id"]: r["verdict"] for r in out["requirements"]}
    assert verdicts["EXTRA-INFORMAL"] == "informal" and verdicts["EXTRA-REFUTED"] == "refuted"
    assert any(r["id"] == "EXTRA-REFUTED" and r.get("counterexample") for r in out["requirements"])
    _check(out["check"], cr.CheckRecord, "check")
    for n in out["compose"]:
        _check(out["compose"][n], cr.CompositionRecord, f"compose[{n}]")
        assert out["health"][n] and all(type(f) is HealthFinding for f in out["health"][n]), n
        assert out["export"][n] and all(type(o) is Obligation for o in out["export"][n]), n
    _check(out["deadlines"], list[sr.DeadlineRecord], "deadlines")
    _check(out["requirements"], list[sr.RequirementRecord], "requirements")
    _check(out["crosscheck"], xr.CrosscheckRecord, "crosscheck")
    _check(out["ground"], sr.GroundingRecord, "ground")
    kinds = {d["kind"] for d in out["diagnosis"]["diagnoses"]}
    assert {"requirement", "vacuity", "refinement"} <= kinds, kinds  # EXTRA-REFUTED among them
    _check(out["diagnosis"], sr.DiagnosisRecord, "diagnosis")


def test_the_sealed_records_are_their_types(run: tuple[Path, dict[str, Any]]) -> None:
    from rclverify.stages.workspace import Workspace as W
    root, out = run
    _check(_sealed(root, W.DIAGNOSTICS), cr.CheckRecord, W.DIAGNOSTICS)
    for n in out["compose"]:
        _check(_sealed(root, W.calculus(n)), cr.CompositionRecord, W.calculus(n))
        health = _sealed(root, W.health(n))
        assert set(health) == {"node", "findings"} and health["node"] == n
        # the one definition decodes the record (an undeclared key or a value of another type is refused)
        assert msgspec.convert(health["findings"], list[HealthFinding]) == out["health"][n], W.health(n)
        for o in out["export"][n]:  # its one definition: exactly its fields, decoding into the obligation exported
            rec = _sealed(root, W.obligation(n, o.id))
            assert set(rec) - {"record_sha256"} == {f.name for f in dataclasses.fields(Obligation)}, o.id
            assert Obligation.from_json(rec) == o, o.id
    deadlines = _sealed(root, "artifacts/deadlines/index.json")
    assert set(deadlines) == {"results"}
    _check(deadlines["results"], list[sr.DeadlineRecord], "artifacts/deadlines/index.json")
    reqs = sorted(p for p in (root / "artifacts/requirements").glob("*.json") if p.name != "index.json")
    assert len(reqs) == len(out["requirements"])
    for p in reqs:
        _check(_sealed(root, f"artifacts/requirements/{p.name}"), sr.RequirementRecord, p.name)
    _check(_sealed(root, "artifacts/crosscheck/index.json"), xr.CrosscheckRecord, "crosscheck")
    _check(_sealed(root, "artifacts/ros/grounding.json"), sr.GroundingRecord, "grounding")
    _check(_sealed(root, "artifacts/diagnosis/index.json"), sr.DiagnosisRecord, "diagnosis")


def test_the_deadline_records_are_their_type(tmp_path: Path) -> None:
    """The rover has no deadline: examples/safety_stop's two, decided with Z3 (rule D3)."""
    from rclverify.app import pipeline
    from rclverify.stages.workspace import Workspace
    shutil.copytree(ROOT / "examples" / "safety_stop", tmp_path / "ws")
    ws = Workspace(tmp_path / "ws")
    pipeline.stage_check(ws)
    records = pipeline.stage_deadlines(ws)
    assert [r["requirement"] for r in records] == ["STOP", "MOVE-FEEDBACK"] and records[0]["chain"]
    _check(records, list[sr.DeadlineRecord], "deadlines")
    sealed = _sealed(tmp_path / "ws", "artifacts/deadlines/index.json")
    assert set(sealed) == {"results"}
    _check(sealed["results"], list[sr.DeadlineRecord], "artifacts/deadlines/index.json")


class _Inner(TypedDict):
    n: int
    note: NotRequired[str | None]


class _Outer(TypedDict):
    rows: list[_Inner]
    by: dict[str, float]


def test_the_checker_fails_on_an_unknown_key_a_missing_key_and_a_wrong_type(
        run: tuple[Path, dict[str, Any]]) -> None:
    _, out = run
    good = out["compose"]["Agent"]
    _check(good, cr.CompositionRecord, "good")
    for bad, word in ((dict(good, extra=1), "'extra' is not declared"),
                      ({k: v for k, v in good.items() if k != "node"}, "required key 'node'"),
                      (dict(good, cone_size="4"), "is not int"),
                      (dict(good, side_conditions=[dict(good["side_conditions"][0], surprise=True)]),
                       "'surprise' is not declared")):
        problems = list(_problems(bad, cr.CompositionRecord, "bad"))
        assert any(word in p for p in problems), problems
    assert list(_problems({"rows": [{"n": 1}, {"n": 2, "note": None}], "by": {"a": 1, "b": 0.5}}, _Outer, "x")) == []
    assert list(_problems({"rows": [{"n": True}], "by": {}}, _Outer, "x")) == ["x.rows[0].n: True is not int"]
    assert len(list(_problems({"rows": [{"n": 1, "note": 3}], "by": {"a": "1"}}, _Outer, "x"))) == 2
