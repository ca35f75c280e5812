"""ROS 2's wire conventions as rclverify speaks them over DDS, each checked
against an independent oracle (docs/monitors.md, "ROS 2 over DDS"):

* the CDR of the structs made at run time (:mod:`rclverify.runtime.dds.types`)
  equals rosbags' CDR, which rosbag2 stores, byte for byte, on random
  messages of standard and workspace types; rmw_cyclonedds' request header
  is the 16 bytes it writes before the request (``serdata.cpp``);
* ``ros_discovery_info`` decodes what rosbags serializes in ROS 2 Humble's
  layout (24-byte GIDs) and in Jazzy's (16 bytes);
* the QoS matching rule equals Cyclone DDS's own matching on random pairs,
  and the reader chosen for a topic's publishers matches as many of them as
  the best of every candidate reader (brute force);
* names: ``rt/``, ``rq/...Request``, ``rr/...Reply``, ``pkg::msg::dds_::T_``.
"""
from __future__ import annotations

import itertools
import random
import struct
from pathlib import Path

import pytest

pytest.importorskip("cyclonedds", reason="the cyclonedds binding is not installed (pip install cyclonedds)")

from rclverify.runtime.dds.types import DdsTypeError, TypeBook, request_id, to_fields  # noqa: E402
from rclverify.ros.live import dds, discovery_info  # noqa: E402
from rclverify.ros.live.dds_qos import (DURABILITY, INFINITE_NS, LIVELINESS, XCDR1, XCDR2, QosProfile,  # noqa: E402
                                   from_dds, mismatches, reader_for, to_dds)
from rclverify.traces.bag import typestore  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
MSG_DIRS = [REPO / "backends" / "monitors" / "msg"]
TYPES = ["std_msgs/msg/Float64", "std_msgs/msg/String", "sensor_msgs/msg/LaserScan", "geometry_msgs/msg/PoseStamped",
         "sensor_msgs/msg/JointState", "nav_msgs/msg/Odometry", "gazebo_radiation_plugin/msg/Snapshot",
         "action_msgs/msg/GoalStatusArray", "sensor_msgs/msg/Image"]


def _random_value(store, desc, rng: random.Random):  # type: ignore[no-untyped-def]
    kind, detail = int(desc[0]), desc[1]
    if kind == 1:
        base = detail[0]
        if base == "string":
            return "".join(rng.choice("abcxyz_ ") for _ in range(rng.randint(0, 9)))
        if base == "bool":
            return rng.random() < 0.5
        if base.startswith("float"):
            return float(struct.unpack("<f", struct.pack("<f", rng.uniform(-1e3, 1e3)))[0])
        bits = int("".join(c for c in base if c.isdigit()) or 8)
        lo, hi = (0, 2 ** bits - 1) if base.startswith(("uint", "byte", "char", "octet")) else (-2 ** (bits - 1),
                                                                                               2 ** (bits - 1) - 1)
        return rng.randint(lo, hi)
    if kind == 2:
        return _random_msg(store, str(detail), rng)
    n = int(detail[1]) if kind == 3 else rng.randint(0, 4)
    return [_random_value(store, detail[0], rng) for _ in range(n)]


def _random_msg(store, name: str, rng: random.Random) -> dict:  # type: ignore[no-untyped-def]
    return {f: _random_value(store, d, rng) for f, d in store.fielddefs[name][1]}


def _plain(store, v):  # type: ignore[no-untyped-def]
    """A rosbags message as plain data (nested messages in lists too)."""
    if hasattr(v, "__msgtype__"):
        return {k: _plain(store, getattr(v, k)) for k, _ in store.fielddefs[v.__msgtype__][1]}
    if hasattr(v, "tolist"):
        return v.tolist()
    if isinstance(v, (list, tuple)):
        return [_plain(store, x) for x in v]
    return v


def test_struct_cdr_equals_rosbags_cdr_on_random_messages() -> None:
    store = typestore(MSG_DIRS)
    book = TypeBook(MSG_DIRS)
    rng = random.Random(20260601)
    for k in range(40):
        name = TYPES[k % len(TYPES)]
        fields = _random_msg(store, name, rng)
        ours = book.build(book.message(name), fields).serialize(use_version_2=False)
        msg = store.deserialize_cdr(ours, name)  # rosbags reads our bytes ...
        assert _plain(store, msg) == to_fields(book.message(name).deserialize(ours))
        theirs = bytes(store.serialize_cdr(msg, name))  # ... and writes the same bytes back
        assert ours == theirs, (name, fields)


