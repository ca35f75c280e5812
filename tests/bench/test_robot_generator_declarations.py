"""The declarations of generated robots (bench/_robot_declarations.py; docs/monitors.md, "Generated
robots"): drawn where the node keeps them by construction, rendered into contracts the project's own
front end parses and type-checks, and a seeded defect that breaks one at its own node.  In process; the
live runs are tests/bench/test_robot_generator_declarations_live.py."""
from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Any

import pytest

from rclverify.lang.errors import RclError

BENCH = Path(__file__).resolve().parents[2] / "bench"
sys.path.insert(0, str(BENCH))
import _robot_declarations as decl  # noqa: E402
import robot_generator as gen  # noqa: E402

SEEDS = [(seed, 5 + seed % 12) for seed in range(840, 852)]


def _by(spec: dict[str, Any]) -> dict[str, dict[str, Any]]:
    return {n["name"]: n for n in spec["nodes"]}


@pytest.mark.parametrize(("seed", "nodes"), SEEDS)
def test_every_declaration_is_drawn_parsed_and_type_checked(seed: int, nodes: int, tmp_path: Path) -> None:
    spec = gen.generate(seed, nodes)
    ws = gen.write_workspace(spec, tmp_path / "ws")
    gen.check_workspace(ws)
    from rclverify.lang.typecheck import load
    checked = load([ws / "contracts" / "robot.rcl"])
    for n in spec["nodes"]:
        node = checked.nodes[n["name"]].node
        if n["kind"] == "sensor":
            assert len(node.initially) == 1 and len(node.periodic) == 1, n["name"]
            per = node.periodic[0]
            assert (per.amount, per.unit) == (str(n["periodic_ms"]), "ms")
        elif n["kind"] in ("alarm", "relay", "fuse"):
            assert not node.initially and not node.periodic and len(node.progress) == 1
            assert str(node.progress[0].bound) == str(n["progress_steps"])
        else:  # a server: its steps are calls, which a bag gives the call checks only
            assert not (node.initially or node.progress or node.periodic)


def test_a_declaration_on_an_output_the_node_lacks_is_refused(tmp_path: Path) -> None:
    """The control of the type check above: the front end refuses a declaration it cannot type."""
    ws = gen.write_workspace(gen.generate(840, 5), tmp_path / "ws")
    gen.check_workspace(ws)
    rcl = ws / "contracts" / "robot.rcl"
    rcl.write_text(rcl.read_text().replace("periodic( out.x,", "periodic( out.nope,", 1))
    with pytest.raises(RclError, match="nope"):
        gen.check_workspace(ws)


@pytest.mark.parametrize("seed", range(840, 850))
def test_each_bound_leaves_its_margin(seed: int) -> None:
    spec = gen.generate(seed, 12)
    by = _by(spec)
    for n in spec["nodes"]:
        if n["kind"] == "sensor":  # a period and 1 s over the period
            assert n["periodic_ms"] == 2 * n["period_ms"] + 1000
        elif n["kind"] == "relay" and n["copy"]:  # the readings that come before its answer, and two more
            assert n["progress_steps"] >= math.ceil(n["delay_ms"] / by[n["source"]]["period_ms"]) + 2
        elif n["kind"] in ("alarm", "relay"):
            assert n["progress_steps"] == 2
        elif n["kind"] == "fuse":  # its second input is a step it does not answer
            assert n["progress_steps"] == 3


def test_a_stamped_sensor_is_declared_periodic_on_the_wall_clock_only() -> None:
    stamped = lambda spec: [n for n in spec["nodes"] if n["kind"] == "sensor"  # noqa: E731
                            and n["sensor_kind"] in ("range", "scan")]
    wall = gen.generate(842, 12)
    assert stamped(wall) and all(n.get("periodic_ms") for n in stamped(wall))  # the control
    for spec in (gen.generate(842, 12, sim_clock=True), gen.generate(842, 12, driver_offset_s=-2.0)):
        assert stamped(spec) and not any(n.get("periodic_ms") for n in stamped(spec))
        assert all(n.get("periodic_ms") for n in spec["nodes"]
                   if n["kind"] == "sensor" and n["sensor_kind"] not in ("range", "scan"))
        assert all(n.get("initially") for n in spec["nodes"] if n["kind"] == "sensor")
        assert gen.render(spec)["contracts/robot.rcl"].count("periodic(") < \
            gen.render(wall)["contracts/robot.rcl"].count("periodic(")


def test_a_defect_may_break_a_declaration_at_its_own_node() -> None:
    kinds: dict[str, int] = {}
    for seed in range(840, 880):
        spec = gen.generate(seed, 6, defect=True)
        victim = next(n for n in spec["nodes"] if n.get("defect"))
        kinds[victim["defect_kind"]] = kinds.get(victim["defect_kind"], 0) + 1
        if victim["defect_kind"] == "skip":  # never a fuse's leading sensor: its fuse would be red
            assert victim.get("periodic_ms") and not any(f.get("a_source") == victim["name"] for f in spec["nodes"])
        if victim["defect_kind"] == "mute":
            assert victim["kind"] == "alarm" and victim["progress_steps"] == 2
        # the contracts are the correct robot's: a defect is in the node, never in its declarations
        keys = ("initially", "periodic_ms", "progress_steps")
        assert [[n.get(k) for k in keys] for n in spec["nodes"]] == \
            [[n.get(k) for k in keys] for n in gen.generate(seed, 6)["nodes"]]
        strip = lambda t: [ln for ln in t.splitlines() if not ln.startswith("//")]  # noqa: E731
        assert strip(gen.render(spec)["contracts/robot.rcl"]) == \
            strip(gen.render(gen.generate(seed, 6))["contracts/robot.rcl"])
    assert kinds.get("skip") and kinds.get("mute") and (kinds.get("beyond") or kinds.get("wrong")), kinds


def test_can_skip_refuses_a_fuses_leading_sensor() -> None:
    spec = next(s for s in (gen.generate(seed, 8) for seed in range(840, 880))
                if any(n["kind"] == "fuse" for n in s["nodes"]))
    fuse = next(n for n in spec["nodes"] if n["kind"] == "fuse")
    by = _by(spec)
    assert not decl.can_skip(by[fuse["a_source"]], spec)
    assert decl.can_skip(by[fuse["b_source"]], spec)  # the control: its other sensor may skip
