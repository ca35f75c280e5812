"""The live monitor's rclpy agent: run in a ROS 2 Python, it hears the
robot through rclpy on whatever middleware the robot runs (Fast DDS,
Cyclone DDS, Zenoh) and hands the monitor what it hears.

Run as a script (``python agent.py``) by :mod:`.bus`; it imports rclpy
and the standard library only (and :mod:`wire`, beside it), never
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
  verdicts), written with serialized messages the monitor made.
* **Type descriptions** (``{"op": "describe", "type", "hash", "node",
  "ns"}``): the definition a publisher declares, as a type description
  (type_description_interfaces/msg/TypeDescription as a dict), for a
  publisher whose type hash is not the monitor's.  First rosidl's own
  description of the type in this Python (``share/<pkg>/msg/<T>.json``,
  written beside the interface when it was built), when its hash is the
  one asked (sha256 of the same description: the same definition); else
  the publisher's node's type description service
  (``<node>/get_type_description``, REP-2011, from Iron on), waited for
  at most :data:`DESCRIBE_TIMEOUT_S`.  Answered by one ``description``
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

Long module: it runs as one script in another Python (a ROS 2 installation's),
importing rclpy, the standard library and :mod:`wire` beside it only, so the
taps, the graph, the services' ends and the type descriptions it serves live
in one file that any ROS 2 Python can run.
"""
from __future__ import annotations

import base64
import importlib
import json
import os
import queue
import signal
import sys
import threading
import time
from typing import Any, TypedDict

from importlib.metadata import version

import rclpy
from rclpy.action import graph as action_graph
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions
from rclpy.utilities import get_rmw_implementation_identifier

import wire  # type: ignore[import-not-found]  # beside this script (module docstring)

GRAPH_PERIOD_S = 0.1
#: seconds between two readings of the services' and actions' servers and clients (one query per node each)
SERVICE_PERIOD_S = 0.5
#: seconds a publisher's node has to answer a type description request (its service found, then the answer)
DESCRIBE_TIMEOUT_S = 5.0


#: the most messages taken from one tap's subscription in one round (:meth:`Agent.drain`), so a busy topic
#: does not hold the others back
TAKE_MAX = 1000
#: the history depth of each tap's subscription (keep-last; a ROS 2 topic is keyless, so samples of the
#: topic): at 5000 messages/s over three
#: topics, about 6 s of one topic's messages, should the agent be held off the CPU or its pipe be full
TAP_DEPTH = 10_000

_out: list[bytes] = []


def _emit(frame: bytes) -> None:
    """Queue one frame for the monitor; :func:`_flush` writes the queued frames, in order."""
    _out.append(frame)


def _flush() -> None:
    """Write every queued frame to stdout in one write (one system call for a batch of samples)."""
    if not _out:
        return
    data = b"".join(_out)
    _out.clear()
    view = memoryview(data)
    while view:
        view = view[os.write(1, view):]


def _class(type_name: str) -> Any:
    """The message class of ``pkg/kind/Name``; an action's feedback message
    (``pkg/action/A_FeedbackMessage``) is ``A.Impl.FeedbackMessage`` in rosidl's Python."""
    pkg, kind, name = type_name.strip("/").split("/")
    module = importlib.import_module(f"{pkg}.{kind}")
    if not hasattr(module, name) and kind == "action" and "_" in name:
        base, _, part = name.rpartition("_")
        return getattr(getattr(module, base).Impl, part)
    return getattr(module, name)


class _Command(TypedDict, total=False):
    """One command line of the monitor (module docstring): ``op`` and the keys of that op."""
    op: str
    id: int
    topic: str
    type: str
    name: str
    action: bool
    depth: int
    reliable: bool
    transient_local: bool
    raw: str
    hash: str
    node: str
    ns: str


class _Endpoint(TypedDict):
    """One endpoint of rclpy's graph as the monitor reads it (:func:`_endpoint`)."""
    gid: str
    node: str
    ns: str
    type: str
    hash: str
    reliable: bool
    durability: str
    #: the offered (publisher) or requested (subscription) deadline and liveliness lease in ns, as
    #: rmw reports them (``RMW_DURATION_INFINITE``, 2**63 - 1, for none), and the liveliness kind's name
    deadline_ns: int
    liveliness: str
    lease_ns: int


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


