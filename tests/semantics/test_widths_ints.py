"""Every IDL primitive at its width (semantics/widths.py, backends/monitors/widths.py,
backends/property_tests/at_width.py; docs/semantics.md, "Widths").

The ranges are checked against two oracles that do not share the code:
``struct.pack`` (C's fixed-width integers and binary32, which raise for a
value the type cannot hold) over every value of the 8-bit types and the
values around the ends of the wider ones, and rclpy's own generated setters
(rosidl_generator_py, run in the ROS 2 Python) on the same values.  The
edges the property tests draw equal a brute-force enumeration of the points
where a comparison with a constant changes its truth.  Then the property
tests themselves: inputs within the field's range with every edge drawn, an
output its field cannot carry a counterexample with the reason, a bounded
string, a bounded sequence and a fixed array within their bounds; and a
hand-made log holding a value no message can carry refused at its line.
"""
from __future__ import annotations

import json
import random
import struct
import subprocess
from fractions import Fraction
from pathlib import Path
from typing import Any

import pytest

from rclverify.cli.commands import main
from rclverify.lang.parser import parse_text
from rclverify.lang.printer import expr_to_rcl
from rclverify.semantics.widths import (INT_RANGES, Carried, Width, at_widths, carried_fault, int_edges,
                                        narrow, nearest_at_width, width_fault)

#: struct's format for each IDL integer type (C's fixed-width types).
FORMATS = {"int8": "<b", "uint8": "<B", "int16": "<h", "uint16": "<H", "int32": "<i", "uint32": "<I",
           "int64": "<q", "uint64": "<Q", "byte": "<B", "octet": "<B", "char": "<B"}


def _packs(fmt: str, v: Any) -> bool:
    try:
        struct.pack(fmt, v)
    except (struct.error, OverflowError):
        return False
    return True


def _probe_values(width: str) -> list[int]:
    lo, hi = INT_RANGES[width]
    if hi - lo < 1 << 9:
        return list(range(lo - 300, hi + 301))  # every value and 300 beyond each end
    rng = random.Random(width)
    near = [e + d for e in (lo, hi, 0) for d in range(-3, 4)]
    return near + [rng.randint(lo - 2 ** 70, hi + 2 ** 70) for _ in range(500)]


@pytest.mark.parametrize("width", sorted(FORMATS))
def test_oracle_the_integer_ranges_equal_what_c_fixed_width_integers_hold(width: str) -> None:
    for v in _probe_values(width):
        assert (width_fault(v, Width(width)) is None) == _packs(FORMATS[width], v), (width, v)
    assert width_fault(True, Width(width)) is not None and width_fault(3.0, Width(width)) is not None


def test_oracle_float32_overflows_exactly_where_binary32_rounding_does() -> None:
    top = struct.unpack("<f", struct.pack("<f", 3.4028234663852886e38))[0]
    rng = random.Random(7)
    cases = [top, -top, top * (1 + 2 ** -25), top * (1 + 2 ** -24), 1e39, -1e39, 1e38, 0.2]
    cases += [top * (1 + rng.uniform(-2 ** -20, 2 ** -20)) for _ in range(2000)]
    for x in cases:
        assert (width_fault(x, Width("float32")) is None) == _packs("<f", x), x
        assert (nearest_at_width(Fraction(x), "float32") is None) == (not _packs("<f", x)), x


def _flips(c: Fraction, lo: int, hi: int) -> set[int]:
    """Brute force: every value v of [lo, hi] where `x < c`, `x <= c` or `x == c` differs between v and a
    neighbour of v in the range (the values a threshold's slip shows at)."""
    def truths(v: int) -> tuple[bool, bool, bool]:
        return v < c, v <= c, v == c
    return {v for v in range(lo, hi + 1) for u in (v - 1, v + 1) if lo <= u <= hi and truths(u) != truths(v)}


@pytest.mark.parametrize("width", ["int8", "uint8"])
def test_oracle_the_drawn_edges_equal_a_brute_force_enumeration(width: str) -> None:
    lo, hi = INT_RANGES[width]
    rng = random.Random(width)
    for _ in range(200):
        consts = [Fraction(rng.randint(-300, 300), rng.choice([1, 1, 2, 3])) for _ in range(rng.randint(0, 3))]
        want = {lo, hi, 0} & set(range(lo, hi + 1))
        for c in consts:
            want |= _flips(c, lo, hi)
        assert int_edges(consts, width) == sorted(want), consts


