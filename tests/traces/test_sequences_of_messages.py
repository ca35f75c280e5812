"""Sequences of messages (traces/mapping.py, backends/monitors/widths.py; docs/monitors.md,
"Sequences of messages"): ``geometry_msgs/PoseArray.poses`` read through a
path inside each item (``poses[*].position.x``) into a ``seq(REAL)``, and
two such paths into a ``seq((REAL, REAL))`` of tuples, judged offline from a
log and from a ROS 2 bag and by the property tests, printed as RCL's
sequence literal.  Before, a sequence of messages could not be mapped: every
item was "not a value of type REAL".

The oracle: on random pose arrays and random answers, the monitor's count
of satisfied and violated answers equals the one Python's ``any``/``all``
over the same items gives.  A malformed path is refused at its line and
column in the mapping file; a path into a field the type does not have, at
check time.
"""
from __future__ import annotations

import json
import random
from pathlib import Path
from typing import Any

import pytest

from rclverify.cli.commands import main
from rclverify.traces.mapping import EVERY, MappingError, TopicRule, field_value, map_value, parse_path
from rclverify.lang import types as T

#: every pose of an area at x <= 2.5 and y >= 0 (also judged live: tests/runtime/test_ros2_sequences.py)
INSIDE = """
node Inside {
  inputs( pts : seq((REAL, REAL)) )
  outputs( inside : BOOL )
  topics( geometry_msgs/PoseArray area matches(in.pts), std_msgs/Bool inside matches(out.inside) )
  assume( TRUE )
  guarantee( out.inside <=> forall((x, y) in in.pts | x <= 2.5 and y >= 0) )
}
"""
INSIDE_MAPPING = '  area: {fields: ["poses[*].position.x", "poses[*].position.y"]}\n  inside: {fields: [data]}\n'
RCL = """
node Near {
  inputs( xs : seq(REAL) )
  outputs( near : BOOL )
  topics( geometry_msgs/PoseArray poses matches(in.xs), std_msgs/Bool near matches(out.near) )
  assume( TRUE )
  guarantee( out.near <=> exists(x in in.xs | x <= 1.5) )
}
""" + INSIDE
MAPPING = 'topics:\n  poses: {fields: ["poses[*].position.x"]}\n  near: {fields: [data]}\n' + INSIDE_MAPPING


def _ws(tmp: Path, mapping: str = MAPPING) -> Path:
    (tmp / "contracts").mkdir(exist_ok=True)
    (tmp / "contracts" / "c.rcl").write_text(RCL)
    (tmp / "contracts" / "plan.yaml").write_text("contracts: [contracts/c.rcl]\n")
    (tmp / "mapping.yaml").write_text(mapping)
    return tmp


