"""Sequence inputs drawn within their bounds, and widths read from the mapping the plan names
(docs/property-tests.md, "Sequences"; docs/monitors.md, "The mapping file").

A ``sensor_msgs/JointState.position`` (``float64[]``) input whose items the
assumption bounds (``forall(q in in.position | -3.14 <= q and q <= 3.14)``)
is drawn with every item inside the bounds and the bounds' ends among the
items, by construction: no drawn example is filtered away.  A joint guard
that takes ``max`` where it should take ``min`` fails within the default
number of examples, at the line with the slip; its correct twin
passes.  The plan's ``bounds`` of a sequence input bound its items, with
their ends and their neighbours inside drawn.  The property tests read the
field widths from the mapping the plan names (a ``monitors`` entry's
``mapping``), not from the default path only.
"""
from __future__ import annotations

import json
import math
from fractions import Fraction
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.property_tests.config import ConfigError, read_config
from rclverify.backends.property_tests.harness import Outcome, run_guarantee
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check

GUARD = """
node JointGuard {
  inputs( position : seq(REAL) )
  outputs( lowest : REAL )
  topics( sensor_msgs/JointState joints matches(in.position), std_msgs/Float64 lowest matches(out.lowest) )
  assume( exists(q in in.position | -3.14 <= q) and forall(q in in.position | -3.14 <= q and q <= 3.14) )
  guarantee( exists(q in in.position | out.lowest == q) and forall(q in in.position | out.lowest <= q) )
}
"""

#: the implementation: records each call's items, then the least joint position (line 9 computes it)
LOWEST = '''import json, pathlib
SEEN = pathlib.Path(__file__).with_name("seen.jsonl")

def step(position):
    with SEEN.open("a") as fh:
        fh.write(json.dumps(list(position)) + "\\n")
    lowest = position[0]
    for q in position[1:]:
        lowest = min(lowest, q)
    return {"lowest": lowest}
'''


def _guard_run(tmp: Path, code: str, assume: str | None = None, **entry: Any) -> tuple[Outcome, list[list[float]]]:
    """The guarantee's run on ``code`` in a workspace at ``tmp`` (the default mapping names
    JointState's ``position``), and the items of every call."""
    (tmp / "impl.py").write_text(code)
    (tmp / "backends" / "monitors").mkdir(parents=True)
    (tmp / "backends" / "monitors" / "mapping.yaml").write_text(
        "topics:\n  joints: {fields: [position]}\n  lowest: {fields: [data]}\n")
    text = GUARD if assume is None else GUARD.replace(GUARD[GUARD.index("assume("):GUARD.index("\n  guarantee")],
                                                      f"assume( {assume} )")
    checked = check([parse_text(text, "guard.rcl")])
    cn = checked.nodes["JointGuard"]
    cfg = read_config({"implementation": "impl.py:step", **entry}, cn, tmp)
    out = run_guarantee(checked, cn, 1, cfg, tmp)
    seen = tmp / "seen.jsonl"
    return out, [json.loads(line) for line in seen.read_text().splitlines()] if seen.exists() else []


def test_a_max_for_min_over_a_float64_sequence_is_found_and_its_twin_passes(tmp_path: Path) -> None:
    """Default examples (200), default seed: the slip fails at the line with the slip; the
    correct code passes with every drawn example kept (before: 2369 drawn for 200 kept)."""
    (tmp_path / "slip").mkdir()
    (tmp_path / "good").mkdir()
    bad, _ = _guard_run(tmp_path / "slip", LOWEST.replace("min(", "max("))
    assert bad.status == "failed", bad.message
    assert bad.counterexample is not None
    assert "forall(q in in.position | out.lowest <= q)" in bad.counterexample["reason"]
    assert bad.counterexample.get("cause", "").startswith("impl.py:9"), bad.counterexample
    good, seen = _guard_run(tmp_path / "good", LOWEST)
    assert good.status == "discharged", good.message
    assert good.counts.valid == 200 and good.counts.rejected == 0, good.counts  # by construction: no filtering
    items = [q for s in seen for q in s]
    assert all(s for s in seen)  # exists(...): at least one item, drawn so
    # the ends: 3.14 as the float64 field carries it (the double 3.14), or, read as the exact decimal, the
    # double next to it inside (the double 3.14 lies just above the decimal)
    assert Fraction(3.14) > Fraction("3.14")
    assert all(-3.14 <= q <= 3.14 for q in items)
    assert min(items) in (-3.14, math.nextafter(-3.14, 0)) and max(items) in (3.14, math.nextafter(3.14, 0))