def test_an_integer_constant_keeps_its_exact_meaning_beside_an_integer_field() -> None:
    spec = parse_text("node N { inputs( n : INTEGER, p : REAL ) outputs( y : BOOL ) assume( TRUE ) "
                      "guarantee( out.y <=> (in.n <= 100 and in.n < 2.5 and in.p <= 0.2) ) }", "n.rcl")
    g = spec.nodes[0].guarantees[0].formula
    text = expr_to_rcl(at_widths(g, {"in.n": "uint8", "in.p": "float32"}))
    assert "in.n <= 100" in text and "in.n < 2.5" in text and "in.p <= 0.20000000298" in text


PROBE = """
import importlib, json, math, sys
from rclpy.serialization import deserialize_message, serialize_message
out = []
for mod, cls, field, v in json.load(sys.stdin):
    t = getattr(importlib.import_module(mod), cls)
    checked = t(check_fields=True)  # rclpy's setters with their checks (ROS_PYTHON_CHECK_FIELDS=1)
    try:
        setattr(checked, field, v)
        refused = False
    except AssertionError:
        refused = True
    m = t()  # the default: no check; what a subscriber reads of what was set
    try:
        setattr(m, field, v)
        got = getattr(deserialize_message(serialize_message(m), t), field)
        heard = got if isinstance(got, (bool, int, str)) else (float(got) if math.isfinite(got) else None)
    except Exception:  # noqa: BLE001 - the conversion to C refused it: nothing published
        heard = "raised"
    out.append([refused, heard])
print(json.dumps(out))
"""


