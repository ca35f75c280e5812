"""One verdict for a threshold however it is written, at a field's width (docs/semantics.md, "Widths").

A ``float32`` input ``in.p`` compared with a threshold ``C`` is read at the
field's width.  The oracle is C++ ``float`` arithmetic with ``f`` literals
(numpy's ``float32``): ``p <= Cf``.  For thresholds next to which the
decimal and the carried value differ, and for every ``float32`` value a few
steps either side of the carried threshold, each algebraically equal form
(the plain literal, a named constant, a difference, a negation, a sum of
constants, ``abs`` where it is equal, the converse) gives that verdict on
each path that reads widths: the monitors' and the property tests' judge
(:func:`rclverify.semantics.floatsem.judge` on the contract as
:func:`rclverify.backends.monitors.widths.at_carried_widths` reads it),
and the exact and double readings alone.  The control: the same forms read
without the widths disagree with the oracle next to the threshold.  End to
end, the monitor of a recorded bag and the property tests find a node's
``<``-for-``<=`` slip at the carried threshold in each form and pass the
correct node; the plain ``x <= 0.2`` is the control there (it was read at
the width before the other forms were).
"""
from __future__ import annotations

import struct
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from rclverify.backends.monitors.widths import at_carried_widths
from rclverify.lang.parser import parse_text
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.typecheck import check
from rclverify.lang.types import Checked, CheckedNode
from rclverify.semantics.floatsem import holds_in, judge

#: thresholds whose nearest float32 is not the decimal (above for 0.2, 0.15, 1.1; below for 0.3, 2.675)
THRESHOLDS = ("0.2", "0.15", "0.3", "1.1", "2.675")
#: (form, whether it is strict) over ``in.p``, the threshold ``{c}``, its half ``{h}`` and the constant ``Limit``
FORMS = (
    ("in.p <= {c}", False), ("in.p <= Limit", False), ("in.p - {c} <= 0", False), ("-in.p >= -{c}", False),
    ("in.p <= {h} + {h}", False), ("abs(in.p) <= {c}", False), ("{c} >= in.p", False),
    ("in.p - Limit <= 0", False), ("0 >= in.p - {c}", False), ("-Limit <= -in.p", False),
    ("in.p < {c}", True), ("in.p < Limit", True), ("in.p - {c} < 0", True), ("-in.p > -{c}", True),
    ("abs(in.p) < {h} + {h}", True),
)


def _f32(x: float) -> float:
    return float(struct.unpack("<f", struct.pack("<f", x))[0])


def _near(c: float, steps: int = 3) -> list[float]:
    """The float32 values ``steps`` either side of ``c``'s nearest float32, the nearest included."""
    bits = struct.unpack("<i", struct.pack("<f", c))[0]
    return [float(struct.unpack("<f", struct.pack("<i", b))[0]) for b in range(bits - steps, bits + steps + 1)]


def _checked(c: str) -> tuple[Checked, CheckedNode]:
    clauses = "\n".join(f"  guarantee( {f.format(c=c, h=_half(c))} )" for f, _ in FORMS)
    text = (f"context {{ Limit : REAL = {c} ; }}\n"
            f"node N {{\n  inputs( p : REAL )\n  outputs( y : BOOL )\n{clauses}\n}}\n")
    checked = check([parse_text(text, "forms.rcl")])
    return checked, checked.nodes["N"]


def _half(c: str) -> str:
    """``c / 2`` as a decimal (exact: the thresholds are decimals with few digits)."""
    q = Fraction(c) / 2
    digits = 0
    while (q * 10 ** digits).denominator != 1:
        digits += 1
    return f"{q.numerator * 10 ** digits // q.denominator / 10 ** digits:.{digits}f}"


@pytest.mark.parametrize("c", THRESHOLDS)
def test_every_form_of_a_threshold_gives_the_float32_verdict_on_every_path(c: str) -> None:
    checked, node = _checked(c)
    at = at_carried_widths(node, {"in.p": "float32"}, checked.env.constants)
    limit = np.float32(float(Fraction(c)))
    for p in _near(float(Fraction(c))):
        assert p >= 0 and _f32(p) == p  # a float32 value, where abs(p) is p
        for (form, strict), clause in zip(FORMS, at.node.guarantees):
            want = bool(np.float32(p) < limit) if strict else bool(np.float32(p) <= limit)
            values = {"in.p": p}
            got = judge(clause.formula, checked, at, values)
            where = f"{form.format(c=c, h=_half(c))} at p = {p!r} read as {expr_to_rcl(clause.formula)}"
            assert got.truth is want, where
            for semantics in ("exact", "double"):
                assert holds_in(semantics, clause.formula, checked, at, values) is want, (semantics, where)


def test_without_the_widths_the_forms_disagree_with_float32_next_to_the_threshold() -> None:
    """The control: as written (decimal thresholds), ``p = 0.2f`` is above 0.2, so the ``<=`` forms are
    false where float32 says true; the test above would fail on the contract read without widths."""
    checked, node = _checked("0.2")
    p = _f32(0.2)
    wrong = [f for (f, strict), cl in zip(FORMS, node.node.guarantees) if not strict
             and judge(cl.formula, checked, node, {"in.p": p}).truth is not True]
    assert len(wrong) == sum(1 for _, strict in FORMS if not strict), wrong


