"""The problem sentences and the ``--strict`` gate of the design and instances stages
(stages/design.py, stages/instances.py) read the report's rows as their records (``DesignRow``,
``InstancesRow``), whether given the record or its JSON object."""
from __future__ import annotations

from typing import Any

import msgspec
import pytest

from rclverify.records.design_rows import DesignRow
from rclverify.records.instance_rows import InstancesRow
from rclverify.stages import design, instances

PLACE = {"file": "design/a.yaml", "line": 3, "col": 5}
DESIGN: dict[str, Any] = {
    "design": "design", "system": "S", "nodes": 2, "wires": 1, "decided": [], "inputs": {},
    "findings": [{"code": "design-timeout", "severity": "error", "message": "the timeout is shorter than the chain",
                  "places": [PLACE]},
                 {"code": "design-unwired", "severity": "warning", "message": "a port is unwired", "places": []}],
    "counts": {"error": 1, "warning": 1, "proved": 0, "refuted": 1, "undecided": 0}}
INSTANCES: dict[str, Any] = {
    "instances": [], "environment_inputs": [], "inputs": {},
    "requirements": [{"id": "R1", "namespace": "/r1", "nodes": {"Guard": "Guard_r1"}, "verdict": "refuted",
                      "unfed": ["Guard_r1.in.cmd"]},
                     {"id": "R1", "namespace": "/r2", "nodes": {"Guard": "Guard_r2"}, "verdict": "proved"}]}


@pytest.mark.parametrize("row", [DESIGN, DesignRow.of(DESIGN)])
def test_a_design_error_is_a_problem_at_its_places_and_fails_strict(row: Any) -> None:
    assert design.design_problems(row) == ["design design-timeout at design/a.yaml:3:5: the timeout is shorter "
                                           "than the chain"]
    assert design.blocks_strict(row)
    # control: the warning alone, on a current record, is no problem and passes --strict
    clean = {**DESIGN, "findings": DESIGN["findings"][1:], "counts": {**DESIGN["counts"], "error": 0}}
    assert design.design_problems(clean) == [] and not design.blocks_strict(clean)
    stale = {**clean, "stale": "made from another design"}
    assert design.design_problems(stale) == ["design: made from another design"] and design.blocks_strict(stale)
    assert design.design_problems(None) == [] and not design.blocks_strict(None)


@pytest.mark.parametrize("row", [INSTANCES, InstancesRow.of(INSTANCES)])
def test_a_namespace_not_proved_is_a_problem_and_its_status_counts(row: Any) -> None:
    assert instances.instance_problems(row) == ["requirement R1 is refuted for the instances in /r1 (Guard as "
                                                "Guard_r1): fed by no node: Guard_r1.in.cmd"]
    assert instances.instance_statuses(row) == ["failed", "discharged"] and instances.blocks_strict(row)
    # control: every namespace proved, the record current: nothing said, --strict passes
    proved = {**INSTANCES, "requirements": INSTANCES["requirements"][1:]}
    assert instances.instance_problems(proved) == [] and not instances.blocks_strict(proved)
    altered = {**proved, "altered": "its seal does not hold"}
    assert instances.instance_statuses(altered) == ["error", "discharged"]
    assert instances.instance_problems(altered) == ["instances: its seal does not hold"]


def test_a_row_of_another_shape_is_refused() -> None:
    with pytest.raises(msgspec.ValidationError, match="verdict"):
        instances.instance_problems({**INSTANCES, "requirements": [{"id": "R1", "namespace": "/r1", "nodes": {}}]})
