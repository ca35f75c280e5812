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
        elif n.get("period_steps"):  # an alarm or a relay: its bound as a period in steps of its one output
            assert not node.initially and not node.progress and len(node.periodic) == 1
            per = node.periodic[0]
            assert (per.amount, per.unit) == (str(n["progress_steps"] + 1), "steps")
            assert [per.output.name] == [o.name for o in node.outputs]
        elif n["kind"] in ("alarm", "relay", "fuse"):
            assert not node.initially and not node.periodic and len(node.progress) == 1
            assert str(node.progress[0].bound) == str(n["progress_steps"])
        else:  # a server: its steps are calls, answered before its client calls again
            assert not node.initially and not node.periodic and len(node.progress) == 1
            bound = node.progress[0].bound
            assert (bound is None) == bool(n.get("eventually")) and str(bound or "") == str(
                n.get("progress_steps") or "")


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


def test_a_stamped_sensors_period_is_declared_in_its_nodes_clock() -> None:
    """A stamped sensor's period is judged on its stamps (backends/monitors/periods.py), so it is declared
    in their clock: on a ``/clock`` the wall-clock bound times the real-time factor and two ticks more, with
    a driver's offset outside the run's clock the wall-clock bound, with a driver behind within the run's
    clock that much more; an unstamped sensor's (its source times) is the wall-clock bound, on a ``/clock``
    (on its simulated timer) its simulated period over the factor."""
    stamped = lambda n: n["kind"] == "sensor" and n["sensor_kind"] in ("range", "scan")  # noqa: E731
    plain = lambda n: n["kind"] == "sensor" and not stamped(n)  # noqa: E731
    rates = set()
    for seed in range(840, 860):
        wall = gen.generate(seed, 12)
        for spec, want in ((wall, lambda p, r: p), (gen.generate(seed, 12, driver_offset_s=-2.0), lambda p, r: p),
                           (gen.generate(seed, 12, driver_offset_s=0.3), lambda p, r: p),
                           (gen.generate(seed, 12, driver_offset_s=-0.05), lambda p, r: p + 50),
                           (gen.generate(seed, 12, sim_clock=True),
                            lambda p, r: math.ceil(r * (p + 2 * decl.CLOCK_STEP_MS)))):
            rate = spec["clock"]["rate"] if spec["clock"] else 1.0
            for n in spec["nodes"]:
                base = 2 * n.get("period_ms", 0) + 1000
                if stamped(n):
                    assert n["periodic_ms"] == want(base, rate) and n["periodic_rate"] == rate, (seed, n["name"])
                    rates.add(rate)
                elif plain(n) and spec["clock"]:  # on its simulated timer: its gaps the wall clock's at the factor
                    assert n["periodic_ms"] == math.ceil(2 * n["period_ms"] / rate) + 1000 and n["periodic_rate"] == 1.0
                elif plain(n):
                    assert n["periodic_ms"] == base and n["periodic_rate"] == 1.0
                if n["kind"] == "sensor":
                    assert n.get("initially")
    assert {0.5, 2.0} <= rates  # the control: factors either side of 1 were drawn


def test_servers_and_answering_nodes_declare_both_forms() -> None:
    """A server declares ``progress( eventually )`` or ``within 1 steps``, an alarm or relay its bound as
    ``progress`` or as a period in steps, each form drawn across seeds, without changing the nodes drawn."""
    forms: set[tuple[str, str]] = set()
    for seed in range(840, 880):
        spec = gen.generate(seed, 12, actions=True)
        for n in spec["nodes"]:
            if n["kind"] in ("service", "action"):
                forms.add((n["kind"], "eventually" if n.get("eventually") else f"within {n['progress_steps']}"))
            elif n["kind"] in ("alarm", "relay"):
                forms.add((n["kind"], "steps" if n.get("period_steps") else "progress"))
    assert forms == {("service", "eventually"), ("service", "within 1"), ("action", "eventually"),
                     ("action", "within 1"), ("alarm", "steps"), ("alarm", "progress"), ("relay", "steps"),
                     ("relay", "progress")}, forms


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
        keys = ("initially", "periodic_ms", "periodic_rate", "progress_steps", "period_steps", "eventually")
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