def test_oracle_rclpy_refuses_exactly_what_the_rule_says_a_field_cannot_carry(tmp_path: Path) -> None:
    """rclpy's generated setters (std_msgs and test_msgs, rosidl_generator_py, with their checks on) refuse
    exactly the values width_fault names; without the checks (Kilted's default) such a value never reaches a
    subscriber as computed: the conversion raises, the integer wraps (300 is heard as 44) or a float32 becomes
    an infinity, while every value the rule accepts is heard as set."""
    from _ros2 import ros2_python
    py = ros2_python()
    probe: list[tuple[str, str, str, Any]] = []  # (module, class, field, value)
    for cls, width in (("Int8", "int8"), ("UInt8", "uint8"), ("Int16", "int16"), ("UInt16", "uint16"),
                       ("Int32", "int32"), ("UInt32", "uint32"), ("Int64", "int64"), ("UInt64", "uint64"),
                       ("Char", "char")):
        lo, hi = INT_RANGES[width]
        probe += [("std_msgs.msg", cls, "data", v) for v in (lo - 1, lo, 0, hi, hi + 1, 300, -1)]
    probe += [("std_msgs.msg", "Float32", "data", v) for v in (1e39, -1e39, 3.4e38, 0.5)]
    probe += [("std_msgs.msg", "Bool", "data", v) for v in (True, False)]
    probe += [("test_msgs.msg", "Strings", "bounded_string_value", "x" * n) for n in (0, 22, 23)]
    script = tmp_path / "probe.py"
    script.write_text(PROBE)
    r = subprocess.run([str(py), str(script)], input=json.dumps(probe), capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    answers = json.loads(r.stdout)
    widths = {"Float32": Width("float32"), "Bool": Width("bool"), "Strings": Width("string", 22),
              "Char": Width("char")}
    for (_, cls, _, v), (refused, heard) in zip(probe, answers):
        fault = width_fault(v, widths.get(cls) or Width(cls.lower()))  # Int8 -> int8, UInt64 -> uint64
        assert (fault is not None) == refused, (cls, v, fault)
        if fault is None:
            assert heard == (narrow(v, "float32") if cls == "Float32" else v), (cls, v, heard)
        elif cls != "Strings":  # Fast DDS carries an over-long bounded string whole to a Python subscriber
            assert heard != v, (cls, v, heard)
    assert sum(r for r, _ in answers) >= 20  # the probe reached rclpy's refusals, not only its acceptances
    # an int in a float field: refused by the checking setter, and heard as another number without the checks
    r = subprocess.run([str(py), str(script)], input=json.dumps([("std_msgs.msg", "Float64", "data", 3)]),
                       capture_output=True, text=True, timeout=120)
    [[refused, heard]] = json.loads(r.stdout)
    assert refused and heard != 3 and "not a float" in (width_fault(3, Width("float64")) or ""), heard


def test_a_sequence_beyond_its_bound_and_a_fixed_array_of_another_length_cannot_be_carried() -> None:
    bounded = Carried((Width("int32"),), True, 3)
    fixed = Carried((Width("float64"),), True, 4, True)
    assert carried_fault((1, 2, 3), bounded) is None and carried_fault((), bounded) is None
    assert carried_fault((1, 2, 3, 4), bounded) == "int32[<=3] cannot carry 4 item(s) (at most 3)"
    assert carried_fault((1.0,) * 3, fixed) == "float64[4] cannot carry 3 item(s) (exactly 4)"
    assert carried_fault((1, 2 ** 31), bounded) == "item 1: int32 cannot carry 2147483648 (its values are " \
                                                  "-2147483648 to 2147483647)"


# --- the property tests at the field's width -------------------------------------------------------------

MSG = "uint8 level\nint32[<=3] xs\nfloat64[4] a\nstring<=4 mode\n"

NODE = """
node Fill {
  inputs( level : INTEGER, xs : seq(INTEGER), a : seq(REAL) )
  outputs( pct : INTEGER, mode : Mode, ys : seq(INTEGER) )
  topics( demo_msgs/Thing thing matches(in.level), demo_msgs/Thing xs matches(in.xs),
          demo_msgs/Thing arr matches(in.a), demo_msgs/Thing pct matches(out.pct),
          demo_msgs/Thing mode matches(out.mode), demo_msgs/Thing ys matches(out.ys) )
  assume( TRUE )
  guarantee( out.pct >= in.level and out.pct <= 255 and (in.level <= 100 -> out.pct >= 0) )
}
"""
CONTEXT = "context { Mode : {idle, run, running} ; }\n"


def _run(tmp: Path, code: str, guarantee: str | None = None, examples: int = 300) -> Any:
    from rclverify.backends.property_tests.config import read_config
    from rclverify.backends.property_tests.harness import run_guarantee
    from rclverify.lang.typecheck import check
    (tmp / "msg" / "demo_msgs" / "msg").mkdir(parents=True, exist_ok=True)
    (tmp / "msg" / "demo_msgs" / "msg" / "Thing.msg").write_text(MSG)
    (tmp / "backends" / "monitors").mkdir(parents=True, exist_ok=True)
    (tmp / "backends" / "monitors" / "mapping.yaml").write_text(
        "msg_dirs: [msg]\ntopics:\n  thing: {fields: [level]}\n  pct: {fields: [level]}\n  xs: {fields: [xs]}\n"
        "  ys: {fields: [xs]}\n  arr: {fields: [a]}\n  mode: {fields: [mode]}\n")
    (tmp / "impl.py").write_text(code)
    text = CONTEXT + (NODE if guarantee is None else NODE.replace(NODE[NODE.index("guarantee("):NODE.rindex(")") + 1],
                                                               f"guarantee( {guarantee} )"))
    checked = check([parse_text(text, "fill.rcl")])
    cn = checked.nodes["Fill"]
    cfg = read_config({"implementation": "impl.py:fill", "max_examples": examples, "seed": 11}, cn, tmp)
    return run_guarantee(checked, cn, 1, cfg, tmp)


RECORDING = """
import json, pathlib
SEEN = pathlib.Path(__file__).with_name("seen.jsonl")

def fill(level, xs, a):
    with SEEN.open("a") as fh:
        fh.write(json.dumps([level, list(xs), list(a)]) + "\\n")
    return {"pct": PCT, "mode": "idle", "ys": tuple(xs)}
"""


def test_inputs_are_drawn_within_the_field_with_every_edge(tmp_path: Path) -> None:
    out = _run(tmp_path, RECORDING.replace("PCT", "min(level * 3, 255)"))
    assert out.status == "discharged", out.message
    seen = [json.loads(line) for line in (tmp_path / "seen.jsonl").read_text().splitlines()]
    levels = {s[0] for s in seen}
    assert all(type(v) is int and 0 <= v <= 255 for v in levels)
    assert {0, 255, 99, 100, 101} <= levels  # the range's ends, 0, and the constant 100's neighbours
    lengths = {len(s[1]) for s in seen}
    assert lengths == {0, 1, 2, 3}  # int32[<=3]: 0 to 3 items, the empty and the full drawn
    assert all(-2 ** 31 <= x < 2 ** 31 and type(x) is int for s in seen for x in s[1])
    assert {len(s[2]) for s in seen} == {4}  # float64[4]: exactly four


def test_an_output_its_field_cannot_carry_is_a_counterexample_with_the_reason(tmp_path: Path) -> None:
    out = _run(tmp_path, RECORDING.replace("PCT", "level * 3"))
    assert out.status == "failed", out.message
    assert "uint8 cannot carry" in out.counterexample["reason"], out.counterexample
    assert "so the robot cannot publish it" in out.counterexample["reason"]
    v = int(out.counterexample["out.pct"])
    assert v > 255 and int(out.counterexample["in.level"]) * 3 == v
    assert f"uint8 cannot carry {v} (its values are 0 to 255)" in out.counterexample["reason"]


@pytest.mark.parametrize("mode, ys, reason", [
    ('"running"', "tuple(xs)", "string<=4 cannot carry 'running' (7 characters)"),
    ('"idle"', "tuple(xs) + (1, 2, 3, 4)", "int32[<=3] cannot carry"),
])
def test_a_bounded_string_and_a_bounded_sequence_beyond_their_bounds(tmp_path: Path, mode: str, ys: str,
                                                                     reason: str) -> None:
    code = f"def fill(level, xs, a):\n    return {{'pct': min(level, 255), 'mode': {mode}, 'ys': {ys}}}\n"
    out = _run(tmp_path, code, examples=50)
    assert out.status == "failed" and reason in out.counterexample["reason"], out.message
    assert "out.ys" in out.counterexample and out.counterexample["out.ys"].startswith("<")  # RCL's sequence literal


# --- a recorded log --------------------------------------------------------------------------------------

def test_a_recorded_value_no_field_can_carry_is_refused_at_its_line(tmp_path: Path,
                                                                    capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "contracts").mkdir()
    (tmp_path / "contracts" / "c.rcl").write_text(
        "node Pct {\n  inputs( level : INTEGER )\n  outputs( pct : INTEGER )\n"
        "  topics( std_msgs/UInt8 level matches(in.level), std_msgs/UInt8 pct matches(out.pct) )\n"
        "  assume( TRUE )\n  guarantee( out.pct >= in.level )\n}\n")
    (tmp_path / "contracts" / "plan.yaml").write_text("contracts: [contracts/c.rcl]\n")
    (tmp_path / "mapping.yaml").write_text("topics:\n  level: {fields: [data]}\n  pct: {fields: [data]}\n")
    lines = [{"topic": "level", "time": 1.0, "data": 100}, {"topic": "pct", "time": 1.01, "data": 200},
             {"topic": "level", "time": 2.0, "data": 100}, {"topic": "pct", "time": 2.01, "data": 300}]
    run = tmp_path / "run.jsonl"
    run.write_text("".join(json.dumps(x) + "\n" for x in lines))
    code = main(["monitor", "-w", str(tmp_path), "--mapping", "mapping.yaml", "--horizon", "1", str(run)])
    out = capsys.readouterr()
    text = out.out + out.err
    assert code != 0 and "run.jsonl:4: error: out.pct on topic pct" in text, text
    assert "uint8 cannot carry 300 (its values are 0 to 255)" in text and "Traceback" not in text
    # the control: the same log within the range is judged (satisfied)
    run.write_text("".join(json.dumps(x) + "\n" for x in lines[:2]))
    assert main(["monitor", "-w", str(tmp_path), "--mapping", "mapping.yaml", "--horizon", "1", str(run)]) == 0


def test_a_recorded_sequence_beyond_its_bound_is_refused_and_one_within_it_judged(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "msg" / "demo_msgs" / "msg").mkdir(parents=True)
    (tmp_path / "msg" / "demo_msgs" / "msg" / "Thing.msg").write_text(MSG)
    (tmp_path / "contracts").mkdir()
    (tmp_path / "contracts" / "c.rcl").write_text(
        "node Count {\n  inputs( xs : seq(INTEGER) )\n  outputs( n : INTEGER )\n"
        "  topics( demo_msgs/Thing xs matches(in.xs), std_msgs/Int64 n matches(out.n) )\n"
        "  assume( TRUE )\n  guarantee( forall(x in in.xs | out.n >= x) )\n}\n")
    (tmp_path / "contracts" / "plan.yaml").write_text("contracts: [contracts/c.rcl]\n")
    (tmp_path / "mapping.yaml").write_text("msg_dirs: [msg]\ntopics:\n  xs: {fields: [xs]}\n  n: {fields: [data]}\n")
    run = tmp_path / "run.jsonl"
    args = ["monitor", "-w", str(tmp_path), "--mapping", "mapping.yaml", "--horizon", "1", str(run)]
    run.write_text(json.dumps({"topic": "xs", "time": 1.0, "xs": [1, 2, 3]}) + "\n"
                   + json.dumps({"topic": "n", "time": 1.01, "data": 3}) + "\n")
    assert main(args) == 0
    run.write_text(json.dumps({"topic": "xs", "time": 1.0, "xs": [1, 2, 3, 4]}) + "\n")
    code = main(args)
    out = capsys.readouterr()
    assert code != 0 and "run.jsonl:1: error: in.xs on topic xs (field xs, int32[<=3]): int32[<=3] cannot carry 4 " \
                         "item(s) (at most 3)" in out.out + out.err, out
