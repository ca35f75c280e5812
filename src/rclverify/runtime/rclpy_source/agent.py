"""The live monitor's rclpy agent: run in a ROS 2 Python, it hears the
robot through rclpy on whatever middleware the robot runs (Fast DDS,
Cyclone DDS, Zenoh) and hands the monitor what it hears.

Run as a script (``python agent.py``) by :mod:`.bus`; it imports rclpy
and the standard library only (and :mod:`wire` and its ``agent_*`` modules, beside it), never
rclverify, so any ROS 2 Python can run it: a sourced apt installation's
``python3`` or a venv with ROS 2's PyPI wheels.

* **Taps** (``{"op": "tap", "id", "topic", "type"}``): a subscription
  of the topic's type that hands over each message serialized, exactly as
  rmw received it (``raw=True``; CDR with its encapsulation header), with
  rmw's message info: the source and receipt stamps, the publisher's GID,
  the writer's sequence number.  The subscription is made once a publisher
  of that type is in the graph, with the QoS every publisher can match
  (reliable only when all are, transient-local when all are: a latched
  message is delivered to it as to any late ROS 2 subscriber), and made
  again when a publisher appears that it cannot match.  Keep-last
  :data:`TAP_DEPTH`.  After each wake-up of the executor
  every tap's subscription is drained (at most :data:`TAKE_MAX` messages
  each a round) and the round's frames are written to the monitor in one
  write: under load the agent takes messages in batches rather than one
  executor turn each, and its history covers seconds at 5000 messages/s.
  After a round that took messages the agent lets the next ones gather
  for the ``linger`` the monitor's ``start`` names (:data:`LINGER_S`
  when it names none) before it waits again: at 1000 messages/s an
  executor turn a message (its wait set built anew, about 200 us) was most
  of its CPU.  A message is then handed over at most that much later; its
  time is its source timestamp, which the wait does not change.
* **A lean node**: no parameter services, no rosout publisher, and no
  default QoS event callbacks on its subscriptions and publishers (the
  monitor compares the publishers' QoS itself): the executor waits on the
  taps, the writers' nothing, and its guard condition only.
* **The graph**: each tapped or watched topic's publishers
  (GID, node, namespace, type, type hash, reliability, durability) as the
  ROS 2 graph API reports them, sent when they change.  The agent's node is
  hidden (``_rclverify_monitor_<pid>``) and its own endpoints are left out.
* **Services and actions** (``{"op": "service", "name", "action"}``): the
  nodes that serve and that call each one (``/ns/name``), from the graph
  API (``get_service_names_and_types_by_node`` and its client twin;
  rclpy.action's for actions), and the nodes that publish its introspection
  events, sent with the graph every :data:`SERVICE_PERIOD_S`: the monitor
  reads from them whose introspection events pair a call (the servers',
  else the clients') and which endpoints it does not hear with contents.
* **Writers** (``writer``, ``write``): publishers of the monitor (its
  verdicts), written with serialized messages the monitor made; a write
  to a writer already made is published by the thread that reads the
  commands as its line comes, without waking the executor.
* **Type descriptions** (``{"op": "describe", "type", "hash", "node",
  "ns"}``): the definition a publisher declares, as a type description
  (type_description_interfaces/msg/TypeDescription as a dict), for a
  publisher whose type hash is not the monitor's.  First rosidl's own
  description of the type in this Python (``share/<pkg>/msg/<T>.json``,
  written beside the interface when it was built), when its hash is the
  one asked (sha256 of the same description: the same definition); else
  the publisher's node's type description service
  (``<node>/get_type_description``, REP-2011, from Iron on), waited for
  at most :data:`agent_describe.DESCRIBE_TIMEOUT_S`.  Answered by one ``description``
  frame: the descriptions found (``candidates``, each with where it came
  from) and why the others were not had (``failures``); the monitor checks
  each candidate's hash itself.  Run as ``agent.py --describe TYPE...``,
  the agent prints this Python's own descriptions of the types named (one
  ``descriptions`` frame) and exits: the definition of a contract type the
  monitor has none of (:func:`.describe.installed_declarations`).

SIGINT is ignored (the monitor stops the agent when it stops: ``stop`` or
the end of stdin), so a Ctrl-C in a terminal does not cut the stream short.
At ``stop`` the agent says ``stopped`` once every sample it took is handed
over, then leaves the graph (its node destroyed, rclpy shut down) on its own:
the monitor need not wait for that to end its run.

The agent's command lines are read by :mod:`agent_commands`, its output queue is :mod:`agent_frames`, its readings of the graph
:mod:`agent_graph`, the type descriptions :mod:`agent_describe`: modules
beside this script, imported as top-level modules like :mod:`wire`.
"""
from __future__ import annotations