def _commands(q: queue.Queue[_Command | None], wake: Any) -> None:
    """Queue each command line, and wake the executor (a guard condition) so it is done at once."""
    for line in sys.stdin:
        if line.strip():
            q.put(json.loads(line))
            wake.trigger()
    q.put(None)
    wake.trigger()


class Agent:
    """The agent's state: its node, taps and writers (module docstring)."""

    def __init__(self) -> None:
        rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
        self.name = f"_rclverify_monitor_{os.getpid()}"
        self.node = Node(self.name)
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
        _emit(wire.json_frame({"what": "hello", "rmw": get_rmw_implementation_identifier(),
                               "distro": os.environ.get("ROS_DISTRO", ""), "rclpy": rclpy_version,
                               "python": sys.version.split()[0], "node": self.name}))

    # -- commands ------------------------------------------------------------------------------
    def command(self, c: _Command) -> None:
        op = c.get("op")
        if op == "tap":
            try:
                cls = _class(c["type"])
            except Exception as exc:  # noqa: BLE001 - said to the monitor, the tap stays deaf
                _emit(wire.json_frame({"what": "error", "id": c["id"], "text": f"{type(exc).__name__}: {exc}"}))
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
            self.writers[int(c["id"])] = self.node.create_publisher(_class(c["type"]), c["topic"], qos)
        elif op == "write":
            self.writers[int(c["id"])].publish(base64.b64decode(c["raw"]))
        elif op == "describe":
            self.describe(c["type"], c["hash"], c.get("node", ""), c.get("ns", "/"))

    # -- type descriptions ---------------------------------------------------------------------
    def describe(self, type_name: str, type_hash: str, node: str, ns: str) -> None:
        """Find the description of ``type_name`` whose hash is ``type_hash`` (module docstring): this
        Python's own when its hash is that one (said at once), else ask ``node``'s service (said by
        :meth:`describing` when it answers or :data:`DESCRIBE_TIMEOUT_S` passed)."""
        failures: list[str] = []
        own = installed_description(type_name)
        if own is not None and own[0] == type_hash:
            _emit(_description_frame(type_name, type_hash, [{"from": own[2], "description": own[1]}], []))
            return
        if own is not None:
            failures.append(f"{own[2]} has the type hash {own[0]}")
        else:
            failures.append(f"this ROS 2 Python has no rosidl description of {type_name}")
        if not node:
            _emit(_description_frame(type_name, type_hash, [], failures + ["the publisher's node is not known"]))
            return
        try:
            self.asked[(type_name, type_hash)] = self.ask_service(type_name, type_hash, node, ns)
        except Exception as exc:  # noqa: BLE001 - a ROS 2 without type_description_interfaces: said
            _emit(_description_frame(type_name, type_hash, [], failures + [
                f"the type description service cannot be called ({type(exc).__name__}: {exc})"]))
            return
        self.asked[(type_name, type_hash)]["failures"] = failures

    def ask_service(self, type_name: str, type_hash: str, node: str, ns: str) -> dict[str, Any]:
        """A request of ``type_name``'s description (hash ``type_hash``) to the type description
        service of node ``ns``/``node``: its state, which :meth:`step_request` moves on.  Raises
        ``ImportError`` where this ROS 2 has no ``type_description_interfaces`` (before Iron)."""
        from type_description_interfaces.srv import GetTypeDescription  # type: ignore[import-not-found]  # deferred: Iron and later only
        service = ns.rstrip("/") + "/" + node + "/get_type_description"
        client = self.node.create_client(GetTypeDescription, service)
        request = GetTypeDescription.Request(type_name=type_name, type_hash=type_hash, include_type_sources=False)
        return {"client": client, "request": request, "future": None, "service": service, "failures": [],
                "deadline": time.monotonic() + DESCRIBE_TIMEOUT_S}

    def step_request(self, state: dict[str, Any]) -> dict[str, Any] | None:
        """Move one service request on: send it once the service is found; ``None`` while it
        waits, else ``{"candidates": [...], "failures": [...]}`` (the client then destroyed)."""
        fut = state["future"]
        done: dict[str, Any] | None = None
        origin = f"the type description service {state['service']}"
        if fut is None and state["client"].service_is_ready():
            state["future"] = fut = state["client"].call_async(state["request"])
        if fut is not None and fut.done():
            exc = fut.exception()
            answer = None if exc is not None else fut.result()
            if answer is not None and answer.successful:
                done = {"candidates": [{"from": origin, "description": _description_dict(answer.type_description)}],
                        "failures": []}
            else:
                why = answer.failure_reason if answer is not None else f"{type(exc).__name__}: {exc}"
                done = {"candidates": [], "failures": [f"{origin} answered: {why}"]}
        elif time.monotonic() >= state["deadline"]:
            done = {"candidates": [], "failures": [f"{origin} did not answer within {DESCRIBE_TIMEOUT_S:g} s" + (
                "" if fut is not None else " (not found: a node from before Iron, or one started with "
                "start_type_description_service false)")]}
        if done is not None:
            self.node.destroy_client(state["client"])
        return done

    def describing(self) -> None:
        """Say each service request that is answered or out of time (:meth:`step_request`)."""
        for key, state in list(self.asked.items()):
            done = self.step_request(state)
            if done is not None:
                del self.asked[key]
                _emit(_description_frame(key[0], key[1], done["candidates"], state["failures"] + done["failures"]))

    # -- the graph -----------------------------------------------------------------------------
    def _publishers(self, topic: str) -> list[Any]:
        return [p for p in self.node.get_publishers_info_by_topic(topic)
                if not (p.node_name == self.name and p.node_namespace == "/")]

    def update(self) -> None:
        """Make or remake each tap's subscription for the publishers in the graph; report changes."""
        topics: dict[str, list[_Endpoint]] = {}
        for t in sorted({t["topic"] for t in self.taps.values()} | self.watched):
            topics[t] = [_endpoint(p) for p in self._publishers(t)]
        if self.services and time.monotonic() >= self.next_ends:
            self.ends = self._service_ends()
            self.next_ends = time.monotonic() + SERVICE_PERIOD_S
        graph = {"what": "graph", "topics": topics, "services": self.ends}
        if graph != self.last_graph:
            self.last_graph = graph
            _emit(wire.json_frame(graph))
        for k, tap in self.taps.items():
            same = [p for p in topics.get(tap["topic"], []) if p["type"] == tap["type"]]
            if not same or tap["cls"] is None:
                continue
            want = (all(p["reliable"] for p in same), all(p["durability"] == "transient_local" for p in same))
            heard = sorted(p["gid"] for p in same)
            if tap["sub"] is not None and _matches(tap["qos"], same):
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
            tap["sub"] = self.node.create_subscription(tap["cls"], tap["topic"], _handler(k), qos, raw=True)
            tap["qos"], tap["heard"] = want, heard
            self._said(k, tap)

    def _service_ends(self) -> dict[str, dict[str, list[str]]]:
        """Each watched service's or action's serving and calling nodes
        (``/ns/name``), and ``events``: the nodes that publish its
        introspection events (:func:`_introspecting`; a node whose
        introspection is off has no such publisher; whether one publishes
        metadata or contents its events tell the monitor)."""
        ends: dict[str, dict[str, set[str]]] = {n: {"servers": set(), "clients": set(), "events": set()}
                                                for n in self.services}
        for svc, is_action in self.services.items():
            ends[svc]["events"] = self._introspecting(svc, is_action)
        for name, ns in self.node.get_node_names_and_namespaces():
            if name == self.name and ns == "/":
                continue
            full = ns.rstrip("/") + "/" + name
            try:
                served = {s for s, _ in self.node.get_service_names_and_types_by_node(name, ns)}
                called = {s for s, _ in self.node.get_client_names_and_types_by_node(name, ns)}
                acts = {s for s, _ in action_graph.get_action_server_names_and_types_by_node(self.node, name, ns)}
                acts_c = {s for s, _ in action_graph.get_action_client_names_and_types_by_node(self.node, name, ns)}
            except Exception:  # noqa: BLE001 - a node that left between the two calls: read again next time
                continue
            for svc, is_action in self.services.items():
                if svc in (acts if is_action else served):
                    ends[svc]["servers"].add(full)
                if svc in (acts_c if is_action else called):
                    ends[svc]["clients"].add(full)
        return {n: {k: sorted(v) for k, v in e.items()} for n, e in ends.items()}

    def _introspecting(self, svc: str, is_action: bool) -> set[str]:
        """The nodes (``/ns/name``) that publish the introspection events of
        service ``svc`` (``<svc>/_service_event``), or of action ``svc``'s
        send-goal and get-result services both (a goal and its result)."""
        topics = ([f"{svc}/_action/send_goal/_service_event", f"{svc}/_action/get_result/_service_event"]
                  if is_action else [f"{svc}/_service_event"])
        found: set[str] | None = None
        for t in topics:
            nodes = {p.node_namespace.rstrip("/") + "/" + p.node_name for p in self._publishers(t)}
            found = nodes if found is None else found & nodes
        return found or set()

    def _said(self, k: int, tap: _Tap) -> None:
        qos = tap["qos"]
        assert qos is not None  # said only once the subscription is made
        _emit(wire.json_frame({"what": "tap", "id": k, "reliable": qos[0], "depth": TAP_DEPTH,
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


def _endpoint(p: Any) -> _Endpoint:
    """One endpoint of rclpy's graph (a ``TopicEndpointInfo``) as the monitor reads it."""
    return {"gid": bytes(p.endpoint_gid[:wire.GID_BYTES]).hex(), "node": p.node_name, "ns": p.node_namespace,
            "type": p.topic_type, "hash": str(p.topic_type_hash),
            "reliable": p.qos_profile.reliability == ReliabilityPolicy.RELIABLE,
            "durability": "transient_local" if p.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL
            else "volatile",
            "deadline_ns": int(p.qos_profile.deadline.nanoseconds), "liveliness": p.qos_profile.liveliness.name.lower(),
            "lease_ns": int(p.qos_profile.liveliness_lease_duration.nanoseconds)}


def _matches(qos: tuple[bool, bool] | None, pubs: list[_Endpoint]) -> bool:
    """Whether a subscription of ``qos`` (reliable, transient-local) matches every publisher of ``pubs``."""
    if qos is None:
        return False
    reliable, latched = qos
    return all((p["reliable"] or not reliable) and (p["durability"] == "transient_local" or not latched)
               for p in pubs)


def installed_description(type_name: str) -> tuple[str, dict[str, Any], str] | None:
    """``(type hash, type description, where)`` of ``type_name`` (``pkg/msg/T``) as rosidl wrote it
    for this Python (``share/<pkg>/msg/<T>.json``: ``type_description_msg`` and ``type_hashes``), from
    the package's share directory in the ament index, else under ``AMENT_PREFIX_PATH`` and this
    Python's prefix; ``None`` where there is none (or it does not describe ``type_name``)."""
    parts = type_name.strip("/").split("/")
    if len(parts) != 3:
        return None
    pkg, kind, name = parts
    shares = []
    try:
        from ament_index_python.packages import get_package_share_directory  # type: ignore[import-not-found]  # deferred: not in every ROS 2 Python
        shares.append(get_package_share_directory(pkg))
    except Exception:  # noqa: BLE001 - not indexed: the prefixes below
        pass
    prefixes = [p for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p] + [sys.prefix]
    shares += [os.path.join(p, "share", pkg) for p in prefixes]
    for share in shares:
        path = os.path.join(share, kind, name + ".json")
        try:
            with open(path, encoding="utf-8") as fh:
                doc = json.load(fh)
            desc = doc["type_description_msg"]
            if desc["type_description"]["type_name"] != type_name:
                continue
            found = next(h["hash_string"] for h in doc["type_hashes"] if h["type_name"] == type_name)
        except (OSError, ValueError, KeyError, TypeError, StopIteration):
            continue
        return str(found), desc, f"this ROS 2 Python's {pkg} ({path})"
    return None


def _description_dict(td: Any) -> dict[str, Any]:
    """A ``type_description_interfaces/msg/TypeDescription`` as the dict the monitor reads (rosidl's
    ``.json`` form)."""
    def one(d: Any) -> dict[str, Any]:
        return {"type_name": d.type_name, "fields": [
            {"name": f.name, "type": {"type_id": f.type.type_id, "capacity": f.type.capacity,
                                      "string_capacity": f.type.string_capacity,
                                      "nested_type_name": f.type.nested_type_name},
             "default_value": f.default_value} for f in d.fields]}
    return {"type_description": one(td.type_description),
            "referenced_type_descriptions": [one(r) for r in td.referenced_type_descriptions]}


def _description_frame(type_name: str, type_hash: str, candidates: list[dict[str, Any]],
                       failures: list[str]) -> bytes:
    frame: bytes = wire.json_frame({"what": "description", "type": type_name, "hash": type_hash,
                                    "candidates": candidates, "failures": failures})
    return frame


def _handler(k: int) -> Any:
    def on_message(raw: bytes, info: dict[str, Any]) -> None:
        gid = (info.get("publisher_gid") or {}).get("data") or b""
        # receipt: when the agent takes the message (as the DDS bus stamps it), never rmw's own receipt stamp: the
        # executor takes each subscription's messages in turn, so rmw's stamps would go back and forth across
        # topics in the order the monitor is handed them (measured: 40 % of verdicts then waited for a later tick)
        received = time.time_ns()
        _emit(wire.sample_frame(k, int(info.get("source_timestamp") or 0), received,
                                int(info.get("publication_sequence_number") or 0), bytes(gid), raw))
    return on_message


def graph_dump(wait_s: float, settle_s: float = 8.0, quiet_s: float = 1.5) -> dict[str, object]:
    """The whole graph as rclpy's graph API reports it, once it is settled:
    after ``wait_s`` seconds of discovery, and on (up to ``settle_s`` more)
    until it has not changed for ``quiet_s``.  Each node with its publishers,
    subscribers, service servers and clients (hidden names included: an
    action's services), and each topic's publishers and subscriptions (GID,
    node, type, reliability, durability, deadline, liveliness and its lease)."""
    rclpy.init()
    name = f"_rclverify_graph_{os.getpid()}"
    node = Node(name)

    def snapshot() -> dict[str, object]:
        nodes = []
        for n, ns in sorted(node.get_node_names_and_namespaces()):
            if n == name:
                continue
            nodes.append({"name": n, "ns": ns,
                          "pubs": node.get_publisher_names_and_types_by_node(n, ns),
                          "subs": node.get_subscriber_names_and_types_by_node(n, ns),
                          "servers": node.get_service_names_and_types_by_node(n, ns),
                          "clients": node.get_client_names_and_types_by_node(n, ns)})
        ends: dict[str, dict[str, list[_Endpoint]]] = {}
        for topic, _types in node.get_topic_names_and_types():
            ends[topic] = {role: [_endpoint(p) for p in infos if p.node_name != name]
                           for role, infos in (("pubs", node.get_publishers_info_by_topic(topic)),
                                               ("subs", node.get_subscriptions_info_by_topic(topic)))}
        return {"nodes": nodes, "endpoints": ends}

    start = time.monotonic()
    last, since = None, start
    while True:
        rclpy.spin_once(node, timeout_sec=0.1)
        now = time.monotonic()
        if now - start < wait_s:
            continue
        snap = snapshot()
        if snap != last:
            last, since = snap, now
        if now - since >= quiet_s or now - start >= wait_s + settle_s:
            break
    node.destroy_node()
    rclpy.try_shutdown()
    return {"what": "graph_all", "rmw": get_rmw_implementation_identifier(), **(last or {})}


def main() -> int:
    if len(sys.argv) == 3 and sys.argv[1] == "--graph":  # ``ros diff --ros2 --source rclpy``: one dump, then exit
        _emit(wire.json_frame(graph_dump(float(sys.argv[2]))))
        _flush()
        return 0
    if len(sys.argv) >= 2 and sys.argv[1] == "--describe":  # this Python's own descriptions of the types named
        found = {t: installed_description(t) for t in sys.argv[2:]}
        _emit(wire.json_frame({"what": "descriptions", "types": {
            t: None if f is None else {"hash": f[0], "description": f[1], "from": f[2]} for t, f in found.items()}}))
        _flush()
        return 0
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    q: queue.Queue[_Command | None] = queue.Queue()
    try:
        agent = Agent()
    except Exception as exc:  # noqa: BLE001 - said to the monitor as one line
        _emit(wire.json_frame({"what": "error", "text": f"rclpy could not start: {type(exc).__name__}: {exc}"}))
        _flush()
        return 1
    wake = agent.node.create_guard_condition(lambda: None)  # a command ends the executor's wait at once
    threading.Thread(target=_commands, args=(q, wake), daemon=True).start()
    agent.hello()
    _flush()
    started = False
    next_graph = 0.0
    try:
        while True:
            try:
                while True:
                    c = q.get_nowait() if started else q.get(timeout=0.05)
                    if c is None:
                        _flush()
                        return 0
                    if c.get("op") == "stop":  # every sample taken is handed over: said, then the node leaves
                        _emit(wire.json_frame({"what": "stopped"}))
                        _flush()
                        return 0
                    if c.get("op") == "start":
                        started = True
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
            _flush()
            agent.ex.spin_once(timeout_sec=GRAPH_PERIOD_S)
            while agent.drain() >= TAKE_MAX:  # a backlog: taken in rounds, each round's frames written at once
                _flush()
            _flush()
    finally:
        agent.close()


if __name__ == "__main__":
    sys.exit(main())