def test_the_request_header_is_rmw_cyclonedds_prefix() -> None:
    book = TypeBook([REPO / "examples" / "safety_stop" / "interfaces"])
    req, rep = book.service("std_srvs/SetBool")
    assert req.__idl_typename__ == "std_srvs::srv::dds_::SetBool_Request_"  # type: ignore[attr-defined]
    guid, seq = 0x0123456789ABCDEF, 42
    raw = book.build(req, {"client_guid_": guid, "sequence_number_": seq, "data": True}).serialize(use_version_2=False)
    assert raw == b"\x00\x01\x00\x00" + struct.pack("<Qq", guid, seq) + b"\x01"
    raw = book.build(rep, {"client_guid_": guid, "sequence_number_": seq, "success": False, "message": "no"}) \
        .serialize(use_version_2=False)
    assert raw == b"\x00\x01\x00\x00" + struct.pack("<Qq?3xI", guid, seq, False, 3) + b"no\x00"
    s = rep.deserialize(raw)
    assert request_id(s) == (guid, seq) and to_fields(s) == {"success": False, "message": "no"}
    a = book.action("rclverify_examples/Move")
    names = (a.send_goal[0].__idl_typename__, a.feedback.__idl_typename__)  # type: ignore[attr-defined]
    assert names == ("rclverify_examples::action::dds_::Move_SendGoal_Request_",
                     "rclverify_examples::action::dds_::Move_FeedbackMessage_")
    goal = b"\x00\x01\x00\x00" + struct.pack("<Qq", 1, 2) + bytes(range(16)) + struct.pack("<d", 2.5)
    assert book.build(a.send_goal[0], {"client_guid_": 1, "sequence_number_": 2, "goal_id": {"uuid": list(range(16))},
                                       "goal": {"target": 2.5}}).serialize(use_version_2=False) == goal


def test_types_that_cannot_be_made_say_which() -> None:
    book = TypeBook([])
    with pytest.raises(DdsTypeError, match="nowhere_msgs/msg/Thing is neither"):
        book.message("nowhere_msgs/Thing")
    with pytest.raises(DdsTypeError, match="Move_Goal is neither"):
        book.action("rclverify_examples/Move")  # its .action file is not among the directories


def _gid(rng: random.Random) -> bytes:
    return bytes(rng.randrange(256) for _ in range(16))


@pytest.mark.parametrize("layout", ["humble", "jazzy"])
def test_ros_discovery_info_decodes_both_gid_layouts(layout: str) -> None:
    from rosbags.typesys import get_types_from_msg
    store = typestore([])
    if layout == "jazzy":  # rmw_dds_common 3: a GID is 16 bytes
        for name, text in (("Gid", "uint8[16] data"),
                           ("NodeEntitiesInfo", "string<=256 node_namespace\nstring<=256 node_name\n"
                                                "rmw_dds_common/Gid[] reader_gid_seq\n"
                                                "rmw_dds_common/Gid[] writer_gid_seq"),
                           ("ParticipantEntitiesInfo", "rmw_dds_common/Gid gid\n"
                                                       "rmw_dds_common/NodeEntitiesInfo[] node_entities_info_seq")):
            store.fielddefs.pop(f"rmw_dds_common/msg/{name}", None)
            store.types.pop(f"rmw_dds_common/msg/{name}", None)
            store.register(get_types_from_msg(text, f"rmw_dds_common/msg/{name}"))
    size = 24 if layout == "humble" else 16
    rng = random.Random(7 + size)
    Gid = store.types["rmw_dds_common/msg/Gid"]
    Node = store.types["rmw_dds_common/msg/NodeEntitiesInfo"]
    Info = store.types["rmw_dds_common/msg/ParticipantEntitiesInfo"]
    import numpy as np
    for _ in range(25):
        part = _gid(rng)
        gids = lambda: [_gid(rng) for _ in range(rng.randint(0, 3))]  # noqa: E731
        nodes = [discovery_info.NodeInfo(rng.choice(["/", "/robot", "/a/b"]), f"n{rng.randrange(100)}", gids(), gids())
                 for _ in range(rng.randint(0, 3))]
        g = lambda b: Gid(data=np.frombuffer(b.ljust(size, b"\0"), dtype=np.uint8))  # noqa: E731
        msg = Info(gid=g(part), node_entities_info_seq=[
            Node(node_namespace=n.namespace, node_name=n.name, reader_gid_seq=[g(x) for x in n.readers],
                 writer_gid_seq=[g(x) for x in n.writers]) for n in nodes])
        raw = bytes(store.serialize_cdr(msg, "rmw_dds_common/msg/ParticipantEntitiesInfo"))
        gid, got, found = discovery_info.decode_participant_info(raw)
        assert (gid, got, found) == (part, nodes, size)
        ours = discovery_info.encode_participant_info(part, nodes, size)
        assert ours[:len(raw)] == raw and not any(ours[len(raw):])  # the same bytes, up to padding
    with pytest.raises(ValueError, match="not a ParticipantEntitiesInfo"):
        discovery_info.decode_participant_info(b"\x00\x01\x00\x00" + bytes(17))