import base64
import os
import queue
import signal
import sys
import threading
import time
from typing import TYPE_CHECKING, Any, TypedDict

from importlib.metadata import version

import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
try:  # Iron and later
    from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
except ImportError:  # Humble
    from rclpy.qos_event import PublisherEventCallbacks, SubscriptionEventCallbacks
from rclpy.signals import SignalHandlerOptions
from rclpy.utilities import get_rmw_implementation_identifier

import wire  # type: ignore[import-not-found]  # beside this script (module docstring)

if TYPE_CHECKING:  # mypy reads the siblings as the package's modules
    from rclverify.runtime.rclpy_source.agent_commands import Command, message_class, read_commands
    from rclverify.runtime.rclpy_source.agent_describe import Describing, installed_description
    from rclverify.runtime.rclpy_source.agent_frames import emit, flush
    from rclverify.runtime.rclpy_source.agent_graph import Endpoint, GraphReading, endpoint, graph_dump, matches
else:  # run as a script: its folder is on sys.path (module docstring)
    from agent_commands import Command, message_class, read_commands
    from agent_describe import Describing, installed_description
    from agent_frames import emit, flush
    from agent_graph import Endpoint, GraphReading, endpoint, graph_dump, matches

GRAPH_PERIOD_S = 0.1
#: seconds the agent lets messages gather after a round that took some, when the monitor's ``start`` names
#: no ``linger`` (module docstring)
LINGER_S = 0.002
#: the interpreter's switch interval in the agent (s; Python's default 5 ms): the thread reading the
#: monitor's commands (a verdict to publish per message) holds the main thread off the samples at most
#: this long
SWITCH_INTERVAL_S = 0.0005
#: seconds between two readings of the services' and actions' servers and clients (one query per node each)
SERVICE_PERIOD_S = 0.5


#: the most messages taken from one tap's subscription in one round (:meth:`Agent.drain`), so a busy topic
#: does not hold the others back
TAKE_MAX = 1000
#: the history depth of each tap's subscription (keep-last; a ROS 2 topic is keyless, so samples of the
#: topic): at 5000 messages/s over three
#: topics, about 6 s of one topic's messages, should the agent be held off the CPU or its pipe be full
TAP_DEPTH = 10_000

class _Tap(TypedDict):
    """A tap's state: its topic and type, the message class (``None``: not importable), the
    subscription and its QoS (reliable, transient-local) once made, how often it was remade,
    and the publishers' GIDs it hears."""
    topic: str
    type: str
    cls: Any
    sub: Any
    qos: tuple[bool, bool] | None
    changes: int
    heard: list[str]


