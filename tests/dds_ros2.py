"""ROS 2-shaped DDS participants for the live tests, written with cyclonedds
to ROS 2's wire conventions (no ROS 2 installation here: nothing of rclpy,
rcl or an RMW runs).

What "ROS 2-shaped" means, as rmw_cyclonedds does it (rclverify/ros/live/dds.py
cites where): topics ``rt/<name>`` of type ``pkg::msg::dds_::T_`` in plain
CDR; a service's requests on ``rq/<name>Request`` and replies on
``rr/<name>Reply``, each sample starting with the client's request-writer
handle and a sequence number, which the server copies into its reply; the
client's endpoints carry ``clientid=...;`` and the server's
``serviceid=...;`` in their USER_DATA; a ROS 2 action is its two services
and its feedback and status topics under ``<name>/_action/``; every writer
announces its type hash (``typehash=RIHS01_...;``); the participant
publishes its nodes and their endpoints' GUIDs on ``ros_discovery_info``
(reliable, transient-local), which is how ``ros2 node list`` and
``rclverify ros diff --ros2`` learn node names.

Everything runs on 127.0.0.1: :func:`dds_env` writes a Cyclone
configuration with the loopback interface, multicast off and the unicast
peer 127.0.0.1, and picks a random ``ROS_DOMAIN_ID`` so that parallel runs
do not hear each other.
"""
from __future__ import annotations

import os
import random
import threading
import time
import uuid
from pathlib import Path
from typing import Any, Callable

from rclverify.runtime.dds.types import TypeBook, request_id, to_fields
from rclverify.ros.live.dds import (make_participant, reply_topic, request_topic, topic_name, type_hash_user_data,
                               write_raw)
from rclverify.ros.live.discovery_info import NodeInfo, discovery_struct, encode_participant_info
from rclverify.ros.live.dds_qos import QosProfile, to_dds

CONFIG = """<?xml version="1.0" encoding="UTF-8"?>
<CycloneDDS xmlns="https://cdds.io/config">
  <Domain Id="any">
    <General>
      <Interfaces><NetworkInterface name="lo" multicast="false"/></Interfaces>
      <AllowMulticast>false</AllowMulticast>
    </General>
    <Discovery>
      <ParticipantIndex>auto</ParticipantIndex>
      <MaxAutoParticipantIndex>40</MaxAutoParticipantIndex>
      <Peers><Peer address="127.0.0.1"/></Peers>
    </Discovery>
  </Domain>
</CycloneDDS>
"""
SERVICE_QOS = QosProfile(reliable=True, durability="volatile", depth=10)  # rmw_qos_profile_services_default


_HELD: list[int] = []  # the lock files of the domains this process took, open until it exits


def _free_domain() -> int:
    """A ``ROS_DOMAIN_ID`` (1..230) that no other test process on this machine
    holds and this one has not used before: each is taken with an exclusive
    lock on a file of the temporary directory, held until the process exits
    (two test workers that drew one domain heard each other's nodes)."""
    import fcntl
    import tempfile
    for d in random.SystemRandom().sample(range(1, 231), 230):
        fd = os.open(os.path.join(tempfile.gettempdir(), f"rclverify-test-dds-domain-{d}.lock"), os.O_CREAT | os.O_RDWR)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)
            continue
        _HELD.append(fd)
        return d
    raise RuntimeError("no free DDS domain for the test: all 230 are held")


def dds_env(tmp: Path) -> dict[str, str]:
    """``CYCLONEDDS_URI`` (a loopback-only configuration written in ``tmp``),
    a ``ROS_DOMAIN_ID`` of its own (:func:`_free_domain`) and
    ``RMW_IMPLEMENTATION=rmw_cyclonedds_cpp`` (the wire form of these
    participants' services, which the monitor reads by it)."""
    cfg = tmp / "cyclonedds.xml"
    cfg.write_text(CONFIG)
    # the participants here speak rmw_cyclonedds' wire form: the monitor is told so as a user would
    return {"CYCLONEDDS_URI": cfg.as_uri(), "ROS_DOMAIN_ID": str(_free_domain()),
            "RMW_IMPLEMENTATION": "rmw_cyclonedds_cpp"}