def test_the_plans_bounds_of_a_sequence_bound_its_items_with_their_edges(tmp_path: Path) -> None:
    """``bounds: {in.position: [-1.5, 1.5]}`` under an assumption that bounds the items wider: every item
    within the plan's bounds, both ends and their neighbours inside drawn, nothing filtered."""
    out, seen = _guard_run(tmp_path, LOWEST, bounds={"in.position": [-1.5, 1.5]}, max_examples=100)
    assert out.status == "discharged", out.message
    assert out.counts.rejected == 0 and out.counts.drawn == out.counts.valid == 100, out.counts
    items = {q for s in seen for q in s}
    assert all(-1.5 <= q <= 1.5 for q in items)
    assert {-1.5, 1.5, math.nextafter(-1.5, 0), math.nextafter(1.5, 0)} <= items


def test_a_sequence_without_item_bounds_keeps_the_default_length_and_draws_the_empty_one(tmp_path: Path) -> None:
    """An unbounded ``float64[]`` under an assumption that bounds nothing: 0 to 4 items (the default
    length), nothing filtered; the empty sequence is drawn and breaks the guarantee's ``exists``."""
    code = LOWEST.replace("    lowest = position[0]", "    lowest = position[0] if position else 0.0")
    out, seen = _guard_run(tmp_path, code, assume="TRUE", max_examples=60)
    assert out.status == "failed" and out.counterexample is not None, out.message
    assert out.counterexample["in.position"] == "<>", out.counterexample
    assert {len(s) for s in seen} <= {0, 1, 2, 3, 4} and out.counts.rejected == 0


def test_bounds_on_an_input_without_numbers_are_refused(tmp_path: Path) -> None:
    checked = check([parse_text("node B {\n  inputs( on : BOOL )\n  outputs( y : BOOL )\n"
                                "  guarantee( out.y == in.on )\n}\n", "b.rcl")])
    (tmp_path / "impl.py").write_text("def step(on):\n    return {'y': on}\n")
    with pytest.raises(ConfigError, match="BOOL has no numbers to bound"):
        read_config({"implementation": "impl.py:step", "bounds": {"in.on": [0, 1]}}, checked.nodes["B"], tmp_path)


# -- one mapping per plan ------------------------------------------------------------------------

RANGER = """
node Ranger {
  inputs( dist : REAL )
  outputs( near : BOOL )
  topics( sensor_msgs/Range range matches(in.dist), std_msgs/Bool near matches(out.near) )
  assume( 0 <= in.dist and in.dist <= 10 )
  guarantee( out.near <=> in.dist <= 0.2 )
}
"""

#: records each call's input; decides at the carried threshold (float32 0.2)
RANGER_IMPL = '''import json, pathlib, struct
SEEN = pathlib.Path(__file__).with_name("seen.jsonl")

def step(dist):
    with SEEN.open("a") as fh:
        fh.write(json.dumps(dist) + "\\n")
    return {"near": dist <= struct.unpack("<f", struct.pack("<f", 0.2))[0]}
'''


