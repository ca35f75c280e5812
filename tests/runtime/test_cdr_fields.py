"""The live monitor's CDR reader (runtime/dds/cdr_fields.py) gives what Cyclone's deserializer and
``to_fields`` give, value for value, type for type and key for key, on ROS 2's standard messages with
random contents in both byte orders, service parts with their request header, and bytes that are
cut short, XCDR2 or of a publisher's own definition."""
from __future__ import annotations

import math
import random
import struct
from typing import Any

import pytest

pytest.importorskip("cyclonedds")

from cyclonedds.idl._support import Endianness  # noqa: E402

from rclverify.runtime.dds.cdr_fields import _READERS, read_fields  # noqa: E402
from rclverify.runtime.dds.types import Declared, TypeBook, to_fields  # noqa: E402

#: messages of every member kind ROS 2 makes: numbers of each width, bool, byte, char, strings, bounded
#: strings, fixed arrays, bounded and unbounded sequences of numbers, strings and structs, nested structs
TYPES = ["std_msgs/msg/Bool", "std_msgs/msg/Byte", "std_msgs/msg/Char", "std_msgs/msg/Float32",
         "std_msgs/msg/Int8", "std_msgs/msg/UInt64", "std_msgs/msg/String", "std_msgs/msg/Float64MultiArray",
         "std_msgs/msg/Empty", "geometry_msgs/msg/PoseWithCovarianceStamped", "geometry_msgs/msg/TwistStamped",
         "geometry_msgs/msg/Polygon", "sensor_msgs/msg/JointState", "sensor_msgs/msg/LaserScan",
         "sensor_msgs/msg/BatteryState", "sensor_msgs/msg/Imu", "sensor_msgs/msg/Image",
         "sensor_msgs/msg/PointCloud2", "sensor_msgs/msg/NavSatFix", "sensor_msgs/msg/CameraInfo",
         "nav_msgs/msg/Odometry", "nav_msgs/msg/Path", "diagnostic_msgs/msg/DiagnosticArray",
         "rcl_interfaces/msg/ParameterEvent", "action_msgs/msg/GoalStatusArray", "tf2_msgs/msg/TFMessage",
         "visualization_msgs/msg/MarkerArray", "trajectory_msgs/msg/JointTrajectory"]
SERVICES = ["std_srvs/srv/SetBool", "std_srvs/srv/Trigger"]


def _value(m: Any, rng: random.Random) -> Any:
    """A random value for one of Cyclone's machines (what the struct's constructor takes)."""
    kind = type(m).__name__
    if kind == "InstanceMachine":
        m.type.__idl__.populate()
        return _value(m.type.__idl__.v1_machine, rng)
    if kind == "StructMachine":
        return m.type(**{k: _value(mm, rng) for k, mm in m.members_machines.items()})
    if kind == "PrimitiveMachine":
        return _number(m.code, rng)
    if kind == "StringMachine":
        n = rng.randint(0, min(m.bound or 6, 6))
        return "".join(rng.choice("az Z09é→\U0001f916") for _ in range(n))
    if kind == "PlainCdrV2ArrayOfPrimitiveMachine":
        return [_number(m.code[-1], rng) for _ in range(m.length)]
    if kind == "PlainCdrV2SequenceOfPrimitiveMachine":
        return [_number(m.code, rng) for _ in range(rng.randint(0, min(m.max_length or 5, 5)))]
    if kind == "ArrayMachine":
        return [_value(m.submachine, rng) for _ in range(m.size)]
    if kind == "SequenceMachine":
        return [_value(m.submachine, rng) for _ in range(rng.randint(0, min(m.maxlen or 3, 3)))]
    if kind == "ByteArrayMachine":
        return bytes(rng.randrange(256) for _ in range(m.size))
    if kind == "BytesMachine":
        return bytes(rng.randrange(256) for _ in range(rng.randint(0, 5)))
    raise AssertionError(f"no values for {kind}")