def wait_until(cond: Callable[[], bool], timeout: float, what: str) -> None:
    end = time.monotonic() + timeout
    while not cond():
        if time.monotonic() > end:
            raise AssertionError(f"{what}: not within {timeout} s")
        time.sleep(0.02)


class Ros2Participant:
    """One ROS 2 context: a participant, its nodes, ``ros_discovery_info``."""

    def __init__(self, types: TypeBook, domain: int) -> None:
        from cyclonedds.pub import DataWriter
        from cyclonedds.topic import Topic
        # made as rclverify makes its own (the domain configured first): the types announce Fast DDS's type
        # objects (rclverify.ros.live.dds_xtypes), which the domain's compatibility settings accept
        self.types, self.dp = types, make_participant(domain)
        self.nodes: list[NodeInfo] = []
        latched = to_dds(QosProfile(reliable=True, durability="transient_local", depth=1))
        self._info = DataWriter(self.dp, Topic(self.dp, "ros_discovery_info", discovery_struct()), qos=latched)
        self._topics: dict[str, Any] = {}
        self.entities: list[Any] = []  # kept: a cyclonedds entity is deleted with its last Python reference
        self.threads: list[threading.Thread] = []
        self.stop = threading.Event()

    def node(self, name: str, namespace: str = "/") -> NodeInfo:
        n = NodeInfo(namespace, name)
        self.nodes.append(n)
        return n

    def announce(self) -> None:
        """Publish this participant's nodes (after each change, as rmw does)."""
        write_raw(self._info, encode_participant_info(self.dp.guid.bytes, self.nodes))

    def _topic(self, name: str, struct: Any) -> Any:
        from cyclonedds.topic import Topic
        if name not in self._topics:
            self._topics[name] = Topic(self.dp, name, struct)
        return self._topics[name]

    def writer(self, node: NodeInfo, dds_topic: str, struct: Any, qos: QosProfile, user: bytes = b"") -> Any:
        from cyclonedds.pub import DataWriter
        ros_type = struct.__idl_typename__.replace("::dds_::", "::").replace("::", "/").rstrip("_")
        w = DataWriter(self.dp, self._topic(dds_topic, struct),
                       qos=to_dds(qos, user + type_hash_user_data(ros_type)))
        node.writers.append(w.guid.bytes)
        self.entities.append(w)
        return w

    def reader(self, node: NodeInfo, dds_topic: str, struct: Any, qos: QosProfile, user: bytes = b"") -> Any:
        from cyclonedds.sub import DataReader
        r = DataReader(self.dp, self._topic(dds_topic, struct), qos=to_dds(qos, user))
        node.readers.append(r.guid.bytes)
        self.entities.append(r)
        return r

    def publisher(self, node: NodeInfo, topic: str, msg_type: str, reliable: bool = True, depth: int = 10) -> Any:
        return self.writer(node, topic_name(topic), self.types.message(msg_type),
                           QosProfile(reliable=reliable, depth=depth))

    def subscriber(self, node: NodeInfo, topic: str, msg_type: str, reliable: bool = True) -> Any:
        return self.reader(node, topic_name(topic), self.types.message(msg_type), QosProfile(reliable=reliable,
                                                                                              depth=100))

    def _loop(self, reader: Any, handle: Callable[[Any], None]) -> None:
        def run() -> None:
            while not self.stop.is_set():
                for s in reader.take(N=64):
                    handle(s)
                time.sleep(0.005)
        t = threading.Thread(target=run, daemon=True)
        t.start()
        self.threads.append(t)

    # -- services -------------------------------------------------------------------------
    def serve(self, node: NodeInfo, service: str, srv_type: str,
              answer: Callable[[int, dict[str, Any]], tuple[dict[str, Any], float]]) -> None:
        """Serve ``service``: ``answer(k, request fields) -> (reply fields, delay s)`` for the k-th call."""
        req, rep = self.types.service(srv_type)
        user = f"serviceid={uuid.uuid4().hex};".encode()
        reader = self.reader(node, request_topic(service), req, SERVICE_QOS, user)
        writer = self.writer(node, reply_topic(service), rep, SERVICE_QOS, user)
        count = [0]

        def handle(s: Any) -> None:
            count[0] += 1
            fields, delay = answer(count[0], to_fields(s))
            if delay:
                time.sleep(delay)
            guid, seq = request_id(s)
            writer.write(self.types.build(rep, {**fields, "client_guid_": guid, "sequence_number_": seq}))
        self._loop(reader, handle)

    def client(self, node: NodeInfo, service: str, srv_type: str) -> Callable[[dict[str, Any], float], Any]:
        """A client of ``service``: ``call(fields, timeout) -> reply fields`` (``None`` on timeout)."""
        req, rep = self.types.service(srv_type)
        user = f"clientid={uuid.uuid4().hex};".encode()
        writer = self.writer(node, request_topic(service), req, SERVICE_QOS, user)
        reader = self.reader(node, reply_topic(service), rep, SERVICE_QOS, user)
        handle = writer.get_instance_handle() & 0xFFFFFFFFFFFFFFFF  # a DDS handle, as uint64
        seq = [0]

        def call(fields: dict[str, Any], timeout: float = 5.0) -> Any:
            seq[0] += 1
            writer.write(self.types.build(req, {**fields, "client_guid_": handle, "sequence_number_": seq[0]}))
            end = time.monotonic() + timeout
            while time.monotonic() < end:
                for s in reader.take(N=16):
                    if request_id(s) == (handle, seq[0]):
                        return to_fields(s)
                time.sleep(0.005)
            return None
        call.writer = writer  # type: ignore[attr-defined]
        call.reader = reader  # type: ignore[attr-defined]
        return call

    # -- actions -----------------------------------------------------------------------------
    def action_server(self, node: NodeInfo, name: str, action_type: str,
                      execute: Callable[[dict[str, Any]], tuple[list[tuple[float, dict[str, Any]]], dict[str, Any]]]
                      ) -> tuple[Any, ...]:
        """Serve action ``name``: ``execute(goal) -> ([(delay s, feedback)], result)``; feedback and the
        status go out as the goal runs; get-result is answered once the goal has finished.  Returns the
        writers a third party hears the goal's answers from (send-goal reply, get-result reply, feedback),
        for a test to wait until a monitor's readers matched them."""
        a = self.types.action(action_type)
        base = name.rstrip("/") + "/_action/"
        user = f"serviceid={uuid.uuid4().hex};".encode()
        goal_rq = self.reader(node, request_topic(base + "send_goal"), a.send_goal[0], SERVICE_QOS, user)
        goal_rr = self.writer(node, reply_topic(base + "send_goal"), a.send_goal[1], SERVICE_QOS, user)
        user2 = f"serviceid={uuid.uuid4().hex};".encode()
        res_rq = self.reader(node, request_topic(base + "get_result"), a.get_result[0], SERVICE_QOS, user2)
        res_rr = self.writer(node, reply_topic(base + "get_result"), a.get_result[1], SERVICE_QOS, user2)
        fb = self.writer(node, topic_name(base + "feedback"), a.feedback, QosProfile(reliable=True, depth=10))
        st = self.writer(node, topic_name(base + "status"), a.status,
                         QosProfile(reliable=True, durability="transient_local", depth=1))
        results: dict[bytes, dict[str, Any]] = {}
        waiting: list[Any] = []
        lock = threading.Lock()

        def status(gid: list[int], code: int) -> None:
            st.write(self.types.build(a.status, {"status_list": [{"goal_info": {"goal_id": {"uuid": gid}},
                                                                  "status": code}]}))

        def on_goal(s: Any) -> None:
            guid, seq = request_id(s)
            gid = list(s.goal_id.uuid)
            goal_rr.write(self.types.build(a.send_goal[1], {"accepted": True, "client_guid_": guid,
                                                            "sequence_number_": seq}))
            status(gid, 2)
            steps, result = execute(to_fields(s.goal))
            for delay, feedback in steps:
                time.sleep(delay)
                fb.write(self.types.build(a.feedback, {"goal_id": {"uuid": gid}, "feedback": feedback}))
            results[bytes(gid)] = result
            status(gid, 4)
            answer_waiting()

        def answer_waiting() -> None:
            with lock:
                todo = list(waiting)
            for s in todo:
                r = results.get(bytes(s.goal_id.uuid))
                if r is not None:
                    guid, seq = request_id(s)
                    res_rr.write(self.types.build(a.get_result[1], {"status": 4, "result": r, "client_guid_": guid,
                                                                   "sequence_number_": seq}))
                    with lock:
                        waiting.remove(s)

        def on_result_request(s: Any) -> None:
            with lock:
                waiting.append(s)
            answer_waiting()
        self._loop(goal_rq, on_goal)
        self._loop(res_rq, on_result_request)
        return goal_rr, res_rr, fb

    def action_client(self, node: NodeInfo, name: str, action_type: str) -> Callable[[dict[str, Any], float], Any]:
        """A client of action ``name``: ``send(goal, timeout) -> (feedbacks, result)``."""
        a = self.types.action(action_type)
        base = name.rstrip("/") + "/_action/"
        user = f"clientid={uuid.uuid4().hex};".encode()
        goal_w = self.writer(node, request_topic(base + "send_goal"), a.send_goal[0], SERVICE_QOS, user)
        goal_r = self.reader(node, reply_topic(base + "send_goal"), a.send_goal[1], SERVICE_QOS, user)
        res_w = self.writer(node, request_topic(base + "get_result"), a.get_result[0], SERVICE_QOS, user)
        res_r = self.reader(node, reply_topic(base + "get_result"), a.get_result[1], SERVICE_QOS, user)
        fb_r = self.reader(node, topic_name(base + "feedback"), a.feedback, QosProfile(reliable=True, depth=10))
        handles = (goal_w.get_instance_handle() & 0xFFFFFFFFFFFFFFFF, res_w.get_instance_handle() & 0xFFFFFFFFFFFFFFFF)
        seq = [0]

        def send(goal: dict[str, Any], timeout: float = 5.0) -> Any:
            gid = list(uuid.uuid4().bytes)
            seq[0] += 1
            goal_w.write(self.types.build(a.send_goal[0], {"goal_id": {"uuid": gid}, "goal": goal,
                                                           "client_guid_": handles[0], "sequence_number_": seq[0]}))
            res_w.write(self.types.build(a.get_result[0], {"goal_id": {"uuid": gid}, "client_guid_": handles[1],
                                                           "sequence_number_": seq[0]}))
            feedbacks: list[Any] = []
            end = time.monotonic() + timeout
            while time.monotonic() < end:
                feedbacks += [to_fields(s.feedback) for s in fb_r.take(N=16) if list(s.goal_id.uuid) == gid]
                goal_r.take(N=16)
                for s in res_r.take(N=16):
                    if request_id(s) == (handles[1], seq[0]):
                        return feedbacks, to_fields(s.result)
                time.sleep(0.005)
            return feedbacks, None
        send.writers = (goal_w, res_w)  # type: ignore[attr-defined]
        return send

    def close(self) -> None:
        self.stop.set()
        for t in self.threads:
            t.join(2)
        self.dp.__del__()


def matched(writer: Any) -> int:
    """How many readers ``writer`` is matched with now."""
    return int(writer.get_publication_matched_status().current_count)


def domain_of(env: dict[str, str]) -> int:
    return int(env["ROS_DOMAIN_ID"])


__all__ = ["Ros2Participant", "dds_env", "domain_of", "matched", "wait_until"]


if __name__ == "__main__":  # pragma: no cover - a manual check
    print(dds_env(Path(os.environ.get("TMPDIR", "/tmp"))))