def _random_qos(rng: random.Random, wild: bool = True) -> QosProfile:
    """A random QoS, each policy off its default now and then (so that
    random pairs match about as often as not)."""
    def pick(default, *others):  # type: ignore[no-untyped-def]
        return default if rng.random() < 0.85 else rng.choice(others)
    parts = [("a",), ("b",), ("",), ("a", "b")] + ([("a*",)] if wild else [])
    return QosProfile(reliable=rng.random() < 0.6, durability=pick("volatile", "transient_local"),
                      depth=rng.choice([1, 10, None]), deadline_ns=pick(INFINITE_NS, 10 ** 9, 2 * 10 ** 9),
                      liveliness=pick("automatic", *LIVELINESS[1:]),
                      lease_ns=pick(INFINITE_NS, 10 ** 9, 2 * 10 ** 9), exclusive=rng.random() < 0.2,
                      partitions=pick((), *parts), representations=pick((XCDR1,), (XCDR2,), (XCDR1, XCDR2)))


def test_the_matching_rule_equals_cyclones_own(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Oracle: Cyclone DDS matches (or not) a writer and a reader of one
    participant; :func:`mismatches` must say the same on 50 random pairs.
    On loopback only, in a random domain (tests/dds_ros2.py)."""
    from dds_ros2 import dds_env
    env = dds_env(tmp_path)
    for k, v in env.items():
        monkeypatch.setenv(k, v)
    from cyclonedds.domain import DomainParticipant
    from cyclonedds.idl import make_idl_struct
    from cyclonedds.idl import types as T
    from cyclonedds.pub import DataWriter
    from cyclonedds.sub import DataReader
    from cyclonedds.topic import Topic
    S = make_idl_struct("QosProbe_", "rclverify::msg::dds_::QosProbe_", {"a": T.int32})
    dp = DomainParticipant(int(env["ROS_DOMAIN_ID"]))
    rng = random.Random(11)
    try:
        pairs = [(_random_qos(rng), _random_qos(rng)) for _ in range(50)]
        ends = []
        for k, (w, r) in enumerate(pairs):
            tp = Topic(dp, f"qos_probe_{k}", S)
            ends.append((DataWriter(dp, tp, qos=to_dds(w)), DataReader(dp, tp, qos=to_dds(r))))
        assert from_dds(to_dds(pairs[0][0])) == pairs[0][0]
        deadline = __import__("time").monotonic() + 5
        while True:  # local matching is immediate; allow the discovery thread a moment
            got = [bool(rd.get_matched_publications()) for _, rd in ends]
            want = [not mismatches(w, r) for w, r in pairs]
            if got == want or __import__("time").monotonic() > deadline:
                break
        assert got == want, [(p, mismatches(*p)) for p, g, w in zip(pairs, got, want) if g != w]
        assert 10 <= sum(want) <= 40  # both outcomes were tried
    finally:
        dp.__del__()


def test_the_reader_hears_as_many_publishers_as_any_reader_could() -> None:
    """Brute force: every candidate reader (reliability, durability,
    ownership, a subset of the offered partitions) against the offers; the
    chosen one matches the most, and every offer when one reader can."""
    rng = random.Random(5)
    for _ in range(60):
        offers = [_random_qos(rng, wild=False) for _ in range(rng.randint(1, 4))]
        names = sorted({p for o in offers for p in (o.partitions or ("",))})
        best = 0
        for rel, dur, exc in itertools.product((True, False), DURABILITY[:2], (True, False)):
            for k in range(1, len(names) + 1):
                for parts in itertools.combinations(names, k):
                    cand = QosProfile(reliable=rel, durability=dur, depth=1000, exclusive=exc,
                                      partitions=parts if parts != ("",) else (),
                                      representations=(XCDR1, XCDR2))
                    best = max(best, sum(not mismatches(o, cand) for o in offers))
        req, left = reader_for(offers)
        assert len(offers) - len(left) == best
        assert left == [k for k, o in enumerate(offers) if mismatches(o, req)]
        assert req.reliable == all(o.reliable for o in offers)  # reliable only when every publisher is


def test_names_follow_ros2_conventions() -> None:
    assert dds.topic_name("/scan") == "rt/scan" and dds.topic_name("scan") == "rt/scan"
    assert (dds.request_topic("/estop"), dds.reply_topic("/estop")) == ("rq/estopRequest", "rr/estopReply")
    assert dds.ros_name("rq/move/_action/send_goalRequest") == ("request", "/move/_action/send_goal")
    assert dds.ros_name("rr/estopReply") == ("reply", "/estop") and dds.ros_name("ros_discovery_info")[0] == "dds"
    assert dds.dds_type("sensor_msgs/LaserScan") == "sensor_msgs::msg::dds_::LaserScan_"
    assert dds.dds_type("std_srvs/srv/SetBool_Request") == "std_srvs::srv::dds_::SetBool_Request_"
    assert dds.ros_type("std_srvs::srv::dds_::SetBool_Request_") == "std_srvs/srv/SetBool_Request"
    assert dds.ros_type("not_ros") is None
    assert dds.service_type("pkg/action/Move_SendGoal_Request") == "pkg/action/Move_SendGoal"


def test_ros_domain_id_is_checked() -> None:
    assert dds.domain_id({}) == 0 and dds.domain_id({"ROS_DOMAIN_ID": " 42 "}) == 42
    for bad in ("x", "233", "-1"):
        with pytest.raises(dds.DdsUnavailable, match="ROS_DOMAIN_ID"):
            dds.domain_id({"ROS_DOMAIN_ID": bad})


# -- issue 62: layouts, type hashes, wide strings, the bag writer's thread -------------------------------

#: hashes rosidl wrote into ROS 2 Kilted's share/<pkg>/msg/<T>.json (and that rclpy's publishers announce)
ROSIDL_HASHES = {
    "std_msgs/msg/Float64MultiArray": "RIHS01_1025ddc6b9552d191f89ef1a8d2f60f3d373e28b283d8891ddcc974e8c55397f",
    "std_msgs/msg/Char": "RIHS01_3ad2d04dd29ba19d04b16659afa3ccaedd691914b02a64e82e252f2fa6a586a9",
    "sensor_msgs/msg/JointState": "RIHS01_a13ee3a330e346c9d87b5aa18d24e11690752bd33a0350f11c5882bc9179260e",
}


@pytest.mark.parametrize("name", sorted(ROSIDL_HASHES))
def test_the_type_hash_is_rosidls(name: str) -> None:
    """REP-2011's hash as rosidl computes it (a .msg ``char`` hashed as ``uint8``, where rosbags' own hash
    differs), from the definitions the type book reads."""
    book = TypeBook([])
    assert book.type_hash(book.message(name)) == ROSIDL_HASHES[name]
    assert book.type_hash(book.message("std_msgs/String").__class__) is None  # not a message struct: no hash


def test_the_announced_type_hash_is_read_from_user_data() -> None:
    h = ROSIDL_HASHES["std_msgs/msg/Char"]
    assert dds.announced_type_hash(f"typehash={h};".encode()) == h
    assert dds.announced_type_hash(f"clientid=1.2;typehash={h};".encode()) == h
    assert dds.announced_type_hash(b"") is None and dds.announced_type_hash(b"typehash=RIHS02_x;") is None


def test_a_layout_difference_names_the_field() -> None:
    from cyclonedds.idl import make_idl_struct
    from cyclonedds.idl import types as T

    from rclverify.runtime.dds.layout import difference, shape
    book = TypeBook([])
    mine = shape(book.message("geometry_msgs/PoseWithCovarianceStamped"))
    point = make_idl_struct("Point_", "x::Point_", {"x": T.float64, "y": T.float64, "z": str})
    quat = make_idl_struct("Quaternion_", "x::Quaternion_", {"x": T.float64, "y": T.float64, "z": T.float64,
                                                               "w": T.float64})
    pose = make_idl_struct("Pose_", "x::Pose_", {"position": point, "orientation": quat})
    cov = make_idl_struct("PoseWithCovariance_", "x::PoseWithCovariance_",
                          {"pose": pose, "covariance": T.array[T.float64, 36]})  # type: ignore[misc]
    assert difference(mine, shape(book.message("geometry_msgs/PoseWithCovarianceStamped"))) is None
    theirs = ("struct", (mine[1][0], ("pose", shape(cov))))
    assert difference(mine, theirs) == "field pose.pose.position.z: the publisher's is string, the contract's float64"
    short = make_idl_struct("PoseWithCovariance_", "y::PoseWithCovariance_",
                            {"pose": book.message("geometry_msgs/Pose"), "covariance": T.array[T.float64, 9]})  # type: ignore[misc]
    assert difference(mine, ("struct", (mine[1][0], ("pose", shape(short))))) == \
        "field pose.covariance: the publisher's is an array of 9 float64, the contract's an array of 36 float64"
    fewer = ("struct", mine[1][:1])
    assert difference(mine, fewer) == "field pose: the publisher's type has no such field"
    assert difference(fewer, mine) == "field pose: the publisher's type has it, the contract's has not"
    seq = shape(book.message("std_msgs/Float64MultiArray"))
    bounded = ("struct", (seq[1][0], ("data", ("sequence", "float64"))))
    assert difference(seq, bounded) is None  # a sequence's bound is not part of the layout (XCDR1 bytes alike)


def test_a_wstring_is_its_wire_form_and_its_text(tmp_path: Path) -> None:
    """Fast DDS's and rmw_cyclonedds' plain CDR: a uint32 count, then 4-byte code units (measured from
    rclpy on Fast DDS with test_msgs/WStrings); decoded back to the text, in arrays too."""
    pkg = tmp_path / "wide_msgs" / "msg"
    pkg.mkdir(parents=True)
    (pkg / "W.msg").write_text("wstring w\nwstring[2] ws\nint32 n\n")
    book = TypeBook([tmp_path])
    W = book.message("wide_msgs/W")
    raw = book.build(W, {"w": "h\u00e9\u30cf", "ws": ["a", ""], "n": 7}).serialize(use_version_2=False)
    assert raw[4:8] == struct.pack("<I", 3) and raw[8:20] == struct.pack("<3I", 0x68, 0xE9, 0x30CF)
    assert to_fields(W.deserialize(raw)) == {"w": "h\u00e9\u30cf", "ws": ["a", ""], "n": 7}  # type: ignore[attr-defined]


def test_the_bag_is_written_from_its_own_thread(tmp_path: Path) -> None:
    """SQLite's objects live in the thread that made them: writes from another thread (the engine's) reach
    the bag, bad input is counted and never written, and the bag reads back whole."""
    import threading

    from rosbags.highlevel import AnyReader

    from rclverify.runtime.dds.bag import BagRecorder
    book = TypeBook([])
    F = book.message("std_msgs/Float64")
    rec = BagRecorder(tmp_path / "bag", "sqlite3", {"/x": "std_msgs/Float64"}, [])
    def engine() -> None:
        for k in range(50):
            rec.write("x", 1_000 + k, F(data=float(k)).serialize(use_version_2=False))
    t = threading.Thread(target=engine)
    t.start()
    t.join()
    rec.write("x", 2_000, "not bytes")  # type: ignore[arg-type]
    rec.write("elsewhere", 2_001, b"\x00\x01\x00\x00")
    out = rec.close()
    assert out["messages"] == 50 and out["failed"] == 1, out
    with AnyReader([tmp_path / "bag"], default_typestore=typestore([])) as reader:
        got = [getattr(reader.deserialize(raw, c.msgtype), "data") for c, _t, raw in reader.messages()]
    assert got == [float(k) for k in range(50)]