def _pose(x: float, y: float) -> dict[str, Any]:
    return {"position": {"x": x, "y": y, "z": 0.0}, "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}}


def _monitor(ws: Path, run: Path, capsys: pytest.CaptureFixture[str]) -> tuple[int, list[dict[str, Any]]]:
    code = main(["monitor", "-w", str(ws), "--mapping", "mapping.yaml", "--horizon", "0.5", "--json", str(run)])
    return code, json.loads(capsys.readouterr().out)


def test_the_path_through_every_item() -> None:
    assert parse_path("poses[*].position.x") == ("poses", EVERY, "position", "x")
    assert parse_path("a[*].b[0]") == ("a", EVERY, "b", 0)
    assert parse_path("a[*].b[*].c") is None and parse_path("a[*") is None and parse_path("a[x]") is None
    msg = {"poses": [_pose(1.0, 2.0), _pose(3.0, -1.0)]}
    assert field_value(msg, "poses[*].position.x") == [1.0, 3.0]
    rule = TopicRule(("poses[*].position.x", "poses[*].position.y"))
    pair = T.SeqT(T.TupleT((T.Scalar("REAL"), T.Scalar("REAL"))))
    assert map_value(pair, msg, rule, None) == ((1.0, 2.0), (3.0, -1.0))
    assert map_value(pair, {"poses": []}, rule, None) == ()
    joints = {"name": ["a", "b"], "position": [1.0, 2.0], "velocity": [0.5, 0.0]}  # parallel arrays zip alike
    assert map_value(pair, joints, TopicRule(("position", "velocity")), None) == ((1.0, 0.5), (2.0, 0.0))
    with pytest.raises(MappingError, match=r"'poses\[1\].position' has no field 'y'"):
        map_value(pair, {"poses": [_pose(1.0, 2.0), {"position": {"x": 1.0}}]}, rule, None)
    with pytest.raises(MappingError, match="different lengths"):
        map_value(pair, {"poses": [_pose(1.0, 2.0)], "more": [_pose(0.0, 0.0)] * 2},
                  TopicRule(("poses[*].position.x", "more[*].position.y")), None)


def test_oracle_random_pose_arrays_judged_as_any_and_all_judge_them(tmp_path: Path,
                                                                     capsys: pytest.CaptureFixture[str]) -> None:
    ws = _ws(tmp_path)
    rng = random.Random(5)
    lines: list[dict[str, Any]] = []
    want = {"Near": [0, 0], "Inside": [0, 0]}  # [satisfied, violated]
    t = 1.0
    for _ in range(120):
        poses = [(rng.choice([1.5, 2.5, 0.0, -1.0, rng.uniform(-4, 4)]), rng.choice([0.0, -0.5, rng.uniform(-2, 2)]))
                 for _ in range(rng.randint(0, 4))]
        near, inside = rng.random() < 0.5, rng.random() < 0.5
        lines.append({"topic": "poses", "time": t, "poses": [_pose(x, y) for x, y in poses]})
        lines.append({"topic": "near", "time": t + 0.01, "data": near})
        lines.append({"topic": "area", "time": t + 0.02, "poses": [_pose(x, y) for x, y in poses]})
        lines.append({"topic": "inside", "time": t + 0.03, "data": inside})
        want["Near"][0 if near == any(x <= 1.5 for x, _ in poses) else 1] += 1
        want["Inside"][0 if inside == all(x <= 2.5 and y >= 0 for x, y in poses) else 1] += 1
        t += 1.0
    run = tmp_path / "run.jsonl"
    run.write_text("".join(json.dumps(x) + "\n" for x in lines))
    code, results = _monitor(ws, run, capsys)
    got = {r["node"]: [r["counts"]["satisfied"], r["counts"]["violated"]] for r in results}
    assert got == want and code == 1
    assert min(min(v) for v in want.values()) > 10  # both verdicts occur for both nodes
    first = next(r for r in results if r["node"] == "Inside")["first_violation"]["values"]["in.pts"]
    assert first.startswith("<") and (first == "<>" or first.startswith("<(")), first  # RCL's sequence of tuples


def _bag(path: Path, poses: list[tuple[float, float]], inside: bool) -> Path:
    from rosbags.rosbag2 import Writer

    from rclverify.traces.bag import typestore
    s = typestore([])
    t = s.types
    header = t["std_msgs/msg/Header"](stamp=t["builtin_interfaces/msg/Time"](sec=0, nanosec=0), frame_id="map")
    arr = t["geometry_msgs/msg/PoseArray"](header=header, poses=[
        t["geometry_msgs/msg/Pose"](position=t["geometry_msgs/msg/Point"](x=x, y=y, z=0.0),
                                    orientation=t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0))
        for x, y in poses])
    with Writer(path, version=9) as w:
        a = w.add_connection("/area", "geometry_msgs/msg/PoseArray", typestore=s)
        b = w.add_connection("/inside", "std_msgs/msg/Bool", typestore=s)
        w.write(a, 1_000_000_000, s.serialize_cdr(arr, "geometry_msgs/msg/PoseArray"))
        w.write(b, 1_010_000_000, s.serialize_cdr(t["std_msgs/msg/Bool"](data=inside), "std_msgs/msg/Bool"))
    return path


