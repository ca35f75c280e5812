"""A ROS 2 bag's service calls read back without middleware (backends/monitors/bag_calls.py; docs/ros2.md,
"Service calls and action goals in the bag").

The bags are made here with rosbags' writer, their events encoded by the structs the live monitor uses and
described by the definitions ``--record`` writes (runtime/dds/bag_types.py): what ``ros2 bag record`` keeps of
a server that publishes its introspection events (no decisions topic), the same with ``METADATA`` only, and a
decisions line naming an event the bag does not hold.  tests/runtime/test_ros2_bag_calls.py runs the real thing.
"""
from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path
from typing import Any, Sequence

import pytest

pytest.importorskip("cyclonedds", reason="the cyclonedds binding is not installed (pip install cyclonedds)")
pytest.importorskip("rosbags", reason="rosbags is not installed (the ros extra)")

RCL = """\
node Lamp {
  inputs( req : BOOL )
  outputs( ok : BOOL )
  services( std_srvs/SetBool lamp serves(in.req, out.ok) )
  assume( TRUE )
  guarantee( in.req -> out.ok ) triggered by in.req within 200 ms
}
"""
GID = bytes(range(1, 17))
T0 = 1_700_000_000_000_000_000  # ns


def _workspace(tmp: Path) -> Path:
    ws = tmp / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/sys.rcl").write_text(RCL)
    (ws / "contracts/plan.yaml").write_text("contracts: [contracts/sys.rcl]\n")
    (ws / "interfaces/std_srvs/srv").mkdir(parents=True)
    (ws / "interfaces/std_srvs/srv/SetBool.srv").write_text("bool data\n---\nbool success\nstring message\n")
    return ws


def _bag(ws: Path, path: Path, events: list[tuple[int, int, int, Any, Any]],
         decisions: Sequence[dict[str, Any]] = ()) -> None:
    """A bag with ``/lamp/_service_event`` events ``(time ns, event type, sequence number, request, response)``
    (dicts or ``None``) and ``/rclverify/call_decisions`` lines."""
    from rosbags.rosbag2 import StoragePlugin, Writer

    from rclverify.runtime.dds.bag_types import definition
    from rclverify.runtime.dds.introspection import event_struct
    from rclverify.runtime.dds.types import TypeBook
    from rclverify.traces.bag import typestore
    types = TypeBook([ws / "interfaces"])
    cls = event_struct(types, "std_srvs/SetBool")
    msgdef, digest = definition(types, "std_srvs/srv/SetBool_Event")
    string = types.message("std_msgs/String")
    with Writer(path, version=8, storage_plugin=StoragePlugin.MCAP) as w:
        conn = w.add_connection("/lamp/_service_event", "std_srvs/srv/SetBool_Event", msgdef=msgdef, rihs01=digest)
        dconn = w.add_connection("/rclverify/call_decisions", "std_msgs/msg/String", typestore=typestore([]))
        for t, kind, seq, req, resp in events:
            data = {"info": {"event_type": kind, "stamp": {"sec": t // 10**9, "nanosec": t % 10**9},
                             "client_gid": list(GID), "sequence_number": seq},
                    "request": [req] if req is not None else [], "response": [resp] if resp is not None else []}
            w.write(conn, t, bytes(types.build(cls, data).serialize()))
        for k, line in enumerate(decisions):
            w.write(dconn, T0 + k, bytes(string(data=json.dumps(line)).serialize()))


def _monitor(ws: Path, *args: str) -> tuple[int, Any, str]:
    from rclverify.cli.commands import main
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(["monitor", "-w", str(ws), "--horizon", "1.0", "--json", *args])
    return code, json.loads(out.getvalue()) if out.getvalue().strip() else None, err.getvalue()


def test_a_servers_introspection_events_are_paired_and_judged(tmp_path: Path) -> None:
    """As ``ros2 bag record`` keeps them: REQUEST_RECEIVED and RESPONSE_SENT of the server, two calls
    overlapping (paired by client_gid + sequence_number, never by order), one answered wrong, one late."""
    ws = _workspace(tmp_path)
    ms = 1_000_000
    _bag(ws, tmp_path / "b", [(T0, 1, 1, {"data": True}, None), (T0 + 10 * ms, 1, 2, {"data": True}, None),
                              (T0 + 50 * ms, 2, 2, None, {"success": True, "message": ""}),
                              (T0 + 400 * ms, 2, 1, None, {"success": False, "message": ""}),
                              (T0 + 3000 * ms, 0, 9, None, None)])  # a client's METADATA event: not the side read
    code, report, err = _monitor(ws, str(tmp_path / "b"))
    (calls,) = [e for e in report if "calls" in e]
    assert calls["calls"]["counts"]["violated"] == 1 and calls["calls"]["counts"]["satisfied"] == 1, (report, err)
    assert calls["calls"]["first_violation"]["values"] == {"in.req": "TRUE", "out.ok": "FALSE"}
    assert calls["call_counts"]["calls"] == 2 and calls["call_counts"]["answered"] == 2
    (dl,) = [e["call_deadlines"] for e in report if "call_deadlines" in e]
    assert dl["counts"]["true"] == 1 and dl["counts"]["false"] == 1, dl  # the 400 ms answer is late
    assert code == 1


def test_events_without_contents_are_never_green(tmp_path: Path) -> None:
    ws = _workspace(tmp_path)
    _bag(ws, tmp_path / "b", [(T0, 1, 1, None, None), (T0 + 10**8, 2, 1, None, None)])
    code, report, err = _monitor(ws, str(tmp_path / "b"))
    items = {i["name"]: i for e in report for i in e.get("not_judged", [])}
    assert code == 0 and "METADATA" in items["/lamp"]["detail"], items
    assert _monitor(ws, "--strict", str(tmp_path / "b"))[0] == 1


def test_a_decision_naming_a_message_the_bag_lacks_is_one_error(tmp_path: Path) -> None:
    ws = _workspace(tmp_path)
    line = {"kind": "call", "link": "lamp", "part": "request", "index": 0, "time": T0 / 1e9, "key": ["w", "ab", 1],
            "where": "lamp call ab#1 request", "ref": ["lamp/_service_event", T0 + 10**6, "request"]}
    _bag(ws, tmp_path / "b", [(T0, 0, 1, {"data": True}, None)], [line])
    code, report, err = _monitor(ws, str(tmp_path / "b"))
    assert code == 2 and "Traceback" not in err, err
    assert f"{tmp_path / 'b'}: topic /rclverify/call_decisions: error:" in err and "does not hold" in err, err
