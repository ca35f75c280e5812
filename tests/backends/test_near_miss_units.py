"""A near-miss threshold with a unit (backends/monitors/near_miss.py; docs/plan.md, docs/monitors.md,
"Near misses").

``near_miss: {value: 0.1 mm}`` is converted to each margin's unit (0.0001 on a guarantee in [m]) and
applies to the margins of its dimension; a bare number is read in each margin's own unit, so on the
guarantees of one node that compare quantities of different dimensions ([mm] and [m/s]) it is refused
at the plan's check, with the guarantees named, where one dimension keeps it working.  The report's
use of the converted threshold on a recorded run: tests/app/test_near_miss_units_report.py.
"""
from __future__ import annotations

import math
from pathlib import Path

import pytest

from rclverify.backends.monitors.near_miss import NearMissError, guarantee_units, parse_near_miss, value_fault
from rclverify.cli.commands import main
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check

MIXED = """node Arm {
  inputs( gap : REAL [mm], v : REAL [m/s] )
  outputs( stop : BOOL )
  assume( TRUE )
  guarantee( in.gap <= 5 -> out.stop )
  guarantee( in.v >= 1.5 -> out.stop )
}
"""
ONE = MIXED.replace("v : REAL [m/s]", "v : REAL [m]")


@pytest.mark.parametrize("raw, value, unit", [
    ({"value": 0.1}, 0.1, None), ({"value": "0.1 mm"}, 0.1, "mm"), ({"value": "5 cm"}, 5.0, "cm"),
    ({"value": "2e-3 m/s"}, 0.002, "m/s"), ({"value": "3"}, 3.0, None),
])
def test_a_value_reads_bare_or_with_a_unit(raw: dict[str, object], value: float, unit: str | None) -> None:
    t = parse_near_miss(raw)
    assert t is not None and t.value == value
    assert (t.value_unit.text if t.value_unit is not None else None) == unit


@pytest.mark.parametrize("raw, says", [
    ({"value": "0.1 furlongs"}, "unknown"), ({"value": "-1 mm"}, "finite number > 0"),
    ({"value": "mm"}, "finite number > 0"), ({"value": True}, "finite number > 0"),
])
def test_a_value_that_does_not_read_is_refused(raw: dict[str, object], says: str) -> None:
    with pytest.raises(NearMissError) as exc:
        parse_near_miss(raw)
    assert exc.value.key == ("value",) and says in str(exc.value)


def test_a_value_with_a_unit_is_converted_to_each_margins_unit() -> None:
    t = parse_near_miss({"value": "0.1 mm"})
    assert t is not None
    assert math.isclose(t.value_in("m"), 0.0001) and math.isclose(t.value_in("mm"), 0.1)
    assert math.isclose(t.value_in("um"), 100.0)
    # another dimension, no unit, a unit that does not read: the threshold does not apply there
    assert t.value_in("m/s") is None and t.value_in("") is None and t.value_in("1/1000*zz") is None
    deg = parse_near_miss({"value": "1 deg"})
    assert deg is not None and math.isclose(deg.value_in("rad"), math.pi / 180)
    # the control: a bare number is read in each margin's own unit, as before
    bare = parse_near_miss({"value": 0.05})
    assert bare is not None and bare.value_in("mm") == 0.05 and bare.value_in("m/s") == 0.05 and bare.value_in("") == 0.05


def test_a_bare_number_on_guarantees_of_two_dimensions_has_no_one_reading() -> None:
    checked = check([parse_text(MIXED, "arm.rcl")])
    units = guarantee_units(checked, "Arm")
    assert units == {1: ["mm"], 2: ["m/s"]}
    why = value_fault(parse_near_miss({"value": 0.05}), units, "Arm")  # type: ignore[arg-type]
    assert why is not None and "guarantee 1 in [mm] (length)" in why and "guarantee 2 in [m/s] (velocity)" in why
    assert value_fault(parse_near_miss({"value": "0.05 mm"}), units, "Arm") is None  # type: ignore[arg-type]
    # the control: one dimension ([mm] and [m]), a bare number keeps working
    one = check([parse_text(ONE, "arm.rcl")])
    assert value_fault(parse_near_miss({"value": 0.05}), guarantee_units(one, "Arm"), "Arm") is None  # type: ignore[arg-type]
    # a unit none of the guarantees' comparisons carries would apply to no margin
    why = value_fault(parse_near_miss({"value": "1 s"}), units, "Arm")  # type: ignore[arg-type]
    assert why is not None and "no guarantee of Arm compares one" in why


def _workspace(root: Path, contract: str, near_miss: str) -> Path:
    (root / "contracts").mkdir(parents=True)
    (root / "contracts" / "arm.rcl").write_text(contract)
    (root / "contracts" / "plan.yaml").write_text(
        "contracts: [contracts/arm.rcl]\nnodes:\n  Arm:\n    evidence:\n"
        f"      - {{backend: monitors, traces: [runs/run.jsonl], near_miss: {near_miss}}}\n")
    return root


@pytest.mark.parametrize("contract, near_miss, code", [
    (MIXED, "{value: 0.05}", 1), (MIXED, "{value: 0.05 mm}", 0), (ONE, "{value: 0.05}", 0),
    (MIXED, "{value: 5 cm, time: 20 ms}", 0),
])
def test_the_plans_check_refuses_a_bare_number_on_two_dimensions(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], contract: str, near_miss: str, code: int) -> None:
    root = _workspace(tmp_path, contract, near_miss)
    assert main(["check", "-w", str(root), str(root / "contracts" / "arm.rcl")]) == code
    err = capsys.readouterr().err
    assert "Traceback" not in err
    if code:
        assert "plan.yaml:5:74:" in err and "near_miss value 0.05 is a bare number" in err, err
        assert "guarantee 1 in [mm] (length)" in err and "guarantee 2 in [m/s] (velocity)" in err