def _number(code: str, rng: random.Random) -> Any:
    if code == "?":
        return rng.random() < 0.5
    if code in "fd":
        x = rng.choice([0.0, -0.0, math.inf, -math.inf, math.nan, 1e-300, rng.uniform(-1e6, 1e6)])
        return struct.unpack("<f", struct.pack("<f", x))[0] if code == "f" else x
    size = struct.calcsize(code)
    lo, hi = (-(1 << (8 * size - 1)), (1 << (8 * size - 1)) - 1) if code.islower() else (0, (1 << (8 * size)) - 1)
    return rng.choice([lo, hi, 0, rng.randint(lo, hi)])


def _outcome(f: Any) -> tuple[str, str]:
    """``("ok", repr of the value)`` or ``("error", the exception's type)``: repr tells 1 from 1.0 and True,
    and a dict's key order (the log line's)."""
    try:
        return "ok", repr(f())
    except Exception as exc:  # noqa: BLE001 - compared between the two readers
        return "error", type(exc).__name__


@pytest.fixture(scope="module")
def book() -> TypeBook:
    return TypeBook()


def _structs(book: TypeBook) -> list[Any]:
    out = [book.message(t) for t in TYPES]
    for s in SERVICES:
        out += list(book.service(s))
    return out


def test_same_fields_as_cyclone_in_both_byte_orders(book: TypeBook) -> None:
    rng = random.Random(106)
    for cls in _structs(book):
        cls.__idl__.populate()
        for _ in range(6):
            sample = _value(cls.__idl__.v1_machine, rng)
            for order in (Endianness.Little, Endianness.Big):
                raw = cls.serialize(sample, use_version_2=False, endianness=order)
                want = to_fields(cls.deserialize(raw))
                got = read_fields(cls, raw)
                assert repr(got) == repr(want), cls
        assert _READERS[cls] is not None, f"{cls}: read by Cyclone, not by the fast reader"


def test_header_fields_of_a_service_part_are_left_out(book: TypeBook) -> None:
    request, _reply = book.service("std_srvs/srv/SetBool")
    raw = request.serialize(request(client_guid_=7, sequence_number_=3, data=True), use_version_2=False)
    assert read_fields(request, raw) == {"data": True}


def test_cut_short_xcdr2_and_declared_bytes_read_as_cyclone_reads_them(book: TypeBook) -> None:
    rng = random.Random(7)
    for t in ("sensor_msgs/msg/JointState", "geometry_msgs/msg/PoseWithCovarianceStamped", "std_msgs/msg/String",
              "diagnostic_msgs/msg/DiagnosticArray"):
        cls = book.message(t)
        cls.__idl__.populate()
        sample = _value(cls.__idl__.v1_machine, rng)
        raw = cls.serialize(sample, use_version_2=False)
        for cut in range(len(raw)):  # every prefix: the same value, or the same error
            short = raw[:cut]
            assert _outcome(lambda: read_fields(cls, short)) == _outcome(lambda: to_fields(cls.deserialize(short)))
        v2 = cls.serialize(sample, use_version_2=True)
        assert repr(read_fields(cls, v2)) == repr(to_fields(cls.deserialize(v2)))
    decl_cls = book.message("std_msgs/msg/String")
    other = book.message("std_msgs/msg/Float64")
    declared = Declared(other.serialize(other(data=2.5), use_version_2=False))
    declared.declaration = type("D", (), {"struct": other})()  # read in the publisher's own definition
    assert read_fields(decl_cls, declared) == {"data": 2.5}


def test_the_fast_reader_reads_without_cyclone_and_leaves_the_rest_to_it(book: TypeBook,
                                                                            monkeypatch: pytest.MonkeyPatch) -> None:
    cls = book.message("sensor_msgs/msg/JointState")
    sample = book.build(cls, {"name": ["a"], "position": [1.5]})
    raw, v2 = cls.serialize(sample, use_version_2=False), cls.serialize(sample, use_version_2=True)

    def refuse(*_a: Any, **_k: Any) -> Any:
        raise RuntimeError("Cyclone's deserializer called")
    monkeypatch.setattr(cls, "deserialize", refuse)
    assert read_fields(cls, raw)["position"] == [1.5]  # plain CDR: read here
    with pytest.raises(RuntimeError):  # control: XCDR2 goes to Cyclone's deserializer
        read_fields(cls, v2)