class Agent(GraphReading, Describing):
    """The agent's state: its node, taps and writers (module docstring)."""

    def __init__(self) -> None:
        rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
        self.name = f"_rclverify_monitor_{os.getpid()}"
        self.node = Node(self.name, start_parameter_services=False, enable_rosout=False)  # lean (docstring)
        self.ex = SingleThreadedExecutor()
        self.ex.add_node(self.node)
        self.taps: dict[int, _Tap] = {}
        self.watched: set[str] = set()
        self.services: dict[str, bool] = {}  # service or action name -> whether an action
        self.ends: dict[str, dict[str, list[str]]] = {}
        self.next_ends = 0.0
        self.writers: dict[int, Any] = {}
        self.last_graph: Any = None
        #: type description requests waiting for a node's answer: (type, hash) -> their state (:meth:`describe`)
        self.asked: dict[tuple[str, str], dict[str, Any]] = {}

    def hello(self) -> None:
        try:
            rclpy_version = version("rclpy")
        except Exception:  # noqa: BLE001 - an apt installation has no distribution metadata
            rclpy_version = ""
        emit(wire.json_frame({"what": "hello", "rmw": get_rmw_implementation_identifier(),
                               "distro": os.environ.get("ROS_DISTRO", ""), "rclpy": rclpy_version,
                               "python": sys.version.split()[0], "node": self.name}))

    # -- commands ------------------------------------------------------------------------------
    def command(self, c: Command) -> None:
        op = c.get("op")
        if op == "tap":
            try:
                cls = message_class(c["type"])
            except Exception as exc:  # noqa: BLE001 - said to the monitor, the tap stays deaf
                emit(wire.json_frame({"what": "error", "id": c["id"], "text": f"{type(exc).__name__}: {exc}"}))
                cls = None
            self.taps[int(c["id"])] = {"topic": c["topic"], "type": c["type"], "cls": cls, "sub": None,
                                       "qos": None, "changes": 0, "heard": []}
        elif op == "watch":
            self.watched.add(c["topic"])
        elif op == "service":
            self.services[c["name"]] = bool(c.get("action"))
        elif op == "writer":
            qos = QoSProfile(depth=int(c.get("depth", 10)),
                             reliability=ReliabilityPolicy.RELIABLE if c.get("reliable", True)
                             else ReliabilityPolicy.BEST_EFFORT,
                             durability=DurabilityPolicy.TRANSIENT_LOCAL if c.get("transient_local")
                             else DurabilityPolicy.VOLATILE)
            self.writers[int(c["id"])] = self.node.create_publisher(
                message_class(c["type"]), c["topic"], qos,
                event_callbacks=PublisherEventCallbacks(use_default_callbacks=False))
        elif op == "write":
            self.writers[int(c["id"])].publish(base64.b64decode(c["raw"]))
        elif op == "describe":
            self.describe(c["type"], c["hash"], c.get("node", ""), c.get("ns", "/"))

    # -- the graph -----------------------------------------------------------------------------
    def update(self) -> None:
        """Make or remake each tap's subscription for the publishers in the graph; report changes."""
        topics: dict[str, list[Endpoint]] = {}
        for t in sorted({t["topic"] for t in self.taps.values()} | self.watched):
            topics[t] = [endpoint(p) for p in self._publishers(t)]
        if self.services and time.monotonic() >= self.next_ends:
            self.ends = self._service_ends()
            self.next_ends = time.monotonic() + SERVICE_PERIOD_S
        graph = {"what": "graph", "topics": topics, "services": self.ends}
        if graph != self.last_graph:
            self.last_graph = graph
            emit(wire.json_frame(graph))
        for k, tap in self.taps.items():
            same = [p for p in topics.get(tap["topic"], []) if p["type"] == tap["type"]]
            if not same or tap["cls"] is None:
                continue
            want = (all(p["reliable"] for p in same), all(p["durability"] == "transient_local" for p in same))
            heard = sorted(p["gid"] for p in same)
            if tap["sub"] is not None and matches(tap["qos"], same):
                if heard != tap["heard"]:
                    tap["heard"] = heard
                    self._said(k, tap)
                continue
            if tap["sub"] is not None:
                self.node.destroy_subscription(tap["sub"])
                tap["changes"] += 1
            qos = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=TAP_DEPTH,
                             reliability=ReliabilityPolicy.RELIABLE if want[0] else ReliabilityPolicy.BEST_EFFORT,
                             durability=DurabilityPolicy.TRANSIENT_LOCAL if want[1] else DurabilityPolicy.VOLATILE)
            tap["sub"] = self.node.create_subscription(
                tap["cls"], tap["topic"], _handler(k), qos, raw=True,
                event_callbacks=SubscriptionEventCallbacks(use_default_callbacks=False))
            tap["qos"], tap["heard"] = want, heard
            self._said(k, tap)

    def _said(self, k: int, tap: _Tap) -> None:
        qos = tap["qos"]
        assert qos is not None  # said only once the subscription is made
        emit(wire.json_frame({"what": "tap", "id": k, "reliable": qos[0], "depth": TAP_DEPTH,
                               "durability": "transient_local" if qos[1] else "volatile",
                               "heard": tap["heard"], "changes": tap["changes"]}))

    def drain(self) -> int:
        """Take what waits in each tap's subscription (at most :data:`TAKE_MAX` each), as the executor
        would one message per wake-up, and queue its frames; the number taken.  An rclpy without
        ``take_message`` on its subscription handle leaves them to the executor (0)."""
        taken = 0
        for k, tap in self.taps.items():
            sub = tap["sub"]
            if sub is None:
                continue
            on_message = _handler(k)
            try:
                with sub.handle:
                    for _ in range(TAKE_MAX):
                        got = sub.handle.take_message(sub.msg_type, True)
                        if got is None:
                            break
                        on_message(got[0], got[1])
                        taken += 1
            except (AttributeError, TypeError):  # an rclpy whose handle takes otherwise: the executor's callbacks
                return taken
        return taken

    def close(self) -> None:
        self.node.destroy_node()
        rclpy.try_shutdown()


