"""The contract's decimal constants compared the way a field carries them
(semantics/widths.py, backends/monitors/widths.py; docs/semantics.md,
"Widths").  A float32 BatteryState.percentage at the threshold 0.2 carries
0.2000000030: the correct `<=` was blamed and the `<` slip passed (an
inverted verdict).  Judged at the field's width, the correct code is green
and the slip is found, at float32 and at float64; the oracle for the
rounding is a brute-force search among the neighbouring binary32 values."""
from __future__ import annotations

import math
import random
import struct
from fractions import Fraction
from pathlib import Path
from typing import Any

import pytest

from _scan import scan_bag
from rclverify.cli.commands import main
from rclverify.lang.parser import parse_text
from rclverify.lang.printer import expr_to_rcl
from rclverify.semantics.widths import at_widths, nearest_at_width

GAUGE = """
node Gauge {
  inputs( p : REAL )
  outputs( low : BOOL )
  topics( TYPE battery matches(in.p), std_msgs/Bool low matches(out.low) )
  assume( TRUE )
  guarantee( out.low <=> in.p <= 0.2 )
}
"""


def _f32_bits(x: float) -> int:
    return int(struct.unpack("<I", struct.pack("<f", x))[0])


def _from_bits(b: int) -> Fraction:
    return Fraction(struct.unpack("<f", struct.pack("<I", b))[0])


def _oracle(q: Fraction) -> Fraction:
    """The nearest binary32 to ``q`` among the ten around the double rounding of ``q`` (ties to even bits)."""
    start = _f32_bits(float(q)) if abs(q) < Fraction(3.4e38) else _f32_bits(3.4e38 * (1 if q > 0 else -1))
    candidates = [b for b in range(start - 5, start + 6) if 0 <= b < 1 << 32]
    finite = [(b, _from_bits(b)) for b in candidates if math.isfinite(struct.unpack("<f", struct.pack("<I", b))[0])]
    return min(finite, key=lambda bv: (abs(bv[1] - q), bv[0] & 1))[1]


def test_oracle_the_nearest_binary32_equals_a_brute_force_search() -> None:
    rng = random.Random(3)
    cases = [Fraction(s) for s in ("0.2", "0.1", "-0.3", "1e-40", "16777217", "0.000000059604644775390625")]
    for _ in range(3000):
        digits = rng.randint(1, 12)
        cases.append(Fraction(rng.randint(-10 ** digits, 10 ** digits), 10 ** rng.randint(0, 14)))
    for _ in range(500):  # exactly halfway between two binary32 values: ties go to the even one
        b = rng.randint(1, (1 << 31) - (1 << 23) - 2)
        cases.append((_from_bits(b) + _from_bits(b + 1)) / 2)
    for q in cases:
        got = nearest_at_width(q, "float32")
        want = _oracle(q)
        if q != 0 and abs(want) > 0 and abs(q) > 0 and got is not None:
            assert got == want or (got == 0 and want == 0), q
    assert nearest_at_width(Fraction("0.2"), "float32") == Fraction(struct.unpack("<f", struct.pack("<f", 0.2))[0])
    assert nearest_at_width(Fraction("0.2"), "float64") == Fraction(0.2)
    assert nearest_at_width(Fraction(10) ** 39, "float32") is None


def test_only_a_constant_read_with_a_variable_of_known_width_moves() -> None:
    spec = parse_text("node N { inputs( p : REAL, q : REAL ) outputs( y : BOOL ) assume( TRUE ) "
                      "guarantee( out.y <=> (in.p <= 0.2 and 0.5 < in.q and in.p + 0.1 <= 1) ) }", "n.rcl")
    g = spec.nodes[0].guarantees[0].formula
    text = expr_to_rcl(at_widths(g, {"in.p": "float32"}))
    assert "in.p <= 0.20000000298023223876953125" in text
    assert "0.5 < in.q" in text  # q's width unknown: as written
    assert "in.p + 0.100000001490116119384765625 <= 1" in text  # a sum with p is at p's width, its constants too


def _workspace(tmp: Path, msg_type: str) -> Path:
    (tmp / "contracts").mkdir()
    (tmp / "contracts" / "c.rcl").write_text(GAUGE.replace("TYPE", msg_type))
    (tmp / "contracts" / "plan.yaml").write_text("contracts: [contracts/c.rcl]\n")
    field = "percentage" if "Battery" in msg_type else "data"
    (tmp / "mapping.yaml").write_text(f"topics:\n  battery: {{fields: [{field}]}}\n  low: {{fields: [data]}}\n")
    return tmp


def _bag(path: Path, msg_type: str, value: float, low: bool) -> Path:
    from rosbags.rosbag2 import Writer

    from rclverify.traces.bag import typestore
    store = typestore([])
    name = msg_type.replace("/", "/msg/", 1)
    cls = store.types[name]
    if "Battery" in msg_type:
        header = store.types["std_msgs/msg/Header"](stamp=store.types["builtin_interfaces/msg/Time"](sec=0, nanosec=0),
                                                    frame_id="")
        fields: dict[str, Any] = {f: 0.0 for f in ("voltage", "temperature", "current", "charge", "capacity",
                                                    "design_capacity")}
        import numpy as np
        msg = cls(header=header, **fields, percentage=value, power_supply_status=0, power_supply_health=0,
                  power_supply_technology=0, present=True, cell_voltage=np.array([], dtype=np.float32),
                  cell_temperature=np.array([], dtype=np.float32), location="", serial_number="")
    else:
        msg = cls(data=value)
    flag = store.types["std_msgs/msg/Bool"](data=low)
    with Writer(path, version=9) as w:
        c1 = w.add_connection("/battery", name, typestore=store)
        c2 = w.add_connection("/low", "std_msgs/msg/Bool", typestore=store)
        w.write(c1, 1_000_000_000, store.serialize_cdr(msg, name))
        w.write(c2, 1_010_000_000, store.serialize_cdr(flag, "std_msgs/msg/Bool"))
    return path