# ---------------------------------------------------------------------------
# end to end: the monitor of a recorded run and the property tests, each form
# ---------------------------------------------------------------------------

#: the forms of "at or below the threshold 0.2" the end-to-end runs read, over the value ``{x}``
LOW_FORMS = ("{x} <= Low", "{x} - 0.2 <= 0", "-{x} >= -0.2", "abs({x}) <= 0.2", "{x} <= 0.1 + 0.1", "{x} <= 0.2")

GAUGE = """
context { Low : REAL = 0.2 ; }
node Gauge {
  inputs( p : REAL )
  outputs( low : BOOL )
  topics( std_msgs/Float32 battery matches(in.p), std_msgs/Bool low matches(out.low) )
  assume( TRUE )
  guarantee( out.low <=> FORM )
}
"""


def _gauge_bag(path: Path, value: float, low: bool) -> Path:
    from rosbags.rosbag2 import Writer

    from rclverify.traces.bag import typestore
    store = typestore([])
    with Writer(path, version=9) as w:
        c1 = w.add_connection("/battery", "std_msgs/msg/Float32", typestore=store)
        c2 = w.add_connection("/low", "std_msgs/msg/Bool", typestore=store)
        w.write(c1, 1_000_000_000, store.serialize_cdr(store.types["std_msgs/msg/Float32"](data=value),
                                                       "std_msgs/msg/Float32"))
        w.write(c2, 1_010_000_000, store.serialize_cdr(store.types["std_msgs/msg/Bool"](data=low), "std_msgs/msg/Bool"))
    return path


@pytest.mark.parametrize("form", LOW_FORMS)
def test_the_monitor_finds_the_slip_in_every_form(tmp_path: Path, form: str) -> None:
    """A bag carrying 0.2 as a Float32 (0.2000000030): the correct node (`<=` at the width) says low and
    is satisfied, the `<` slip says not low and is violated, whatever form the contract writes."""
    from rclverify.cli.commands import main
    (tmp_path / "contracts").mkdir()
    (tmp_path / "contracts" / "c.rcl").write_text(GAUGE.replace("FORM", form.format(x="in.p")))
    (tmp_path / "contracts" / "plan.yaml").write_text("contracts: [contracts/c.rcl]\n")
    (tmp_path / "mapping.yaml").write_text("topics:\n  battery: {fields: [data]}\n  low: {fields: [data]}\n")
    args = ["monitor", "-w", str(tmp_path), "--mapping", "mapping.yaml", "--horizon", "1"]
    assert main([*args, str(_gauge_bag(tmp_path / "correct", 0.2, True))]) == 0
    assert main([*args, str(_gauge_bag(tmp_path / "slip", 0.2, False))]) == 1


BATTERY = """
context { Low : REAL = 0.2 ; }
node Battery {
  inputs( level : REAL )
  outputs( p : REAL, low : BOOL )
  topics( std_msgs/Float64 level matches(in.level), std_msgs/Float32 battery matches(out.p),
          std_msgs/Bool low matches(out.low) )
  assume( 0 <= in.level and in.level <= 1 )
  guarantee( out.low <=> FORM )
}
"""
CORRECT = ("import struct\n\ndef battery(level):\n    p = struct.unpack('<f', struct.pack('<f', level))[0]\n"
           "    return {'p': p, 'low': p <= struct.unpack('<f', struct.pack('<f', 0.2))[0]}\n")


def _property_run(tmp: Path, form: str, code: str) -> object:
    from rclverify.backends.property_tests.config import read_config
    from rclverify.backends.property_tests.harness import run_guarantee
    tmp.mkdir()
    (tmp / "impl.py").write_text(code)
    (tmp / "backends" / "monitors").mkdir(parents=True)
    (tmp / "backends" / "monitors" / "mapping.yaml").write_text("topics:\n  battery: {fields: [data]}\n")
    checked = check([parse_text(BATTERY.replace("FORM", form.format(x="out.p")), "b.rcl")])
    cn = checked.nodes["Battery"]
    cfg = read_config({"implementation": "impl.py:battery", "max_examples": 200}, cn, tmp)
    return run_guarantee(checked, cn, 1, cfg, tmp)


@pytest.mark.parametrize("form", LOW_FORMS)
def test_the_property_tests_find_the_slip_in_every_form(tmp_path: Path, form: str) -> None:
    """The implementation decides at the field's width: `<=` is correct and discharged, `<` the slip,
    found on the carried 0.2, whatever form the contract writes."""
    assert getattr(_property_run(tmp_path / "correct", form, CORRECT), "status") == "discharged"
    out = _property_run(tmp_path / "slip", form, CORRECT.replace("p <= struct", "p < struct"))
    assert getattr(out, "status") == "failed", getattr(out, "message")