#: samples taken so far (the executor's callbacks and :meth:`Agent.drain`'s), for the round's linger
_TAKEN = [0]


def _handler(k: int) -> Any:
    def on_message(raw: bytes, info: dict[str, Any]) -> None:
        _TAKEN[0] += 1
        gid = (info.get("publisher_gid") or {}).get("data") or b""
        # receipt: when the agent takes the message (as the DDS bus stamps it), never rmw's own receipt stamp: the
        # executor takes each subscription's messages in turn, so rmw's stamps would go back and forth across
        # topics in the order the monitor is handed them (measured: 40 % of verdicts then waited for a later tick)
        received = time.time_ns()
        emit(wire.sample_frame(k, int(info.get("source_timestamp") or 0), received,
                                int(info.get("publication_sequence_number") or 0), bytes(gid), raw))
    return on_message


def main() -> int:
    if len(sys.argv) == 3 and sys.argv[1] == "--graph":  # ``ros diff --ros2 --source rclpy``: one dump, then exit
        emit(wire.json_frame(graph_dump(float(sys.argv[2]))))
        flush()
        return 0
    if len(sys.argv) >= 2 and sys.argv[1] == "--describe":  # this Python's own descriptions of the types named
        found = {t: installed_description(t) for t in sys.argv[2:]}
        emit(wire.json_frame({"what": "descriptions", "types": {
            t: None if f is None else {"hash": f[0], "description": f[1], "from": f[2]} for t, f in found.items()}}))
        flush()
        return 0
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    sys.setswitchinterval(SWITCH_INTERVAL_S)
    q: queue.Queue[Command | None] = queue.Queue()
    try:
        agent = Agent()
    except Exception as exc:  # noqa: BLE001 - said to the monitor as one line
        emit(wire.json_frame({"what": "error", "text": f"rclpy could not start: {type(exc).__name__}: {exc}"}))
        flush()
        return 1
    wake = agent.node.create_guard_condition(lambda: None)  # a command ends the executor's wait at once
    threading.Thread(target=read_commands, args=(q, wake, agent), daemon=True).start()
    agent.hello()
    flush()
    started = False
    linger = LINGER_S
    next_graph = 0.0
    try:
        while True:
            try:
                while True:
                    c = q.get_nowait() if started else q.get(timeout=0.05)
                    if c is None:
                        flush()
                        return 0
                    if c.get("op") == "stop":  # every sample taken is handed over: said, then the node leaves
                        emit(wire.json_frame({"what": "stopped"}))
                        flush()
                        return 0
                    if c.get("op") == "start":
                        started = True
                        linger = float(c.get("linger", LINGER_S))
                    agent.command(c)
            except queue.Empty:
                pass
            if not started:
                continue
            now = time.monotonic()
            if now >= next_graph:
                agent.update()
                next_graph = now + GRAPH_PERIOD_S
            if agent.asked:
                agent.describing()
            flush()
            before = _TAKEN[0]
            agent.ex.spin_once(timeout_sec=GRAPH_PERIOD_S)
            while agent.drain() >= TAKE_MAX:  # a backlog: taken in rounds, each round's frames written at once
                flush()
            flush()
            if _TAKEN[0] > before:  # messages come: let the next ones gather (module docstring)
                time.sleep(linger)
    finally:
        agent.close()


if __name__ == "__main__":
    sys.exit(main())