def test_a_bag_of_pose_arrays_a_right_and_a_wrong_answer(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    ws = _ws(tmp_path)
    poses = [(1.0, 0.5), (2.5, 0.0), (2.0, 3.0)]
    code, results = _monitor(ws, _bag(tmp_path / "right", poses, True), capsys)
    inside = next(r for r in results if r["node"] == "Inside")
    assert code == 0 and inside["counts"]["satisfied"] == 1, inside
    code, results = _monitor(ws, _bag(tmp_path / "wrong", poses + [(2.6, 0.0)], True), capsys)
    inside = next(r for r in results if r["node"] == "Inside")
    assert code == 1 and inside["counts"]["violated"] == 1
    assert inside["first_violation"]["values"]["in.pts"] == "<(1.0, 0.5), (2.5, 0.0), (2.0, 3.0), (2.6, 0.0)>"


def test_a_malformed_path_is_refused_at_its_line_and_column(tmp_path: Path,
                                                             capsys: pytest.CaptureFixture[str]) -> None:
    ws = _ws(tmp_path, MAPPING.replace('"poses[*].position.x"]}\n  near', '"poses[*].position[*].x"]}\n  near'))
    run = tmp_path / "run.jsonl"
    run.write_text(json.dumps({"topic": "poses", "time": 1.0, "poses": []}) + "\n")
    code = main(["monitor", "-w", str(ws), "--mapping", "mapping.yaml", str(run)])
    out = capsys.readouterr()
    text = out.out + out.err
    assert code != 0 and "mapping.yaml:2:" in text and "is not a field path" in text and "Traceback" not in text, text


def test_a_path_the_type_does_not_have_is_refused_at_check_time(tmp_path: Path) -> None:
    from rclverify.backends.monitors.fieldpaths import check_field_paths
    from rclverify.lang.parser import parse_text
    from rclverify.lang.typecheck import check
    ws = _ws(tmp_path, MAPPING.replace('"poses[*].position.y"', '"poses[*].positio.y"'))
    checked = check([parse_text(RCL, "c.rcl")])
    diags = [str(d) for d in check_field_paths(ws, "mapping.yaml", [], checked)]
    assert len(diags) == 1 and diags[0].startswith("mapping.yaml:4:") and "has no field 'positio'" in diags[0], diags
    (ws / "mapping.yaml").write_text(MAPPING)
    assert check_field_paths(ws, "mapping.yaml", [], checked) == []  # the arrays fill the sequences: no error


# --- property tests: a bounded sequence of messages ------------------------------------------------------

AREA_MSG = "geometry_msgs/Point[<=2] pts\n"
AREA = """
node Fence {
  inputs( pts : seq((REAL, REAL)) )
  outputs( inside : BOOL )
  topics( demo_msgs/Area area matches(in.pts), std_msgs/Bool inside matches(out.inside) )
  assume( TRUE )
  guarantee( out.inside <=> forall((x, y) in in.pts | x <= 2.5 and y >= 0) )
}
"""
FENCE = """
import json, pathlib

def fence(pts):
    with pathlib.Path(__file__).with_name("seen.jsonl").open("a") as fh:
        fh.write(json.dumps([list(p) for p in pts]) + "\\n")
    return {"inside": all(x CMP 2.5 and y >= 0 for x, y in pts)}
"""


def _fence(tmp: Path, cmp: str) -> Any:
    from rclverify.backends.property_tests.config import read_config
    from rclverify.backends.property_tests.harness import run_guarantee
    from rclverify.lang.parser import parse_text
    from rclverify.lang.typecheck import check
    (tmp / "msg" / "demo_msgs" / "msg").mkdir(parents=True)
    (tmp / "msg" / "demo_msgs" / "msg" / "Area.msg").write_text(AREA_MSG)
    (tmp / "backends" / "monitors").mkdir(parents=True)
    (tmp / "backends" / "monitors" / "mapping.yaml").write_text(
        'msg_dirs: [msg]\ntopics:\n  area: {fields: ["pts[*].x", "pts[*].y"]}\n  inside: {fields: [data]}\n')
    (tmp / "impl.py").write_text(FENCE.replace("CMP", cmp))
    checked = check([parse_text(AREA, "fence.rcl")])
    cn = checked.nodes["Fence"]
    cfg = read_config({"implementation": "impl.py:fence", "max_examples": 200, "seed": 3}, cn, tmp)
    return run_guarantee(checked, cn, 1, cfg, tmp)


def test_property_tests_draw_within_the_bound_and_find_the_slip_at_the_threshold(tmp_path: Path) -> None:
    (tmp_path / "right").mkdir()
    (tmp_path / "slip").mkdir()
    right = _fence(tmp_path / "right", "<=")
    assert right.status == "discharged", right.message
    seen = [json.loads(x) for x in (tmp_path / "right" / "seen.jsonl").read_text().splitlines()]
    assert {len(s) for s in seen} == {0, 1, 2}  # Point[<=2]: 0, 1 or 2 items, the empty and the full drawn
    assert any(x == 2.5 for s in seen for x, _ in s)  # the contract's constant drawn in the items
    slip = _fence(tmp_path / "slip", "<")
    assert slip.status == "failed", slip.message
    assert slip.counterexample is not None and slip.counterexample["in.pts"].startswith("<("), slip.counterexample
    assert "2.5" in slip.counterexample["in.pts"]