def _ranger(tmp: Path, mapping: str, named: bool) -> tuple[Any, list[Any]]:
    """The property test of the range reader in a workspace whose mapping file lies at ``mapping``
    (named by the plan's monitors entry when ``named``): the evidence, the target and every drawn input."""
    from rclverify.backends.property_tests.backend import PropertyTestsBackend
    from rclverify.stages.workspace import Workspace
    (tmp / "contracts").mkdir(parents=True)
    (tmp / "contracts" / "ranger.rcl").write_text(RANGER)
    (tmp / "impl.py").write_text(RANGER_IMPL)
    (tmp / mapping).parent.mkdir(parents=True, exist_ok=True)
    (tmp / mapping).write_text("topics:\n  range: {fields: [range]}\n  near: {fields: [data]}\n")
    (tmp / "contracts" / "plan.yaml").write_text(
        "contracts: [contracts/ranger.rcl]\nnodes:\n  Ranger:\n    evidence:\n      - backend: property_tests\n"
        "        implementation: impl.py:step\n        max_examples: 40\n      - backend: monitors\n"
        + (f"        mapping: {mapping}\n" if named else "") + "        traces: []\n")
    target = Workspace(tmp).target("Ranger", 0)
    backend = PropertyTestsBackend()
    obligation = backend.export(target)[0]
    ev = backend.run(obligation, target)
    seen = [json.loads(line) for line in (tmp / "seen.jsonl").read_text().splitlines()]
    return (ev, target, obligation), seen


def _f32(x: float) -> float:
    import struct
    return float(struct.unpack("<f", struct.pack("<f", x))[0])


@pytest.mark.parametrize("mapping, named", [("contracts/mapping.yaml", True),
                                            ("backends/monitors/mapping.yaml", False)])
def test_the_property_tests_read_widths_from_the_mapping_the_plan_names(tmp_path: Path, mapping: str,
                                                                        named: bool) -> None:
    """Range's float32 ``range`` (not its uint8 ``radiation_type``, the first field the message has) is
    drawn at float32 width: the mapping the plan's monitors entry names at a path of its own, and the
    control at the default path the plan need not name.  The mapping is an input of the obligation."""
    (ev, target, obligation), seen = _ranger(tmp_path, mapping, named)
    assert target.mapping == (mapping if named else None)  # none named: the default path
    assert ev.status == "discharged", ev.explanation
    assert mapping in obligation.inputs
    assert all(_f32(v) == v and 0 <= v <= 10 for v in seen)  # binary32 values within the assumption
    assert any(v != int(v) for v in seen)  # not the integers 0..4 of radiation_type
    assert _f32(0.2) in seen  # the threshold as the field carries it


@pytest.mark.parametrize("idl, max_len, fixed, lengths", [
    ("float64", 3, False, {1, 2, 3}),  # float64[<=3] under exists(...): 1 to 3 items, both ends drawn
    ("float64", 4, True, {4}),         # float64[4]: exactly 4
    ("float32", None, False, {1, 2, 3, 4}),  # float32[]: 1 to the default 4
    ("int32", 3, False, {1, 2, 3}),    # int32[<=3]: integer items within the bound too
])
def test_items_and_lengths_of_every_array_form_stay_within_their_bounds(idl: str, max_len: int | None, fixed: bool,
                                                                       lengths: set[int]) -> None:
    """The drawing rule itself (``at_width.carried_value``) for each array form of the field, the items bounded by
    the assumption's ``forall`` to [-2, 5] and its ``exists`` asking for one item: every drawn sequence within."""
    from hypothesis import given, settings

    from rclverify.backends.property_tests.at_width import carried_value
    from rclverify.backends.property_tests.strategies import input_space
    from rclverify.semantics.widths import Carried, Width
    elem = "INTEGER" if idl.startswith("int") else "REAL"
    text = (f"node N {{\n  inputs( xs : seq({elem}) )\n  outputs( y : BOOL )\n"
            "  assume( exists(x in in.xs | x >= -2) and forall(x in in.xs | -2 <= x and x <= 5) )\n"
            "  guarantee( out.y )\n}\n")
    cn = check([parse_text(text, "n.rcl")]).nodes["N"]
    space = input_space(cn, {})
    strategy = carried_value(space, cn.inputs["xs"], space.bounds["xs"],
                             Carried((Width(idl),), seq=True, max_len=max_len, fixed=fixed))
    drawn: list[tuple[Any, ...]] = []

    @settings(max_examples=150, database=None, derandomize=True)
    @given(strategy)
    def draw(xs: tuple[Any, ...]) -> None:
        drawn.append(xs)

    draw()
    assert {len(xs) for xs in drawn} == lengths
    items = [x for xs in drawn for x in xs]
    assert all(-2 <= x <= 5 for x in items) and {-2, 5} <= set(items)