@pytest.mark.parametrize("msg_type", ["sensor_msgs/BatteryState", "std_msgs/Float32", "std_msgs/Float64"])
def test_a_slip_at_a_decimal_threshold_is_found_and_the_correct_code_is_green(tmp_path: Path, msg_type: str,
                                                                             capsys: pytest.CaptureFixture[str]) -> None:
    """At the threshold as the field carries it, the correct `<=` says low and the `<` slip does not."""
    ws = _workspace(tmp_path, msg_type)
    args = ["monitor", "-w", str(ws), "--mapping", "mapping.yaml", "--horizon", "1"]
    assert main([*args, str(_bag(tmp_path / "correct", msg_type, 0.2, True))]) == 0
    assert main([*args, str(_bag(tmp_path / "slip", msg_type, 0.2, False))]) == 1
    out = capsys.readouterr().out
    assert "violated" in out
    # the control below the threshold: both codes say low; above it, neither
    assert main([*args, str(_bag(tmp_path / "below", msg_type, 0.1875, True))]) == 0
    assert main([*args, str(_bag(tmp_path / "above", msg_type, 0.25, False))]) == 0


BATTERY = """
node Battery {
  inputs( level : REAL )
  outputs( p : REAL, low : BOOL )
  topics( std_msgs/Float64 level matches(in.level), std_msgs/Float32 battery matches(out.p),
          std_msgs/Bool low matches(out.low) )
  assume( 0 <= in.level and in.level <= 1 )
  guarantee( out.low <=> out.p <= 0.2 )
}
"""
def _property_run(tmp: Path, code: str) -> Any:
    from rclverify.backends.property_tests.config import read_config
    from rclverify.backends.property_tests.harness import run_guarantee
    from rclverify.lang.typecheck import check
    (tmp / "impl.py").write_text(code)
    (tmp / "backends" / "monitors").mkdir(parents=True)
    (tmp / "backends" / "monitors" / "mapping.yaml").write_text("topics:\n  battery: {fields: [data]}\n")
    checked = check([parse_text(BATTERY, "b.rcl")])
    cn = checked.nodes["Battery"]
    cfg = read_config({"implementation": "impl.py:battery", "max_examples": 200}, cn, tmp)
    return run_guarantee(checked, cn, 1, cfg, tmp)


def test_property_tests_find_the_slip_at_the_carried_threshold(tmp_path: Path) -> None:
    """The flag decided at the field's width: `<=` is correct, `<` the slip, found only on the carried 0.2
    (the double 0.2 is not a float32: before, the slip's flag agreed with the decimal reading there)."""
    correct = "import struct\n\ndef battery(level):\n    p = struct.unpack('<f', struct.pack('<f', level))[0]\n" \
              "    return {'p': p, 'low': p <= struct.unpack('<f', struct.pack('<f', 0.2))[0]}\n"
    slip = correct.replace("p <= struct", "p < struct")
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    assert _property_run(tmp_path / "a", correct).status == "discharged"
    out = _property_run(tmp_path / "b", slip)
    assert out.status == "failed", out.message
    assert out.counterexample is not None and out.counterexample["out.p"].startswith("0.2000000029")


GUARD = """
node Guard {
  inputs( ranges : seq(REAL) )
  outputs( stop : BOOL )
  topics( sensor_msgs/LaserScan scan matches(in.ranges), std_msgs/Bool stop matches(out.stop) )
  assume( TRUE )
  guarantee( out.stop <=> exists(r in in.ranges | r <= 0.2) )
}
"""


def _scan_bag(path: Path, ranges: list[float], stop: bool) -> Path:
    return scan_bag(path, ranges, "stop", "Bool", stop)


def test_a_threshold_over_the_items_of_a_float32_sequence(tmp_path: Path) -> None:
    """`exists(r in in.ranges | r <= 0.2)` over LaserScan.ranges (float32 items): a beam at the carried 0.2
    stops the robot with the correct `<=`; the `<` slip does not, and is found."""
    (tmp_path / "contracts").mkdir()
    (tmp_path / "contracts" / "c.rcl").write_text(GUARD)
    (tmp_path / "contracts" / "plan.yaml").write_text("contracts: [contracts/c.rcl]\n")
    (tmp_path / "mapping.yaml").write_text("topics:\n  scan: {fields: [ranges]}\n  stop: {fields: [data]}\n")
    args = ["monitor", "-w", str(tmp_path), "--mapping", "mapping.yaml", "--horizon", "1"]
    assert main([*args, str(_scan_bag(tmp_path / "correct", [3.0, 0.2], True))]) == 0
    assert main([*args, str(_scan_bag(tmp_path / "slip", [3.0, 0.2], False))]) == 1
    assert main([*args, str(_scan_bag(tmp_path / "clear", [3.0, 0.25], False))]) == 0

